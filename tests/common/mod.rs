//! Shared by the integration tests.

use std::path::PathBuf;

/// The `heliodon` executable of this build. It lives in the `heliodon-app`
/// package (app/), which `cargo test --workspace` (tools/test) builds with
/// the tests.
pub fn heliodon_exe() -> PathBuf {
    let test_exe = std::env::current_exe().expect("test executable path");
    let profile_dir = test_exe.parent().and_then(|deps| deps.parent()).expect("target/<profile>/deps");
    let path = profile_dir.join(format!("heliodon{}", std::env::consts::EXE_SUFFIX));
    assert!(path.exists(), "{} is missing: run the tests with `cargo test --workspace` (tools/test), which builds it", path.display());
    path
}
