//! The `heliodon` executable: the command line of the heliodon crate with
//! the built-in panels (plugins/) known to every scene it loads.

use std::process::ExitCode;

use heliodon::panel::PanelCatalog;

/// The built-in panels, registered the way any app registers panel types.
fn builtin_panels() -> PanelCatalog {
    PanelCatalog::new()
        .with(heliodon_prismatic::Prismatic)
        .with(heliodon_laser_cut::LaserCut)
        .with(heliodon_venetian::Venetian)
        .with(heliodon_bsdf::Bsdf)
}

fn main() -> ExitCode {
    heliodon::cli::main(builtin_panels())
}
