//! `heliodon export-radiance`: the same scene, sky and sensors for Radiance.

use std::path::PathBuf;

use crate::cli::CliError;
use crate::cli::args::{SceneCase, load_for_command, sky_for};
use crate::panel::PanelCatalog;

#[derive(clap::Args, Debug)]
pub struct ExportArgs {
    #[command(flatten)]
    pub case: SceneCase,
    /// Folder to write scene.rad, sky.rad, sensors.pts, sensors.txt and run.sh into
    #[arg(long)]
    pub out: PathBuf,
}

/// Writes the Radiance model into `--out`.
pub fn run(args: &ExportArgs, panels: &PanelCatalog) -> Result<(), CliError> {
    let (case, spec) = (&args.case, args.case.sky.spec()?);
    let scene = load_for_command(&case.scene, panels, false)?;
    let when = case.when();
    let (position, sky) = sky_for(&scene, &spec, &case.sky.sky, when)?;
    let label = format!(
        "{} {} {} sky, sun altitude {:.4}°, azimuth {:.4}° (SPA)",
        when.date, when.time, case.sky.sky, position.altitude, position.azimuth
    );
    Ok(crate::radiance::export(&scene, &sky, &label, &args.out)?)
}
