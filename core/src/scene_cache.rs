//! The loaded model on disk. On a large model most of a warm `sensors` run
//! was the load, not the light: the furnished floor of offices (31 MB of
//! OBJ, 281k triangles) spent 0.6 of its 0.9 s parsing, grouping and
//! cutting patches. So what `scene::build_model` makes of
//! the model's files (materials, triangles, surfaces, windows, patches and
//! the warnings on the way) is stored beside the light cache
//! (`light-scene-{key}.bin`, the same folder, bound and atomic writes),
//! and read back when the files are the same.
//!
//! The key hashes the scene file's path and bytes, the OBJ's bytes, and
//! the loader itself (this crate's version and a hash of its sources,
//! made by `build.rs`): a loader that cuts patches otherwise never reads
//! what an older one stored. The MTL libraries' paths come from the OBJ,
//! so the file lists them with a hash of each, checked on every read. The
//! rest of the scene (site, sensors, cameras, shades) is read from the
//! scene file each time, and panel models are built again from their
//! parameters (a panel's data files are not part of the key).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use glam::Vec3;

use crate::light::cache::{CacheOutcome, DOES_NOT_FIT, Reader, StableHash, Writer, mark_used, open_entry, store_entry};
use crate::panel::{PanelCatalog, PanelHandle, Parameters, base_dir as panel_base_dir};
use crate::scene::{
    self, BuiltModel, FsReader, LoadedScene, Location, Material, MaterialKind, MaterialOrigin, Patch, PatchMesh, Rgb, SceneError,
    SceneReader, SceneWarning, Surface, Triangle, Window,
};

/// Bump when the stored layout changes.
const FORMAT: u64 = 1;

/// [`scene::load_scene`] through the cache in `dir` (none: no cache).
pub fn load_scene_cached(path: &Path, panels: &PanelCatalog, dir: Option<&Path>) -> Result<(LoadedScene, CacheOutcome), SceneError> {
    futures_lite::future::block_on(load_scene_cached_with(path, panels, &mut FsReader, dir))
}

/// [`scene::load_scene_with`] through the cache in `dir` (none: no cache).
pub async fn load_scene_cached_with(
    scene_path: &Path,
    panels: &PanelCatalog,
    reader: &mut impl SceneReader,
    dir: Option<&Path>,
) -> Result<(LoadedScene, CacheOutcome), SceneError> {
    let (mut parsed, obj_path, obj_text) = scene::read_scene_and_obj(scene_path, reader).await?;
    let Some(dir) = dir else {
        let (built, mtls) = scene::build_model(&mut parsed, &obj_path, &obj_text, panels, reader).await?;
        let paths = mtls.into_iter().map(|(path, _)| path).collect();
        return Ok((scene::assemble(parsed, obj_path, paths, built)?, CacheOutcome::Skipped("disabled".into())));
    };
    let key = key(scene_path, &parsed.text, &obj_text);
    let (file, found) = open_entry(dir, &format!("scene-{key:016x}"), key);
    let rebuilt = match found {
        None => None,
        Some(Err(why)) => Some(why),
        Some(Ok(payload)) => {
            let mut r = Reader(&payload);
            match read_libraries(&mut r) {
                Some(mtls) if libraries_unchanged(&mtls, reader).await => {
                    let base = panel_base_dir(&parsed.path);
                    match read_model(&mut r, panels, &base) {
                        Some(built) => {
                            mark_used(&file);
                            let paths = mtls.into_iter().map(|(path, _)| path).collect();
                            return Ok((scene::assemble(parsed, obj_path, paths, built)?, CacheOutcome::Hit(file)));
                        }
                        None => Some(DOES_NOT_FIT.to_string()),
                    }
                }
                Some(_) => Some("an MTL library changed".to_string()),
                None => Some(DOES_NOT_FIT.to_string()),
            }
        }
    };
    let (built, mtls) = scene::build_model(&mut parsed, &obj_path, &obj_text, panels, reader).await?;
    let libraries: Vec<(PathBuf, u64)> = mtls.into_iter().map(|(path, text)| (path, library_hash(&text))).collect();
    let outcome = match payload(&libraries, &built) {
        Some(payload) => store_entry(dir, file, key, &payload, rebuilt),
        None => CacheOutcome::Skipped("a path is not UTF-8".into()),
    };
    let paths = libraries.into_iter().map(|(path, _)| path).collect();
    Ok((scene::assemble(parsed, obj_path, paths, built)?, outcome))
}

/// The scene file's path and bytes, the OBJ's, and the loader's version.
fn key(scene_path: &Path, scene_text: &str, obj_text: &str) -> u64 {
    let mut hash = StableHash::new();
    let loader = [
        b"HELIOSC\0".as_slice(),
        &FORMAT.to_le_bytes(),
        env!("CARGO_PKG_VERSION").as_bytes(),
        env!("HELIODON_CORE_SOURCE_HASH").as_bytes(),
    ];
    // Lengths first, so no two different lists hash the same bytes.
    for part in loader.into_iter().chain([scene_path.as_os_str().as_encoded_bytes(), scene_text.as_bytes()]) {
        hash.u64(part.len() as u64).bytes(part);
    }
    // The OBJ (tens of megabytes) a megabyte a block, side by side.
    let megabytes: Vec<&[u8]> = obj_text.as_bytes().chunks(1 << 20).collect();
    hash.blocks_of(&megabytes, 1, |h, block| {
        h.bytes(block);
    });
    hash.finish()
}

fn library_hash(text: &str) -> u64 {
    StableHash::new().bytes(text.as_bytes()).finish()
}

/// Whether each MTL library still reads as it did.
async fn libraries_unchanged(libraries: &[(PathBuf, u64)], reader: &mut impl SceneReader) -> bool {
    for (path, hash) in libraries {
        match scene::read_text(reader, path, None).await {
            Ok(text) if library_hash(&text) == *hash => {}
            _ => return false,
        }
    }
    true
}

/// The file's payload; `None` when a path cannot be stored (not UTF-8).
fn payload(libraries: &[(PathBuf, u64)], built: &BuiltModel) -> Option<Vec<u8>> {
    let mut w = Writer::default();
    w.u32(libraries.len() as u32);
    for (path, hash) in libraries {
        text(&mut w, path.to_str()?);
        w.u64(*hash);
    }
    w.u32(built.materials.len() as u32);
    for material in &built.materials {
        write_material(&mut w, material)?;
    }
    w.u32(built.unused_materials.len() as u32);
    for (name, material) in &built.unused_materials {
        text(&mut w, name);
        write_material(&mut w, material)?;
    }
    w.vec3(built.origin);
    w.u32(built.triangles.len() as u32);
    for triangle in &built.triangles {
        corners(&mut w, &triangle.vertices);
        w.u32(triangle.material);
        triangle.file_vertices.iter().for_each(|&v| w.u32(v));
    }
    w.u32(built.surfaces.len() as u32);
    for s in &built.surfaces {
        w.u32(s.material);
        [s.triangles.start, s.triangles.end, s.patches.start, s.patches.end].iter().for_each(|&v| w.u32(v));
        vector(&mut w, s.normal);
        w.f32(s.area);
    }
    w.u32(built.windows.len() as u32);
    for window in &built.windows {
        w.u32(window.surface);
        w.u32(window.material);
        w.f32(window.area);
        vector(&mut w, window.normal);
        vector(&mut w, window.centroid);
    }
    let mesh = &built.patches;
    w.u32(mesh.patches.len() as u32);
    for p in &mesh.patches {
        w.u32(p.surface);
        w.u32(p.material);
        w.f32(p.area);
        vector(&mut w, p.normal);
        vector(&mut w, p.centroid);
        w.u32(p.triangles.start);
        w.u32(p.triangles.end);
    }
    w.u32(mesh.triangles.len() as u32);
    mesh.triangles.iter().for_each(|t| corners(&mut w, t));
    w.u32(mesh.clusters.len() as u32);
    for (patch, surfaces) in &mesh.clusters {
        w.u32(*patch);
        w.u32(surfaces.len() as u32);
        surfaces.iter().for_each(|&s| w.u32(s));
    }
    w.u32(built.warnings.len() as u32);
    for warning in &built.warnings {
        write_location(&mut w, &warning.location)?;
        text(&mut w, &warning.message);
    }
    Some(w.0)
}

fn read_libraries(r: &mut Reader) -> Option<Vec<(PathBuf, u64)>> {
    (0..r.u32()?).map(|_| Some((PathBuf::from(read_text(r)?), r.u64()?))).collect()
}

/// The model as [`payload`] wrote it, panels built again; `None` when it
/// does not read back (or a panel no longer builds: the load then says why).
fn read_model(r: &mut Reader, panels: &PanelCatalog, base: &Path) -> Option<BuiltModel> {
    let materials = (0..r.u32()?).map(|_| read_material(r, panels, base)).collect::<Option<Vec<_>>>()?;
    let unused_materials =
        (0..r.u32()?).map(|_| Some((read_text(r)?, read_material(r, panels, base)?))).collect::<Option<BTreeMap<_, _>>>()?;
    let origin = r.vec3()?;
    let triangles = counted(r, 52, |r| {
        Some(Triangle { vertices: read_corners(r)?, material: r.u32()?, file_vertices: [r.u32()?, r.u32()?, r.u32()?] })
    })?;
    let surfaces = counted(r, 36, |r| {
        Some(Surface {
            material: r.u32()?,
            triangles: r.u32()?..r.u32()?,
            patches: r.u32()?..r.u32()?,
            normal: read_vector(r)?,
            area: r.f32()?,
        })
    })?;
    let windows = counted(r, 36, |r| {
        Some(Window { surface: r.u32()?, material: r.u32()?, area: r.f32()?, normal: read_vector(r)?, centroid: read_vector(r)? })
    })?;
    let patches = counted(r, 44, |r| {
        Some(Patch {
            surface: r.u32()?,
            material: r.u32()?,
            area: r.f32()?,
            normal: read_vector(r)?,
            centroid: read_vector(r)?,
            triangles: r.u32()?..r.u32()?,
        })
    })?;
    let render_triangles = counted(r, 36, read_corners)?;
    let clusters = counted(r, 8, |r| Some((r.u32()?, counted(r, 4, |r| r.u32())?)))?;
    let warnings = counted(r, 8, |r| Some(SceneWarning { location: read_location(r)?, message: read_text(r)? }))?;
    r.is_empty().then_some(BuiltModel {
        materials,
        unused_materials,
        origin,
        triangles,
        surfaces,
        windows,
        patches: PatchMesh { patches, triangles: render_triangles, clusters },
        warnings,
    })
}

/// A count, then as many items of at least `size` bytes each (a count the
/// bytes left cannot hold is refused before anything is allocated).
fn counted<T>(r: &mut Reader, size: usize, mut item: impl FnMut(&mut Reader) -> Option<T>) -> Option<Vec<T>> {
    let n = r.u32()? as usize;
    if n > r.0.len() / size {
        return None;
    }
    let mut items = Vec::with_capacity(n);
    for _ in 0..n {
        items.push(item(r)?);
    }
    Some(items)
}

fn write_material(w: &mut Writer, material: &Material) -> Option<()> {
    text(w, &material.name);
    match &material.kind {
        MaterialKind::Diffuse { reflectance } => {
            w.u8(0);
            reflectance.0.iter().for_each(|&c| w.f32(c));
        }
        MaterialKind::Glass { transmittance } => {
            w.u8(1);
            w.f32(*transmittance);
        }
        MaterialKind::Panel { panel, up, parameters, .. } => {
            w.u8(2);
            text(w, panel);
            match up {
                Some(up) => {
                    w.u8(1);
                    vector(w, *up);
                }
                None => w.u8(0),
            }
            text(w, &toml::to_string(parameters).ok()?);
        }
    }
    match &material.origin {
        MaterialOrigin::Scene(location) => {
            w.u8(0);
            write_location(w, location)?;
        }
        MaterialOrigin::Mtl(location) => {
            w.u8(1);
            write_location(w, location)?;
        }
        MaterialOrigin::Unassigned => w.u8(2),
    }
    Some(())
}

fn read_material(r: &mut Reader, panels: &PanelCatalog, base: &Path) -> Option<Material> {
    let name = read_text(r)?;
    let kind = match r.u8()? {
        0 => MaterialKind::Diffuse { reflectance: Rgb([r.f32()?, r.f32()?, r.f32()?]) },
        1 => MaterialKind::Glass { transmittance: r.f32()? },
        2 => {
            let panel = read_text(r)?;
            let up = match r.u8()? {
                0 => None,
                _ => Some(read_vector(r)?),
            };
            let parameters: toml::Table = toml::from_str(&read_text(r)?).ok()?;
            let model = panels.build(&panel, &Parameters::new(parameters.clone(), base.to_path_buf())).ok()?;
            MaterialKind::Panel { panel, up, parameters, model: PanelHandle(model) }
        }
        _ => return None,
    };
    let origin = match r.u8()? {
        0 => MaterialOrigin::Scene(read_location(r)?),
        1 => MaterialOrigin::Mtl(read_location(r)?),
        2 => MaterialOrigin::Unassigned,
        _ => return None,
    };
    Some(Material { name, kind, origin })
}

fn write_location(w: &mut Writer, location: &Location) -> Option<()> {
    text(w, location.file.to_str()?);
    w.u64(location.line.map_or(0, |line| line as u64 + 1));
    match &location.key {
        Some(key) => {
            w.u8(1);
            text(w, key);
        }
        None => w.u8(0),
    }
    Some(())
}

fn read_location(r: &mut Reader) -> Option<Location> {
    let file = PathBuf::from(read_text(r)?);
    let line = r.u64()?.checked_sub(1).map(|line| line as usize);
    let key = match r.u8()? {
        0 => None,
        _ => Some(read_text(r)?),
    };
    Some(Location { file, line, key })
}

fn text(w: &mut Writer, s: &str) {
    w.u32(s.len() as u32);
    w.0.extend_from_slice(s.as_bytes());
}

fn read_text(r: &mut Reader) -> Option<String> {
    let n = r.u32()? as usize;
    (n <= r.0.len()).then_some(())?;
    let (bytes, rest) = r.0.split_at(n);
    r.0 = rest;
    String::from_utf8(bytes.to_vec()).ok()
}

fn vector(w: &mut Writer, v: Vec3) {
    v.to_array().iter().for_each(|&c| w.f32(c));
}

fn read_vector(r: &mut Reader) -> Option<Vec3> {
    Some(Vec3::new(r.f32()?, r.f32()?, r.f32()?))
}

fn corners(w: &mut Writer, corners: &[Vec3; 3]) {
    corners.iter().for_each(|&v| vector(w, v));
}

fn read_corners(r: &mut Reader) -> Option<[Vec3; 3]> {
    Some([read_vector(r)?, read_vector(r)?, read_vector(r)?])
}
