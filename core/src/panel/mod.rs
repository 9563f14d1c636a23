//! Complex fenestration systems: the panel API (thesis sections 1.2, 3.4).
//!
//! A panel turns light arriving from one direction into a few specular
//! lobes (outgoing direction, share of the incoming flux, angular width)
//! plus diffuse transmission and reflection. A [`PanelType`] builds a
//! [`PanelModel`] from a material's own keys in the scene file; panel types
//! are registered by name in a [`PanelCatalog`] (in a Bevy app, with
//! `heliodon::ecs::RegisterPanel`, a one-liner). A panel crate depends on
//! this crate only, never on Bevy. The built-in panels live in `plugins/`,
//! one crate each, written as any modder would write one.
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
    /// The light engine (and the renderer with it) spreads a lobe of 4° or
    /// more over that cone as three beams; a narrower one is one beam.
    pub width: f64,
}

/// What a panel does to light arriving from one direction: shares of the
/// incoming flux. Lobes with z > 0 are transmitted, z < 0 reflected. The
/// parts add up to 1.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PanelResponse {
    /// The specular lobes: transmitted into the room (z > 0) or reflected back
    /// out (z < 0).
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

    /// The share of the room's light falling on the panel that it reflects
    /// back into the room (diffusely, averaged over the hemisphere): blinds
    /// return a good part of it. 0 by default: it all leaves or is absorbed.
    fn back_reflectance(&self) -> f64 {
        0.0
    }

    /// The measured data the model was fitted to, as a file Radiance reads
    /// with its `BSDF` material (LBNL BSDF XML): `export-radiance` then
    /// lets Radiance compute with the data itself, not the lobes. `None`
    /// (the default) for models that are their own geometry or formulas.
    fn bsdf_file(&self) -> Option<&Path> {
        None
    }

    /// The measured transmission behind the lobes, where the model has it.
    /// Sensors then take the direct sun through the panel from the data,
    /// integrated over the windows they see, rather than from the lobes'
    /// beams, which land where a lobe's middle does. `None` (the default):
    /// the lobes are all the model has.
    fn measured(&self) -> Option<&dyn MeasuredTransmission> {
        None
    }
}

/// A panel's measured transmission (BTDF, 1/sr: lobes and diffuse part
/// together) from outside into the room, read as Radiance reads the data:
/// constant over cells of outgoing directions (a Klems basis's patches, a
/// tensor tree's finest leaves). A sensor finds the cell of each direction
/// it sees a window in once; each sun then costs one row of the data.
pub trait MeasuredTransmission: Send + Sync {
    /// The cells the outgoing directions fall in.
    fn outgoing_cells(&self) -> usize;
    /// The cell (below [`Self::outgoing_cells`]) holding `outgoing`, the
    /// way light leaves into the room (unit, panel frame, z > 0).
    fn outgoing_cell(&self, outgoing: DVec3) -> usize;
    /// The BTDF into every outgoing cell for light travelling along
    /// `incoming` (unit, panel frame, z > 0).
    fn row(&self, incoming: DVec3) -> Vec<f64>;
    /// Patches of incoming directions the data's rows hold for (a Klems
    /// basis: sky light is gathered per patch, as Radiance's 3-phase method
    /// does).
    fn incoming_patches(&self) -> usize;
    /// The incoming patch (below [`Self::incoming_patches`]) holding
    /// `incoming` (unit, panel frame, z > 0).
    fn incoming_patch(&self, incoming: DVec3) -> usize;
    /// The BTDF into every outgoing cell for light arriving over incoming
    /// patch `patch`, averaged over it.
    fn patch_row(&self, patch: usize) -> Vec<f64>;
}

/// A kind of panel, registered by name: builds models from scene-file keys.
pub trait PanelType: Send + Sync {
    /// The name scene files give as `panel = "..."`.
    fn name(&self) -> &str;
    /// The keys this panel takes: they check scene files (any other key is
    /// refused) and give the designer's UI one widget each.
    fn keys(&self) -> &[Key];
    /// A model from a material's keys; a bad or missing key is an error
    /// naming it.
    fn build(&self, parameters: &Parameters) -> Result<Arc<dyn PanelModel>, ParameterError>;
}

/// One key a panel takes: its name, what it means and the values it
/// accepts. The same description checks scene files (through
/// [`Parameters`]) and gives the designer's UI its widget.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Key {
    /// The key as scene files write it, in the material's table.
    pub name: &'static str,
    /// What the key means, with its unit, in a few words (the UI's tooltip).
    pub help: &'static str,
    /// A material must give it; otherwise the kind's default is used.
    pub required: bool,
    /// The values it accepts, and its default.
    pub kind: KeyKind,
}

/// The values a [`Key`] accepts. `default` is used when an optional key is
/// absent; for a required key it is only where the UI starts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum KeyKind {
    /// A number within `range`.
    Number {
        /// Smallest and largest value accepted, both included.
        range: (f64, f64),
        /// The value when the key is absent.
        default: f64,
    },
    /// A list of as many numbers as `default` has, each within `range`.
    Numbers {
        /// Smallest and largest value accepted for each number, both included.
        range: (f64, f64),
        /// The values when the key is absent; its length is the list's.
        default: &'static [f64],
    },
    /// A whole number within `range`.
    Count {
        /// Smallest and largest value accepted, both included.
        range: (i64, i64),
        /// The value when the key is absent.
        default: i64,
    },
    /// A file, relative to the scene file's folder, with this extension.
    File {
        /// Without the dot (`xml`): the viewer offers the files that have it.
        extension: &'static str,
    },
}

impl Key {
    /// An optional number.
    pub const fn number(name: &'static str, help: &'static str, range: (f64, f64), default: f64) -> Self {
        Self { name, help, required: false, kind: KeyKind::Number { range, default } }
    }

    /// An optional list of numbers.
    pub const fn numbers(name: &'static str, help: &'static str, range: (f64, f64), default: &'static [f64]) -> Self {
        Self { name, help, required: false, kind: KeyKind::Numbers { range, default } }
    }

    /// An optional whole number.
    pub const fn count(name: &'static str, help: &'static str, range: (i64, i64), default: i64) -> Self {
        Self { name, help, required: false, kind: KeyKind::Count { range, default } }
    }

    /// A file (always required).
    pub const fn file(name: &'static str, help: &'static str, extension: &'static str) -> Self {
        Self { name, help, required: true, kind: KeyKind::File { extension } }
    }

    /// The same key, required.
    pub const fn required(self) -> Self {
        Self { required: true, ..self }
    }

    /// The value the key stands for when a material does not give it
    /// (what the UI starts from), as it would be written in a scene file.
    pub fn default_value(&self) -> Option<toml::Value> {
        match self.kind {
            KeyKind::Number { default, .. } => Some(toml::Value::Float(default)),
            KeyKind::Numbers { default, .. } => Some(toml::Value::Array(default.iter().map(|v| toml::Value::Float(*v)).collect())),
            KeyKind::Count { default, .. } => Some(toml::Value::Integer(default)),
            KeyKind::File { .. } => None,
        }
    }
}

/// Checks a panel's key declarations: names unique, ranges finite and in
/// order, defaults inside them, lists not empty, files required. A panel
/// whose keys fail this cannot be built ([`PanelCatalog::build`] says why);
/// panel crates check it in their tests.
pub fn check_keys(keys: &[Key]) -> Result<(), String> {
    for (i, key) in keys.iter().enumerate() {
        let bad = |why: &str| Err(format!("key '{}': {why}", key.name));
        if keys[..i].iter().any(|k| k.name == key.name) {
            return bad("declared twice");
        }
        let numbers = |(lo, hi): (f64, f64), defaults: &[f64]| {
            lo.is_finite() && hi.is_finite() && lo <= hi && defaults.iter().all(|d| (lo..=hi).contains(d))
        };
        match key.kind {
            KeyKind::Number { range, default } if !numbers(range, &[default]) => {
                return bad("its range must be finite and in order, its default inside it");
            }
            KeyKind::Numbers { default: [], .. } => return bad("a list needs a default as long as the list"),
            KeyKind::Numbers { range, default } if !numbers(range, default) => {
                return bad("its range must be finite and in order, its defaults inside it");
            }
            KeyKind::Count { range: (lo, hi), default } if lo > hi || !(lo..=hi).contains(&default) => {
                return bad("its range must be in order, its default inside it");
            }
            KeyKind::File { .. } if !key.required => return bad("a file key must be required"),
            _ => {}
        }
    }
    Ok(())
}

/// Every key at its default (files left out): where the UI starts when a
/// window is switched to a panel.
pub fn default_values(keys: &[Key]) -> toml::Table {
    keys.iter().filter_map(|k| Some((k.name.to_string(), k.default_value()?))).collect()
}

/// A problem with one of a panel's keys.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ParameterError {
    /// The key at fault, as the scene file names it (`panel` when it is the
    /// panel itself).
    pub key: String,
    /// What is wrong with it, in a few words (`must be a number`).
    pub message: String,
}

impl ParameterError {
    /// An error on `key`.
    pub fn new(key: &str, message: impl Into<String>) -> Self {
        Self { key: key.to_string(), message: message.into() }
    }
}

/// A panel material's own keys (everything but `kind`, `panel` and `up`),
/// with typed, range-checked access. Relative paths resolve against the
/// scene file's folder.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Parameters {
    /// The material's keys as the scene file gives them.
    pub values: toml::Table,
    /// The scene file's folder, against which [`KeyKind::File`] keys resolve.
    pub base_dir: PathBuf,
}

impl Parameters {
    /// A material's keys, and the folder of the scene file they came from.
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

    /// The value of `key`, or `None` when it is absent and optional (its
    /// default applies).
    fn given(&self, key: &Key) -> Result<Option<&toml::Value>, ParameterError> {
        match self.values.get(key.name) {
            None if key.required => Err(ParameterError::new(key.name, "is required")),
            value => Ok(value),
        }
    }

    /// A panel asked for a key as a kind it did not declare: the panel's bug,
    /// reported as an error on the key rather than a panic.
    fn undeclared(key: &Key, kind: &str) -> ParameterError {
        ParameterError::new(key.name, format!("is not declared as {kind} by its panel ({:?})", key.kind))
    }

    /// A [`KeyKind::Number`] key.
    pub fn number(&self, key: &Key) -> Result<f64, ParameterError> {
        let KeyKind::Number { range, default } = key.kind else { return Err(Self::undeclared(key, "a number")) };
        match self.given(key)? {
            Some(value) => Self::check_range(key.name, Self::as_number(key.name, value)?, range),
            None => Ok(default),
        }
    }

    /// A [`KeyKind::Numbers`] key of `N` numbers.
    pub fn numbers<const N: usize>(&self, key: &Key) -> Result<[f64; N], ParameterError> {
        let KeyKind::Numbers { range, default } = key.kind else { return Err(Self::undeclared(key, "a list of numbers")) };
        let Ok(default) = <[f64; N]>::try_from(default) else { return Err(Self::undeclared(key, &format!("a list of {N} numbers"))) };
        let Some(value) = self.given(key)? else { return Ok(default) };
        let toml::Value::Array(items) = value else { return Err(ParameterError::new(key.name, format!("must be a list of {N} numbers"))) };
        if items.len() != N {
            return Err(ParameterError::new(key.name, format!("must be a list of {N} numbers, not {}", items.len())));
        }
        let mut out = [0.0; N];
        for (slot, item) in out.iter_mut().zip(items) {
            *slot = Self::check_range(key.name, Self::as_number(key.name, item)?, range)?;
        }
        Ok(out)
    }

    /// A [`KeyKind::Count`] key.
    pub fn count(&self, key: &Key) -> Result<i64, ParameterError> {
        let KeyKind::Count { range, default } = key.kind else { return Err(Self::undeclared(key, "a whole number")) };
        match self.given(key)? {
            Some(toml::Value::Integer(i)) if (range.0..=range.1).contains(i) => Ok(*i),
            Some(toml::Value::Integer(i)) => Err(ParameterError::new(key.name, format!("{i} is outside {}..{}", range.0, range.1))),
            Some(_) => Err(ParameterError::new(key.name, "must be a whole number")),
            None => Ok(default),
        }
    }

    /// A [`KeyKind::File`] key, resolved against the scene file's folder.
    pub fn path(&self, key: &Key) -> Result<PathBuf, ParameterError> {
        let KeyKind::File { .. } = key.kind else { return Err(Self::undeclared(key, "a file")) };
        match self.given(key)? {
            Some(toml::Value::String(s)) if !s.is_empty() => Ok(self.base_dir.join(s)),
            _ => Err(ParameterError::new(key.name, "must be a file name")),
        }
    }

    /// The first key that `panel` does not take.
    pub fn unknown_key(&self, known: &[Key]) -> Option<&str> {
        self.values.keys().map(String::as_str).find(|k| known.iter().all(|key| key.name != *k))
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
    /// An empty catalog: no panel type registered.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a panel type; a later registration of the same name replaces it.
    pub fn register(&mut self, panel: Arc<dyn PanelType>) {
        self.types.insert(panel.name().to_string(), panel);
    }

    /// Adds every panel type of `other` (its registrations win).
    pub fn extend(&mut self, other: &PanelCatalog) {
        self.types.extend(other.types.iter().map(|(name, panel)| (name.clone(), panel.clone())));
    }

    /// The catalog with `panel` added: `PanelCatalog::new().with(Prismatic)`.
    pub fn with(mut self, panel: impl PanelType + 'static) -> Self {
        self.register(Arc::new(panel));
        self
    }

    /// The panel type registered as `name`.
    pub fn get(&self, name: &str) -> Option<&Arc<dyn PanelType>> {
        self.types.get(name)
    }

    /// The registered names, in alphabetical order.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.types.keys().map(String::as_str)
    }

    /// Whether no panel type is registered.
    pub fn is_empty(&self) -> bool {
        self.types.is_empty()
    }

    /// Builds the model of a panel material: the type's own checks, plus
    /// unknown keys refused.
    pub fn build(&self, name: &str, parameters: &Parameters) -> Result<Arc<dyn PanelModel>, ParameterError> {
        let panel = self.get(name).ok_or_else(|| ParameterError::new("panel", format!("no panel named '{name}' is registered")))?;
        check_keys(panel.keys()).map_err(|e| ParameterError::new("panel", format!("panel '{name}' declares its keys wrongly: {e}")))?;
        if let Some(key) = parameters.unknown_key(panel.keys()) {
            return Err(ParameterError::new(
                key,
                format!(
                    "is not a key of panel '{name}' (its keys: {})",
                    panel.keys().iter().map(|k| k.name).collect::<Vec<_>>().join(", ")
                ),
            ));
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
        const A: Key = Key::number("a", "", (1.0, 2.0), 1.2);
        const A_HIGH: Key = Key::number("a", "", (2.0, 3.0), 2.5);
        const MISSING: Key = Key::number("missing", "", (0.0, 5.0), 4.0);
        const B: Key = Key::numbers("b", "", (0.0, 3.0), &[1.0, 1.0]);
        const C: Key = Key::file("c", "", "xml");
        const N: Key = Key::count("n", "", (1, 5), 2);
        let values: toml::Table = toml::from_str("a = 1.5\nb = [1.0, 2.0]\nc = \"x\"\nn = 3").unwrap();
        let p = Parameters::new(values, "/scenes");
        assert_eq!(p.number(&A), Ok(1.5));
        assert_eq!(p.number(&A_HIGH).unwrap_err().key, "a");
        assert_eq!(p.number(&MISSING), Ok(4.0));
        assert!(p.number(&MISSING.required()).unwrap_err().message.contains("required"));
        assert_eq!(p.numbers::<2>(&B), Ok([1.0, 2.0]));
        assert!(p.numbers::<3>(&B).is_err());
        assert!(p.number(&Key::number("c", "", (0.0, 1.0), 0.5)).unwrap_err().message.contains("number"));
        assert_eq!(p.path(&C), Ok(PathBuf::from("/scenes/x")));
        assert_eq!(p.count(&N), Ok(3));
        // Asking for a key as a kind it was not declared as is an error, not a panic.
        assert!(p.count(&A).unwrap_err().message.contains("not declared"));
        assert_eq!(p.unknown_key(&[A, B, C]), Some("n"));
        assert_eq!(B.default_value(), Some(toml::Value::Array(vec![1.0.into(), 1.0.into()])));
        // Declarations a panel could get wrong.
        assert_eq!(check_keys(&[A, B, C, N]), Ok(()));
        assert!(check_keys(&[A, A_HIGH]).unwrap_err().contains("twice"));
        assert!(check_keys(&[Key::number("x", "", (0.0, 1.0), 2.0)]).unwrap_err().contains("default"));
        assert!(check_keys(&[Key::number("x", "", (0.0, f64::INFINITY), 2.0)]).is_err());
        assert!(check_keys(&[Key::numbers("x", "", (0.0, 1.0), &[])]).is_err());
        assert!(check_keys(&[Key { required: false, ..C }]).is_err());
    }
}
