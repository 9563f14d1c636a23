//! Complex fenestration systems: the panel API (thesis sections 1.2, 3.4).
//!
//! A panel turns light arriving from one direction into a few specular
//! lobes (outgoing direction, share of the incoming flux, angular width)
//! plus diffuse transmission and reflection. A [`PanelType`] builds a
//! [`PanelModel`] from a material's own keys in the scene file; panel types
//! are registered by name in a [`PanelCatalog`] (in the app, by a Bevy
//! plugin through [`crate::ecs::PanelRegistry`]). The built-in panels live in
//! `plugins/`, one crate each, written as any modder would write one.
//!
//! Directions are in the panel's frame: z is the window's normal pointing
//! into the room (light from outside travels with z > 0), y is the panel's
//! `up` in its plane, x = y × z. Directions are the way light travels.
//! Plain Rust, no Bevy types.

use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::DVec3;

/// One specular lobe of a panel's response.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lobe {
    /// Unit direction the light leaves along (panel frame).
    pub direction: DVec3,
    /// Share of the incoming flux (0-1).
    pub share: f64,
    /// Angular width: the full angle of the cone it spreads over, degrees.
    pub width: f64,
}

/// What a panel does to light arriving from one direction: shares of the
/// incoming flux. Lobes with z > 0 are transmitted, z < 0 reflected. The
/// parts add up to 1.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PanelResponse {
    pub lobes: Vec<Lobe>,
    /// Transmitted diffusely (spread as a Lambertian emitter into the room).
    pub diffuse_transmittance: f64,
    /// Reflected diffusely back outside.
    pub diffuse_reflectance: f64,
    /// Absorbed in the panel (or guided inside it to its edges).
    pub absorbed: f64,
}

impl PanelResponse {
    /// Everything that leaves the panel: lobes and diffuse parts.
    pub fn total(&self) -> f64 {
        self.lobes.iter().map(|l| l.share).sum::<f64>() + self.diffuse_transmittance + self.diffuse_reflectance
    }

    /// What enters the room: transmitted lobes and diffuse transmission.
    pub fn transmitted(&self) -> f64 {
        self.lobes.iter().filter(|l| l.direction.z > 0.0).map(|l| l.share).sum::<f64>() + self.diffuse_transmittance
    }
}

/// A panel with its parameters: the response to any incoming direction.
pub trait PanelModel: Send + Sync + fmt::Debug {
    /// The response to light travelling along `incoming` (unit, panel frame;
    /// z > 0 for light from outside).
    fn response(&self, incoming: DVec3) -> PanelResponse;
}

/// A kind of panel, registered by name: builds models from scene-file keys.
pub trait PanelType: Send + Sync {
    /// The name scene files give as `panel = "..."`.
    fn name(&self) -> &str;
    /// The keys this panel takes, for error messages and the UI.
    fn keys(&self) -> &[&str];
    /// A model from a material's keys; a bad or missing key is an error
    /// naming it.
    fn build(&self, parameters: &Parameters) -> Result<Arc<dyn PanelModel>, ParameterError>;
}

/// A problem with one of a panel's keys.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ParameterError {
    pub key: String,
    pub message: String,
}

impl ParameterError {
    pub fn new(key: &str, message: impl Into<String>) -> Self {
        Self { key: key.to_string(), message: message.into() }
    }
}

/// A panel material's own keys (everything but `kind`, `panel` and `up`),
/// with typed, range-checked access. Relative paths resolve against the
/// scene file's folder.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Parameters {
    pub values: toml::Table,
    pub base_dir: PathBuf,
}

impl Parameters {
    pub fn new(values: toml::Table, base_dir: impl Into<PathBuf>) -> Self {
        Self { values, base_dir: base_dir.into() }
    }

    /// Keys written as in a scene file, for tests and tools.
    pub fn from_toml(text: &str, base_dir: impl Into<PathBuf>) -> Result<Self, String> {
        Ok(Self::new(text.parse::<toml::Table>().map_err(|e| e.to_string())?, base_dir))
    }

    fn as_number(key: &str, value: &toml::Value) -> Result<f64, ParameterError> {
        let v = match value {
            toml::Value::Float(f) => *f,
            toml::Value::Integer(i) => *i as f64,
            _ => return Err(ParameterError::new(key, "must be a number")),
        };
        if v.is_finite() { Ok(v) } else { Err(ParameterError::new(key, "must be finite")) }
    }

    fn check_range(key: &str, v: f64, (lo, hi): (f64, f64)) -> Result<f64, ParameterError> {
        if (lo..=hi).contains(&v) { Ok(v) } else { Err(ParameterError::new(key, format!("{v} is outside {lo}..{hi}"))) }
    }

    /// A number within `range`; `default` when absent (`None`: required).
    pub fn number(&self, key: &str, default: Option<f64>, range: (f64, f64)) -> Result<f64, ParameterError> {
        match (self.values.get(key), default) {
            (Some(value), _) => Self::check_range(key, Self::as_number(key, value)?, range),
            (None, Some(default)) => Ok(default),
            (None, None) => Err(ParameterError::new(key, "is required")),
        }
    }

    /// Exactly `N` numbers, each within `range`.
    pub fn numbers<const N: usize>(&self, key: &str, default: Option<[f64; N]>, range: (f64, f64)) -> Result<[f64; N], ParameterError> {
        let Some(value) = self.values.get(key) else {
            return default.ok_or_else(|| ParameterError::new(key, "is required"));
        };
        let toml::Value::Array(items) = value else { return Err(ParameterError::new(key, format!("must be a list of {N} numbers"))) };
        if items.len() != N {
            return Err(ParameterError::new(key, format!("must be a list of {N} numbers, not {}", items.len())));
        }
        let mut out = [0.0; N];
        for (slot, item) in out.iter_mut().zip(items) {
            *slot = Self::check_range(key, Self::as_number(key, item)?, range)?;
        }
        Ok(out)
    }

    /// A whole number within `range`.
    pub fn count(&self, key: &str, default: Option<i64>, range: (i64, i64)) -> Result<i64, ParameterError> {
        match (self.values.get(key), default) {
            (Some(toml::Value::Integer(i)), _) if (range.0..=range.1).contains(i) => Ok(*i),
            (Some(toml::Value::Integer(i)), _) => Err(ParameterError::new(key, format!("{i} is outside {}..{}", range.0, range.1))),
            (Some(_), _) => Err(ParameterError::new(key, "must be a whole number")),
            (None, Some(default)) => Ok(default),
            (None, None) => Err(ParameterError::new(key, "is required")),
        }
    }

    /// A file path, relative to the scene file's folder.
    pub fn path(&self, key: &str) -> Result<PathBuf, ParameterError> {
        match self.values.get(key) {
            Some(toml::Value::String(s)) if !s.is_empty() => Ok(self.base_dir.join(s)),
            Some(_) => Err(ParameterError::new(key, "must be a file name")),
            None => Err(ParameterError::new(key, "is required")),
        }
    }

    /// The first key that `panel` does not take.
    pub fn unknown_key(&self, known: &[&str]) -> Option<&str> {
        self.values.keys().map(String::as_str).find(|k| !known.contains(k))
    }
}

/// The registered panel types by name.
#[derive(Clone, Default)]
pub struct PanelCatalog {
    types: BTreeMap<String, Arc<dyn PanelType>>,
}

impl fmt::Debug for PanelCatalog {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_list().entries(self.types.keys()).finish()
    }
}

impl PanelCatalog {
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a panel type; a later registration of the same name replaces it.
    pub fn register(&mut self, panel: Arc<dyn PanelType>) {
        self.types.insert(panel.name().to_string(), panel);
    }

    pub fn get(&self, name: &str) -> Option<&Arc<dyn PanelType>> {
        self.types.get(name)
    }

    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.types.keys().map(String::as_str)
    }

    pub fn is_empty(&self) -> bool {
        self.types.is_empty()
    }

    /// Builds the model of a panel material: the type's own checks, plus
    /// unknown keys refused.
    pub fn build(&self, name: &str, parameters: &Parameters) -> Result<Arc<dyn PanelModel>, ParameterError> {
        let panel = self.get(name).ok_or_else(|| ParameterError::new("panel", format!("no panel named '{name}' is registered")))?;
        if let Some(key) = parameters.unknown_key(panel.keys()) {
            return Err(ParameterError::new(key, format!("is not a key of panel '{name}' (its keys: {})", panel.keys().join(", "))));
        }
        panel.build(parameters)
    }
}

/// A built panel model shared by a material; equal when it is the same model.
#[derive(Clone)]
pub struct PanelHandle(pub Arc<dyn PanelModel>);

impl fmt::Debug for PanelHandle {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.0.fmt(f)
    }
}

impl PartialEq for PanelHandle {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}

/// Fresnel reflectance of unpolarised light from a medium of index `n1`
/// into `n2` at incidence cosine `cos_i` (total internal reflection gives 1).
pub fn fresnel_reflectance(n1: f64, n2: f64, cos_i: f64) -> f64 {
    let cos_i = cos_i.abs().min(1.0);
    let sin_t = n1 / n2 * (1.0 - cos_i * cos_i).sqrt();
    if sin_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin_t * sin_t).sqrt();
    let rs = ((n1 * cos_i - n2 * cos_t) / (n1 * cos_i + n2 * cos_t)).powi(2);
    let rp = ((n1 * cos_t - n2 * cos_i) / (n1 * cos_t + n2 * cos_i)).powi(2);
    0.5 * (rs + rp)
}

/// Snell refraction of unit `direction` at a surface with unit `normal`
/// (either side) from index `n1` into `n2`; `None` on total internal
/// reflection.
pub fn refract(direction: DVec3, normal: DVec3, n1: f64, n2: f64) -> Option<DVec3> {
    let normal = if direction.dot(normal) > 0.0 { -normal } else { normal };
    let cos_i = -direction.dot(normal);
    let eta = n1 / n2;
    let k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
    (k >= 0.0).then(|| (eta * direction + (eta * cos_i - k.sqrt()) * normal).normalize())
}

/// Mirror reflection of `direction` at a surface with unit `normal`.
pub fn reflect(direction: DVec3, normal: DVec3) -> DVec3 {
    direction - 2.0 * direction.dot(normal) * normal
}

/// Where a panel's data files are looked up from: the scene file's folder.
pub fn base_dir(scene_file: &Path) -> PathBuf {
    scene_file.parent().map(Path::to_path_buf).unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn snell_and_total_internal_reflection() {
        // 30° in air into n = 1.5: sin θt = 0.5 / 1.5.
        let d = DVec3::new(30f64.to_radians().sin(), 0.0, 30f64.to_radians().cos());
        let t = refract(d, DVec3::Z, 1.0, 1.5).unwrap();
        assert!((t.x - 0.5 / 1.5).abs() < 1e-12 && t.z > 0.0);
        // Out of n = 1.5 beyond the critical angle (41.8°): reflected.
        let d = DVec3::new(45f64.to_radians().sin(), 0.0, 45f64.to_radians().cos());
        assert!(refract(d, DVec3::Z, 1.5, 1.0).is_none());
        assert_eq!(fresnel_reflectance(1.5, 1.0, 45f64.to_radians().cos()), 1.0);
        // Normal incidence: ((n-1)/(n+1))² = 0.04.
        assert!((fresnel_reflectance(1.0, 1.5, 1.0) - 0.04).abs() < 1e-12);
    }

    #[test]
    fn parameters_are_checked_by_key() {
        let values: toml::Table = toml::from_str("a = 1.5\nb = [1.0, 2.0]\nc = \"x\"\nn = 3").unwrap();
        let p = Parameters::new(values, "/scenes");
        assert_eq!(p.number("a", None, (1.0, 2.0)), Ok(1.5));
        assert_eq!(p.number("a", None, (2.0, 3.0)).unwrap_err().key, "a");
        assert_eq!(p.number("missing", Some(4.0), (0.0, 5.0)), Ok(4.0));
        assert!(p.number("missing", None, (0.0, 5.0)).unwrap_err().message.contains("required"));
        assert_eq!(p.numbers::<2>("b", None, (0.0, 3.0)), Ok([1.0, 2.0]));
        assert!(p.numbers::<3>("b", None, (0.0, 3.0)).is_err());
        assert!(p.number("c", None, (0.0, 1.0)).unwrap_err().message.contains("number"));
        assert_eq!(p.path("c"), Ok(PathBuf::from("/scenes/x")));
        assert_eq!(p.count("n", None, (1, 5)), Ok(3));
        assert_eq!(p.unknown_key(&["a", "b", "c"]), Some("n"));
    }
}
