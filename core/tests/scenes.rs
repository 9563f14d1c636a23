//! Scene loading without Bevy: the bundled scenes against values known from
//! their generator and every kind of bad input (the command line is tested
//! in app/tests/cli.rs).

#[path = "../../tests/support/fixture.rs"]
mod fixture;

use std::path::Path;

use heliodon_core::panel::PanelCatalog;
use heliodon_core::scene::{LoadedScene, MaterialKind, SceneError, load_scene};

use fixture::{Fixture, OBJ, SITE, fixture, scene_toml};

fn no_panels() -> PanelCatalog {
    PanelCatalog::new()
}

fn bundled(name: &str) -> LoadedScene {
    load_scene(&heliodon_core::bundled_scene(name), &no_panels()).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn kinds(loaded: &LoadedScene) -> (usize, usize, usize) {
    let count = |label| loaded.scene.materials.iter().filter(|m| m.kind.label() == label).count();
    (count("diffuse"), count("glass"), count("panel"))
}

/// Curved glass of the living room: 14 planar segments of the arc through
/// (0, 5), (3.5, 6.5), (7, 5) m, glazed from 0.6 to 2.3 m.
fn living_room_curved_glass() -> f32 {
    let (half, bulge) = (3.5f32, 1.5f32);
    let radius = (half * half + bulge * bulge) / (2.0 * bulge);
    let span = (half / radius).asin();
    let chord = 2.0 * radius * (span / 14.0).sin();
    14.0 * chord * 1.7
}

#[test]
fn test_room_loads_with_its_six_windows() {
    let loaded = bundled("test_room");
    let scene = &loaded.scene;
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    assert_eq!(kinds(&loaded), (3, 1, 0));
    assert_eq!(scene.windows.len(), 6);
    let areas: Vec<f32> = scene.windows.iter().map(|w| w.area).collect();
    assert_eq!(areas.iter().filter(|a| (**a - 0.9).abs() < 1e-4).count(), 3, "{areas:?}");
    assert_eq!(areas.iter().filter(|a| (**a - 0.63).abs() < 1e-4).count(), 3, "{areas:?}");
    for window in &scene.windows {
        // Glazing faces out: south.
        assert!((window.normal - glam::Vec3::NEG_Y).length() < 1e-5);
    }
    assert_eq!(scene.sensors.len(), 5 + 6 * 10);
    let (lo, hi) = scene.bounds;
    assert!((lo - glam::Vec3::ZERO).length() < 1e-5 && (hi - glam::Vec3::new(4.0, 6.0, 3.0)).length() < 1e-5);
    // Walls, floor and ceiling: 4·3·2 + 2·6·3 + 2·4·6 = 108 m² of surface, less 4.59 of glass.
    let opaque: f32 = scene.surfaces.iter().filter(|s| !scene.material(s.material).kind.transmits()).map(|s| s.area).sum();
    assert!((opaque - (108.0 - 4.59)).abs() < 1e-3, "{opaque}");
    // Patches cover every surface exactly and are no larger than a grid cell
    // and a half (a sliver along a wall's edge joins the cell beside it), but
    // for 1 m cells 4 m from the windows and more, a metre and more from the
    // grid (0.5 m in from the walls, 0.8 m up): the ceiling's, 2.2 m over it,
    // the walls' above 1.8 m, and the floor's, behind it.
    let patch_area: f32 = scene.patches.patches.iter().map(|p| p.area).sum();
    let surface_area: f32 = scene.surfaces.iter().map(|s| s.area).sum();
    assert!((patch_area - surface_area).abs() < 1e-3);
    let material = |name: &str| scene.materials.iter().position(|m| m.name == name).unwrap() as u32;
    let (ceiling, floor, wall) = (material("ceiling"), material("floor"), material("wall"));
    let wide = |p: &&heliodon_core::scene::Patch| p.area > 1.5 * 0.25 + 1e-5;
    assert!(
        scene
            .patches
            .patches
            .iter()
            .filter(wide)
            .all(|p| ([ceiling, floor].contains(&p.material) || (p.material == wall && p.centroid.z > 1.8))
                && p.centroid.y > 4.0
                && p.area <= 1.0 + 1e-5)
    );
    for coarser in [ceiling, floor] {
        assert!(scene.patches.patches.iter().any(|p| p.material == coarser && wide(&p)), "the ceiling's and the floor's backs are coarser");
    }
    assert!(scene.patches.patches.iter().filter(|p| p.area > 0.25 + 1e-5).count() > 0, "slivers joined the cells beside them");
    // The floor (4 × 6 m) is 0.5 m patches but for the eight 1 m cells of its
    // back 2 m: 4 m and more from the windows, behind the desks' sensors, and
    // a metre and more from the sensor on the back wall, which sees them.
    let floor_patches: Vec<_> = scene.patches.patches.iter().filter(|p| p.material == floor).map(|p| (p.centroid, p.area)).collect();
    assert_eq!(floor_patches.len(), 96 - 8 * 4 + 8, "{floor_patches:?}");
}

#[test]
fn grid_sensors_are_named_and_placed_per_the_contract() {
    let scene = bundled("test_room").scene;
    let grid: Vec<_> = scene.sensors.iter().filter(|s| s.grid.as_deref() == Some("workplane")).collect();
    assert_eq!(grid.len(), 60);
    // Cell centres, x fastest: k = 0 at (0.75, 0.75), k = 1 at (1.25, 0.75), k = 6 at (0.75, 1.25).
    assert_eq!(grid[0].name, "workplane/0");
    assert!((grid[0].position - glam::Vec3::new(0.75, 0.75, 0.8)).length() < 1e-5);
    assert!((grid[1].position - glam::Vec3::new(1.25, 0.75, 0.8)).length() < 1e-5);
    assert_eq!(grid[6].name, "workplane/6");
    assert!((grid[6].position - glam::Vec3::new(0.75, 1.25, 0.8)).length() < 1e-5);
    let back = scene.sensors.iter().find(|s| s.name == "back-wall").unwrap();
    assert_eq!(back.size, Some(0.5));
    // A vertical sensor's square has a horizontal edge.
    assert!(back.axes[0].z.abs() < 1e-6 && back.axes[1].z.abs() > 0.999);
}

#[test]
fn office_has_west_windows_and_two_skylights() {
    let loaded = bundled("office");
    let scene = &loaded.scene;
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    assert_eq!(kinds(&loaded), (7, 3, 0));
    assert_eq!(scene.windows.len(), 12);
    assert!((scene.window_area() - 24.88).abs() < 1e-3, "{}", scene.window_area());
    let west = scene.windows.iter().filter(|w| (w.normal - glam::Vec3::NEG_X).length() < 1e-5).count();
    let up = scene.windows.iter().filter(|w| (w.normal - glam::Vec3::Z).length() < 1e-5).count();
    assert_eq!((west, up), (10, 2));
    assert_eq!(scene.sensors.len(), 8 + 2 + 10 * 14);
    // The scene table overrides the MTL: carpet is coloured, view glass 0.7.
    let carpet = scene.materials.iter().find(|m| m.name == "carpet").unwrap();
    assert!(matches!(carpet.kind, MaterialKind::Diffuse { reflectance } if reflectance.0 == [0.18, 0.17, 0.15]));
    let view = scene.materials.iter().find(|m| m.name == "view_glass").unwrap();
    assert_eq!(view.kind, MaterialKind::Glass { transmittance: 0.7 });
    // Walls from the MTL alone.
    let wall = scene.materials.iter().find(|m| m.name == "wall").unwrap();
    assert!(matches!(wall.kind, MaterialKind::Diffuse { reflectance } if reflectance.0 == [0.6; 3]));
    assert!(scene.triangles.len() < 5000);
}

#[test]
fn living_room_maps_centimetres_y_up_and_turned_north() {
    let loaded = bundled("living_room");
    let scene = &loaded.scene;
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    assert_eq!(kinds(&loaded), (5, 2, 0));
    assert_eq!(scene.windows.len(), 14 + 2);
    let expected = living_room_curved_glass() + 2.0;
    assert!((scene.window_area() - expected).abs() < 1e-3, "{} vs {expected}", scene.window_area());
    // Model height 350 cm (skylight tops) becomes 3.5 m of z.
    let (lo, hi) = scene.bounds;
    assert!((hi.z - lo.z - 3.5).abs() < 1e-4, "{lo} {hi}");
    // The table sensor is 40 cm up and faces up.
    let table = scene.sensors.iter().find(|s| s.name == "table").unwrap();
    assert!((table.position.z - 0.4).abs() < 1e-5);
    assert!((table.normal - glam::Vec3::Z).length() < 1e-5);
    assert!((table.size.unwrap() - 0.4).abs() < 1e-6);
    // North (0.5, 0, -0.866) in the model is +y: the back wall's sensor, facing
    // model +z (30° from south towards east, turned), faces azimuth 150°.
    let back = scene.sensors.iter().find(|s| s.name == "back-wall").unwrap();
    let azimuth = back.normal.x.atan2(back.normal.y).to_degrees().rem_euclid(360.0);
    assert!((azimuth - 150.0).abs() < 0.01, "{azimuth}");
    assert_eq!(scene.sensors.len(), 4 + 24);
    // Skylights face up whatever the model's axes.
    assert_eq!(scene.windows.iter().filter(|w| w.normal.z > 0.9999).count(), 2);
}

// ---- bad input -------------------------------------------------------------

/// Loading a fixture's scene.
trait Loads {
    fn load(&self) -> Result<LoadedScene, SceneError>;
    fn error(&self) -> SceneError;
}

impl Loads for Fixture {
    fn load(&self) -> Result<LoadedScene, SceneError> {
        load_scene(&self.scene(), &no_panels())
    }

    fn error(&self) -> SceneError {
        match self.load() {
            Ok(_) => panic!("{} loaded", self.dir.display()),
            Err(e) => e,
        }
    }
}

#[test]
fn a_good_minimal_scene_loads() {
    let f = fixture("good", &scene_toml(""), OBJ);
    let loaded = f.load().unwrap();
    assert_eq!(loaded.scene.materials.len(), 2);
    assert_eq!(loaded.scene.windows.len(), 1);
    assert!((loaded.scene.windows[0].area - 0.5).abs() < 1e-6);
    assert_eq!(loaded.scene.material(loaded.scene.windows[0].material).kind, MaterialKind::Glass { transmittance: 0.88 });
}

#[test]
fn missing_scene_file() {
    let e = load_scene(Path::new("/nonexistent/scene.toml"), &no_panels()).unwrap_err();
    assert_eq!(e.to_string(), "/nonexistent/scene.toml: cannot read scene file: not found");
}

#[test]
fn malformed_toml_names_the_line() {
    let f = fixture("malformed", &format!("{SITE}\n[model\nobj = \"room.obj\"\n"), OBJ);
    let e = f.error();
    assert_eq!(e.location.line, Some(6), "{e}");
    assert!(e.to_string().starts_with(&format!("{}:6:", f.scene().display())), "{e}");
}

#[test]
fn missing_keys_and_out_of_range_site_values_name_the_key() {
    let f = fixture("no_obj", &format!("{SITE}\n[model]\nup = \"z\"\n"), OBJ);
    assert!(f.error().to_string().contains("missing field `obj`"), "{}", f.error());
    let f = fixture("latitude", &scene_toml("").replace("42.36", "142.0"), OBJ);
    let e = f.error();
    assert_eq!((e.location.line, e.location.key.as_deref()), (Some(3), Some("site.latitude")), "{e}");
    let f = fixture("up", &scene_toml("up = \"x\"\n"), OBJ);
    assert_eq!(f.error().location.key.as_deref(), Some("model.up"));
    let f = fixture("north", &scene_toml("north = [0.0, 0.0, 1.0]\n"), OBJ);
    assert!(f.error().to_string().contains("model.north: north must not be parallel"), "{}", f.error());
}

#[test]
fn missing_obj_names_the_scene_key() {
    let f = Fixture::new("missing_obj", &[("scene.toml", &scene_toml(""))]);
    let e = f.error();
    assert_eq!(e.location.file, f.scene());
    assert_eq!((e.location.line, e.location.key.as_deref()), (Some(8), Some("model.obj")), "{e}");
    assert!(e.message.contains("room.obj") && e.message.contains("not found"), "{e}");
}

#[test]
fn missing_mtl_names_the_obj_line() {
    let f = Fixture::new("missing_mtl", &[("scene.toml", &scene_toml("")), ("room.obj", OBJ)]);
    let e = f.error();
    assert_eq!(e.location.file, f.dir.join("room.obj"));
    assert_eq!(e.location.line, Some(1));
    assert!(e.message.contains("room.mtl") && e.message.contains("not found"), "{e}");
}

#[test]
fn unknown_material_kind() {
    let f = fixture("kind", &scene_toml("\n[materials.wall]\nkind = \"difuse\"\nreflectance = 0.5\n"), OBJ);
    let e = f.error();
    assert_eq!((e.location.line, e.location.key.as_deref()), (Some(11), Some("materials.wall.kind")), "{e}");
    assert!(e.message.contains("unknown material kind 'difuse'"), "{e}");
}

#[test]
fn material_values_are_checked() {
    let f = fixture("rho", &scene_toml("\n[materials.wall]\nkind = \"diffuse\"\nreflectance = 1.5\n"), OBJ);
    assert_eq!(f.error().location.key.as_deref(), Some("materials.wall.reflectance"));
    let f = fixture("extra", &scene_toml("\n[materials.wall]\nkind = \"diffuse\"\nreflectance = 0.5\ncolour = 1\n"), OBJ);
    assert_eq!(f.error().location.key.as_deref(), Some("materials.wall.colour"));
    let f = fixture("undefined", &scene_toml(""), &OBJ.replace("usemtl glass", "usemtl brick"));
    let e = f.error();
    assert_eq!((e.location.file.clone(), e.location.line), (f.dir.join("room.obj"), Some(8)), "{e}");
    assert!(e.message.contains("'brick'"), "{e}");
}

/// MTL statements with too few numbers (tobj 4 panics on `Ks 0`), or a
/// dissolve outside 0-1 (which would silently make windows black), are one
/// error naming the MTL line, even when the scene file overrides the
/// material; a byte-order mark at the start of a file is read past.
#[test]
fn malformed_mtl_statements_are_one_line() {
    let mtl_with = |extra: &str| format!("newmtl wall\nKd 0.5 0.5 0.5\n{extra}\nnewmtl glass\nd 0.12\n");
    let cases = [
        ("Ks 0", "Ks needs 3 numbers, not 1"),
        ("Kd 0.5 x 0.5", "Kd needs 3 finite numbers"),
        ("d 1.5", "d 1.5 is outside 0-1"),
        ("Tr -0.2", "Tr -0.2 is outside 0-1"),
        ("Ns", "Ns needs 1 number, not 0"),
    ];
    for (k, (statement, expected)) in cases.iter().enumerate() {
        let toml = scene_toml("\n[materials.wall]\nkind = \"diffuse\"\nreflectance = 0.5\n");
        let f = Fixture::new(&format!("mtl_{k}"), &[("scene.toml", &toml), ("room.obj", OBJ), ("room.mtl", &mtl_with(statement))]);
        let e = f.error();
        assert_eq!((e.location.file.clone(), e.location.line), (f.dir.join("room.mtl"), Some(3)), "{statement}: {e}");
        assert!(e.message.contains(expected), "{statement}: {e}");
    }
    let bom = Fixture::new(
        "bom",
        &[("scene.toml", &scene_toml("")), ("room.obj", &format!("\u{feff}{OBJ}")), ("room.mtl", &format!("\u{feff}{}", mtl_with("")))],
    );
    let loaded = bom.load().unwrap();
    assert_eq!(loaded.scene.windows.len(), 1);
}

/// `patch_size` stays where the engine is right: outside 0.05-10 m an
/// error naming the key, above 1 m a warning, and a size that would need
/// more than a million patches is refused before any is cut.
#[test]
fn patch_sizes_are_bounded_by_what_the_engine_handles() {
    let with = |size: &str| scene_toml(&format!("\n[lighting]\npatch_size = {size}\n"));
    for size in ["0.01", "1000.0"] {
        let e = fixture(&format!("patch_{size}"), &with(size), OBJ).error();
        assert_eq!(e.location.key.as_deref(), Some("lighting.patch_size"), "{e}");
    }
    let coarse = fixture("patch_coarse", &with("2.0"), OBJ).load().unwrap();
    assert!(coarse.warnings.iter().any(|w| w.message.contains("loses accuracy")), "{:?}", coarse.warnings);
    // A 2 km square slab at 5 cm: 1.6 billion patches, refused at once.
    let slab = "mtllib room.mtl\nv 0 0 0\nv 2000 0 0\nv 2000 2000 0\nv 0 2000 0\nusemtl wall\nf 1 2 3 4\n";
    let e = fixture("patch_too_many", &with("0.05"), slab).error();
    assert!(e.message.contains("more than 1000000 patches"), "{e}");
}

/// Copies of one face load in near-linear time and count once, with a
/// warning.
#[test]
fn duplicated_faces_count_once() {
    let copies = "f 1 2 3\n".repeat(50_000);
    let obj = OBJ.replace("usemtl wall\nf 1 2 3\n", &format!("usemtl wall\n{copies}"));
    let loaded = fixture("duplicates", &scene_toml(""), &obj).load().unwrap();
    assert_eq!(loaded.scene.triangles.len(), 2);
    assert!(loaded.warnings.iter().any(|w| w.message.contains("dropped 49999 duplicated triangle(s)")), "{:?}", loaded.warnings);
}

#[test]
fn unused_scene_material_is_a_warning() {
    let f = fixture("unused", &scene_toml("\n[materials.marble]\nkind = \"diffuse\"\nreflectance = 0.7\n"), OBJ);
    let loaded = f.load().unwrap();
    assert_eq!(loaded.warnings.len(), 1);
    let w = &loaded.warnings[0];
    assert_eq!((w.location.line, w.location.key.as_deref()), (Some(10), Some("materials.marble")), "{w}");
    assert!(w.message.contains("no face of") && w.message.contains("'marble'"), "{w}");
}

/// A model with sensors and no surface that passes light (panes left out
/// by the export, or glass whose material reads as opaque) says so once;
/// with a pane it says nothing of it.
#[test]
fn sensors_in_a_model_without_glass_are_a_warning() {
    let sensor = "\n[[sensors]]\nname = \"desk\"\nposition = [0.5, 0.5, 0.8]\nnormal = [0.0, 0.0, 1.0]\n";
    let without_glass = fixture("no_glass", &scene_toml(sensor), &OBJ.replace("usemtl glass\n", ""));
    let loaded = without_glass.load().unwrap();
    let said: Vec<_> = loaded.warnings.iter().filter(|w| w.message.starts_with("no surface passes light")).collect();
    assert_eq!(said.len(), 1, "{:?}", loaded.warnings);
    assert!(said[0].location.file.ends_with("room.obj") && said[0].message.contains("kind = \"glass\""), "{}", said[0]);
    let with_glass = fixture("with_glass", &scene_toml(sensor), OBJ).load().unwrap();
    assert!(with_glass.warnings.iter().all(|w| !w.message.starts_with("no surface passes light")), "{:?}", with_glass.warnings);
}

#[test]
fn unregistered_panel() {
    let toml = scene_toml("\n[materials.glass]\nkind = \"panel\"\npanel = \"prismatic\"\nfacet_angles = [40.0, 5.0]\n");
    let f = fixture("panel", &toml, OBJ);
    let e = f.error();
    assert_eq!((e.location.line, e.location.key.as_deref()), (Some(12), Some("materials.glass.panel")), "{e}");
    assert!(e.message.contains("no panel named 'prismatic' is registered (registered: none)"), "{e}");
    // With panels registered, see app/tests/panels.rs.
}

/// A vertex that is not three numbers is named by its line (the
/// OBJ reader names the first bad line).
#[test]
fn malformed_vertices_name_their_line() {
    for (name, vertex, message) in [
        ("two", "v 1 0", "vertex needs three coordinates"),
        ("bare", "v", "vertex needs three coordinates"),
        ("word", "v 1 x 0", "vertex coordinate 'x' is not a number"),
    ] {
        let f = fixture(name, &scene_toml(""), &OBJ.replace("v 1 0 0", vertex));
        let e = f.error();
        assert_eq!((e.location.file.clone(), e.location.line), (f.dir.join("room.obj"), Some(3)), "{e}");
        assert_eq!(e.message, message);
    }
}

#[test]
fn non_finite_coordinates() {
    let f = fixture("nan", &scene_toml(""), &OBJ.replace("v 1 1 0", "v 1 nan 0"));
    let e = f.error();
    assert_eq!((e.location.file.clone(), e.location.line), (f.dir.join("room.obj"), Some(4)), "{e}");
    assert!(e.message.contains("non-finite"), "{e}");
    let f = fixture("inf", &scene_toml(""), &OBJ.replace("v 1 0 0", "v inf 0 0"));
    assert_eq!(f.error().location.line, Some(3));
    let sensor = "\n[[sensors]]\nname = \"s\"\nposition = [0.5, nan, 0.8]\nnormal = [0.0, 0.0, 1.0]\n";
    let f = fixture("nan_sensor", &scene_toml(sensor), OBJ);
    let e = f.error();
    assert_eq!((e.location.line, e.location.key.as_deref()), (Some(12), Some("sensors[0].position")), "{e}");
    // Finite in f64 but past what f32 keeps: refused, not read as infinity.
    let f = fixture("huge", &scene_toml(""), &OBJ.replace("v 1 0 0", "v 1e39 0 0"));
    let e = f.error();
    assert!(e.location.line == Some(3) && e.message.contains("beyond ±1e9"), "{e}");
    let sensor = "\n[[sensors]]\nname = \"s\"\nposition = [0.5, 1e39, 0.8]\nnormal = [0.0, 0.0, 1.0]\n";
    let e = fixture("huge_sensor", &scene_toml(sensor), OBJ).error();
    assert_eq!(e.location.key.as_deref(), Some("sensors[0].position"), "{e}");
    // A normal of enormous length is a direction like any other.
    let sensor = "\n[[sensors]]\nname = \"s\"\nposition = [0.5, 0.5, 0.8]\nnormal = [0.0, 0.0, 1e300]\n";
    let loaded = fixture("long_normal", &scene_toml(sensor), OBJ).load().unwrap();
    assert!((loaded.scene.sensors[0].normal - glam::Vec3::Z).length() < 1e-6, "{:?}", loaded.scene.sensors[0].normal);
}

#[test]
fn degenerate_triangles_are_dropped_with_a_count() {
    let obj = format!("{OBJ}v 2 0 0\nv 3 0 0\nf 1 5 6\nf 2 2 3\n");
    let f = fixture("degenerate", &scene_toml(""), &obj);
    let loaded = f.load().unwrap();
    assert_eq!(loaded.scene.triangles.len(), 2);
    assert_eq!(loaded.warnings.len(), 1);
    assert!(loaded.warnings[0].message.contains("dropped 2 degenerate"), "{}", loaded.warnings[0]);
}

#[test]
fn obj_without_faces() {
    let f = fixture("no_faces", &scene_toml(""), "mtllib room.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\n");
    let e = f.error();
    assert_eq!(e.to_string(), format!("{}: the model has no faces", f.dir.join("room.obj").display()));
    let f = fixture("only_degenerate", &scene_toml(""), "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
    assert!(f.error().message.contains("no faces with a non-zero area"));
}

#[test]
fn sensor_with_zero_normal() {
    let sensor = "\n[[sensors]]\nname = \"desk\"\nposition = [0.5, 0.5, 0.8]\nnormal = [0.0, 0.0, 0.0]\n";
    let f = fixture("zero_normal", &scene_toml(sensor), OBJ);
    let e = f.error();
    assert_eq!((e.location.line, e.location.key.as_deref()), (Some(13), Some("sensors[0].normal")), "{e}");
    assert!(e.message.contains("zero"), "{e}");
}

#[test]
fn sensor_names_are_unique_and_grids_non_empty() {
    let twice = "\n[[sensors]]\nname = \"a\"\nposition = [0, 0, 1]\nnormal = [0, 0, 1]\n".repeat(2);
    let f = fixture("duplicate", &scene_toml(&twice), OBJ);
    assert!(f.error().message.contains("duplicate sensor name 'a'"));
    let grid = "\n[[sensor_grids]]\nname = \"g\"\nmin = [0, 0]\nmax = [0.2, 1]\nheight = 0.8\nspacing = 0.5\n";
    let f = fixture("empty_grid", &scene_toml(grid), OBJ);
    assert_eq!(f.error().location.key.as_deref(), Some("sensor_grids[0].max"));
}

#[test]
fn the_scene_cache_gives_the_scene_its_files_give() {
    use heliodon_core::light::cache::CacheOutcome;
    use heliodon_core::scene_cache::load_scene_cached;
    let office = heliodon_core::bundled_scene("office");
    let work = Path::new(env!("CARGO_TARGET_TMPDIR")).join("scene_cache_office");
    let _ = std::fs::remove_dir_all(&work);
    std::fs::create_dir_all(&work).unwrap();
    for file in ["scene.toml", "model.mtl"] {
        std::fs::copy(office.with_file_name(file), work.join(file)).unwrap();
    }
    // A face written twice: the warning the load gives must come from the cache too.
    let obj = std::fs::read_to_string(office.with_file_name("model.obj")).unwrap();
    let face = obj.lines().find(|l| l.starts_with("f ")).unwrap();
    let twice = obj.replacen(face, &format!("{face}\n{face}"), 1);
    std::fs::write(work.join("model.obj"), &twice).unwrap();
    let scene = work.join("scene.toml");
    let dir = work.join("cache");
    let same_as_files = |loaded: &LoadedScene| {
        let uncached = load_scene(&scene, &no_panels()).unwrap();
        assert!(uncached.warnings.iter().any(|w| w.message.contains("duplicated")), "{:?}", uncached.warnings);
        assert_eq!(format!("{loaded:?}"), format!("{uncached:?}"));
    };
    let (stored, outcome) = load_scene_cached(&scene, &no_panels(), Some(&dir)).unwrap();
    let CacheOutcome::Stored(path) = outcome else { panic!("{outcome:?}") };
    same_as_files(&stored);
    let (read, outcome) = load_scene_cached(&scene, &no_panels(), Some(&dir)).unwrap();
    assert_eq!(outcome, CacheOutcome::Hit(path.clone()));
    same_as_files(&read);
    // An MTL library edited (its path comes from the OBJ, so it is checked on reading).
    let mtl = std::fs::read_to_string(work.join("model.mtl")).unwrap();
    std::fs::write(work.join("model.mtl"), format!("{mtl}\n# edited\n")).unwrap();
    let (read, outcome) = load_scene_cached(&scene, &no_panels(), Some(&dir)).unwrap();
    assert_eq!(outcome, CacheOutcome::Rebuilt(path.clone(), "an MTL library changed".into()));
    same_as_files(&read);
    // A damaged file is rebuilt, never trusted.
    let mut damaged = std::fs::read(&path).unwrap();
    let middle = damaged.len() / 2;
    damaged[middle] ^= 0x10;
    std::fs::write(&path, damaged).unwrap();
    let (read, outcome) = load_scene_cached(&scene, &no_panels(), Some(&dir)).unwrap();
    assert_eq!(outcome, CacheOutcome::Rebuilt(path.clone(), "checksum mismatch".into()));
    same_as_files(&read);
    // Another OBJ (or scene file) is another file; no folder, no cache.
    std::fs::write(work.join("model.obj"), format!("{twice}\n# edited\n")).unwrap();
    let (read, outcome) = load_scene_cached(&scene, &no_panels(), Some(&dir)).unwrap();
    assert!(matches!(&outcome, CacheOutcome::Stored(p) if *p != path), "{outcome:?}");
    same_as_files(&read);
    let (read, outcome) = load_scene_cached(&scene, &no_panels(), None).unwrap();
    assert_eq!(outcome, CacheOutcome::Skipped("disabled".into()));
    same_as_files(&read);
}
