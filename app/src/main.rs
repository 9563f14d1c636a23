//! The `heliodon` executable: the command line of the heliodon crate with
//! the built-in panels (plugins/) registered in every app it makes.

use std::process::ExitCode;

use heliodon::bevy::prelude::App;

/// The built-in panels, added the way any app adds panel plugins.
fn add_builtin_panels(app: &mut App) {
    app.add_plugins((
        heliodon_prismatic::PrismaticPlugin,
        heliodon_laser_cut::LaserCutPlugin,
        heliodon_venetian::VenetianPlugin,
        heliodon_bsdf::BsdfPlugin,
    ));
}

fn main() -> ExitCode {
    heliodon::cli::main(add_builtin_panels)
}
