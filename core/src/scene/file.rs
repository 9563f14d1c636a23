//! The scene file's TOML schema, read with spans so that every later check can
//! name the line and key it complains about.

use std::collections::BTreeMap;
use std::ops::Range;
use std::path::{Path, PathBuf};

use serde::Deserialize;
use toml::Spanned;

use super::error::{Location, SceneError};
use super::frame::{ModelFrame, UpAxis};
use super::{DEFAULT_PATCH_SIZE, MAX_COORDINATE, MAX_PATCH_SIZE, MIN_PATCH_SIZE};
use crate::site::Site;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    pub name: Option<String>,
    pub site: Spanned<SiteTable>,
    pub model: Spanned<ModelTable>,
    pub lighting: Option<LightingTable>,
    #[serde(default)]
    pub materials: BTreeMap<String, Spanned<MaterialTable>>,
    #[serde(default)]
    pub sensors: Vec<Spanned<SensorTable>>,
    #[serde(default)]
    pub sensor_grids: Vec<Spanned<SensorGridTable>>,
    #[serde(default)]
    pub cameras: Vec<Spanned<CameraTable>>,
    #[serde(default)]
    pub shades: Vec<Spanned<ShadeTable>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SiteTable {
    pub latitude: Spanned<f64>,
    pub longitude: Spanned<f64>,
    pub timezone: Spanned<f64>,
    pub ground_reflectance: Option<Spanned<f64>>,
    pub elevation: Option<Spanned<f64>>,
    pub pressure: Option<Spanned<f64>>,
    pub temperature: Option<Spanned<f64>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelTable {
    pub obj: Spanned<String>,
    pub up: Option<Spanned<String>>,
    pub north: Option<Spanned<[f64; 3]>>,
    pub scale: Option<Spanned<f64>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightingTable {
    pub patch_size: Option<Spanned<f64>>,
    /// `false`: patches of `patch_size` everywhere (no coarser ones away
    /// from the windows and sensors).
    pub adaptive: Option<bool>,
}

/// A material's keys stay loose here: which keys are allowed depends on its
/// `kind` (and, for panels, on the panel), checked in `material.rs`.
pub type MaterialTable = BTreeMap<String, Spanned<toml::Value>>;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorTable {
    pub name: Spanned<String>,
    pub position: Spanned<[f64; 3]>,
    pub normal: Spanned<[f64; 3]>,
    pub size: Option<Spanned<f64>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorGridTable {
    pub name: Spanned<String>,
    pub min: Spanned<[f64; 2]>,
    pub max: Spanned<[f64; 2]>,
    pub height: Spanned<f64>,
    pub spacing: Spanned<f64>,
}

/// A named viewpoint (an extension of the contract: `[[cameras]]`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraTable {
    pub name: Spanned<String>,
    pub eye: Spanned<[f64; 3]>,
    pub target: Spanned<[f64; 3]>,
    pub fov: Option<Spanned<f64>>,
}

/// An operable shade group (IES LM-83, the contract's `[[shades]]`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShadeTable {
    pub windows: Spanned<String>,
    pub shade: Spanned<String>,
}

/// The scene file after schema and range checks of its site, model and
/// lighting tables; materials and sensors are checked where they are built.
#[derive(Debug)]
pub struct ParsedScene {
    pub path: PathBuf,
    pub text: String,
    pub name: String,
    pub site: Site,
    pub frame: ModelFrame,
    /// `[lighting] patch_size`, or the default.
    pub patch_size: f32,
    /// `[lighting] adaptive` (default true): patches coarser away from the focus.
    pub adaptive_patches: bool,
    pub model: ModelTable,
    pub materials: BTreeMap<String, Spanned<MaterialTable>>,
    pub sensors: Vec<Spanned<SensorTable>>,
    pub sensor_grids: Vec<Spanned<SensorGridTable>>,
    pub cameras: Vec<Spanned<CameraTable>>,
    pub shades: Vec<Spanned<ShadeTable>>,
}

impl ParsedScene {
    /// Location of a value in the scene file, for messages.
    pub fn at(&self, span: Range<usize>, key: impl Into<String>) -> Location {
        Location::key(&self.path, &self.text, span.start, key)
    }

    pub fn error<T>(&self, span: Range<usize>, key: impl Into<String>, message: impl Into<String>) -> Result<T, SceneError> {
        Err(SceneError::new(self.at(span, key), message))
    }

    pub fn obj_path(&self) -> PathBuf {
        self.path.parent().unwrap_or(Path::new("")).join(self.model.obj.get_ref())
    }

    pub fn obj_location(&self) -> Location {
        self.at(self.model.obj.span(), "model.obj")
    }

    /// A number that must be finite and within `range` (inclusive).
    pub fn number(&self, value: &Spanned<f64>, key: &str, range: (f64, f64)) -> Result<f64, SceneError> {
        let v = *value.get_ref();
        if !v.is_finite() || v < range.0 || v > range.1 {
            return self.error(value.span(), key, format!("{v} is out of range [{}, {}]", range.0, range.1));
        }
        Ok(v)
    }

    /// A vector whose components must all be finite.
    pub fn finite<const N: usize>(&self, value: &Spanned<[f64; N]>, key: &str) -> Result<[f64; N], SceneError> {
        let v = *value.get_ref();
        if v.iter().any(|c| !c.is_finite()) {
            return self.error(value.span(), key, "coordinates must be finite numbers");
        }
        Ok(v)
    }

    /// [`Self::finite`] for a position: also within ±[`MAX_COORDINATE`].
    pub fn position<const N: usize>(&self, value: &Spanned<[f64; N]>, key: &str) -> Result<[f64; N], SceneError> {
        let v = self.finite(value, key)?;
        if let Some(c) = v.iter().find(|c| c.abs() > MAX_COORDINATE) {
            return self.error(value.span(), key, format!("{c:e} is beyond ±{MAX_COORDINATE:e} model units"));
        }
        Ok(v)
    }
}

/// Parses and checks a scene file's text.
pub fn parse(path: &Path, text: &str) -> Result<ParsedScene, SceneError> {
    let file: SceneFile = toml::from_str(text).map_err(|error| {
        let location = match error.span() {
            Some(span) => Location::line(path, super::error::line_of(text, span.start)),
            None => Location::file(path),
        };
        SceneError::new(location, error.message().trim().replace('\n', " "))
    })?;
    let mut parsed = ParsedScene {
        path: path.to_path_buf(),
        text: text.to_string(),
        name: String::new(),
        site: Site::new(0.0, 0.0, 0.0),
        frame: ModelFrame::default(),
        patch_size: DEFAULT_PATCH_SIZE,
        adaptive_patches: true,
        model: file.model.into_inner(),
        materials: file.materials,
        sensors: file.sensors,
        sensor_grids: file.sensor_grids,
        cameras: file.cameras,
        shades: file.shades,
    };
    parsed.name = file.name.unwrap_or_else(|| path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default());
    parsed.site = site(&parsed, file.site.get_ref())?;
    parsed.frame = frame(&parsed)?;
    if let Some(lighting) = file.lighting {
        if let Some(size) = lighting.patch_size {
            parsed.patch_size = parsed.number(&size, "lighting.patch_size", (MIN_PATCH_SIZE, MAX_PATCH_SIZE))? as f32;
        }
        parsed.adaptive_patches = lighting.adaptive.unwrap_or(true);
    }
    Ok(parsed)
}

fn site(parsed: &ParsedScene, table: &SiteTable) -> Result<Site, SceneError> {
    let optional = |value: &Option<Spanned<f64>>, key: &str, range, default| match value {
        Some(v) => parsed.number(v, key, range),
        None => Ok(default),
    };
    Ok(Site {
        latitude: parsed.number(&table.latitude, "site.latitude", (-90.0, 90.0))?,
        longitude: parsed.number(&table.longitude, "site.longitude", (-180.0, 180.0))?,
        timezone: parsed.number(&table.timezone, "site.timezone", (-14.0, 14.0))?,
        ground_reflectance: optional(&table.ground_reflectance, "site.ground_reflectance", (0.0, 1.0), Site::DEFAULT_GROUND_REFLECTANCE)?,
        elevation: optional(&table.elevation, "site.elevation", (-500.0, 9000.0), Site::DEFAULT_ELEVATION)?,
        pressure: optional(&table.pressure, "site.pressure", (300.0, 1200.0), Site::DEFAULT_PRESSURE)?,
        temperature: optional(&table.temperature, "site.temperature", (-90.0, 60.0), Site::DEFAULT_TEMPERATURE)?,
        north_turn: 0.0,
    })
}

fn frame(parsed: &ParsedScene) -> Result<ModelFrame, SceneError> {
    let model = &parsed.model;
    let up = match &model.up {
        None => UpAxis::Z,
        Some(up) => match up.get_ref().as_str() {
            "z" | "Z" => UpAxis::Z,
            "y" | "Y" => UpAxis::Y,
            other => return parsed.error(up.span(), "model.up", format!("'{other}' is not an up axis (expected \"z\" or \"y\")")),
        },
    };
    let north = match &model.north {
        Some(north) => Some((parsed.finite(north, "model.north")?, north.span())),
        None => None,
    };
    let scale = match &model.scale {
        Some(scale) => {
            let s = *scale.get_ref();
            if !s.is_finite() || s <= 0.0 {
                return parsed.error(scale.span(), "model.scale", format!("{s} is not a positive number"));
            }
            s
        }
        None => 1.0,
    };
    let north_vector = north.as_ref().map(|(n, _)| glam::DVec3::from_array(*n).as_vec3());
    ModelFrame::new(up, north_vector, scale as f32).map_err(|message| {
        let span = north.map(|(_, span)| span).unwrap_or(0..0);
        SceneError::new(parsed.at(span, "model.north"), message)
    })
}
