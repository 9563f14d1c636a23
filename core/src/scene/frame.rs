//! The model's frame: which axis is up, where north points and what a model
//! unit measures, mapped into heliodon's canonical frame (metres, x east,
//! y north, z up, as in Radiance).

use glam::{DVec3, Mat3, Vec3};

/// The model's vertical axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UpAxis {
    /// z is up, as in Radiance: north defaults to +y.
    Z,
    /// y is up, as many modellers export OBJ: north defaults to −z.
    Y,
}

impl UpAxis {
    /// Model-space up vector.
    pub fn vector(self) -> Vec3 {
        match self {
            UpAxis::Z => Vec3::Z,
            UpAxis::Y => Vec3::Y,
        }
    }

    /// The model's two horizontal axes in scene-file order (x then y for
    /// z-up models, x then z for y-up ones).
    pub fn horizontal_axes(self) -> [Vec3; 2] {
        match self {
            UpAxis::Z => [Vec3::X, Vec3::Y],
            UpAxis::Y => [Vec3::X, Vec3::Z],
        }
    }

    /// Default model-space north: +Y for z-up models, -Z for y-up ones.
    pub fn default_north(self) -> Vec3 {
        match self {
            UpAxis::Z => Vec3::Y,
            UpAxis::Y => Vec3::NEG_Z,
        }
    }

    /// The rotation that turns this up axis into +z (y-up: y → z, -z → y).
    fn to_z_up(self) -> Mat3 {
        match self {
            UpAxis::Z => Mat3::IDENTITY,
            UpAxis::Y => Mat3::from_cols(Vec3::X, Vec3::Z, Vec3::NEG_Y),
        }
    }
}

/// The mapping from model coordinates to canonical coordinates: a rotation
/// (up axis, then north about the vertical) after a uniform scale.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModelFrame {
    /// The model's vertical axis.
    pub up: UpAxis,
    /// Model-space direction of true north, as given.
    pub north: Vec3,
    /// Metres per model unit.
    pub scale: f32,
    /// The model-space point placed at the canonical origin: zero, or the
    /// centre of a model given in survey coordinates (recentred in f64
    /// before anything becomes f32, which keeps millimetres only near 0).
    pub origin: DVec3,
    rotation: Mat3,
}

impl Default for ModelFrame {
    fn default() -> Self {
        Self::new(UpAxis::Z, None, 1.0).expect("the default frame is valid")
    }
}

impl ModelFrame {
    /// Builds the frame; fails (with a message) when north is zero or vertical.
    pub fn new(up: UpAxis, north: Option<Vec3>, scale: f32) -> Result<Self, String> {
        let north = north.unwrap_or(up.default_north());
        let level = up.to_z_up() * north;
        let horizontal = Vec3::new(level.x, level.y, 0.0);
        if north.length() == 0.0 {
            return Err("north must not be the zero vector".into());
        }
        if horizontal.length() <= 1e-6 * north.length() {
            return Err("north must not be parallel to the up axis".into());
        }
        let angle = horizontal.x.atan2(horizontal.y);
        let rotation = Mat3::from_rotation_z(angle) * up.to_z_up();
        Ok(Self { up, north, scale, origin: DVec3::ZERO, rotation })
    }

    /// Where the scene file puts true north: degrees clockwise (seen from
    /// above) from the model's default north.
    pub fn north_angle(&self) -> f64 {
        let level = self.up.to_z_up() * self.north;
        f64::from(level.x.atan2(level.y).to_degrees())
    }

    /// A model-space point in canonical coordinates (relative to [`Self::origin`]).
    pub fn point(&self, p: DVec3) -> Vec3 {
        self.rotation * ((p - self.origin).as_vec3() * self.scale)
    }

    /// A model-space direction in canonical coordinates (unit length).
    pub fn direction(&self, d: Vec3) -> Vec3 {
        (self.rotation * d).normalize_or_zero()
    }

    /// A canonical point in model space: what [`Self::point`] undoes.
    pub fn model_point(&self, p: Vec3) -> [f64; 3] {
        ((self.rotation.transpose() * p).as_dvec3() / f64::from(self.scale) + self.origin).to_array()
    }

    /// A canonical direction in model space (unit length).
    pub fn model_direction(&self, d: Vec3) -> Vec3 {
        (self.rotation.transpose() * d).normalize_or_zero()
    }

    /// A model-space length in metres.
    pub fn length(&self, l: f32) -> f32 {
        l * self.scale
    }

    /// The model's horizontal axes in canonical coordinates.
    pub fn horizontal_axes(&self) -> [Vec3; 2] {
        self.up.horizontal_axes().map(|axis| self.direction(axis))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).length() < 1e-6
    }

    #[test]
    fn z_up_with_default_north_is_the_identity() {
        let frame = ModelFrame::new(UpAxis::Z, None, 1.0).unwrap();
        assert!(close(frame.point(DVec3::new(1.0, 2.0, 3.0)), Vec3::new(1.0, 2.0, 3.0)));
    }

    #[test]
    fn y_up_maps_up_to_z_and_minus_z_to_north() {
        let frame = ModelFrame::new(UpAxis::Y, None, 1.0).unwrap();
        assert!(close(frame.direction(Vec3::Y), Vec3::Z));
        assert!(close(frame.direction(Vec3::NEG_Z), Vec3::Y));
        assert!(close(frame.direction(Vec3::X), Vec3::X));
    }

    #[test]
    fn north_rotates_about_the_vertical_and_keeps_handedness() {
        // Model north along +x: the model's +x must become canonical +y (north),
        // and its +y (west of north in a right-handed frame) canonical -x.
        let frame = ModelFrame::new(UpAxis::Z, Some(Vec3::X), 2.0).unwrap();
        assert!(close(frame.direction(Vec3::X), Vec3::Y));
        assert!(close(frame.direction(Vec3::Y), Vec3::NEG_X));
        assert!(close(frame.point(DVec3::new(1.0, 0.0, 1.0)), Vec3::new(0.0, 2.0, 2.0)));
        let m = Mat3::from_cols(frame.direction(Vec3::X), frame.direction(Vec3::Y), frame.direction(Vec3::Z));
        assert!((m.determinant() - 1.0).abs() < 1e-6);
    }

    #[test]
    fn vertical_or_zero_north_is_rejected() {
        assert!(ModelFrame::new(UpAxis::Z, Some(Vec3::Z), 1.0).is_err());
        assert!(ModelFrame::new(UpAxis::Y, Some(Vec3::ZERO), 1.0).is_err());
    }
}
