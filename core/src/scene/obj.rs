//! The OBJ model and its MTL libraries, read through tobj.
//!
//! tobj reports errors without line numbers and forgets the names of materials
//! no MTL defines, so a light scan of the text comes first: it finds the
//! material libraries, the `usemtl` names and bad vertices with their lines.

use std::collections::{BTreeMap, HashMap};
use std::io::Cursor;
use std::path::{Path, PathBuf};

use glam::{DVec3, Vec3};

use super::error::{Location, SceneError, SceneWarning};
use super::frame::ModelFrame;
use super::{MAX_COORDINATE, Triangle, polygon};

/// A `mtllib` or `usemtl` reference and the line it stands on.
#[derive(Debug, Clone)]
pub struct Reference {
    pub line: usize,
    pub name: String,
}

/// What the first pass over the OBJ text found.
#[derive(Debug, Default)]
pub struct ObjScan {
    pub material_libraries: Vec<Reference>,
    /// Each material name used by `usemtl`, with its first line.
    pub used_materials: Vec<Reference>,
    pub face_count: usize,
}

/// Scans OBJ text for references and faces (what reading the model needs
/// before tobj: its MTL libraries and the material names it uses).
pub fn scan(text: &str) -> ObjScan {
    let mut scan = ObjScan::default();
    for (index, line) in text.lines().enumerate() {
        let line = line.trim();
        let (keyword, rest) = line.split_once(char::is_whitespace).unwrap_or((line, ""));
        let rest = rest.trim();
        match keyword {
            "f" => scan.face_count += 1,
            "mtllib" if !rest.is_empty() => scan.material_libraries.push(Reference { line: index + 1, name: rest.to_string() }),
            "usemtl" if !rest.is_empty() && !scan.used_materials.iter().any(|r| r.name == rest) => {
                scan.used_materials.push(Reference { line: index + 1, name: rest.to_string() });
            }
            _ => {}
        }
    }
    scan
}

/// Rejects vertices that are not three finite numbers within
/// [`MAX_COORDINATE`], and a model without faces: one error naming the line.
/// (Apart from [`scan`], so that it runs beside tobj: parsing the numbers
/// is most of a pass over a large OBJ.)
pub fn check(path: &Path, text: &str, scan: &ObjScan) -> Result<(), SceneError> {
    for (index, line) in text.lines().enumerate() {
        let Some(rest) = line.trim().strip_prefix('v').filter(|rest| rest.is_empty() || rest.starts_with(char::is_whitespace)) else {
            continue;
        };
        let at = || Location::line(path, index + 1);
        let coordinates: Vec<&str> = rest.split_whitespace().collect();
        if coordinates.len() < 3 {
            return Err(SceneError::new(at(), "vertex needs three coordinates"));
        }
        for c in &coordinates[..3] {
            match c.parse::<f64>() {
                Ok(v) if v.is_finite() && v.abs() <= MAX_COORDINATE => {}
                Ok(v) if v.is_finite() => {
                    return Err(SceneError::new(at(), format!("vertex coordinate {c} is beyond ±{MAX_COORDINATE:e} model units")));
                }
                Ok(_) => return Err(SceneError::new(at(), format!("vertex has a non-finite coordinate '{c}'"))),
                Err(_) => return Err(SceneError::new(at(), format!("vertex coordinate '{c}' is not a number"))),
            }
        }
    }
    if scan.face_count == 0 {
        return Err(SceneError::new(Location::file(path), "the model has no faces"));
    }
    Ok(())
}

/// The model as tobj read it, with every material name it uses.
pub struct ObjModel {
    pub meshes: Vec<tobj::Model>,
    /// tobj's materials by index: those of the MTL files, then one empty entry
    /// for each `usemtl` name no MTL defines.
    pub materials: Vec<MtlMaterial>,
}

pub struct MtlMaterial {
    pub name: String,
    /// The MTL definition, or `None` for a name only `usemtl` mentions.
    pub definition: Option<tobj::Material>,
    /// Where the definition (or, for undefined names, the first use) is.
    pub location: Location,
}

/// Material library name that tobj is handed first: every material of every
/// MTL goes through it, so `usemtl` resolves whatever the order of the lines.
const ALL_MATERIALS: &str = "heliodon-all-materials.mtl";

/// Runs a reader that may panic on input it does not expect (tobj 4 does,
/// e.g. on `Ks 0`): `None` instead of a panic reaching the user.
fn guarded<T>(read: impl FnOnce() -> T) -> Option<T> {
    let quiet = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(read)).ok();
    std::panic::set_hook(quiet);
    result
}

/// Checks the MTL statements heliodon reads before tobj sees them: colours
/// take three finite numbers, scalars one, `d` and `Tr` lie in 0-1. One
/// error naming the file, line and statement.
fn check_mtl(path: &Path, text: &str) -> Result<(), SceneError> {
    for (k, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let Some(statement) = words.next() else { continue };
        let count = match statement {
            "Ka" | "Kd" | "Ks" | "Ke" | "Tf" => 3,
            "Ns" | "Ni" | "d" | "Tr" => 1,
            _ => continue,
        };
        let at = Location::line(path, k + 1);
        let numbers = if count > 1 { "numbers" } else { "number" };
        let values: Vec<f64> = words
            .take(count)
            .map(|w| w.parse::<f64>().ok().filter(|v| v.is_finite()))
            .collect::<Option<_>>()
            .ok_or_else(|| SceneError::new(at.clone(), format!("{statement} needs {count} finite {numbers}")))?;
        if values.len() < count {
            return Err(SceneError::new(at, format!("{statement} needs {count} {numbers}, not {}", values.len())));
        }
        if matches!(statement, "d" | "Tr") && !(0.0..=1.0).contains(&values[0]) {
            return Err(SceneError::new(at, format!("{statement} {} is outside 0-1", values[0])));
        }
    }
    Ok(())
}

/// Reads the OBJ with tobj, triangulated, with materials from `mtls`.
pub fn import(path: &Path, text: &str, scan: &ObjScan, mtls: &[(PathBuf, String)]) -> Result<ObjModel, SceneError> {
    let mut materials: Vec<MtlMaterial> = Vec::new();
    for (mtl_path, mtl_text) in mtls {
        check_mtl(mtl_path, mtl_text)?;
        let (defined, _) = guarded(|| tobj::load_mtl_buf(&mut Cursor::new(mtl_text.as_bytes())))
            .ok_or_else(|| SceneError::new(Location::file(mtl_path), "cannot parse MTL: the MTL reader (tobj) failed on it"))?
            .map_err(|error| SceneError::new(Location::file(mtl_path), format!("cannot parse MTL: {error}")))?;
        for material in defined {
            let line = mtl_text
                .lines()
                .position(|l| l.trim().strip_prefix("newmtl").map(str::trim) == Some(material.name.as_str()))
                .map_or(0, |i| i + 1);
            materials.retain(|m| m.name != material.name);
            materials.push(MtlMaterial {
                name: material.name.clone(),
                location: Location::line(mtl_path, line),
                definition: Some(material),
            });
        }
    }
    for used in &scan.used_materials {
        if !materials.iter().any(|m| m.name == used.name) {
            materials.push(MtlMaterial { name: used.name.clone(), definition: None, location: Location::line(path, used.line) });
        }
    }
    let library: Vec<tobj::Material> = materials.iter().map(|m| tobj::Material { name: m.name.clone(), ..Default::default() }).collect();
    let index: HashMap<String, usize> = materials.iter().enumerate().map(|(i, m)| (m.name.clone(), i)).collect();
    let source = format!("mtllib {ALL_MATERIALS}\n{text}");
    let options = tobj::LoadOptions { single_index: true, triangulate: false, ignore_points: true, ignore_lines: true };
    let (meshes, _) = guarded(|| {
        tobj::load_obj_buf(&mut Cursor::new(source.as_bytes()), &options, |library_path| {
            if library_path == Path::new(ALL_MATERIALS) {
                Ok((library.clone(), index.clone()))
            } else {
                // Real libraries were read above and are already in ALL_MATERIALS.
                Ok((Vec::new(), HashMap::new()))
            }
        })
    })
    .ok_or_else(|| SceneError::new(Location::file(path), "cannot parse OBJ: the OBJ reader (tobj) failed on it"))?
    .map_err(|error| SceneError::new(Location::file(path), format!("cannot parse OBJ: {error}")))?;
    Ok(ObjModel { meshes, materials })
}

/// The model's triangles in the canonical frame, with tobj's material index
/// (or `None` for faces before any `usemtl`). Degenerate triangles are dropped
/// with a warning.
pub fn triangles(
    model: &ObjModel,
    frame: &ModelFrame,
    material_of: &BTreeMap<Option<usize>, u32>,
    path: &Path,
    warnings: &mut Vec<SceneWarning>,
) -> Result<Vec<Triangle>, SceneError> {
    let mut triangles = Vec::new();
    let mut degenerate = 0usize;
    // Faces written twice (same corners, same material) count once: copies
    // would weigh on every ray and pass for nothing.
    let mut seen: rustc_hash::FxHashSet<([[u32; 3]; 3], u32)> = rustc_hash::FxHashSet::default();
    seen.reserve(model.meshes.iter().map(|m| m.mesh.indices.len() / 3).sum());
    let mut duplicated = 0usize;
    // tobj numbers each mesh's vertices from 0: numbered on across meshes.
    let mut first_vertex = 0u32;
    for model_mesh in &model.meshes {
        let mesh = &model_mesh.mesh;
        let file_vertex = |i: u32| first_vertex + i;
        let position = |i: u32| {
            let i = i as usize * 3;
            frame.point(DVec3::new(mesh.positions[i], mesh.positions[i + 1], mesh.positions[i + 2]))
        };
        let material = material_of[&mesh.material_id];
        // Faces as written (all triangles when tobj lists no arities).
        let arities: Box<dyn Iterator<Item = u32>> = if mesh.face_arities.is_empty() {
            Box::new(std::iter::repeat_n(3, mesh.indices.len() / 3))
        } else {
            Box::new(mesh.face_arities.iter().copied())
        };
        let mut start = 0;
        for arity in arities {
            let indices = &mesh.indices[start..start + arity as usize];
            let face: Vec<Vec3> = indices.iter().map(|&i| position(i)).collect();
            start += arity as usize;
            let pieces = polygon::triangulate(&face);
            degenerate += usize::from(pieces.is_empty());
            for [a, b, c] in pieces {
                let file_vertices = [a, b, c].map(|k| file_vertex(indices[k]));
                let triangle = Triangle { vertices: [face[a], face[b], face[c]], material, file_vertices };
                let mut corners = triangle.vertices.map(|v| v.to_array().map(f32::to_bits));
                corners.sort_unstable();
                if is_degenerate(&triangle) {
                    degenerate += 1;
                } else if !seen.insert((corners, material)) {
                    duplicated += 1;
                } else {
                    triangles.push(triangle);
                }
            }
        }
        first_vertex += (mesh.positions.len() / 3) as u32;
    }
    if duplicated > 0 {
        warnings.push(SceneWarning {
            location: Location::file(path),
            message: format!("dropped {duplicated} duplicated triangle(s) (the same corners and material twice)"),
        });
    }
    if degenerate > 0 {
        warnings.push(SceneWarning {
            location: Location::file(path),
            message: format!("dropped {degenerate} degenerate (zero-area) triangle(s)"),
        });
    }
    if triangles.is_empty() {
        return Err(SceneError::new(Location::file(path), "the model has no faces with a non-zero area"));
    }
    Ok(triangles)
}

/// The centre of the model's bounds (model units, f64) when it lies farther
/// than `beyond` from the origin; `None` for a model near its origin.
pub fn far_centre(model: &ObjModel, beyond: f64) -> Option<DVec3> {
    let (lo, hi) = model
        .meshes
        .iter()
        .flat_map(|m| m.mesh.positions.chunks_exact(3))
        .map(|p| DVec3::new(p[0], p[1], p[2]))
        .fold((DVec3::MAX, DVec3::MIN), |(lo, hi), p| (lo.min(p), hi.max(p)));
    let centre = (lo + hi) / 2.0;
    (lo.x <= hi.x && centre.abs().max_element() > beyond).then_some(centre)
}

/// Zero area, up to rounding: the smallest angle's sine below 1e-6 or an area
/// under a square millimetre's millionth.
fn is_degenerate(triangle: &Triangle) -> bool {
    let [a, b, c] = triangle.vertices;
    let longest = (b - a).length_squared().max((c - b).length_squared()).max((a - c).length_squared());
    let doubled_area = triangle.cross().length();
    !(doubled_area > 1e-6 * longest && doubled_area > 2e-12)
}
