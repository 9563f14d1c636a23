//! The OBJ model and its MTL libraries. The OBJ is read here (vertices,
//! faces, `usemtl`), in chunks side by side, every error naming its line;
//! the MTL libraries through tobj. A light scan of the text comes first:
//! it finds the material libraries to read and the `usemtl` names.

use std::collections::{BTreeMap, HashMap};
use std::hash::{Hash, Hasher};
use std::io::Cursor;
use std::ops::Range;
use std::path::{Path, PathBuf};

use glam::{DVec3, Vec3};

use super::error::{Location, SceneError, SceneWarning};
use super::frame::ModelFrame;
use super::{MAX_COORDINATE, Triangle, polygon};
use crate::parallel::{par_chunks, par_map};

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
/// first: its MTL libraries and the material names it uses), in chunks
/// side by side as [`read`] does.
pub fn scan(text: &str) -> ObjScan {
    scan_in_chunks(text, CHUNK_BYTES)
}

/// An OBJ line's keyword and the rest of it, trimmed.
fn statement(line: &str) -> (&str, &str) {
    let line = line.trim();
    let (keyword, rest) = line.split_once(char::is_whitespace).unwrap_or((line, ""));
    (keyword, rest.trim())
}

/// [`scan`] in chunks of about `chunk_bytes`.
fn scan_in_chunks(text: &str, chunk_bytes: usize) -> ObjScan {
    let pieces = chunks(text, chunk_bytes);
    let scanned = par_map(None, pieces.len(), |k| {
        let (mut piece, mut lines) = (ObjScan::default(), 0);
        let mut used = std::collections::HashSet::new();
        for (index, line) in pieces[k].lines().enumerate() {
            lines += 1;
            let (keyword, rest) = statement(line);
            match keyword {
                "f" => piece.face_count += 1,
                "mtllib" if !rest.is_empty() => piece.material_libraries.push(Reference { line: index, name: rest.to_string() }),
                "usemtl" if !rest.is_empty() && used.insert(rest) => {
                    piece.used_materials.push(Reference { line: index, name: rest.to_string() })
                }
                _ => {}
            }
        }
        (piece, lines)
    });
    // Lines numbered from the file's start, each name used once: at its first line.
    let mut scan = ObjScan::default();
    let (mut first_line, mut used) = (0, std::collections::HashSet::new());
    for (piece, lines) in scanned {
        let numbered = |r: Reference| Reference { line: first_line + r.line + 1, ..r };
        scan.material_libraries.extend(piece.material_libraries.into_iter().map(numbered));
        for reference in piece.used_materials {
            if used.insert(reference.name.clone()) {
                scan.used_materials.push(numbered(reference));
            }
        }
        scan.face_count += piece.face_count;
        first_line += lines;
    }
    scan
}

pub struct MtlMaterial {
    pub name: String,
    /// The MTL definition, or `None` for a name only `usemtl` mentions.
    pub definition: Option<tobj::Material>,
    /// Where the definition (or, for undefined names, the first use) is.
    pub location: Location,
}

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

/// The materials of the MTL libraries `mtls` (a later definition of a
/// name replaces an earlier one), then those `usemtl` names that no
/// library defines.
fn materials(path: &Path, scan: &ObjScan, mtls: &[(PathBuf, String)]) -> Result<Vec<MtlMaterial>, SceneError> {
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
    Ok(materials)
}

/// A face's corners and material as the file writes them.
#[derive(Debug, Clone, PartialEq)]
pub struct ObjFace {
    /// Index into [`ObjModel::materials`]; `None` before any `usemtl`.
    pub material: Option<usize>,
    /// Range into [`ObjModel::corners`].
    pub corners: Range<u32>,
}

/// One corner of a face.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Corner {
    /// Index into [`ObjModel::positions`].
    pub position: u32,
    /// Which of the file's vertices it is ([`super::Triangle::file_vertices`]):
    /// its position, texture and normal within one run of faces between
    /// `o`, `g` and `usemtl` lines.
    pub vertex: u32,
}

/// The model as its OBJ writes it, with every material name it uses.
pub struct ObjModel {
    /// The `v` lines, in model units.
    pub positions: Vec<DVec3>,
    /// The faces of three corners or more (points and lines are not
    /// surfaces).
    pub faces: Vec<ObjFace>,
    pub corners: Vec<Corner>,
    /// The materials by index: those of the MTL files, then one empty entry
    /// for each `usemtl` name no MTL defines.
    pub materials: Vec<MtlMaterial>,
}

/// An index of a face corner as written: from the start of the file
/// (`k`, 1-based) or back from the element last read (`-k`).
#[derive(Debug, Clone, Copy)]
enum Written {
    /// 0-based.
    FromStart(u32),
    /// How many such elements the chunk had read, and how far back.
    Back { read: u32, back: u32 },
}

/// A face corner's three indices as written.
#[derive(Debug, Clone, Copy)]
struct WrittenCorner {
    v: Written,
    vt: Option<Written>,
    vn: Option<Written>,
}

/// A face as a chunk read it.
struct ChunkFace {
    /// Its line in the chunk (0-based).
    line: u32,
    /// The run of faces it is in (0: the run the chunk began in).
    run: u32,
    /// Its material; `None`: as the chunk began.
    material: Option<Option<usize>>,
    /// Range into [`Chunk::corners`].
    corners: Range<u32>,
}

/// What one chunk of the OBJ's lines holds, with indices and states that
/// depend on the chunks before it left open.
#[derive(Default)]
struct Chunk {
    lines: usize,
    positions: Vec<DVec3>,
    texcoords: u32,
    normals: u32,
    faces: Vec<ChunkFace>,
    corners: Vec<WrittenCorner>,
    /// The material of the chunk's last `usemtl`, if any.
    last_material: Option<Option<usize>>,
    /// How many runs of faces began in it.
    runs: u32,
    /// The first bad line: its number in the chunk (0-based) and why.
    error: Option<(usize, String)>,
}

/// Chunks of about this many bytes are read side by side.
const CHUNK_BYTES: usize = 1 << 20;

/// Reads the OBJ's vertices and faces with materials from `mtls`: one
/// error naming the line for a vertex that is not three finite numbers
/// within [`MAX_COORDINATE`] or a face corner that names no vertex. Large
/// files are read in chunks side by side (most of a load's time was
/// parsing them); the result is the same however they are cut.
pub fn read(path: &Path, text: &str, scan: &ObjScan, mtls: &[(PathBuf, String)]) -> Result<ObjModel, SceneError> {
    read_in_chunks(path, text, scan, mtls, CHUNK_BYTES)
}

/// [`read`] in chunks of about `chunk_bytes`.
fn read_in_chunks(path: &Path, text: &str, scan: &ObjScan, mtls: &[(PathBuf, String)], chunk_bytes: usize) -> Result<ObjModel, SceneError> {
    let materials = materials(path, scan, mtls)?;
    let index: HashMap<&str, usize> = materials.iter().enumerate().map(|(i, m)| (m.name.as_str(), i)).collect();
    let pieces = chunks(text, chunk_bytes);
    let chunks = par_map(None, pieces.len(), |k| read_chunk(pieces[k], &index));
    if let Some((line, message)) = chunks
        .iter()
        .scan(0, |first, chunk| {
            let at = *first;
            *first += chunk.lines;
            Some(chunk.error.as_ref().map(|(line, message)| (at + line + 1, message)))
        })
        .flatten()
        .next()
    {
        return Err(SceneError::new(Location::line(path, line), message.clone()));
    }
    if scan.face_count == 0 {
        return Err(SceneError::new(Location::file(path), "the model has no faces"));
    }
    join(path, chunks, materials)
}

/// The text cut into pieces of whole lines, about `bytes` each.
fn chunks(text: &str, bytes: usize) -> Vec<&str> {
    let mut pieces = Vec::new();
    let mut rest = text;
    while rest.len() > bytes {
        // After a newline: a character's boundary, whatever comes before.
        let cut = rest.as_bytes()[bytes..].iter().position(|&b| b == b'\n').map_or(rest.len(), |k| bytes + k + 1);
        let (piece, after) = rest.split_at(cut);
        pieces.push(piece);
        rest = after;
    }
    pieces.push(rest);
    pieces
}

/// A corner's index as written (`k` or `-k`, 1-based); `None` for 0 or
/// what is not a whole number.
fn written(word: &str, read: u32) -> Option<Written> {
    let k: i64 = word.parse().ok()?;
    match k {
        1.. => Some(Written::FromStart(u32::try_from(k - 1).ok()?)),
        ..0 => Some(Written::Back { read, back: u32::try_from(-k).ok()? }),
        0 => None,
    }
}

fn read_chunk(text: &str, materials: &HashMap<&str, usize>) -> Chunk {
    let mut chunk = Chunk::default();
    for (line_index, line) in text.lines().enumerate() {
        chunk.lines += 1;
        if chunk.error.is_some() {
            continue;
        }
        let (keyword, rest) = statement(line);
        let fail = |chunk: &mut Chunk, message: String| chunk.error = Some((line_index, message));
        match keyword {
            "v" => match vertex(rest) {
                Ok(p) => chunk.positions.push(p),
                Err(message) => fail(&mut chunk, message),
            },
            "vt" => chunk.texcoords += 1,
            "vn" => chunk.normals += 1,
            "f" => {
                let start = chunk.corners.len() as u32;
                let read = (chunk.positions.len() as u32, chunk.texcoords, chunk.normals);
                for word in rest.split_whitespace().take_while(|w| !w.starts_with('#')) {
                    let mut parts = word.split('/');
                    let index = |part: Option<&str>, read: u32| part.filter(|p| !p.is_empty()).and_then(|p| written(p, read));
                    let Some(v) = index(parts.next(), read.0) else {
                        fail(&mut chunk, format!("face corner '{word}' names no vertex (expected v, v/vt, v//vn or v/vt/vn, 1-based)"));
                        break;
                    };
                    chunk.corners.push(WrittenCorner { v, vt: index(parts.next(), read.1), vn: index(parts.next(), read.2) });
                }
                let end = chunk.corners.len() as u32;
                if chunk.error.is_none() && end - start >= 3 {
                    chunk.faces.push(ChunkFace {
                        line: line_index as u32,
                        run: chunk.runs,
                        material: chunk.last_material,
                        corners: start..end,
                    });
                } else {
                    chunk.corners.truncate(start as usize);
                }
            }
            "o" | "g" => chunk.runs += 1,
            "usemtl" if !rest.is_empty() => {
                chunk.runs += 1;
                chunk.last_material = Some(materials.get(rest).copied());
            }
            _ => {}
        }
    }
    chunk
}

/// A `v` line's first three numbers (a fourth, w, or colours after them
/// are not geometry).
fn vertex(rest: &str) -> Result<DVec3, String> {
    let mut coordinates = [0.0; 3];
    let mut words = rest.split_whitespace();
    for c in &mut coordinates {
        let word = words.next().ok_or("vertex needs three coordinates")?;
        *c = match word.parse::<f64>() {
            Ok(v) if v.is_finite() && v.abs() <= MAX_COORDINATE => v,
            Ok(v) if v.is_finite() => return Err(format!("vertex coordinate {word} is beyond ±{MAX_COORDINATE:e} model units")),
            Ok(_) => return Err(format!("vertex has a non-finite coordinate '{word}'")),
            Err(_) => return Err(format!("vertex coordinate '{word}' is not a number")),
        };
    }
    Ok(DVec3::from_array(coordinates))
}

/// The chunks joined: indices made absolute, materials and runs carried
/// over from the chunks before, the file's vertices numbered.
fn join(path: &Path, chunks: Vec<Chunk>, materials: Vec<MtlMaterial>) -> Result<ObjModel, SceneError> {
    let total = chunks.iter().map(|c| c.positions.len()).sum::<usize>();
    let mut positions = Vec::with_capacity(total);
    let mut faces = Vec::with_capacity(chunks.iter().map(|c| c.faces.len()).sum());
    let mut corners = Vec::with_capacity(chunks.iter().map(|c| c.corners.len()).sum());
    // Each file vertex (its position, texture and normal within a run of
    // faces) numbered as first met. Runs end for good, so the map holds
    // one run's: small, where a map of all the file's was most of a read.
    let (mut numbers, mut numbered, mut current_run) = (rustc_hash::FxHashMap::<(u32, i64, i64), u32>::default(), 0u32, 0u32);
    let (mut first_line, mut runs, mut material) = (0usize, 0u32, None);
    let (mut texcoords, mut normals) = (0i64, 0i64);
    for chunk in chunks {
        let before = positions.len() as i64;
        let absolute = |w: Written, before: i64| match w {
            Written::FromStart(k) => i64::from(k),
            Written::Back { read, back } => before + i64::from(read) - i64::from(back),
        };
        for face in &chunk.faces {
            let face_material = face.material.unwrap_or(material);
            let start = corners.len() as u32;
            for written in &chunk.corners[face.corners.start as usize..face.corners.end as usize] {
                let v = absolute(written.v, before);
                let Some(position) = u32::try_from(v).ok().filter(|&v| (v as usize) < total) else {
                    let message = if v < 0 {
                        "face goes back past the file's first vertex".to_string()
                    } else {
                        format!("face names vertex {} but the file has {total} vertices", v + 1)
                    };
                    return Err(SceneError::new(Location::line(path, first_line + face.line as usize + 1), message));
                };
                let vt = written.vt.map_or(-1, |w| absolute(w, texcoords));
                let vn = written.vn.map_or(-1, |w| absolute(w, normals));
                if runs + face.run != current_run {
                    current_run = runs + face.run;
                    numbered += numbers.len() as u32;
                    // A large run's table is not cleared bucket by bucket at every small one after it.
                    if numbers.capacity() > 1024 {
                        numbers = rustc_hash::FxHashMap::default();
                    } else {
                        numbers.clear();
                    }
                }
                let next = numbered + numbers.len() as u32;
                let vertex = *numbers.entry((position, vt, vn)).or_insert(next);
                corners.push(Corner { position, vertex });
            }
            faces.push(ObjFace { material: face_material, corners: start..corners.len() as u32 });
        }
        positions.extend(chunk.positions);
        first_line += chunk.lines;
        runs += chunk.runs;
        material = chunk.last_material.unwrap_or(material);
        texcoords += i64::from(chunk.texcoords);
        normals += i64::from(chunk.normals);
    }
    Ok(ObjModel { positions, faces, corners, materials })
}

/// The model's triangles in the canonical frame, with the material index
/// of their face (`None` for faces before any `usemtl`). Degenerate and
/// duplicated triangles are dropped with a warning.
pub fn triangles(
    model: &ObjModel,
    frame: &ModelFrame,
    material_of: &BTreeMap<Option<usize>, u32>,
    path: &Path,
    warnings: &mut Vec<SceneWarning>,
) -> Result<Vec<Triangle>, SceneError> {
    let points: Vec<Vec3> = par_map(None, model.positions.len(), |k| frame.point(model.positions[k]));
    // Faces triangulated side by side, in blocks; each block's triangles
    // and degenerate faces in file order.
    let blocks = par_chunks(None, &model.faces, 4096, |block| {
        let mut face: Vec<Vec3> = Vec::new();
        let (mut pieces, mut degenerate) = (Vec::new(), 0usize);
        for obj_face in block {
            let corners = &model.corners[obj_face.corners.start as usize..obj_face.corners.end as usize];
            face.clear();
            face.extend(corners.iter().map(|c| points[c.position as usize]));
            let material = material_of[&obj_face.material];
            let triangles = polygon::triangulate(&face);
            degenerate += usize::from(triangles.is_empty());
            for [a, b, c] in triangles {
                let triangle =
                    Triangle { vertices: [face[a], face[b], face[c]], material, file_vertices: [a, b, c].map(|k| corners[k].vertex) };
                if is_degenerate(&triangle) {
                    degenerate += 1;
                } else {
                    pieces.push(triangle);
                }
            }
        }
        (pieces, degenerate)
    });
    let degenerate: usize = blocks.iter().map(|(_, degenerate)| degenerate).sum();
    let candidates: Vec<Triangle> = blocks.into_iter().flat_map(|(pieces, _)| pieces).collect();
    // Faces written twice (same corners, same material) count once: copies
    // would weigh on every ray and pass for nothing. Found by sorting the
    // triangles by a hash of their corners, the first of each kept (a set
    // of all the corners took 0.1 s of a large model's load).
    let key = |t: &Triangle| {
        let mut corners = t.vertices.map(|v| v.to_array().map(f32::to_bits));
        corners.sort_unstable();
        (corners, t.material)
    };
    let hash = |t: &Triangle| {
        let mut hash = rustc_hash::FxHasher::default();
        key(t).hash(&mut hash);
        hash.finish()
    };
    let mut by_hash: Vec<(u64, u32)> = par_map(None, candidates.len(), |k| (hash(&candidates[k]), k as u32));
    by_hash.sort_unstable();
    let mut copy = vec![false; candidates.len()];
    for same in by_hash.chunk_by(|a, b| a.0 == b.0).filter(|same| same.len() > 1) {
        for (n, &(_, later)) in same.iter().enumerate().skip(1) {
            let later_key = key(&candidates[later as usize]);
            copy[later as usize] =
                same[..n].iter().any(|&(_, earlier)| !copy[earlier as usize] && key(&candidates[earlier as usize]) == later_key);
        }
    }
    let duplicated = copy.iter().filter(|&&c| c).count();
    let triangles: Vec<Triangle> = candidates.into_iter().zip(copy).filter(|(_, copy)| !copy).map(|(t, _)| t).collect();
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

/// The centre of the bounds of the vertices faces use (model units, f64)
/// when it lies farther than `beyond` from the origin; `None` for a model
/// near its origin.
pub fn far_centre(model: &ObjModel, beyond: f64) -> Option<DVec3> {
    let (lo, hi) = model
        .corners
        .iter()
        .map(|c| model.positions[c.position as usize])
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

#[cfg(test)]
mod tests {
    use super::*;

    const PATH: &str = "model.obj";

    fn read_text(text: &str, chunk_bytes: usize) -> Result<ObjModel, SceneError> {
        read_in_chunks(Path::new(PATH), text, &scan(text), &[], chunk_bytes)
    }

    fn faces(model: &ObjModel) -> Vec<(Option<&str>, Vec<u32>, Vec<u32>)> {
        model
            .faces
            .iter()
            .map(|f| {
                let corners = &model.corners[f.corners.start as usize..f.corners.end as usize];
                (
                    f.material.map(|m| model.materials[m].name.as_str()),
                    corners.iter().map(|c| c.position).collect(),
                    corners.iter().map(|c| c.vertex).collect(),
                )
            })
            .collect()
    }

    /// Every way a corner may be written, indices back from the last
    /// vertex read, runs of faces between `o`, `g` and `usemtl`, a
    /// multi-byte name: read the same however the text is cut, down to a
    /// line a chunk.
    #[test]
    fn a_file_reads_the_same_however_it_is_cut() {
        let text = "# a test\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\nvn 0 0 -1\n\
                    f 1 2 3\nusemtl béton\nf 1/1 2/2 3/3 4\nf -4//1 -3//1 -2//2\no next\nf 1/1/1 2/2/1 3/3/1\n\
                    v 0 0 2\nf -1 -4 -3 # a comment\nusemtl béton\nf 1 2 5\ng last\nl 1 2\nf 1 2\nf 5 2 3 4\n";
        let whole = read_text(text, 1 << 20).unwrap();
        let faces_whole = faces(&whole);
        let b = Some("béton");
        let expected_positions =
            [vec![0, 1, 2], vec![0, 1, 2, 3], vec![0, 1, 2], vec![0, 1, 2], vec![4, 1, 2], vec![0, 1, 4], vec![4, 1, 2, 3]];
        let got: Vec<_> = faces_whole.iter().map(|(_, positions, _)| positions.clone()).collect();
        assert_eq!(got, expected_positions, "points and lines are not faces");
        let materials: Vec<_> = faces_whole.iter().map(|(m, _, _)| *m).collect();
        assert_eq!(materials, [None, b, b, b, b, b, b]);
        let scanned = |bytes| {
            let scan = scan_in_chunks(text, bytes);
            (scan.face_count, scan.used_materials.iter().map(|r| (r.name.clone(), r.line)).collect::<Vec<_>>())
        };
        assert_eq!(scanned(1 << 20), (8, vec![("béton".to_string(), 12)]));
        for bytes in [1, 7, 40, 100] {
            assert_eq!(scanned(bytes), scanned(1 << 20), "scanned in chunks of {bytes} bytes");
            let cut = read_text(text, bytes).unwrap();
            assert_eq!(cut.positions, whole.positions, "in chunks of {bytes} bytes");
            assert_eq!(faces(&cut), faces_whole, "in chunks of {bytes} bytes");
        }
    }

    /// A file vertex is a position with its texture and normal within one
    /// run of faces: shared by faces written with it, apart across runs or
    /// with another normal.
    #[test]
    fn file_vertices_are_position_texture_and_normal_within_a_run() {
        let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nvn 0 0 -1\n\
                    f 1//1 2//1 3//1\nf 1//1 3//1 4//1\nf 1//2 3//2 4//2\nusemtl a\nf 1//1 2//1 3//1\n";
        let model = read_text(text, 1 << 20).unwrap();
        let vertices: Vec<Vec<u32>> = faces(&model).into_iter().map(|(_, _, v)| v).collect();
        assert_eq!(vertices[0], [0, 1, 2]);
        assert_eq!(vertices[1], [0, 2, 3], "the same vertices, shared");
        assert_eq!(vertices[2], [4, 5, 6], "another normal: other vertices");
        assert_eq!(vertices[3], [7, 8, 9], "another run: other vertices");
    }

    /// A corner that names no vertex is one error naming its line.
    #[test]
    fn bad_corners_name_their_line() {
        for (face, message) in [
            ("f 1 2 9", "face names vertex 9 but the file has 3 vertices"),
            ("f 1 -7 3", "face goes back past the file's first vertex"),
            ("f 1 x 3", "face corner 'x' names no vertex"),
            ("f 1 0 3", "face corner '0' names no vertex"),
            ("f 1 /2 3", "face corner '/2' names no vertex"),
        ] {
            let text = format!("v 0 0 0\nv 1 0 0\n\nv 1 1 0\n{face}\n");
            for bytes in [1, 1 << 20] {
                let error = read_text(&text, bytes).err().unwrap_or_else(|| panic!("{face} read"));
                assert_eq!(error.location.line, Some(5), "{face}");
                assert!(error.message.starts_with(message), "{face}: {}", error.message);
            }
        }
    }
}
