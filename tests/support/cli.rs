//! The one runner of the `heliodon` executable for the tests of the app
//! package (Cargo builds the binary for them: `CARGO_BIN_EXE_heliodon`).
//! Included by path (`#[path = "../../tests/support/cli.rs"] mod cli;`).
//! Runs in the workspace root, so bundled scenes are `assets/scenes/…`.

use std::path::{Path, PathBuf};

/// What a run printed and how it ended.
pub struct Run {
    /// The exit status (-1 when killed by a signal).
    pub code: i32,
    pub out: String,
    pub err: String,
}

/// The workspace root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Runs `heliodon ARGS` with its light cache in `cache` (a test's own
/// folder, never the user's).
pub fn heliodon(args: &[&str], cache: &Path) -> Run {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_heliodon"))
        .args(args)
        .current_dir(root())
        .env("HELIODON_CACHE_DIR", cache)
        .output()
        .expect("run heliodon");
    Run {
        code: out.status.code().unwrap_or(-1),
        out: String::from_utf8_lossy(&out.stdout).into_owned(),
        err: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
}
