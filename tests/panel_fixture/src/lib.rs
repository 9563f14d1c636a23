//! A panel plugin used only by tests, written as a modder would: `panel =
//! "grey_filter"` passes a share of the light straight through, unchanged
//! in direction (`transmittance`, required, 0-1), and absorbs the rest; it
//! returns `back_reflectance` (0-1, default 0) of the room's light to it.

use std::sync::Arc;

use heliodon_core::glam::DVec3;
use heliodon_core::panel::{Key, Lobe, PanelModel, PanelResponse, PanelType, ParameterError, Parameters};

pub struct GreyFilter;

const TRANSMITTANCE: Key = Key::number("transmittance", "share passed straight through", (0.0, 1.0), 0.5).required();
const BACK_REFLECTANCE: Key = Key::number("back_reflectance", "share of the room's light reflected back", (0.0, 1.0), 0.0);

impl PanelType for GreyFilter {
    fn name(&self) -> &str {
        "grey_filter"
    }

    fn keys(&self) -> &[Key] {
        &[TRANSMITTANCE, BACK_REFLECTANCE]
    }

    fn build(&self, parameters: &Parameters) -> Result<Arc<dyn PanelModel>, ParameterError> {
        Ok(Arc::new(GreyFilterModel {
            transmittance: parameters.number(&TRANSMITTANCE)?,
            back_reflectance: parameters.number(&BACK_REFLECTANCE)?,
        }))
    }
}

#[derive(Debug)]
pub struct GreyFilterModel {
    transmittance: f64,
    back_reflectance: f64,
}

impl PanelModel for GreyFilterModel {
    fn response(&self, incoming: DVec3) -> PanelResponse {
        PanelResponse {
            lobes: vec![Lobe { direction: incoming.normalize(), share: self.transmittance, width: 0.0 }],
            diffuse_transmittance: 0.0,
            diffuse_reflectance: 0.0,
            absorbed: 1.0 - self.transmittance,
        }
    }

    fn back_reflectance(&self) -> f64 {
        self.back_reflectance
    }
}
