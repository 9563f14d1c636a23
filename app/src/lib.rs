//! What the `heliodon` executable adds to the heliodon crate: the built-in
//! panels (plugins/), registered the way any app registers panel types, for
//! the executable and its render benchmark alike.

use heliodon::panel::PanelCatalog;

/// The built-in panels.
pub fn builtin_panels() -> PanelCatalog {
    PanelCatalog::new()
        .with(heliodon_prismatic::Prismatic)
        .with(heliodon_laser_cut::LaserCut)
        .with(heliodon_venetian::Venetian)
        .with(heliodon_bsdf::Bsdf)
}
