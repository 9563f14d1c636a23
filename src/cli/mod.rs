//! The `heliodon` command line (the contract is `shared/interface.md`; the
//! README lists every flag): clap parses, each subcommand in
//! [`commands`] runs, and every failure leaves through one path
//! ([`CliError`]): one line on standard error, then its exit code.
//!
//! - [`args`]: flags shared by several commands (scene case, sky, format);
//! - [`commands`]: `view`, `info`, `sensors`, `export-radiance`, `render`,
//!   `sun`, `annual`.

pub mod args;
pub mod commands;
pub mod plot;
pub mod sweep_table;

use std::fmt;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use crate::panel::PanelCatalog;
use commands::annual::AnnualArgs;
use commands::export_radiance::ExportArgs;
use commands::render::RenderArgs;
use commands::sensors::SensorsArgs;
use commands::sun::SunArgs;
use commands::sweep::{MergeArgs, SweepArgs};
use commands::view::ViewArgs;

#[derive(Parser, Debug)]
#[command(
    name = "heliodon",
    version,
    about = "Daylighting design: sun, sky and interreflected light on building models",
    args_conflicts_with_subcommands = true,
    allow_negative_numbers = true
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
    /// Scene file (TOML) to open in the viewer; the bundled example when absent
    pub scene: Option<PathBuf>,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Open the interactive viewer
    #[command(allow_negative_numbers = true)]
    View(ViewArgs),
    /// Print a summary of a scene: geometry, patches, materials, windows, sensors, site
    Info {
        /// Scene file (TOML)
        scene: PathBuf,
    },
    /// Illuminance at the scene's sensors (lux): total, direct sun, direct sky, indirect
    #[command(allow_negative_numbers = true)]
    Sensors(SensorsArgs),
    /// Write a Radiance model of the scene, sky and sensors, with a run.sh that computes the sensors in Radiance
    #[command(name = "export-radiance", allow_negative_numbers = true)]
    ExportRadiance(ExportArgs),
    /// Draw a view of the scene lit by the sun and sky to a PNG, headless (any GPU or a software Vulkan driver)
    #[command(allow_negative_numbers = true)]
    Render(RenderArgs),
    /// Sun position (NREL SPA) for a site and a local standard time, or the day's sunrise, noon and sunset
    #[command(allow_negative_numbers = true)]
    Sun(SunArgs),
    /// A year of EPW weather at the sensors: DA300, UDI and ASE hours per sensor, the scene's sDA and ASE
    Annual(AnnualArgs),
    /// Vary one or two keys of a window material over a grid: the sensors' lux at an instant, or DA300 and sDA over a year
    #[command(allow_negative_numbers = true)]
    Sweep(SweepArgs),
    /// Join the CSV parts of a sharded sweep into the unsharded output
    #[command(name = "sweep-merge")]
    SweepMerge(MergeArgs),
}

/// Why a command failed: one line for standard error, and the exit code
/// (2 for flags that do not fit together, 1 for everything else).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CliError {
    pub message: String,
    pub code: u8,
}

impl CliError {
    /// A command that could not do its work (bad scene, unreadable file…): exit 1.
    pub fn failure(message: impl Into<String>) -> Self {
        Self { message: message.into(), code: 1 }
    }

    /// Flags that parse but do not fit together: exit 2, as clap's own errors.
    pub fn usage(message: impl Into<String>) -> Self {
        Self { message: message.into(), code: 2 }
    }
}

impl From<String> for CliError {
    fn from(message: String) -> Self {
        Self::failure(message)
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

/// Parses the command line and runs it; `panels` are the panel types every
/// scene may name (registered in every app it makes). The process's entry:
/// call it before starting any thread (it may set `XDG_RUNTIME_DIR`).
pub fn main(panels: PanelCatalog) -> ExitCode {
    give_a_private_runtime_dir();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(error) => {
            use clap::error::ErrorKind;
            if matches!(
                error.kind(),
                ErrorKind::DisplayHelp | ErrorKind::DisplayVersion | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
            ) {
                error.exit();
            }
            // clap's message on one line: what is wrong, without the usage and tips.
            let rendered = error.render().to_string();
            let message: Vec<&str> = rendered
                .lines()
                .take_while(|l| !l.starts_with("Usage:"))
                .map(str::trim)
                .filter(|l| !l.is_empty() && !l.starts_with("tip:") && !l.starts_with("For more information"))
                .collect();
            eprintln!("{} (see heliodon --help)", message.join(" "));
            return ExitCode::from(2);
        }
    };
    let done = |result: Result<(), CliError>| result.map(|()| ExitCode::SUCCESS);
    let outcome = match cli.command {
        None => commands::view::run(cli.scene, None, &panels),
        Some(Command::View(args)) => commands::view::run(args.scene.clone(), Some(&args), &panels),
        Some(Command::Info { scene }) => done(commands::info::run(&scene, &panels)),
        Some(Command::Sensors(args)) => done(commands::sensors::run(&args, &panels)),
        Some(Command::ExportRadiance(args)) => done(commands::export_radiance::run(&args, &panels)),
        Some(Command::Render(args)) => done(commands::render::run(&args, &panels)),
        Some(Command::Annual(args)) => done(commands::annual::run(&args, &panels)),
        Some(Command::Sweep(args)) => done(commands::sweep::run(&args, &panels)),
        Some(Command::SweepMerge(args)) => done(commands::sweep::merge(&args)),
        Some(Command::Sun(args)) => {
            commands::sun::run(&args);
            Ok(ExitCode::SUCCESS)
        }
    };
    outcome.unwrap_or_else(|error| {
        eprintln!("error: {error}");
        ExitCode::from(error.code)
    })
}

/// Mesa's Vulkan drivers print `error: XDG_RUNTIME_DIR is invalid or not
/// set in the environment` (once per probe) when the variable is missing,
/// though nothing is wrong and the run succeeds: without a usable one, this
/// process gets a private folder of its own (0700, what `tools/test`
/// does), so a successful run prints no error line.
fn give_a_private_runtime_dir() {
    #[cfg(target_os = "linux")]
    {
        use std::os::unix::fs::{DirBuilderExt, MetadataExt, PermissionsExt};
        if std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|dir| std::path::Path::new(&dir).is_dir()) {
            return;
        }
        let Ok(me) = std::fs::metadata("/proc/self").map(|m| m.uid()) else { return };
        let dir = std::env::temp_dir().join(format!("heliodon-runtime-{me}"));
        let _ = std::fs::DirBuilder::new().mode(0o700).create(&dir);
        // Only a folder that is ours and closed to others.
        let ours = std::fs::symlink_metadata(&dir).is_ok_and(|m| m.is_dir() && m.uid() == me && m.permissions().mode() & 0o077 == 0);
        if ours {
            // SAFETY: `main` runs first in the process, before any thread
            // that could read the environment is started.
            unsafe { std::env::set_var("XDG_RUNTIME_DIR", &dir) };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fixed-seed fuzzer over the flags: any sequence of words parses or
    /// gives clap's error, never a panic.
    #[test]
    fn random_flags_never_panic() {
        let words = [
            "sensors",
            "sun",
            "render",
            "info",
            "view",
            "export-radiance",
            "annual",
            "--weather",
            "--occupied",
            "--date",
            "--time",
            "--sky",
            "--dni",
            "--dhi",
            "--format",
            "--eye",
            "--target",
            "--fov",
            "--width",
            "--latitude",
            "--longitude",
            "--timezone",
            "--day",
            "2026-02-30",
            "24:00",
            "99999999:00",
            "-5",
            "nan",
            "1e39",
            "csv",
            "clear",
            "perez",
            "cie:16",
            "1,2",
            "1,2,3",
            "scene.toml",
            "",
            "--",
            "-",
        ];
        let mut state: u64 = 7;
        for _ in 0..2000 {
            let mut args = vec!["heliodon".to_string()];
            for _ in 0..(state % 9) {
                state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                args.push(words[((state >> 33) as usize) % words.len()].to_string());
            }
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            let parsed = std::panic::catch_unwind(|| Cli::try_parse_from(&args).map(|_| ()));
            assert!(parsed.is_ok(), "{args:?} panicked");
        }
    }
}
