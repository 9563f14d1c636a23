//! Scene loading: a scene file (TOML) with its OBJ and MTL turned into the
//! geometry, materials, windows, patches and sensors every other part of
//! heliodon works on. Plain Rust, no Bevy types: the Bevy asset loader and
//! the tests go through [`load_scene_with`], the CLI through
//! [`crate::scene_cache`], which keeps what `build_model` makes of the
//! model's files (`BuiltModel`) and assembles the rest each time.
//!
//! Everything is in one canonical frame: metres, x east, y north, z up (as in
//! Radiance). [`ModelFrame`] maps the model's own axes, north and units into it.
//! [`save`] writes a scene's edits back into its file.

mod contacts;
mod cut_plane;
mod error;
mod file;
mod frame;
mod material;
mod obj;
mod patches;
mod polygon;
mod repair;
pub mod save;
pub(crate) use patches::clip as clip_convex;
mod sensors;
mod shades;
pub(crate) mod shells;
mod surfaces;

use std::collections::BTreeMap;
use std::future::Future;
use std::io;
use std::ops::Range;
use std::path::{Path, PathBuf};

use glam::{DVec3, Vec3};

pub use cut_plane::CutPlane;
pub use error::{Location, SceneError, SceneWarning, line_of};
pub use frame::{ModelFrame, UpAxis};
pub use material::{Material, MaterialKind, MaterialOrigin, Rgb};
pub use patches::{Patch, PatchMesh, PatchSizing};
pub use sensors::{DEFAULT_FOV, Sensor, Viewpoint};
pub use shades::ShadeGroup;

use crate::panel::PanelCatalog;
use crate::site::Site;

/// The largest coordinate (model units) heliodon reads: beyond it f32 loses
/// the model (1e9 m is 6 times the Earth–Sun distance; survey coordinates of
/// a few hundred km are well inside).
pub const MAX_COORDINATE: f64 = 1e9;

/// The smallest `[lighting] patch_size` (m): finer patches only multiply the work.
pub const MIN_PATCH_SIZE: f64 = 0.05;
/// The largest `[lighting] patch_size` (m): coarser, a room is a handful of patches.
pub const MAX_PATCH_SIZE: f64 = 10.0;
/// Above this patch size (m) interreflected light loses accuracy: in the
/// validation room ±5% at 2 m, up to 17% at 5 m.
pub const ACCURATE_PATCH_SIZE: f32 = 1.0;
/// The most patches a scene may need, estimated before cutting them (about
/// 3 kB each once gathered: a million is 3 GB).
pub const MAX_PATCHES: f64 = 1.0e6;

/// Models whose centre lies farther than this from their origin (model
/// units) are recentred: f32 keeps about a millimetre at 10 km.
pub const RECENTRE_BEYOND: f64 = 1e4;

/// Default side of the largest lighting patch, in metres.
pub const DEFAULT_PATCH_SIZE: f32 = 0.5;

/// A loaded scene in the canonical frame (metres, x east, y north, z up).
#[derive(Debug, Clone)]
pub struct Scene {
    /// The scene file's `name`, or its file name without the extension.
    pub name: String,
    /// The files it was read from.
    pub files: SceneFiles,
    /// Where it stands: coordinates, timezone, ground reflectance.
    pub site: Site,
    /// How the model's coordinates map into the canonical frame.
    pub frame: ModelFrame,
    /// Side (metres) of the square the largest lighting patch fits in: the
    /// scene file's `[lighting] patch_size`, [`DEFAULT_PATCH_SIZE`] when absent.
    pub patch_size: f32,
    /// Every material a face uses; triangles, surfaces, patches and windows
    /// index into it.
    pub materials: Vec<Material>,
    /// The model's triangles after the frame mapping, degenerate ones dropped,
    /// ordered by surface.
    pub triangles: Vec<Triangle>,
    /// Connected planar pieces of one material, in the order of their
    /// triangles.
    pub surfaces: Vec<Surface>,
    /// The surfaces of transmitting materials (glass and panels).
    pub windows: Vec<Window>,
    /// The lighting patches the surfaces are cut into, with their render
    /// triangles.
    pub patches: PatchMesh,
    /// Illuminance sensors, grids expanded to their points.
    pub sensors: Vec<Sensor>,
    /// Named camera positions (`[[cameras]]`).
    pub viewpoints: Vec<Viewpoint>,
    /// Operable shades (`[[shades]]`), for the annual study.
    pub shades: Vec<ShadeGroup>,
    /// Axis-aligned bounds of all triangles: (min, max).
    pub bounds: (Vec3, Vec3),
    /// The bounds of what the scene is about: its windows and sensors (the
    /// whole model's bounds when it has neither): views frame it rather
    /// than a site's ground.
    pub focus: (Vec3, Vec3),
    /// The patch sizes allowed where the patches lie: how much each patch
    /// matters to the readings ([`PatchSizing::ray_share`]).
    pub patch_sizing: PatchSizing,
}

/// The files a scene was read from, as the user would name them.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct SceneFiles {
    /// The scene file (TOML).
    pub scene: PathBuf,
    /// The OBJ model: the scene file's `model.obj`, resolved against its folder.
    pub obj: PathBuf,
    /// The MTL libraries the OBJ names (`mtllib`), resolved against its folder.
    pub mtls: Vec<PathBuf>,
}

/// One triangle of the model, single-sided as in Radiance (both sides reflect).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Triangle {
    /// Corners in the canonical frame; their winding gives the normal.
    pub vertices: [Vec3; 3],
    /// Index into [`Scene::materials`].
    pub material: u32,
    /// Which of the model file's vertices each corner is, numbered across
    /// the file (an OBJ vertex with its texture and normal, per group and
    /// material): faces of one solid written with shared vertices share
    /// them, where two solids that merely touch have points that are equal
    /// but not the same vertex (the sun pass finds closed shells by them).
    pub file_vertices: [u32; 3],
}

impl Triangle {
    /// Twice the area times the unit normal (counter-clockwise winding).
    pub fn cross(&self) -> Vec3 {
        let [a, b, c] = self.vertices;
        (b - a).cross(c - a)
    }

    /// Area, m².
    pub fn area(&self) -> f32 {
        0.5 * self.cross().length()
    }

    /// Unit normal (counter-clockwise winding); zero for a degenerate triangle.
    pub fn normal(&self) -> Vec3 {
        self.cross().normalize_or_zero()
    }

    /// The mean of the three corners.
    pub fn centroid(&self) -> Vec3 {
        let [a, b, c] = self.vertices;
        (a + b + c) / 3.0
    }
}

/// A connected, planar group of triangles of one material: a wall, a desk top,
/// a window pane. Patches subdivide surfaces.
#[derive(Debug, Clone, PartialEq)]
pub struct Surface {
    /// Index into [`Scene::materials`].
    pub material: u32,
    /// Range into [`Scene::triangles`].
    pub triangles: Range<u32>,
    /// Range into [`PatchMesh::patches`].
    pub patches: Range<u32>,
    /// Area-weighted unit normal.
    pub normal: Vec3,
    /// Sum of its triangles' areas, m².
    pub area: f32,
}

impl Surface {
    /// Its triangles' indices into [`Scene::triangles`].
    pub fn triangle_indices(&self) -> Range<usize> {
        self.triangles.start as usize..self.triangles.end as usize
    }

    /// Its patches' indices into [`PatchMesh::patches`].
    pub fn patch_indices(&self) -> Range<usize> {
        self.patches.start as usize..self.patches.end as usize
    }

    /// The area-weighted centroid of its triangles, given all the model's
    /// `triangles` (those [`Self::triangles`] indexes).
    pub fn centroid(&self, triangles: &[Triangle]) -> Vec3 {
        triangles[self.triangle_indices()].iter().map(|t| t.centroid() * t.area()).sum::<Vec3>() / self.area.max(f32::MIN_POSITIVE)
    }
}

/// An aperture: a surface of a transmitting material (glass or panel).
#[derive(Debug, Clone, PartialEq)]
pub struct Window {
    /// Index into [`Scene::surfaces`].
    pub surface: u32,
    /// Index into [`Scene::materials`]: a glass or a panel.
    pub material: u32,
    /// Glazed area, m².
    pub area: f32,
    /// The surface's area-weighted unit normal.
    pub normal: Vec3,
    /// Area-weighted centroid of its triangles.
    pub centroid: Vec3,
}

/// A scene and what the user should hear about it.
#[derive(Debug, Clone)]
pub struct LoadedScene {
    /// The scene, loaded.
    pub scene: Scene,
    /// What did not stop the load (unused materials, dropped degenerate
    /// triangles), to show the user.
    pub warnings: Vec<SceneWarning>,
}

/// Reads the files a scene refers to. The loader stays independent of where
/// bytes come from: the file system for the CLI, Bevy's asset readers in apps.
pub trait SceneReader {
    /// The whole content of the file at `path`.
    fn read(&mut self, path: &Path) -> impl Future<Output = io::Result<Vec<u8>>>;
}

/// Reads straight from the file system.
pub struct FsReader;

impl SceneReader for FsReader {
    async fn read(&mut self, path: &Path) -> io::Result<Vec<u8>> {
        std::fs::read(path)
    }
}

/// Loads a scene file from disk; panel materials are built by the types in
/// `panels`.
pub fn load_scene(path: &Path, panels: &PanelCatalog) -> Result<LoadedScene, SceneError> {
    futures_lite::future::block_on(load_scene_with(path, panels, &mut FsReader))
}

/// Loads a scene file and everything it refers to through `reader`.
pub async fn load_scene_with(scene_path: &Path, panels: &PanelCatalog, reader: &mut impl SceneReader) -> Result<LoadedScene, SceneError> {
    let (mut parsed, obj_path, obj_text) = read_scene_and_obj(scene_path, reader).await?;
    let (built, mtls) = build_model(&mut parsed, &obj_path, &obj_text, panels, reader).await?;
    assemble(parsed, obj_path, mtls.into_iter().map(|(path, _)| path).collect(), built)
}

/// The scene file, parsed, with its OBJ's path and text: what a load
/// starts from (and the scene cache's key is made of).
pub(crate) async fn read_scene_and_obj(
    scene_path: &Path,
    reader: &mut impl SceneReader,
) -> Result<(file::ParsedScene, PathBuf, String), SceneError> {
    let scene_text = read_text(reader, scene_path, None).await?;
    let parsed = file::parse(scene_path, &scene_text)?;
    let obj_path = parsed.obj_path();
    let obj_text = read_text(reader, &obj_path, Some(parsed.obj_location())).await?;
    Ok((parsed, obj_path, obj_text))
}

/// Reads the MTL libraries the OBJ names and builds the model from them
/// (the costly part of a load); also gives the libraries (paths and text).
/// A model in survey coordinates moves `parsed`'s frame origin to its centre.
pub(crate) async fn build_model(
    parsed: &mut file::ParsedScene,
    obj_path: &Path,
    obj_text: &str,
    panels: &PanelCatalog,
    reader: &mut impl SceneReader,
) -> Result<(BuiltModel, Vec<(PathBuf, String)>), SceneError> {
    let obj_scan = obj::scan(obj_text);
    let mut mtls = Vec::new();
    for library in &obj_scan.material_libraries {
        let path = obj_path.parent().unwrap_or(Path::new("")).join(&library.name);
        let location = Location::line(obj_path, library.line);
        let text = read_text(reader, &path, Some(location)).await?;
        mtls.push((path, text));
    }
    let built = build(parsed, obj_path, obj_text, obj_scan, &mtls, panels)?;
    Ok((built, mtls))
}

pub(crate) async fn read_text(reader: &mut impl SceneReader, path: &Path, referenced_at: Option<Location>) -> Result<String, SceneError> {
    let bytes = reader.read(path).await.map_err(|error| {
        let what = match error.kind() {
            io::ErrorKind::NotFound => "not found".to_string(),
            _ => error.to_string(),
        };
        match referenced_at {
            Some(location) => SceneError::new(location, format!("cannot read '{}': {what}", path.display())),
            None => SceneError::new(Location::file(path), format!("cannot read scene file: {what}")),
        }
    })?;
    let text = String::from_utf8(bytes).map_err(|_| SceneError::new(Location::file(path), "not UTF-8 text"))?;
    // A byte-order mark (editors on Windows write one) is not part of the text.
    Ok(match text.strip_prefix('\u{feff}') {
        Some(rest) => rest.to_string(),
        None => text,
    })
}

/// What loading makes of the model's files: the costly part of a load,
/// which the scene cache keeps; the rest ([`assemble`]) is read from the
/// scene file each time.
#[derive(Debug, Clone)]
pub(crate) struct BuiltModel {
    pub materials: Vec<Material>,
    /// Materials of `[materials]` no face uses (a shade may).
    pub unused_materials: BTreeMap<String, Material>,
    /// The model-space point placed at the canonical origin.
    pub origin: DVec3,
    pub triangles: Vec<Triangle>,
    pub surfaces: Vec<Surface>,
    pub windows: Vec<Window>,
    pub patches: PatchMesh,
    pub warnings: Vec<SceneWarning>,
}

/// `triangles` less the ones `gone` names (by index).
fn without(triangles: &[Triangle], gone: impl IntoIterator<Item = u32>) -> Vec<Triangle> {
    let mut dropped = vec![false; triangles.len()];
    gone.into_iter().for_each(|t| dropped[t as usize] = true);
    triangles.iter().zip(dropped).filter(|(_, dropped)| !dropped).map(|(t, _)| *t).collect()
}

fn build(
    parsed: &mut file::ParsedScene,
    obj_path: &Path,
    obj_text: &str,
    obj_scan: obj::ObjScan,
    mtls: &[(PathBuf, String)],
    panels: &PanelCatalog,
) -> Result<BuiltModel, SceneError> {
    let mut warnings = Vec::new();
    let model = obj::read(obj_path, obj_text, &obj_scan, mtls)?;
    let (materials, material_of, unused_materials) = material::resolve(parsed, &model, panels, obj_path, &mut warnings)?;
    // A model in survey coordinates is recentred, in f64, before anything
    // becomes f32 (which keeps millimetres only within a few km of 0).
    if let Some(centre) = obj::far_centre(&model, RECENTRE_BEYOND) {
        parsed.frame.origin = centre;
        warnings.push(SceneWarning {
            location: Location::file(obj_path),
            message: format!(
                "the model lies {:.0} km from its origin (survey coordinates?): it is recentred on ({:.3}, {:.3}, {:.3}) for precision; positions heliodon prints are relative to that point",
                centre.length() * f64::from(parsed.frame.scale) / 1000.0,
                centre.x,
                centre.y,
                centre.z
            ),
        });
    }
    let raw_triangles = obj::triangles(&model, &parsed.frame, &material_of, obj_path, &mut warnings)?;
    let (mut triangles, mut surfaces) = surfaces::group(raw_triangles);
    let (box_faces, panes) = repair::thick_glass(&triangles, &surfaces, &materials);
    if panes > 0 {
        warnings.push(SceneWarning {
            location: Location::file(obj_path),
            message: format!(
                "{panes} glass panes are modelled as boxes (two faces up to {} cm apart): each is read as one pane, its far face and edges dropped ({} surfaces)",
                repair::MAX_PANE_THICKNESS * 100.0,
                box_faces.len()
            ),
        });
        let keep: Vec<Triangle> = surfaces
            .iter()
            .enumerate()
            .filter(|(index, _)| box_faces.binary_search(&(*index as u32)).is_err())
            .flat_map(|(_, s)| triangles[s.triangle_indices()].iter().copied())
            .collect();
        (triangles, surfaces) = surfaces::group(keep);
    }
    let opaque = |material: u32| !materials[material as usize].kind.transmits();
    let clutter = patches::CLUTTER * parsed.patch_size * parsed.patch_size;
    let mut large = contacts::LargeFaces::new(&triangles, &surfaces, clutter);
    let mut windows = surfaces::windows(&triangles, &surfaces, &materials);
    // Glass lying on a solid's face in its own plane leads into the solid.
    let buried = repair::glass_on_solids(&large, &triangles, &surfaces, &windows, opaque);
    if let Some(&(first, _)) = buried.first() {
        let panes = buried.chunk_by(|a, b| a.0 == b.0).count();
        warnings.push(SceneWarning {
            location: Location::file(obj_path),
            message: format!(
                "{} glass triangles of {panes} windows lie on the face of a solid in its plane (the first of material '{}'): read as that face, as Radiance and the sun's shadows read it, so no light passes there; if the solid should not be there (an IFC zone exported as geometry over the façade), remove it",
                buried.len(),
                materials[windows[first].material as usize].name
            ),
        });
        (triangles, surfaces) = surfaces::group(without(&triangles, buried.iter().map(|&(_, t)| t)));
        windows = surfaces::windows(&triangles, &surfaces, &materials);
        large = contacts::LargeFaces::new(&triangles, &surfaces, clutter);
    }
    // An opaque face on a larger one of another material in its plane is hidden.
    let hidden = repair::hidden_faces(&large, &triangles, &surfaces, opaque);
    if let Some(&first) = hidden.first() {
        let first = triangles[first as usize].material;
        let under = surfaces.iter().filter(|s| s.triangles.clone().any(|t| hidden.binary_search(&t).is_ok())).count();
        warnings.push(SceneWarning {
            location: Location::file(obj_path),
            message: format!(
                "{} triangles of {under} surfaces lie on a larger face of another material in their own plane, facing the same way (the first of material '{}'): which of the two a ray meets is a matter of rounding, in Radiance too; read as the larger face, they are dropped",
                hidden.len(),
                materials[first as usize].name
            ),
        });
        (triangles, surfaces) = surfaces::group(without(&triangles, hidden.iter().copied()));
        windows = surfaces::windows(&triangles, &surfaces, &materials);
        large = contacts::LargeFaces::new(&triangles, &surfaces, clutter);
    }
    let sensors = sensors::sensors(parsed)?;
    if windows.is_empty() && !sensors.is_empty() {
        warnings.push(SceneWarning {
            location: Location::file(obj_path),
            message: "no surface passes light (no glass or panel material): daylight comes in through open air only; if the model's panes are there, give their material kind = \"glass\" under [materials], and if the export left them out, the rooms read too bright".into(),
        });
    }
    let (sizing, _) = sizing_and_focus(parsed, &sensors, &triangles, &surfaces, &windows);
    // Clutter gathers into clusters; windows keep patches of their own.
    let clusterable: Vec<bool> =
        surfaces.iter().map(|s| matches!(materials[s.material as usize].kind, MaterialKind::Diffuse { .. })).collect();
    if parsed.patch_size > ACCURATE_PATCH_SIZE {
        warnings.push(SceneWarning {
            location: Location::file(&parsed.path),
            message: format!(
                "lighting.patch_size {} m is coarse: interreflected light loses accuracy above {ACCURATE_PATCH_SIZE} m (±5% at 2 m)",
                parsed.patch_size
            ),
        });
    }
    let estimate = patches::estimate(&triangles, &surfaces, &sizing, MAX_PATCHES as u64 + 1) as f64;
    if estimate > MAX_PATCHES {
        return Err(SceneError::new(
            Location::file(&parsed.path),
            format!(
                "lighting.patch_size {} m would cut the model into more than {MAX_PATCHES:.0} patches (more than {:.0} GB of light data): use a larger patch_size",
                parsed.patch_size,
                MAX_PATCHES * 3e3 / 1e9
            ),
        ));
    }
    let window_planes: Vec<CutPlane> =
        windows.iter().map(|w| CutPlane::around_window(w.normal, &triangles[surfaces[w.surface as usize].triangle_indices()])).collect();
    let covered: Vec<(usize, f32)> = windows
        .iter()
        .map(|w| large.covered_share(&surfaces[w.surface as usize], opaque))
        .enumerate()
        .filter(|&(_, share)| share >= 0.5)
        .collect();
    if let Some(&(first, share)) = covered.first() {
        warnings.push(SceneWarning {
            location: Location::file(obj_path),
            message: format!(
                "{} windows lie under an opaque face in their own plane (the first, window #{first} of material '{}', {:.0}% covered): whether light passes there is up to the ray tracer, and Radiance and heliodon may disagree; remove the covering faces (an IFC zone exported as geometry?)",
                covered.len(),
                materials[windows[first].material as usize].name,
                share * 100.0
            ),
        });
    }
    let patches = patches::subdivide(&triangles, &mut surfaces, &sizing, &clusterable, &window_planes, &large);
    Ok(BuiltModel { materials, unused_materials, origin: parsed.frame.origin, triangles, surfaces, windows, patches, warnings })
}

/// Where patches are finest ([`PatchSizing`]) and what views frame (the
/// windows and the sensors; `None` with neither).
fn sizing_and_focus(
    parsed: &file::ParsedScene,
    sensors: &[Sensor],
    triangles: &[Triangle],
    surfaces: &[Surface],
    windows: &[Window],
) -> (PatchSizing, Option<(Vec3, Vec3)>) {
    let window_bounds: Vec<(Vec3, Vec3)> =
        windows.iter().map(|w| bounds(&triangles[surfaces[w.surface as usize].triangle_indices()])).collect();
    let focus = window_bounds
        .iter()
        .copied()
        .chain(sensors.iter().map(|s| (s.position, s.position)))
        .reduce(|(lo, hi), (a, b)| (lo.min(a), hi.max(b)));
    // Patches are finest around the sensors and the windows that light them (see `patches`).
    let sizing = if parsed.adaptive_patches {
        PatchSizing::around(parsed.patch_size, sensors, &window_bounds)
    } else {
        PatchSizing::uniform(parsed.patch_size)
    };
    (sizing, focus)
}

/// The scene: the built model with what the scene file says besides
/// (site, sensors, cameras, shades).
pub(crate) fn assemble(
    mut parsed: file::ParsedScene,
    obj_path: PathBuf,
    mtls: Vec<PathBuf>,
    built: BuiltModel,
) -> Result<LoadedScene, SceneError> {
    let BuiltModel { materials, unused_materials, origin, triangles, surfaces, windows, patches, warnings } = built;
    // Sensors and cameras are placed in the model's frame, recentred or not.
    parsed.frame.origin = origin;
    let shades = shades::shade_groups(&parsed, &materials, &unused_materials)?;
    let sensors = sensors::sensors(&parsed)?;
    let viewpoints = sensors::viewpoints(&parsed)?;
    let (patch_sizing, focus) = sizing_and_focus(&parsed, &sensors, &triangles, &surfaces, &windows);
    let bounds = bounds(&triangles);
    Ok(LoadedScene {
        scene: Scene {
            name: parsed.name,
            files: SceneFiles { scene: parsed.path, obj: obj_path, mtls },
            site: parsed.site,
            frame: parsed.frame,
            patch_size: parsed.patch_size,
            materials,
            triangles,
            surfaces,
            windows,
            patches,
            sensors,
            viewpoints,
            shades,
            bounds,
            focus: focus.unwrap_or(bounds),
            patch_sizing,
        },
        warnings,
    })
}

/// The box (min, max) around `triangles`.
pub(crate) fn bounds(triangles: &[Triangle]) -> (Vec3, Vec3) {
    triangles
        .iter()
        .flat_map(|t| t.vertices)
        .fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(lo, hi), v| (lo.min(v), hi.max(v)))
}

impl Scene {
    /// The triangles of surface `surface`.
    pub fn surface_triangles(&self, surface: u32) -> &[Triangle] {
        &self.triangles[self.surfaces[surface as usize].triangle_indices()]
    }

    /// The material of index `id`, as triangles, surfaces, patches and windows
    /// hold it.
    pub fn material(&self, id: u32) -> &Material {
        &self.materials[id as usize]
    }

    /// Total glazed area of all windows (m²), for summaries.
    pub fn window_area(&self) -> f32 {
        self.windows.iter().map(|w| w.area).sum()
    }

    /// Gives `surfaces` (say, the windows of one façade) a material of their
    /// own: a copy of the one the first of them has, named `name`, so it can
    /// be changed without touching the others that shared it. Their
    /// triangles, patches and windows follow. Returns the new material's
    /// index; `None` when `surfaces` is empty, out of range or of more than
    /// one material.
    pub fn give_own_material(&mut self, surfaces: &[u32], name: String) -> Option<u32> {
        let material = self.surfaces.get(*surfaces.first()? as usize)?.material;
        if surfaces.iter().any(|&s| self.surfaces.get(s as usize).is_none_or(|s| s.material != material)) {
            return None;
        }
        let new = self.materials.len() as u32;
        self.materials.push(Material { name, ..self.materials[material as usize].clone() });
        for &index in surfaces {
            let surface = &mut self.surfaces[index as usize];
            surface.material = new;
            for triangle in &mut self.triangles[surface.triangle_indices()] {
                triangle.material = new;
            }
            for patch in &mut self.patches.patches[surface.patch_indices()] {
                patch.material = new;
            }
        }
        for window in self.windows.iter_mut().filter(|w| surfaces.contains(&w.surface)) {
            window.material = new;
        }
        Some(new)
    }
}
