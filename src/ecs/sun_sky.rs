//! [`SunSkyPlugin`]: the site's clock and sky choice as resources; when any
//! of [`Site`], [`SolarTime`], [`SkyChoice`] or [`SkySubdivision`] changes,
//! recomputes the sun (SPA), the sky and its patch radiances into [`SunSky`]
//! and sends [`LightChanged`]. Nothing runs on frames where nothing changed.

use std::sync::Arc;

use bevy::prelude::*;

use super::{HeliodonSystems, Site};
use crate::sky::{Sky, SkyPatches, SkySpec, sky_at};
use crate::sun::SolarPosition;
use crate::time::{Date, LocalDateTime, TimeOfDay};

pub struct SunSkyPlugin;

impl Plugin for SunSkyPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<SolarTime>()
            .init_resource::<SkyChoice>()
            .init_resource::<SkySubdivision>()
            .add_message::<LightChanged>()
            .add_message::<SkyRejected>()
            .add_systems(
                Update,
                update_sun_and_sky.in_set(HeliodonSystems::UpdateSunSky).run_if(
                    resource_exists::<Site>.and_then(
                        resource_changed::<Site>
                            .or_eager(resource_changed::<SolarTime>)
                            .or_eager(resource_changed::<SkyChoice>)
                            .or_eager(resource_changed::<SkySubdivision>),
                    ),
                ),
            );
    }
}

/// The local standard date and time at the site.
#[derive(Resource, Debug, Clone, Copy, PartialEq)]
pub struct SolarTime(pub LocalDateTime);

impl Default for SolarTime {
    /// The March equinox at noon: a neutral first view.
    fn default() -> Self {
        Self(LocalDateTime { date: Date::new(2026, 3, 21).expect("valid date"), time: TimeOfDay::from_hours(12.0).expect("valid time") })
    }
}

/// The sky the user chose.
#[derive(Resource, Debug, Clone, PartialEq)]
pub struct SkyChoice(pub SkySpec);

impl Default for SkyChoice {
    fn default() -> Self {
        Self(SkySpec::Clear { turbidity: crate::sky::DEFAULT_TURBIDITY })
    }
}

/// Reinhart MF:n of the sky patches (1 is Tregenza's 145).
#[derive(Resource, Debug, Clone, Copy, PartialEq, Eq)]
pub struct SkySubdivision(pub u32);

impl Default for SkySubdivision {
    fn default() -> Self {
        Self(4)
    }
}

/// The sun and sky for the current site, time and sky choice.
#[derive(Resource, Debug, Clone)]
pub struct SunSky {
    /// The sun's true position (azimuth from true north). The light and the
    /// renderer use `sky.sun`, which is in the model's frame: turned by the
    /// site's `north_turn`.
    pub sun: SolarPosition,
    pub sky: Sky,
    pub patches: Arc<SkyPatches>,
    /// Mean radiance of each sky patch (sun excluded), W/sr/m².
    pub patch_radiance: Vec<f64>,
    /// Counts recomputations, so consumers can tell results apart.
    pub generation: u64,
}

/// The sun or sky changed: lighting that depends on them is stale.
#[derive(Message, Debug, Clone, Copy, PartialEq, Eq)]
pub struct LightChanged {
    pub generation: u64,
}

/// The chosen sky cannot be made for this sun (say, Perez light with the sun
/// down); the previous sun and sky stay. `message` is one line.
#[derive(Message, Debug, Clone, PartialEq)]
pub struct SkyRejected {
    pub message: String,
}

#[allow(clippy::too_many_arguments)]
fn update_sun_and_sky(
    mut commands: Commands,
    site: Res<Site>,
    time: Res<SolarTime>,
    choice: Res<SkyChoice>,
    subdivision: Res<SkySubdivision>,
    current: Option<ResMut<SunSky>>,
    mut changed: MessageWriter<LightChanged>,
    mut rejected: MessageWriter<SkyRejected>,
) {
    let (sun, sky) = sky_at(&site, &choice.0, &time.0);
    let sky = match sky {
        Ok(sky) => sky,
        Err(error) => {
            rejected.write(SkyRejected { message: error.0 });
            return;
        }
    };
    match current {
        Some(mut state) => {
            if state.patches.subdivision != subdivision.0 {
                state.patches = Arc::new(SkyPatches::reinhart(subdivision.0));
            }
            let SunSky { patches, patch_radiance, .. } = &mut *state;
            patches.integrate_into(&sky, patch_radiance);
            state.sun = sun;
            state.sky = sky;
            state.generation += 1;
            changed.write(LightChanged { generation: state.generation });
        }
        None => {
            let patches = Arc::new(SkyPatches::reinhart(subdivision.0));
            let patch_radiance = patches.integrate(&sky);
            commands.insert_resource(SunSky { sun, sky, patches, patch_radiance, generation: 0 });
            changed.write(LightChanged { generation: 0 });
        }
    }
}
