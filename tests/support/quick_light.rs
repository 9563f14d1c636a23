//! Light settings for tests that need the light engine's behaviour, not its
//! precision: few rays and sun samples, so a bundled room lights in a
//! moment. Included by path by the core's and the Bevy layer's tests.

use heliodon_core::light::LightSettings;

pub fn quick_light() -> LightSettings {
    LightSettings {
        rays_per_patch: 64,
        rays_per_sensor: 512,
        sky_rays_per_sensor: 512,
        window_rays_per_sensor: 256,
        sun_samples_per_patch: 4,
        area_sensor_sun_grid: 4,
        ..Default::default()
    }
}
