//! The `heliodon` executable: the command line of the heliodon crate with
//! the built-in panels (plugins/) known to every scene it loads.

use std::process::ExitCode;

fn main() -> ExitCode {
    heliodon::cli::main(heliodon_app::builtin_panels())
}
