//! The OBJ model and its MTL libraries, read through tobj.
//!
//! tobj reports errors without line numbers and forgets the names of materials
//! no MTL defines, so a light scan of the text comes first: it finds the
//! material libraries, the `usemtl` names and bad vertices with their lines.

use std::collections::{BTreeMap, HashMap};
use std::io::Cursor;
use std::path::{Path, PathBuf};

use glam::Vec3;

use super::Triangle;
use super::error::{Location, SceneError, SceneWarning};
use super::frame::ModelFrame;

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

/// Scans OBJ text for references and faces, and rejects vertices that are not
/// three finite numbers.
pub fn scan(path: &Path, text: &str) -> Result<ObjScan, SceneError> {
    let mut scan = ObjScan::default();
    for (index, line) in text.lines().enumerate() {
        let line_no = index + 1;
        let line = line.trim();
        let (keyword, rest) = line.split_once(char::is_whitespace).unwrap_or((line, ""));
        let rest = rest.trim();
        match keyword {
            "v" => {
                let coordinates: Vec<&str> = rest.split_whitespace().collect();
                if coordinates.len() < 3 {
                    return Err(SceneError::new(Location::line(path, line_no), "vertex needs three coordinates"));
                }
                for c in &coordinates[..3] {
                    match c.parse::<f64>() {
                        Ok(v) if v.is_finite() => {}
                        Ok(_) => {
                            return Err(SceneError::new(
                                Location::line(path, line_no),
                                format!("vertex has a non-finite coordinate '{c}'"),
                            ));
                        }
                        Err(_) => {
                            return Err(SceneError::new(Location::line(path, line_no), format!("vertex coordinate '{c}' is not a number")));
                        }
                    }
                }
            }
            "f" => scan.face_count += 1,
            "mtllib" if !rest.is_empty() => scan.material_libraries.push(Reference { line: line_no, name: rest.to_string() }),
            "usemtl" if !rest.is_empty() && !scan.used_materials.iter().any(|r| r.name == rest) => {
                scan.used_materials.push(Reference { line: line_no, name: rest.to_string() });
            }
            _ => {}
        }
    }
    if scan.face_count == 0 {
        return Err(SceneError::new(Location::file(path), "the model has no faces"));
    }
    Ok(scan)
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

/// Reads the OBJ with tobj, triangulated, with materials from `mtls`.
pub fn import(path: &Path, text: &str, scan: &ObjScan, mtls: &[(PathBuf, String)]) -> Result<ObjModel, SceneError> {
    let mut materials: Vec<MtlMaterial> = Vec::new();
    for (mtl_path, mtl_text) in mtls {
        let (defined, _) = tobj::load_mtl_buf(&mut Cursor::new(mtl_text.as_bytes()))
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
    let options = tobj::LoadOptions { single_index: true, triangulate: true, ignore_points: true, ignore_lines: true };
    let (meshes, _) = tobj::load_obj_buf(&mut Cursor::new(source.as_bytes()), &options, |library_path| {
        if library_path == Path::new(ALL_MATERIALS) {
            Ok((library.clone(), index.clone()))
        } else {
            // Real libraries were read above and are already in ALL_MATERIALS.
            Ok((Vec::new(), HashMap::new()))
        }
    })
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
    for model_mesh in &model.meshes {
        let mesh = &model_mesh.mesh;
        let position = |i: u32| {
            let i = i as usize * 3;
            frame.point(Vec3::new(mesh.positions[i], mesh.positions[i + 1], mesh.positions[i + 2]))
        };
        let material = material_of[&mesh.material_id];
        for face in mesh.indices.chunks_exact(3) {
            let triangle = Triangle { vertices: [position(face[0]), position(face[1]), position(face[2])], material };
            if is_degenerate(&triangle) {
                degenerate += 1;
            } else {
                triangles.push(triangle);
            }
        }
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

/// Zero area, up to rounding: the smallest angle's sine below 1e-6 or an area
/// under a square millimetre's millionth.
fn is_degenerate(triangle: &Triangle) -> bool {
    let [a, b, c] = triangle.vertices;
    let longest = (b - a).length_squared().max((c - b).length_squared()).max((a - c).length_squared());
    let doubled_area = triangle.cross().length();
    !(doubled_area > 1e-6 * longest && doubled_area > 2e-12)
}
