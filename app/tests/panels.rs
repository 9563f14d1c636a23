//! Panels through the `heliodon` executable and the registry: the built-in
//! panels are known by name, a panel from a crate that only tests use is
//! found the same way, and bad panel input gives one line naming the key.

#[path = "../../tests/support/quad_obj.rs"]
mod quad_obj;

use quad_obj::QuadObj;
use std::path::{Path, PathBuf};

use heliodon::bevy::prelude::App;
use heliodon::ecs::{PanelRegistry, RegisterPanel};
use heliodon::panel::PanelCatalog;
use heliodon::scene::{MaterialKind, load_scene};
use heliodon_panel_fixture::GreyFilter;

#[test]
fn a_panel_from_a_test_only_crate_is_found_by_name() {
    let path = room("fixture", Some("panel = \"grey_filter\"\ntransmittance = 0.4\n"));
    // Registered in an app with the one line a modder writes.
    let mut app = App::new();
    app.register_panel(GreyFilter);
    let catalog = app.world().resource::<PanelRegistry>().catalog();
    let loaded = load_scene(&path, &catalog).expect("the fixture's panel is registered");
    let window = loaded.scene.materials.iter().find(|m| m.name == "window").unwrap();
    let MaterialKind::Panel { panel, model, .. } = &window.kind else { panic!("{window:?}") };
    assert_eq!(panel, "grey_filter");
    let response = model.0.response(heliodon::glam::DVec3::new(0.0, -0.6, 0.8));
    assert!((response.transmitted() - 0.4).abs() < 1e-12);
    assert_eq!(loaded.scene.windows.len(), 1);
    // Without the plugin the same file names the panels that are known.
    let error = load_scene(&path, &PanelCatalog::new()).unwrap_err().to_string();
    assert!(error.contains("no panel named 'grey_filter' is registered (registered: none)"), "{error}");
}

/// A closed 4 × 6 × 3 m room with a 2 × 1 m opening in its south wall,
/// filled with `window` (a material table body) or left open (`None`).
fn room(name: &str, window: Option<&str>) -> PathBuf {
    room_with(name, window, false)
}

/// [`room`], with a 1 m deep overhang outside, 0.2 m above its window, when
/// `overhang`: at winter noon it shades the top quarter of the window.
fn room_with(name: &str, window: Option<&str>, overhang: bool) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("panel_room_{name}"));
    std::fs::create_dir_all(&dir).unwrap();
    let mut obj = QuadObj::new("room.mtl");
    let (w, d, h) = (4.0, 6.0, 3.0);
    obj.quad("floor", [[0.0, 0.0, 0.0], [w, 0.0, 0.0], [w, d, 0.0], [0.0, d, 0.0]]);
    obj.quad("wall", [[0.0, 0.0, h], [0.0, d, h], [w, d, h], [w, 0.0, h]]);
    obj.quad("wall", [[0.0, d, 0.0], [w, d, 0.0], [w, d, h], [0.0, d, h]]);
    obj.quad("wall", [[0.0, 0.0, 0.0], [0.0, d, 0.0], [0.0, d, h], [0.0, 0.0, h]]);
    obj.quad("wall", [[w, d, 0.0], [w, 0.0, 0.0], [w, 0.0, h], [w, d, h]]);
    // South wall around the opening x 1-3, z 1-2.
    obj.quad("wall", [[0.0, 0.0, 0.0], [w, 0.0, 0.0], [w, 0.0, 1.0], [0.0, 0.0, 1.0]]);
    obj.quad("wall", [[0.0, 0.0, 2.0], [w, 0.0, 2.0], [w, 0.0, h], [0.0, 0.0, h]]);
    obj.quad("wall", [[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [1.0, 0.0, 2.0], [0.0, 0.0, 2.0]]);
    obj.quad("wall", [[3.0, 0.0, 1.0], [w, 0.0, 1.0], [w, 0.0, 2.0], [3.0, 0.0, 2.0]]);
    if window.is_some() {
        obj.quad("window", [[1.0, 0.0, 1.0], [3.0, 0.0, 1.0], [3.0, 0.0, 2.0], [1.0, 0.0, 2.0]]);
    }
    if overhang {
        obj.quad("wall", [[0.5, 0.0, 2.2], [3.5, 0.0, 2.2], [3.5, -1.0, 2.2], [0.5, -1.0, 2.2]]);
    }
    std::fs::write(dir.join("room.obj"), obj.text()).unwrap();
    std::fs::write(dir.join("room.mtl"), "newmtl floor\nKd 0.2 0.2 0.2\nnewmtl wall\nKd 0.5 0.5 0.5\nnewmtl window\nd 0.1\n").unwrap();
    let mut text =
        String::from("name = \"Panel room\"\n[site]\nlatitude = 42.36\nlongitude = -71.06\ntimezone = -5.0\n[model]\nobj = \"room.obj\"\n");
    if let Some(window) = window {
        text.push_str(&format!("\n[materials.window]\nkind = \"panel\"\n{window}"));
    }
    for (k, y) in [2.5, 3.0, 3.5, 4.0].iter().enumerate() {
        text.push_str(&format!("\n[[sensors]]\nname = \"floor-{k}\"\nposition = [2.0, {y}, 0.0]\nnormal = [0.0, 0.0, 1.0]\n"));
    }
    std::fs::write(dir.join("scene.toml"), text).unwrap();
    dir.join("scene.toml")
}

fn all_panels() -> PanelCatalog {
    PanelCatalog::new()
        .with(GreyFilter)
        .with(heliodon_prismatic::Prismatic)
        .with(heliodon_laser_cut::LaserCut)
        .with(heliodon_venetian::Venetian)
        .with(heliodon_bsdf::Bsdf)
}

fn winter_noon(scene: &heliodon::scene::Scene) -> heliodon::sky::Sky {
    use heliodon::time::{Date, LocalDateTime, TimeOfDay};
    let when = LocalDateTime { date: Date::new(2026, 12, 21).unwrap(), time: TimeOfDay::from_hours(12.0).unwrap() };
    let sun = heliodon::sun::solar_position(&scene.site, &when);
    heliodon::sky::Sky::new(&heliodon::sky::SkySpec::Clear { turbidity: 2.45 }, sun.altitude, sun.azimuth, 0.2, 355).unwrap()
}

fn quick() -> heliodon::light::LightSettings {
    heliodon::light::LightSettings {
        rays_per_patch: 16,
        rays_per_sensor: 64,
        sky_rays_per_sensor: 64,
        window_rays_per_sensor: 32,
        sun_samples_per_patch: 64,
        ..Default::default()
    }
}

/// A panel whose one lobe goes straight on with its whole share passes the
/// sun exactly like an open window, and a share of it when it says so: the
/// panel's frame, its inside and outside, and the lobe's beam all check out.
#[test]
fn a_straight_lobe_passes_the_sun_as_an_opening_does() {
    use std::sync::Arc;
    let catalog = all_panels();
    // Direct sun and direct sky at each floor sensor, the sky by the same
    // hemisphere rays through the opening and the panel (an opening is no
    // window that rays could be aimed at).
    let settings = heliodon::light::LightSettings { window_rays_per_sensor: 0, ..quick() };
    let direct = |path: PathBuf| -> Vec<(f64, f64)> {
        let scene = Arc::new(load_scene(&path, &catalog).unwrap().scene);
        let model = heliodon::light::LightModel::precompute(scene.clone(), settings).unwrap();
        let lighting = model.solve(&winter_noon(&scene), None);
        lighting.sensors.iter().map(|s| (s.direct_sun, s.direct_sky)).collect()
    };
    let open = direct(room("open", None));
    let clear = direct(room("clear", Some("panel = \"grey_filter\"\ntransmittance = 1.0\n")));
    let grey = direct(room("grey", Some("panel = \"grey_filter\"\ntransmittance = 0.4\n")));
    assert!(open.iter().filter(|e| e.0 > 1000.0).count() >= 2, "the beam reaches the floor sensors: {open:?}");
    assert!(open.iter().all(|e| e.1 > 10.0), "the sky is seen: {open:?}");
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-6 * a.max(1.0);
    for ((o, c), g) in open.iter().zip(&clear).zip(&grey) {
        // The sun along the lobe's beam, the sky through the panel's transfer.
        assert!(close(o.0, c.0) && close(o.1, c.1), "open {o:?} vs clear panel {c:?}");
        assert!(close(0.4 * o.0, g.0) && close(0.4 * o.1, g.1), "open {o:?} vs grey panel {g:?}");
    }
}

/// A measured tensor tree (assets/bsdf/redirect_tt4.xml: the light's way
/// mirrored in the panel's up axis) turns the low winter sun, which plain
/// glass lays on the floor, up onto the ceiling: the tree's axes are the
/// panel's frame (+z into the room, y up) end to end.
#[test]
fn a_redirecting_tensor_tree_sends_the_sun_to_the_ceiling() {
    use std::sync::Arc;
    let tree = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/bsdf/redirect_tt4.xml");
    let direct_sun = |name: &str, window: &str| -> Vec<(String, f64)> {
        let path = room(name, Some(window));
        let mut text = std::fs::read_to_string(&path).unwrap();
        for (k, y) in [2.5, 3.0, 3.5, 4.0].iter().enumerate() {
            text.push_str(&format!("\n[[sensors]]\nname = \"ceiling-{k}\"\nposition = [2.0, {y}, 3.0]\nnormal = [0.0, 0.0, -1.0]\n"));
        }
        std::fs::write(&path, text).unwrap();
        let scene = Arc::new(load_scene(&path, &all_panels()).unwrap().scene);
        let model = heliodon::light::LightModel::precompute(scene.clone(), quick()).unwrap();
        model.solve(&winter_noon(&scene), None).sensors.iter().map(|s| (s.name.clone(), s.direct_sun)).collect()
    };
    let sum = |readings: &[(String, f64)], surface: &str| readings.iter().filter(|r| r.0.starts_with(surface)).map(|r| r.1).sum::<f64>();
    let glass = direct_sun("tree_glass", "panel = \"grey_filter\"\ntransmittance = 1.0\n");
    let redirected = direct_sun("tree", &format!("panel = \"bsdf\"\nfile = \"{}\"\n", tree.display()));
    assert!(sum(&glass, "floor") > 1000.0 && sum(&glass, "ceiling") == 0.0, "glass: {glass:?}");
    assert!(sum(&redirected, "ceiling") > 1000.0, "the tree sends the sun up: {redirected:?}");
    // What stays on the floor is the tree's diffuse rest, not a beam.
    assert!(sum(&redirected, "floor") < 0.1 * sum(&redirected, "ceiling"), "{redirected:?}");
}

/// Sensors read a measured panel's data itself, not its lobes' beams: a
/// tensor tree (written here) sends the light of every incoming direction
/// evenly into a block of outgoing leaves 22-39° below the horizontal, so
/// that each floor sensor sees only part of the window through it. The
/// sensors' direct sun is the data's integral over the window, Eₙ cos θᵢ ∫
/// f cos θₛ cos θₒ dA / r² (a 400 × 400 midpoint sum here, by the tree's
/// own lookup), within 1%; the lobe's three beams, all or nothing at each
/// sensor, are printed beside it.
#[test]
fn sensors_read_a_measured_panels_data_not_its_beams() {
    use heliodon_bsdf::tensor_tree::TensorTree;
    use std::sync::Arc;
    // 16 leaves per axis, the first axis slowest; outgoing leaves u 7-8, v 3-4 hold the light.
    let leaves = 16;
    let lit = |u: usize, v: usize| (7..=8).contains(&u) && (3..=4).contains(&v);
    let values: Vec<&str> =
        (0..leaves * leaves * leaves * leaves).map(|k| if lit((k / leaves) % leaves, k % leaves) { "12" } else { "0" }).collect();
    let data = format!("{{ {} }}", values.join(" "));
    let tree = TensorTree::parse(&data, 4).unwrap();
    let xml = format!(
        "<?xml version=\"1.0\"?>\n<WindowElement><Optical><Layer><DataDefinition><IncidentDataStructure>TensorTree4</IncidentDataStructure></DataDefinition>\n<WavelengthData><Wavelength unit=\"Integral\">Visible</Wavelength><WavelengthDataBlock><WavelengthDataDirection>Transmission Front</WavelengthDataDirection><AngleBasis>LBNL/Shirley-Chiu</AngleBasis><ScatteringDataType>BTDF</ScatteringDataType>\n<ScatteringData>\n{data}\n</ScatteringData></WavelengthDataBlock></WavelengthData>\n</Layer></Optical></WindowElement>\n"
    );
    let path = room("block", Some("panel = \"bsdf\"\nfile = \"block.xml\"\nlobe_width = 40.0\n"));
    std::fs::write(path.with_file_name("block.xml"), xml).unwrap();
    let scene = Arc::new(load_scene(&path, &all_panels()).unwrap().scene);
    let sky = winter_noon(&scene);
    let sun = sky.sun_up().unwrap();
    let model = heliodon::light::LightModel::precompute(scene.clone(), quick()).unwrap();
    let readings = model.solve(&sky, None).sensors;
    // The panel frame of the south window: x = −x (west), y = up, z = north, into the room.
    let to_panel = |d: heliodon::glam::DVec3| heliodon::glam::DVec3::new(-d.x, d.z, d.y);
    let travel = to_panel(-sun.direction);
    let n = 400;
    // Where the engine measures: 1 cm off the floor.
    let points = heliodon::light::sensor_points(&scene);
    for ((reading, sensor), points) in readings.iter().zip(&scene.sensors).zip(&points) {
        let p = points[0];
        let mut integral = 0.0;
        for k in 0..n * n {
            let q = heliodon::glam::DVec3::new(1.0 + 2.0 * ((k / n) as f64 + 0.5) / n as f64, 0.0, 1.0 + ((k % n) as f64 + 0.5) / n as f64);
            let (to_sensor, r2) = ((p - q).normalize(), p.distance_squared(q));
            let out = to_panel(to_sensor);
            integral += tree.value(-travel, out) * out.z * -to_sensor.z * (2.0 / (n * n) as f64) / r2;
        }
        let expected = sun.normal_irradiance() * travel.z * integral * heliodon::sky::LUMINOUS_EFFICACY;
        let beams = model.beams_irradiance(p, sensor.normal.as_dvec3(), &model.sun_beams(&sun)) * heliodon::sky::LUMINOUS_EFFICACY;
        println!(
            "{}: direct sun {:.0} lux, the data's {expected:.0} ({:+.2}%); the lobe's beams would give {beams:.0}",
            reading.name,
            reading.direct_sun,
            100.0 * (reading.direct_sun / expected - 1.0),
        );
        assert!(expected > 100.0, "{}: the sensor sees the light through the block: {expected}", reading.name);
        assert!((reading.direct_sun / expected - 1.0).abs() < 0.01, "{}: {} vs {expected}", reading.name, reading.direct_sun);
    }
}

/// A panel's room side returns its back reflectance of the room's light:
/// an opaque panel (transmittance 0) reflecting half of it back lights the
/// room as a diffuse wall of reflectance 0.5 in its place does, and one
/// that returns nothing leaves the room darker.
#[test]
fn a_panel_reflects_the_rooms_light_back_as_a_wall_would() {
    use std::sync::Arc;
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("panel_back_reflectance");
    std::fs::create_dir_all(&dir).unwrap();
    let mut obj = QuadObj::new("room.mtl");
    let (w, d, h) = (4.0, 6.0, 3.0);
    obj.quad("floor", [[0.0, 0.0, 0.0], [w, 0.0, 0.0], [w, d, 0.0], [0.0, d, 0.0]]);
    obj.quad("wall", [[0.0, 0.0, h], [0.0, d, h], [w, d, h], [w, 0.0, h]]);
    obj.quad("wall", [[0.0, 0.0, 0.0], [0.0, d, 0.0], [0.0, d, h], [0.0, 0.0, h]]);
    obj.quad("wall", [[w, d, 0.0], [w, 0.0, 0.0], [w, 0.0, h], [w, d, h]]);
    // The south wall around a glass window (x 1-3, z 1-2), the north wall
    // around the "blind" (x 0.5-3.5, z 0.5-2.5).
    for (y, (x0, x1, z0, z1), name) in [(0.0, (1.0, 3.0, 1.0, 2.0), "glass"), (d, (0.5, 3.5, 0.5, 2.5), "blind")] {
        obj.quad("wall", [[0.0, y, 0.0], [w, y, 0.0], [w, y, z0], [0.0, y, z0]]);
        obj.quad("wall", [[0.0, y, z1], [w, y, z1], [w, y, h], [0.0, y, h]]);
        obj.quad("wall", [[0.0, y, z0], [x0, y, z0], [x0, y, z1], [0.0, y, z1]]);
        obj.quad("wall", [[x1, y, z0], [w, y, z0], [w, y, z1], [x1, y, z1]]);
        obj.quad(name, [[x0, y, z0], [x1, y, z0], [x1, y, z1], [x0, y, z1]]);
    }
    std::fs::write(dir.join("room.obj"), obj.text()).unwrap();
    let mtl = "newmtl floor\nKd 0.2 0.2 0.2\nnewmtl wall\nKd 0.5 0.5 0.5\nnewmtl glass\nd 0.12\nnewmtl blind\nKd 0.5 0.5 0.5\n";
    std::fs::write(dir.join("room.mtl"), mtl).unwrap();
    let indirect = |name: &str, blind: &str| -> Vec<f64> {
        let mut text = format!(
            "name = \"{name}\"\n[site]\nlatitude = 42.36\nlongitude = -71.06\ntimezone = -5.0\n[model]\nobj = \"room.obj\"\n{blind}"
        );
        // The same patches whether the blind is a window or a wall (a
        // window's focus keeps the ceiling near it finer), so that both
        // rooms draw the same rays and differ by the blind alone.
        text.push_str("\n[lighting]\nadaptive = false\n");
        for (k, y) in [1.0, 2.5, 4.0, 5.5].iter().enumerate() {
            text.push_str(&format!("\n[[sensors]]\nname = \"s{k}\"\nposition = [2.0, {y}, 0.8]\nnormal = [0.0, 0.0, 1.0]\n"));
        }
        let path = dir.join(format!("{name}.toml"));
        std::fs::write(&path, text).unwrap();
        let scene = Arc::new(load_scene(&path, &all_panels()).unwrap().scene);
        let model = heliodon::light::LightModel::precompute(scene.clone(), quick()).unwrap();
        let sky = heliodon::sky::Sky::new(&heliodon::sky::SkySpec::Overcast, 45.0, 180.0, 0.2, 355).unwrap();
        model.solve(&sky, None).sensors.iter().map(|s| s.indirect).collect()
    };
    let wall = indirect("wall", "");
    let panel = |rho: f64| {
        format!("\n[materials.blind]\nkind = \"panel\"\npanel = \"grey_filter\"\ntransmittance = 0.0\nback_reflectance = {rho}\n")
    };
    let reflecting = indirect("reflecting", &panel(0.5));
    let dark = indirect("dark", &panel(0.0));
    for ((w, r), d) in wall.iter().zip(&reflecting).zip(&dark) {
        println!("indirect: wall {w:.2}, reflecting panel {r:.2}, dark panel {d:.2}");
    }
    for ((w, r), d) in wall.iter().zip(&reflecting).zip(&dark) {
        assert!((r / w - 1.0).abs() < 0.02, "a panel returning 0.5 lights the room as a 0.5 wall: {r} vs {w}");
        assert!(d < w, "a panel returning nothing leaves the room darker: {d} vs {w}");
    }
    // Most of all beside it.
    assert!(dark[3] < 0.8 * wall[3], "{dark:?} vs {wall:?}");
}

/// A panel sees the sky its window sees. Under an overhang a redirecting
/// tree, which sends the upper sky's light to the ceiling, sends less of it
/// when the overhang hides that sky; and a clear panel (one straight lobe,
/// all of the light) lets in less sky than without the overhang, though
/// more than an opening in its place at these floor sensors: a panel takes
/// its windows' mean view of each sky bin (as Radiance's 3-phase daylight
/// matrix does), an opening each ray's own, and the floor sensors look
/// through the window's lower part, which sees under the overhang.
#[test]
fn an_overhang_hides_the_sky_from_a_panel_as_from_an_opening() {
    use std::sync::Arc;
    let catalog = all_panels();
    // Direct sky at the floor sensors, then at four ceiling sensors above them.
    let direct_sky = |name: &str, window: Option<&str>, overhang: bool| -> Vec<f64> {
        let path = room_with(name, window, overhang);
        let mut text = std::fs::read_to_string(&path).unwrap();
        for (k, y) in [2.5, 3.0, 3.5, 4.0].iter().enumerate() {
            text.push_str(&format!("\n[[sensors]]\nname = \"ceiling-{k}\"\nposition = [2.0, {y}, 3.0]\nnormal = [0.0, 0.0, -1.0]\n"));
        }
        std::fs::write(&path, text).unwrap();
        let scene = Arc::new(load_scene(&path, &catalog).unwrap().scene);
        // Many sensor rays: a sensor sees a little sky through a small window.
        let settings = heliodon::light::LightSettings { rays_per_sensor: 16384, ..quick() };
        let model = heliodon::light::LightModel::precompute(scene.clone(), settings).unwrap();
        let sky = heliodon::sky::Sky::new(&heliodon::sky::SkySpec::Overcast, 30.0, 180.0, 0.2, 355).unwrap();
        model.solve(&sky, None).sensors.iter().map(|s| s.direct_sky).collect()
    };
    let clear = Some("panel = \"grey_filter\"\ntransmittance = 1.0\n");
    let (open, panel) = (direct_sky("overhang_open", None, true), direct_sky("overhang_clear", clear, true));
    let unshaded = direct_sky("no_overhang_open", None, false);
    let tree = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/bsdf/redirect_tt4.xml");
    let tree = format!("panel = \"bsdf\"\nfile = \"{}\"\n", tree.display());
    let (redirected, redirected_shaded) = (direct_sky("tree_open_sky", Some(&tree), false), direct_sky("tree_overhang", Some(&tree), true));
    for k in 0..4 {
        println!(
            "floor {k}: opening {:.1} under the overhang, clear panel {:.1} under it, opening {:.1} without; ceiling {k}: tree {:.1}, under the overhang {:.1}",
            open[k],
            panel[k],
            unshaded[k],
            redirected[4 + k],
            redirected_shaded[4 + k]
        );
    }
    for k in 0..4 {
        assert!(open[k] < 0.9 * unshaded[k], "the overhang hides sky: {open:?} vs {unshaded:?}");
        assert!(panel[k] < 0.9 * unshaded[k] && panel[k] > open[k], "the panel sees the overhang: {panel:?} vs {open:?}, {unshaded:?}");
        assert!(redirected_shaded[4 + k] < 0.9 * redirected[4 + k], "{redirected_shaded:?} vs {redirected:?}");
    }
}

/// All the sun a prismatic window lets in lands inside the closed room:
/// the direct sun on every patch side, times its area, adds up to the flux
/// on the window times the panel's transmitted share.
#[test]
fn sunlight_through_a_prismatic_window_is_conserved() {
    use std::sync::Arc;
    let path = room("prismatic", Some("panel = \"prismatic\"\nfacet_angles = [40.0, 5.0]\n"));
    let scene = Arc::new(load_scene(&path, &all_panels()).unwrap().scene);
    let model = heliodon::light::LightModel::precompute(scene.clone(), quick()).unwrap();
    let sky = winter_noon(&scene);
    let lighting = model.solve(&sky, None);
    // The sides facing the inside of the box (the sun on its outer sides is not the panel's).
    let centre = heliodon::glam::DVec3::new(2.0, 3.0, 1.5);
    let landed: f64 = scene
        .patches
        .patches
        .iter()
        .enumerate()
        .filter(|(_, p)| matches!(scene.materials[p.material as usize].kind, MaterialKind::Diffuse { .. }))
        .map(|(i, p)| {
            let inward = if p.normal.as_dvec3().dot(centre - p.centroid.as_dvec3()) > 0.0 { 2 * i } else { 2 * i + 1 };
            f64::from(p.area) * lighting.sides[inward].sun
        })
        .sum();
    let sun = sky.sun.unwrap();
    let window = &scene.windows[0];
    let MaterialKind::Panel { model: panel, .. } = &scene.materials[window.material as usize].kind else { panic!() };
    let frame = heliodon::light::PanelFrame::new(heliodon::glam::DVec3::Y, None);
    let incoming = frame.to_panel(-sun.direction);
    let transmitted = panel.0.response(incoming).transmitted();
    let expected = sun.normal_irradiance() * incoming.z * f64::from(window.area) * transmitted;
    println!("landed {landed:.1} W, expected {expected:.1} W (transmitted share {transmitted:.3})");
    assert!(transmitted > 0.5);
    assert!((landed / expected - 1.0).abs() < 0.03, "landed {landed} vs {expected}");
}

/// The annual path's sensor coefficients read panel rooms as a radiosity
/// solve does: the sky through each panel group's transfer, its diffused
/// sun and its lobes (past an overhang) all folded in.
#[test]
fn sensor_coefficients_read_panel_rooms_as_a_solve_does() {
    use std::sync::Arc;
    for (name, body) in [
        ("coefficients_prismatic", "panel = \"prismatic\"\nfacet_angles = [40.0, 5.0]\n"),
        ("coefficients_grey", "panel = \"grey_filter\"\ntransmittance = 0.4\n"),
    ] {
        let path = room_with(name, Some(body), true);
        let scene = Arc::new(load_scene(&path, &all_panels()).unwrap().scene);
        let model = heliodon::light::LightModel::precompute(scene.clone(), quick()).unwrap();
        let sky = winter_noon(&scene);
        let solved = model.solve(&sky, None);
        let read = model.sensor_coefficients().readings(&model, &sky, None);
        for (a, b) in solved.sensors.iter().zip(&read) {
            let close = |x: f64, y: f64, tolerance: f64| (x - y).abs() <= tolerance * x.abs().max(y.abs()) + 0.01;
            assert!(close(a.direct_sun, b.direct_sun, 1e-9) && close(a.direct_sky, b.direct_sky, 1e-9), "{name}: {a:?} vs {b:?}");
            assert!(close(a.indirect, b.indirect, 2e-3), "{name} indirect: {a:?} vs {b:?}");
        }
        assert!(read.iter().any(|r| r.direct_sun > 100.0 && r.indirect > 10.0), "{name}: sun comes in: {read:?}");
    }
}

/// The renderer draws each panel lobe as a fake sun: the direct-sun image
/// of each panel room agrees with the CPU reference (shadow rays along the
/// lobes through the panel), pixel by pixel.
#[test]
fn panel_lobes_are_drawn_where_the_engine_puts_them() {
    use heliodon::render::offscreen::OffscreenRequest;
    use heliodon::render::reference::compare_direct_sun;
    use heliodon::render::{RenderMode, RenderSettings};
    use heliodon::time::{Date, LocalDateTime, TimeOfDay};
    for (room, date, hours) in [
        ("prismatic_room", (2026, 12, 21), 12.0),
        ("prismatic_room", (2026, 3, 21), 10.0),
        ("laser_cut_room", (2026, 3, 21), 12.0),
        ("venetian_room", (2026, 3, 21), 12.0),
        ("bsdf_room", (2026, 3, 21), 10.0),
    ] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../assets/scenes/{room}/scene.toml"));
        let scene = load_scene(&path, &all_panels()).unwrap().scene;
        let request = OffscreenRequest {
            scene: path.clone(),
            view: Some(scene.viewpoints[0].clone()),
            fov: None,
            width: 320,
            height: 200,
            when: Some(LocalDateTime { date: Date::new(date.0, date.1, date.2).unwrap(), time: TimeOfDay::from_hours(hours).unwrap() }),
            sky: Some(heliodon::sky::SkySpec::Clear { turbidity: 2.45 }),
            settings: RenderSettings { mode: RenderMode::Sun, ..Default::default() },
            light: Default::default(),
            panels: all_panels(),
        };
        let file = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("sun_{room}_{}_{hours}.png", date.1));
        let result = compare_direct_sun(&request, &file).unwrap();
        println!("{room} {date:?} {hours}: {result} -> {}", file.display());
        assert!(result.lit > 500, "{result}");
        assert!(result.agreement >= 0.99 && result.within >= 0.99, "{result}");
    }
}

/// A panel is seen as what it sends into the room: an eye inside a lobe's
/// cone, looking back at the panel against the lobe's light, sees it as
/// bright as the lobe (E·share/cos θout over the cone's solid angle,
/// saturating the physical image at 60,000 cd/m²); an eye outside every
/// cone sees the sky and ground the panel passes its way (the engine's sky
/// transfer) and its diffusely transmitted sun.
#[test]
fn a_panel_shows_its_lobes_to_an_eye_inside_their_cones() {
    use heliodon::glam::DVec3;
    use heliodon::light::LightModel;
    use heliodon::render::offscreen::{OffscreenRequest, render};
    use heliodon::render::{RenderMode, RenderSettings};
    use heliodon::scene::Viewpoint;
    use heliodon::time::{Date, LocalDateTime, TimeOfDay};
    let path = room("lobe_look", Some("panel = \"prismatic\"\nfacet_angles = [40.0, 5.0]\n"));
    let scene = std::sync::Arc::new(load_scene(&path, &all_panels()).unwrap().scene);
    let model = LightModel::unlit(scene.clone());
    let looks = model.panel_looks(&winter_noon(&scene));
    assert_eq!(looks.len(), 1, "one panel group");
    let cone = |l: &heliodon::light::LobeLook| l.luminance * (1.0 - l.half_angle.cos());
    let lobe = *looks[0].lobes.iter().max_by(|a, b| cone(a).total_cmp(&cone(b))).expect("the winter sun makes lobes");
    // The panel's middle; eyes 2 m from it, inside the room.
    let middle = DVec3::new(2.0, 0.0, 1.5);
    let seen_from = |direction: DVec3| {
        let eye = middle + direction * 2.0;
        assert!(eye.y > 0.1 && eye.y < 5.9 && eye.z > 0.1 && eye.z < 2.9, "{eye} is in the room");
        let view = Viewpoint { name: "panel".into(), eye: eye.as_vec3(), target: middle.as_vec3(), fov: 10.0 };
        let image = render(OffscreenRequest {
            scene: path.clone(),
            view: Some(view),
            fov: None,
            width: 33,
            height: 33,
            when: Some(LocalDateTime { date: Date::new(2026, 12, 21).unwrap(), time: TimeOfDay::from_hours(12.0).unwrap() }),
            sky: Some(heliodon::sky::SkySpec::Clear { turbidity: 2.45 }),
            settings: RenderSettings { mode: RenderMode::Full, exposure: Some(12.0), ..Default::default() },
            light: quick(),
            panels: all_panels(),
        })
        .unwrap();
        heliodon::light::luminous(image.physical[16 * 33 + 16].map(f64::from))
    };
    // Off the lobe by three of its half angles, turned about the panel's
    // horizontal axis, and inside no other lobe's cone.
    let off = {
        let (s, c) = (3.0 * lobe.half_angle).sin_cos();
        let d = DVec3::new(lobe.travel.x, lobe.travel.y * c - lobe.travel.z * s, lobe.travel.y * s + lobe.travel.z * c);
        assert!(looks[0].lobes.iter().all(|l| d.dot(l.travel) < l.half_angle.cos()), "{d} is outside every cone");
        d
    };
    let (inside, outside) = (seen_from(lobe.travel), seen_from(off));
    let expected = lobe.luminance.min(60_000.0);
    // Outside the cones: the sky and ground the panel passes that way, and its diffuse sun.
    let passed = model.panel_sky_luminance(&looks[0], -off) + looks[0].diffuse;
    println!(
        "lobe {lobe:?}: seen inside its cone {inside:.0} cd/m², outside {outside:.0} (the sky it passes that way and its diffuse sun: {passed:.0})"
    );
    assert!(inside > 0.95 * expected, "{inside} against {expected}");
    assert!((outside / passed - 1.0).abs() < 0.05, "{outside} against {passed}");
}

/// Exterior shading acts on the real sun before the panel turns it into
/// lobes: the overhang's shadow on a prismatic window keeps each lobe's
/// light off part of the floor, in the engine and in the picture alike.
#[test]
fn an_overhang_shades_the_lobes_of_a_panel() {
    use heliodon::render::offscreen::OffscreenRequest;
    use heliodon::render::reference::compare_direct_sun;
    use heliodon::render::{RenderMode, RenderSettings};
    use heliodon::scene::Viewpoint;
    use heliodon::time::{Date, LocalDateTime, TimeOfDay};
    let path = room_with("overhang", Some("panel = \"prismatic\"\nfacet_angles = [40.0, 5.0]\n"), true);
    let view = Viewpoint {
        name: "floor".into(),
        eye: heliodon::glam::Vec3::new(2.0, 5.5, 2.5),
        target: heliodon::glam::Vec3::new(2.0, 2.0, 0.0),
        fov: 70.0,
    };
    let request = OffscreenRequest {
        scene: path.clone(),
        view: Some(view),
        fov: None,
        width: 320,
        height: 200,
        when: Some(LocalDateTime { date: Date::new(2026, 12, 21).unwrap(), time: TimeOfDay::from_hours(12.0).unwrap() }),
        sky: Some(heliodon::sky::SkySpec::Clear { turbidity: 2.45 }),
        settings: RenderSettings { mode: RenderMode::Sun, ..Default::default() },
        light: Default::default(),
        panels: all_panels(),
    };
    let file = Path::new(env!("CARGO_TARGET_TMPDIR")).join("sun_overhang_prismatic.png");
    let result = compare_direct_sun(&request, &file).unwrap();
    println!("overhang over a prismatic window: {result} -> {}", file.display());
    assert!(result.lit > 1000, "{result}");
    assert!(result.agreement >= 0.99 && result.within >= 0.99, "{result}");
    // And the overhang does shade: the same view without it has more sun.
    let open = OffscreenRequest { scene: room("no_overhang", Some("panel = \"prismatic\"\nfacet_angles = [40.0, 5.0]\n")), ..request };
    let unshaded = compare_direct_sun(&open, &file.with_file_name("sun_no_overhang_prismatic.png")).unwrap();
    assert!(result.lit < unshaded.lit * 9 / 10, "{} lit with the overhang, {} without", result.lit, unshaded.lit);
}
