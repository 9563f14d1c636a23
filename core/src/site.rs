//! The building's site: where on Earth it stands and what surrounds it.
//! Plain data shared by the scene loader, the sun position and the sky.

/// Geographic site of a scene, in the contract's conventions
/// (north-positive latitude, east-positive longitude, local standard time).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Site {
    /// Degrees, north positive.
    pub latitude: f64,
    /// Degrees, east positive (ISO 6709).
    pub longitude: f64,
    /// Hours from UTC of local standard time.
    pub timezone: f64,
    /// Metres above sea level.
    pub elevation: f64,
    /// Mean annual air pressure in millibars (for refraction).
    pub pressure: f64,
    /// Mean annual temperature in °C (for refraction).
    pub temperature: f64,
    /// Reflectance of the ground outside the model.
    pub ground_reflectance: f64,
    /// Where true north is, in degrees clockwise (seen from above) from the
    /// canonical +y: the designer turning the building on its site after
    /// loading. 0 from a scene file, whose `model.north` turns the geometry
    /// itself. Turning the sun and sky the other way is the same as turning
    /// the building, and needs no new precomputation.
    pub north_turn: f64,
}

impl Site {
    /// Sea level (metres), when the scene file gives no `site.elevation`.
    pub const DEFAULT_ELEVATION: f64 = 0.0;
    /// One standard atmosphere (millibars), for refraction when none is given.
    pub const DEFAULT_PRESSURE: f64 = 1013.25;
    /// °C, for refraction when none is given (pvlib's default).
    pub const DEFAULT_TEMPERATURE: f64 = 12.0;
    /// Ground albedo when none is given: gensky's and gendaylit's default.
    pub const DEFAULT_GROUND_REFLECTANCE: f64 = 0.2;

    /// A site with the contract's defaults for everything but its coordinates.
    pub fn new(latitude: f64, longitude: f64, timezone: f64) -> Self {
        Self {
            latitude,
            longitude,
            timezone,
            elevation: Self::DEFAULT_ELEVATION,
            pressure: Self::DEFAULT_PRESSURE,
            temperature: Self::DEFAULT_TEMPERATURE,
            ground_reflectance: Self::DEFAULT_GROUND_REFLECTANCE,
            north_turn: 0.0,
        }
    }
}
