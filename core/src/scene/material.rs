//! Materials: the scene file's `[materials]` table over the MTL defaults.

use std::collections::{BTreeMap, BTreeSet};

use glam::{DVec3, Vec3};
use toml::{Spanned, Value};

use super::error::{Location, SceneError, SceneWarning};
use super::file::{MaterialTable, ParsedScene};
use super::obj::ObjModel;
use crate::panel::{PanelCatalog, PanelHandle, Parameters, base_dir as panel_base_dir};

/// A colour triple (linear RGB); scalars are grey.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rgb(pub [f32; 3]);

impl Rgb {
    /// The same value in all three channels.
    pub fn grey(v: f32) -> Self {
        Self([v; 3])
    }
}

/// What a material does with light.
#[derive(Debug, Clone, PartialEq)]
pub enum MaterialKind {
    /// Lambertian on both sides.
    Diffuse {
        /// Per channel, 0-1 (the scene file's `reflectance`, or MTL `Kd`).
        reflectance: Rgb,
    },
    /// Clear glazing as Radiance's `glass`: `transmittance` at normal incidence.
    Glass {
        /// 0-1 (the scene file's `transmittance`, or MTL `Tr`, or 1 − `d`).
        transmittance: f32,
    },
    /// A complex fenestration system handled by a registered panel model.
    Panel {
        /// The panel type's name, as registered in the [`PanelCatalog`].
        panel: String,
        /// The panel's in-plane orientation (canonical frame), when given.
        up: Option<Vec3>,
        /// The panel's own keys, as the scene file gives them.
        parameters: toml::Table,
        /// The model built from them by the panel's type.
        model: PanelHandle,
    },
}

impl MaterialKind {
    /// The kind's name as scene files write it: `diffuse`, `glass` or `panel`.
    pub fn label(&self) -> &'static str {
        match self {
            MaterialKind::Diffuse { .. } => "diffuse",
            MaterialKind::Glass { .. } => "glass",
            MaterialKind::Panel { .. } => "panel",
        }
    }

    /// Whether light passes through it: faces of such materials are windows.
    pub fn transmits(&self) -> bool {
        !matches!(self, MaterialKind::Diffuse { .. })
    }
}

/// Where a material's definition came from.
#[derive(Debug, Clone, PartialEq)]
pub enum MaterialOrigin {
    /// The scene file's `[materials.NAME]` table.
    Scene(Location),
    /// An MTL `newmtl` block.
    Mtl(Location),
    /// Faces before any `usemtl`: grey diffuse, with a warning.
    Unassigned,
}

/// A material of the scene: its name, what it does with light and where it
/// was defined.
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    /// The name faces use it by (`usemtl`); `(none)` for faces before any.
    pub name: String,
    /// What it does with light.
    pub kind: MaterialKind,
    /// Where it was defined, for messages.
    pub origin: MaterialOrigin,
}

/// Reflectance of faces that name no material (with a warning).
const UNASSIGNED_REFLECTANCE: f32 = 0.5;

/// Materials in order, and each OBJ material index's place among them.
pub type ResolvedMaterials = (Vec<Material>, BTreeMap<Option<usize>, u32>, BTreeMap<String, Material>);

/// The materials the model's faces use, in order of their index in
/// [`ObjModel::materials`] (faces with no material last), and each index's
/// place in that list; and the
/// `[materials]` no face uses, by name (shades draw them).
pub fn resolve(
    parsed: &ParsedScene,
    model: &ObjModel,
    panels: &PanelCatalog,
    obj_path: &std::path::Path,
    warnings: &mut Vec<SceneWarning>,
) -> Result<ResolvedMaterials, SceneError> {
    let mut scene_materials = BTreeMap::new();
    for (name, table) in &parsed.materials {
        scene_materials.insert(name.as_str(), scene_material(parsed, name, table, panels)?);
    }
    let mut used: BTreeSet<Option<usize>> = BTreeSet::new();
    let mut last = None;
    for face in &model.faces {
        // Faces come in runs of one material: each run inserted once.
        if last != Some(face.material) {
            used.insert(face.material);
            last = Some(face.material);
        }
    }
    let used_names: BTreeSet<&str> = used.iter().flatten().map(|&i| model.materials[i].name.as_str()).collect();
    // Shade materials are drawn only when a shade is down (see `shades`).
    let shade_names: BTreeSet<&str> = parsed.shades.iter().map(|s| s.get_ref().shade.get_ref().as_str()).collect();
    for (name, table) in &parsed.materials {
        if !used_names.contains(name.as_str()) && !shade_names.contains(name.as_str()) {
            warnings.push(SceneWarning {
                location: parsed.at(table.span(), format!("materials.{name}")),
                message: format!("no face of {} uses material '{name}'", obj_path.display()),
            });
        }
    }
    let mut materials = Vec::new();
    let mut index = BTreeMap::new();
    // `None` sorts first in a BTreeSet; keep named materials first.
    for &id in used.iter().filter(|id| id.is_some()).chain(used.iter().filter(|id| id.is_none())) {
        let material = match id {
            Some(i) => {
                let source = &model.materials[i];
                match scene_materials.remove(source.name.as_str()) {
                    Some(material) => material,
                    None => mtl_material(source)?,
                }
            }
            None => {
                let faces: usize = model.faces.iter().filter(|f| f.material.is_none()).map(|f| f.corners.len() - 2).sum();
                warnings.push(SceneWarning {
                    location: Location::file(obj_path),
                    message: format!(
                        "{faces} triangle(s) come before any usemtl; they are diffuse with reflectance {UNASSIGNED_REFLECTANCE}"
                    ),
                });
                Material {
                    name: "(none)".into(),
                    kind: MaterialKind::Diffuse { reflectance: Rgb::grey(UNASSIGNED_REFLECTANCE) },
                    origin: MaterialOrigin::Unassigned,
                }
            }
        };
        index.insert(id, materials.len() as u32);
        materials.push(material);
    }
    let unused = scene_materials.into_iter().map(|(name, material)| (name.to_string(), material)).collect();
    Ok((materials, index, unused))
}

pub(super) fn scene_material(
    parsed: &ParsedScene,
    name: &str,
    table: &Spanned<MaterialTable>,
    panels: &PanelCatalog,
) -> Result<Material, SceneError> {
    let key = |k: &str| format!("materials.{name}.{k}");
    let entries = table.get_ref();
    let Some(kind) = entries.get("kind") else {
        return parsed.error(table.span(), format!("materials.{name}"), "missing key 'kind' (diffuse, glass or panel)");
    };
    let kind_name = match kind.get_ref() {
        Value::String(s) => s.as_str(),
        _ => return parsed.error(kind.span(), key("kind"), "must be a string: diffuse, glass or panel"),
    };
    let allowed: &[&str] = match kind_name {
        "diffuse" => &["kind", "reflectance"],
        "glass" => &["kind", "transmittance"],
        "panel" => &[],
        other => {
            return parsed.error(kind.span(), key("kind"), format!("unknown material kind '{other}' (expected diffuse, glass or panel)"));
        }
    };
    if !allowed.is_empty()
        && let Some((extra, value)) = entries.iter().find(|(k, _)| !allowed.contains(&k.as_str()))
    {
        return parsed.error(value.span(), key(extra), format!("unknown key for a {kind_name} material (allowed: {})", allowed.join(", ")));
    }
    let required = |k: &str| {
        entries.get(k).ok_or_else(|| SceneError::new(parsed.at(table.span(), format!("materials.{name}")), format!("missing key '{k}'")))
    };
    let kind = match kind_name {
        "diffuse" => {
            let value = required("reflectance")?;
            MaterialKind::Diffuse { reflectance: fraction_or_rgb(parsed, value, &key("reflectance"))? }
        }
        "glass" => {
            let value = required("transmittance")?;
            let t = number(parsed, value, &key("transmittance"))?;
            if !(0.0..=1.0).contains(&t) {
                return parsed.error(value.span(), key("transmittance"), format!("{t} is out of range [0, 1]"));
            }
            MaterialKind::Glass { transmittance: t as f32 }
        }
        _ => {
            let panel = required("panel")?;
            let Value::String(panel_name) = panel.get_ref() else {
                return parsed.error(panel.span(), key("panel"), "must be a panel name (a string)");
            };
            if panels.get(panel_name).is_none() {
                let registered = if panels.is_empty() { "none".to_string() } else { panels.names().collect::<Vec<_>>().join(", ") };
                return parsed.error(
                    panel.span(),
                    key("panel"),
                    format!("no panel named '{panel_name}' is registered (registered: {registered})"),
                );
            }
            let up = match entries.get("up") {
                Some(value) => Some(panel_up(parsed, value, &key("up"))?),
                None => None,
            };
            let parameters: toml::Table = entries
                .iter()
                .filter(|(k, _)| !matches!(k.as_str(), "kind" | "panel" | "up"))
                .map(|(k, v)| (k.clone(), v.get_ref().clone()))
                .collect();
            let model = panels.build(panel_name, &Parameters::new(parameters.clone(), panel_base_dir(&parsed.path))).map_err(|e| {
                // Point at the key, or at the material when the key is missing.
                let span = entries.get(&e.key).map_or(table.span(), |v| v.span());
                SceneError::new(parsed.at(span, key(&e.key)), e.message)
            })?;
            MaterialKind::Panel { panel: panel_name.clone(), up, parameters, model: PanelHandle(model) }
        }
    };
    Ok(Material { name: name.to_string(), kind, origin: MaterialOrigin::Scene(parsed.at(table.span(), format!("materials.{name}"))) })
}

fn number(parsed: &ParsedScene, value: &Spanned<Value>, key: &str) -> Result<f64, SceneError> {
    let v = match value.get_ref() {
        Value::Float(f) => *f,
        Value::Integer(i) => *i as f64,
        _ => return parsed.error(value.span(), key, "must be a number"),
    };
    if !v.is_finite() {
        return parsed.error(value.span(), key, "must be a finite number");
    }
    Ok(v)
}

/// A reflectance: a number or `[r, g, b]`, each in [0, 1].
fn fraction_or_rgb(parsed: &ParsedScene, value: &Spanned<Value>, key: &str) -> Result<Rgb, SceneError> {
    let components = match value.get_ref() {
        Value::Array(items) if items.len() == 3 => {
            let mut rgb = [0.0; 3];
            for (slot, item) in rgb.iter_mut().zip(items) {
                *slot = number(parsed, &Spanned::new(value.span(), item.clone()), key)?;
            }
            rgb
        }
        Value::Array(_) => return parsed.error(value.span(), key, "must be a number or [r, g, b]"),
        _ => [number(parsed, value, key)?; 3],
    };
    if components.iter().any(|c| !(0.0..=1.0).contains(c)) {
        return parsed.error(value.span(), key, "reflectance must lie in [0, 1]");
    }
    Ok(Rgb(components.map(|c| c as f32)))
}

/// A panel's `up`: a non-zero model-space vector, mapped to the canonical frame.
fn panel_up(parsed: &ParsedScene, value: &Spanned<Value>, key: &str) -> Result<Vec3, SceneError> {
    let Value::Array(items) = value.get_ref() else {
        return parsed.error(value.span(), key, "must be [x, y, z]");
    };
    if items.len() != 3 {
        return parsed.error(value.span(), key, "must be [x, y, z]");
    }
    let mut v = [0.0; 3];
    for (slot, item) in v.iter_mut().zip(items) {
        *slot = number(parsed, &Spanned::new(value.span(), item.clone()), key)?;
    }
    let v = DVec3::from_array(v).as_vec3();
    if v.length() == 0.0 {
        return parsed.error(value.span(), key, "must not be the zero vector");
    }
    Ok(parsed.frame.direction(v))
}

/// A material the scene file does not list, from its MTL block.
fn mtl_material(source: &super::obj::MtlMaterial) -> Result<Material, SceneError> {
    let Some(definition) = &source.definition else {
        return Err(SceneError::new(
            source.location.clone(),
            format!("usemtl '{}': no MTL file and no [materials.{}] table defines it", source.name, source.name),
        ));
    };
    let error = |message: String| SceneError::new(source.location.clone(), message);
    let transparency = definition
        .unknown_param
        .get("Tr")
        .map(|tr| tr.trim().parse::<f32>().map_err(|_| error(format!("material '{}': Tr '{tr}' is not a number", source.name))))
        .transpose()?;
    // tobj reads in f64 (for the positions); materials are f32 as ever.
    let transmittance = match (definition.dissolve.map(|d| d as f32), transparency) {
        (_, Some(tr)) if tr > 0.0 => Some(tr),
        (Some(d), _) if d < 1.0 => Some(1.0 - d),
        _ => None,
    };
    let kind = match transmittance {
        Some(t) if (0.0..=1.0).contains(&t) => MaterialKind::Glass { transmittance: t },
        Some(t) => return Err(error(format!("material '{}': transmittance {t} is out of range [0, 1]", source.name))),
        None => {
            let kd = definition.diffuse.map_or([UNASSIGNED_REFLECTANCE; 3], |kd| kd.map(|c| c as f32));
            if kd.iter().any(|c| !(0.0..=1.0).contains(c)) {
                return Err(error(format!("material '{}': Kd {kd:?} must lie in [0, 1]", source.name)));
            }
            MaterialKind::Diffuse { reflectance: Rgb(kd) }
        }
    };
    Ok(Material { name: source.name.clone(), kind, origin: MaterialOrigin::Mtl(source.location.clone()) })
}
