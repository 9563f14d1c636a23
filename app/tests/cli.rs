//! The command line, through the `heliodon` executable (one runner,
//! tests/support/cli.rs): every subcommand's output in the contract's
//! formats against the library, and bad input answered in one line with a
//! non-zero exit.

#[path = "../../tests/support/cli.rs"]
mod cli;
#[path = "../../tests/support/epw.rs"]
mod epw;
#[path = "../../tests/support/fixture.rs"]
mod fixture;

use std::path::{Path, PathBuf};
use std::sync::Arc;

use heliodon_core::light::{LightModel, LightSettings};
use heliodon_core::panel::PanelCatalog;
use heliodon_core::scene::{Scene, load_scene};
use heliodon_core::site::Site;
use heliodon_core::sky::{Sky, SkySpec};
use heliodon_core::sun::solar_position;
use heliodon_core::time::{Date, LocalDateTime, TimeOfDay};

use cli::{Run, heliodon, root};
use epw::{boston_clear_thirds_epw, boston_epw};
use fixture::{OBJ, fixture, scene_toml};

/// A light cache for the commands whose caching is not what is tested.
fn scratch() -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR")).join("cli_cache")
}

fn bundled_scene(name: &str) -> PathBuf {
    root().join("assets/scenes").join(name).join("scene.toml")
}

/// The bundled test room copied into `folder` (under the test target's
/// temporary folder), its scene file ending with `extra`; the scene's path.
fn test_room_with(folder: &str, extra: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(folder);
    std::fs::create_dir_all(&dir).unwrap();
    let room = bundled_scene("test_room");
    for file in ["model.obj", "model.mtl"] {
        std::fs::copy(room.with_file_name(file), dir.join(file)).unwrap();
    }
    std::fs::write(dir.join("scene.toml"), std::fs::read_to_string(&room).unwrap() + extra).unwrap();
    dir.join("scene.toml")
}

/// A folder `folder` under the test target's temporary folder holding a
/// synthetic year of weather; (the folder, the EPW's path).
fn folder_with_a_year(folder: &str) -> (PathBuf, PathBuf) {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(folder);
    std::fs::create_dir_all(&dir).unwrap();
    let epw = dir.join("boston.epw");
    std::fs::write(&epw, boston_epw(8760)).unwrap();
    (dir, epw)
}

fn load(path: &Path) -> Arc<Scene> {
    Arc::new(load_scene(path, &PanelCatalog::new()).unwrap().scene)
}

/// The validation room (tests/fixtures/sideroom).
fn sideroom() -> PathBuf {
    root().join("tests/fixtures/sideroom/scene.toml")
}

fn sky_at(scene: &Scene, spec: &SkySpec, date: &str, time: &str) -> Sky {
    let when = LocalDateTime { date: Date::parse(date).unwrap(), time: TimeOfDay::parse(time).unwrap() };
    heliodon_core::sky::sky_at(&scene.site, spec, &when).1.unwrap()
}

const BOSTON: [&str; 6] = ["--latitude", "42.36", "--longitude", "-71.06", "--timezone", "-5"];

// Panel scenes: a floor and a material `upper` given as a panel table body.
const PANEL_OBJ: &str = "mtllib room.mtl\nusemtl floor\nv 0 0 0\nv 4 0 0\nv 4 6 0\nv 0 6 0\nf 1 2 3 4\nusemtl upper\nv 0 0 2\nv 4 0 2\nv 4 0 3\nv 0 0 3\nf 5 6 7 8\n";
const PANEL_MTL: &str = "newmtl floor\nKd 0.3 0.3 0.3\nnewmtl upper\nKd 0.5 0.5 0.5\n";

// ---- info ------------------------------------------------------------------------

#[test]
fn info_summarises_each_bundled_scene() {
    let Run { code, out, err } = heliodon(&["info", "assets/scenes/test_room/scene.toml"], &scratch());
    assert_eq!(code, 0, "{err}");
    assert!(err.is_empty(), "{err}");
    for expected in [
        "scene      Small test room",
        "triangles  80",
        "  diffuse  3: ",
        "  glass    1: glass τ=0.88",
        "windows    6, 4.59 m² in all",
        "facing S (azimuth 180°)",
        "sensors    65 (3 point, 2 area, grids: workplane 60)",
        "latitude 42.3600°, longitude -71.0600°, UTC-5",
    ] {
        assert!(out.contains(expected), "missing {expected:?} in\n{out}");
    }
    let patches: usize = out
        .lines()
        .find_map(|l| l.strip_prefix("patches    "))
        .and_then(|l| l.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .expect("patch line");
    // 108 m² of surfaces would be 432 patches at the finest 0.5 m; the
    // ceiling, 2.2 m over the grid, is coarser away from the windows, and no
    // patch in the room is wider than 1 m (108).
    assert!((108..432).contains(&patches), "{out}");
    // Where the patches go: the 4 × 6 × 3 m room's floor and ceiling face
    // up and down, its walls sideways, and every patch has a width class.
    let facing = out.lines().find_map(|l| l.strip_prefix("  facing   ")).expect("facing line");
    assert!(facing.contains(" (24 m²), down ") && facing.ends_with(" (60 m²)"), "{out}");
    let counted: usize = (out.lines().find_map(|l| l.strip_prefix("  wide     ")).expect("width line").split(", "))
        .map(|class| class.split_whitespace().rev().nth(2).and_then(|n| n.parse::<usize>().ok()).expect("a count"))
        .sum();
    assert_eq!(counted, patches, "{out}");
    // The surfaces cut past their area in finest cells, most first: the
    // wall the windows' planes cut into strips around its six openings.
    let most = out.lines().find_map(|l| l.strip_prefix("  most     ")).expect("most line");
    assert!(most.contains(" of wall facing N (azimuth 0°) at (2.00, 0.00, "), "{out}");
    let past: Vec<usize> = most
        .split("; ")
        .map(|surface| {
            let number = |text: &str| text.split_whitespace().next().and_then(|n| n.parse::<usize>().ok()).expect("a count");
            let cells = surface.split(" (").nth(1).map(number).expect("finest cells");
            number(surface) - cells
        })
        .collect();
    assert!(past.len() == 3 && past.windows(2).all(|w| w[0] >= w[1]) && past[2] > 0, "{out}");
    let Run { code, out, .. } = heliodon(&["info", "assets/scenes/office/scene.toml"], &scratch());
    assert_eq!(code, 0);
    assert!(out.contains("windows    12, 24.88 m² in all") && out.contains("facing W (azimuth 270°)"), "{out}");
    let Run { code, out, .. } = heliodon(&["info", "assets/scenes/living_room/scene.toml"], &scratch());
    assert_eq!(code, 0);
    assert!(out.contains("up Y, scale 0.01 m/unit") && out.contains("windows    16"), "{out}");
}

#[test]
fn cli_errors_are_one_line_and_non_zero() {
    let f = fixture("cli_kind", &scene_toml("\n[materials.wall]\nkind = \"stone\"\n"), OBJ);
    let scene = f.scene();
    let Run { code, out, err } = heliodon(&["info", scene.to_str().unwrap()], &scratch());
    assert_ne!(code, 0);
    assert!(out.is_empty());
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.starts_with(&format!("error: {}:11: materials.wall.kind: unknown material kind 'stone'", scene.display())), "{err}");
    let Run { code, err, .. } = heliodon(&["info", "no/such/scene.toml"], &scratch());
    assert_ne!(code, 0);
    assert_eq!(err.trim_end(), "error: no/such/scene.toml: cannot read scene file: not found");
    let Run { code, err, .. } = heliodon(&["info", "assets/scenes/test_room/scene.toml", "--bogus"], &scratch());
    assert_eq!(code, 2);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("--bogus"), "{err}");
    let Run { code, err, .. } = heliodon(&["info"], &scratch());
    assert_eq!(code, 2);
    assert_eq!(err.lines().count(), 1, "{err}");
    let render = ["render", "assets/scenes/test_room/scene.toml", "--date", "2026-03-21", "--time", "12:00", "--out", "x.png"];
    let Run { code, err, .. } = heliodon(&[&render[..], &["--quality", "0"]].concat(), &scratch());
    assert_eq!(code, 2);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("--quality"), "{err}");
    // Warnings go to stderr and do not fail the command.
    let f = fixture("cli_warning", &scene_toml("\n[materials.marble]\nkind = \"diffuse\"\nreflectance = 0.7\n"), OBJ);
    let Run { code, err, .. } = heliodon(&["info", f.scene().to_str().unwrap()], &scratch());
    assert_eq!(code, 0);
    assert!(err.starts_with("warning: ") && err.contains("materials.marble"), "{err}");
}

#[test]
fn help_lists_only_what_exists() {
    let Run { code, out, .. } = heliodon(&["--help"], &scratch());
    assert_eq!(code, 0);
    // Subcommands arrive with their features: none is listed before it exists.
    let commands: Vec<&str> = out
        .lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next())
        .collect();
    assert_eq!(
        commands,
        ["view", "info", "sensors", "export-radiance", "render", "sun", "annual", "sweep", "sweep-merge", "help"],
        "{out}"
    );
}

// ---- sun -------------------------------------------------------------------------

#[test]
fn sun_command_prints_the_contract_formats() {
    let mut args = vec!["sun"];
    args.extend(BOSTON);
    args.extend(["--date", "2026-03-21", "--time", "12:00"]);
    let site = Site::new(42.36, -71.06, -5.0);
    let expected =
        solar_position(&site, &LocalDateTime { date: Date::new(2026, 3, 21).unwrap(), time: TimeOfDay::from_hours(12.0).unwrap() });

    let Run { code, out, err } = heliodon(&[args.as_slice(), &["--format", "csv"]].concat(), &scratch());
    assert_eq!(code, 0, "{err}");
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines[0], "altitude_deg,azimuth_deg");
    assert_eq!(lines.len(), 2);
    let values: Vec<f64> = lines[1].split(',').map(|v| v.parse().unwrap()).collect();
    assert!((values[0] - expected.altitude).abs() < 1e-6 && (values[1] - expected.azimuth).abs() < 1e-6);

    let Run { code, out, .. } = heliodon(&[args.as_slice(), &["--format", "json"]].concat(), &scratch());
    assert_eq!(code, 0);
    assert_eq!(out.trim(), format!("{{\"altitude_deg\": {:.6}, \"azimuth_deg\": {:.6}}}", expected.altitude, expected.azimuth));

    let Run { code, out, .. } = heliodon(&args, &scratch());
    assert_eq!(code, 0);
    assert!(out.contains(&format!("altitude   {:9.4}°", expected.altitude)), "{out}");

    let mut day = vec!["sun"];
    day.extend(BOSTON);
    day.extend(["--date", "2026-03-21", "--day", "--format", "csv"]);
    let Run { code, out, .. } = heliodon(&day, &scratch());
    assert_eq!(code, 0);
    let rows: Vec<&str> = out.lines().collect();
    assert_eq!(rows[0], "event,time,altitude_deg,azimuth_deg");
    assert!(
        rows[1].starts_with("sunrise,05:45:42,") && rows[2].starts_with("noon,11:51:19,") && rows[3].starts_with("sunset,17:57:41,"),
        "{out}"
    );
}

#[test]
fn sun_command_rejects_bad_input_in_one_line() {
    let cases: [(&[&str], &str); 8] = [
        (&["--latitude", "95", "--longitude", "0", "--timezone", "0", "--date", "2026-03-21", "--time", "12:00"], "--latitude"),
        (&["--latitude", "10", "--longitude", "-181", "--timezone", "0", "--date", "2026-03-21", "--time", "12:00"], "--longitude"),
        (&["--latitude", "10", "--longitude", "0", "--timezone", "-15", "--date", "2026-03-21", "--time", "12:00"], "--timezone"),
        (
            &["--latitude", "10", "--longitude", "0", "--timezone", "0", "--date", "2026-02-30", "--time", "12:00"],
            "February 2026 has 28 days",
        ),
        (&["--latitude", "10", "--longitude", "0", "--timezone", "0", "--date", "2026-03-21", "--time", "24:01"], "outside 00:00-24:00"),
        (&["--latitude", "10", "--longitude", "0", "--timezone", "0", "--date", "2026-03-21", "--time", "7pm"], "--time"),
        (&["--latitude", "10", "--longitude", "0", "--timezone", "0", "--date", "2026-03-21"], "--time"),
        (&["--latitude", "nan", "--longitude", "0", "--timezone", "0", "--date", "2026-03-21", "--time", "12:00"], "--latitude"),
    ];
    for (args, expected) in cases {
        let Run { code, out, err } = heliodon(&[&["sun"], args].concat(), &scratch());
        assert_eq!(code, 2, "{args:?}");
        assert!(out.is_empty());
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.starts_with("error: ") && err.contains(expected), "{args:?}: {err}");
    }
}

// ---- sensors and export-radiance --------------------------------------------------

#[test]
fn sensors_command_prints_the_contract_csv_and_shares_one_precomputation() {
    let cache = Path::new(env!("CARGO_TARGET_TMPDIR")).join("sensors_cli_cache");
    let _ = std::fs::remove_dir_all(&cache);
    let scene_path = sideroom();
    let scene = scene_path.to_str().unwrap();
    let args = ["sensors", scene, "--date", "2026-03-21", "--time", "12:00", "--sky", "overcast", "--format", "csv"];
    let Run { code, out: first, err } = heliodon(&args, &cache);
    assert_eq!(code, 0, "{err}");
    let lines: Vec<&str> = first.lines().collect();
    assert_eq!(lines[0], "name,illuminance_lux,direct_sun_lux,direct_sky_lux,indirect_lux");
    assert_eq!(lines.len(), 1 + 19);
    for line in &lines[1..] {
        let f: Vec<&str> = line.split(',').collect();
        let v: Vec<f64> = f[1..].iter().map(|x| x.parse().unwrap()).collect();
        assert!(v.iter().all(|x| x.is_finite() && *x >= 0.0));
        assert!((v[0] - v[1] - v[2] - v[3]).abs() <= 0.2, "parts add up: {line}");
        assert_eq!(v[1], 0.0, "no sun under an overcast sky");
    }
    // The same from the library.
    let model = LightModel::precompute(load(&scene_path), LightSettings::default()).unwrap();
    let expected = model.solve(&sky_at(&model.scene, &SkySpec::Overcast, "2026-03-21", "12:00"), None);
    assert_eq!(
        lines[1],
        format!(
            "s00,{:.1},{:.1},{:.1},{:.1}",
            expected.sensors[0].total, expected.sensors[0].direct_sun, expected.sensors[0].direct_sky, expected.sensors[0].indirect
        )
    );
    // A second run reads the caches (the light's and the loaded model's) and says the same.
    let Run { out: second, .. } = heliodon(&args, &cache);
    assert_eq!(first, second);
    let files: Vec<String> = std::fs::read_dir(&cache).unwrap().map(|f| f.unwrap().file_name().to_string_lossy().into_owned()).collect();
    assert_eq!(files.len(), 2, "{files:?}");
    assert_eq!(files.iter().filter(|f| f.starts_with("light-scene-")).count(), 1, "{files:?}");
    // Several times and dates in one call.
    let Run { code, out: many, .. } = heliodon(
        &["sensors", scene, "--date", "2026-03-21,2026-06-21", "--time", "09:00,12:00", "--sky", "clear", "--format", "csv"],
        &cache,
    );
    assert_eq!(code, 0);
    let rows: Vec<&str> = many.lines().collect();
    assert_eq!(rows[0], "date,time,name,illuminance_lux,direct_sun_lux,direct_sky_lux,indirect_lux");
    assert_eq!(rows.len(), 1 + 4 * 19);
    assert!(rows[1].starts_with("2026-03-21,09:00:00,s00,") && rows[rows.len() - 1].starts_with("2026-06-21,12:00:00,ceiling_centre,"));
}

/// A sensor outside every room, and a model with no room at all, are named
/// in one warning line; the command still answers.
#[test]
fn sensors_in_the_open_are_warned_about() {
    let scene = test_room_with(
        "sensor_outside",
        "\n[[sensors]]\nname = \"in-the-garden\"\nposition = [2.0, -12.0, 0.8]\nnormal = [0.0, 0.0, 1.0]\n",
    );
    let args = ["sensors", scene.to_str().unwrap(), "--date", "2026-03-21", "--time", "12:00", "--format", "csv"];
    let Run { code, out, err } = heliodon(&args, &scratch());
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("in-the-garden,"), "it still reads: {out}");
    let warnings: Vec<&str> = err.lines().filter(|l| l.contains("open sky")).collect();
    assert_eq!(warnings.len(), 1, "{err}");
    assert!(
        warnings[0].contains("sensors outside every room") && warnings[0].ends_with("in-the-garden; they read the light where they are"),
        "{err}"
    );
    // No room at all: a wall and a pane in the open.
    let open =
        fixture("open_model", &scene_toml("\n[[sensors]]\nname = \"s\"\nposition = [0.5, 0.5, 1.0]\nnormal = [0.0, 0.0, 1.0]\n"), OBJ);
    let Run { code, err, .. } =
        heliodon(&["sensors", open.scene().to_str().unwrap(), "--date", "2026-03-21", "--time", "12:00"], &scratch());
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("the model has no enclosed room around them"), "{err}");
}

/// Names with commas, quotes, line breaks and control characters leave
/// the CSV (RFC 4180), the JSON and the Radiance export valid.
#[test]
fn odd_sensor_names_keep_every_output_valid() {
    let sensor = |name: &str| format!("\n[[sensors]]\nname = \"{name}\"\nposition = [2.0, 3.0, 0.8]\nnormal = [0.0, 0.0, 1.0]\n");
    let scene = test_room_with("odd_names", &(sensor(r#"desk, \"north\""#) + &sensor(r"two\nlines") + &sensor(r"bell\u0007")));
    let case = ["--date", "2026-03-21", "--time", "12:00", "--sky", "overcast"];
    let run = |format: &str| heliodon(&[&["sensors", scene.to_str().unwrap()], &case[..], &["--format", format]].concat(), &scratch());
    let Run { code, out, err } = run("csv");
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("\n\"desk, \"\"north\"\"\","), "{out}");
    assert!(out.contains("\n\"two\nlines\","), "{out}");
    assert!(out.contains("\nbell\u{7},"), "{out}");
    let Run { out, .. } = run("json");
    assert!(out.contains(r#""name": "desk, \"north\"""#) && out.contains(r#""name": "two\nlines""#), "{out}");
    assert!(out.contains(r#""name": "bell\u0007""#) && !out.contains('\u{7}'), "{out}");
    let export = scene.with_file_name("export");
    let Run { code, err, .. } =
        heliodon(&[&["export-radiance", scene.to_str().unwrap()], &case[..], &["--out", export.to_str().unwrap()]].concat(), &scratch());
    assert_eq!(code, 0, "{err}");
    let index = std::fs::read_to_string(export.join("sensors.txt")).unwrap();
    assert!(index.lines().all(|l| l.split(' ').count() == 2), "one word and a count a line: {index}");
    let names = std::fs::read_to_string(export.join("names.csv")).unwrap();
    assert_eq!(names.lines().count(), index.lines().count());
    assert!(names.contains("\"desk, \"\"north\"\"\"\n") && names.contains("two lines\n"), "{names}");
}

#[test]
fn sensors_command_rejects_bad_input_in_one_line() {
    let cache = Path::new(env!("CARGO_TARGET_TMPDIR")).join("sensors_cli_cache_bad");
    let scene_path = sideroom();
    let scene = scene_path.to_str().unwrap();
    let cases: [(&[&str], &str); 5] = [
        (&["sensors", scene, "--date", "2026-03-21", "--time", "12:00", "--sky", "sunny"], "unknown sky 'sunny'"),
        (&["sensors", scene, "--date", "2026-03-21", "--time", "12:00", "--sky", "perez"], "--sky perez"),
        (&["sensors", scene, "--date", "2026-03-21", "--time", "12:00", "--sky", "perez", "--dni", "-3", "--dhi", "100"], "non-negative"),
        (&["sensors", "no/such/scene.toml", "--date", "2026-03-21", "--time", "12:00"], "no/such/scene.toml: cannot read scene file"),
        (&["sensors", scene, "--date", "2026-03-21", "--time", "25:00"], "--time"),
    ];
    for (args, expected) in cases {
        let Run { code, out, err } = heliodon(args, &cache);
        assert_ne!(code, 0, "{args:?}");
        assert!(out.is_empty(), "{out}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.starts_with("error: ") && err.contains(expected), "{args:?}: {err}");
    }
    // Perez light with the sun down is refused, naming the case.
    let Run { code, err, .. } =
        heliodon(&["sensors", scene, "--date", "2026-03-21", "--time", "03:00", "--sky", "perez", "--dni", "100", "--dhi", "50"], &cache);
    assert_ne!(code, 0);
    assert!(err.contains("2026-03-21 03:00:00") && err.contains("below the horizon"), "{err}");
}

#[test]
fn export_radiance_writes_the_same_model_and_sky() {
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("export_test_room");
    let _ = std::fs::remove_dir_all(&out);
    let scene_path = bundled_scene("test_room");
    let run = heliodon(
        &[
            "export-radiance",
            scene_path.to_str().unwrap(),
            "--date",
            "2026-03-21",
            "--time",
            "10:00",
            "--sky",
            "clear",
            "--out",
            out.to_str().unwrap(),
        ],
        &scratch(),
    );
    assert_eq!(run.code, 0, "{}", run.err);
    let scene = load(&scene_path);
    let rad = std::fs::read_to_string(out.join("scene.rad")).unwrap();
    assert_eq!(rad.matches(" polygon ").count(), scene.triangles.len());
    assert!(rad.contains("void glass m_glass\n0\n0\n3 0.9"), "Radiance transmissivity of 88% glass is 0.96");
    let sky_rad = std::fs::read_to_string(out.join("sky.rad")).unwrap();
    let sky = sky_at(&scene, &SkySpec::Clear { turbidity: 2.45 }, "2026-03-21", "10:00");
    let (zenith, f2) = sky.gensky_arguments().unwrap();
    assert!(sky_rad.contains(&format!("7 1 {zenith:.9e} {:.9e} {f2:.9e}", sky.ground_radiance)), "{sky_rad}");
    assert!(sky_rad.contains(&format!("3 {r:.6e} {r:.6e} {r:.6e}", r = sky.sun.unwrap().radiance)));
    let points = std::fs::read_to_string(out.join("sensors.pts")).unwrap();
    let index = std::fs::read_to_string(out.join("sensors.txt")).unwrap();
    let expected: usize = scene.sensors.iter().map(|s| if s.size.is_some() { 16 } else { 1 }).sum();
    assert_eq!(points.lines().count(), expected);
    assert_eq!(index.lines().count(), scene.sensors.len());
    assert!(std::fs::read_to_string(out.join("run.sh")).unwrap().contains("rtrace -h -I -ab 64"));
    // The floor sensor lies on the floor: it is exported lifted 1 cm, as heliodon reads it.
    let floor = index.lines().position(|l| l.starts_with("floor-centre ")).unwrap();
    let first_point: usize = index.lines().take(floor).map(|l| l.split(' ').nth(1).unwrap().parse::<usize>().unwrap()).sum();
    let z: f64 = points.lines().nth(first_point).unwrap().split(' ').nth(2).unwrap().parse().unwrap();
    assert!((z - 0.01).abs() < 1e-6, "{z}");
}

/// A panel fitted to a BSDF file is exported as Radiance's `BSDF` material
/// on that file (so Radiance computes with the data), its up the panel's,
/// its window polygons facing into the room whatever way the model wound
/// them.
#[test]
fn export_radiance_gives_bsdf_panels_their_data() {
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("export_bsdf_room");
    let _ = std::fs::remove_dir_all(&out);
    let scene_path = bundled_scene("bsdf_room");
    let args = ["export-radiance", scene_path.to_str().unwrap(), "--date", "2026-03-21", "--time", "10:00", "--out", out.to_str().unwrap()];
    let run = heliodon(&args, &scratch());
    assert_eq!(run.code, 0, "{}", run.err);
    let rad = std::fs::read_to_string(out.join("scene.rad")).unwrap();
    let blinds = std::fs::canonicalize(scene_path.parent().unwrap().join("../../bsdf/blinds.xml")).unwrap();
    // The south windows: up is the zenith.
    let material = format!("void BSDF m_upper_g0\n6 0 {} 0.000000000 0.000000000 1.000000000 .\n0\n0\n", blinds.display());
    assert!(rad.contains(&material), "{rad}");
    let polygons: Vec<&str> = rad.split("m_upper_g0 polygon ").skip(1).collect();
    let scene = load_scene(&scene_path, &PanelCatalog::new().with(heliodon_bsdf::Bsdf)).unwrap().scene;
    let upper = scene.materials.iter().position(|m| m.name == "upper").unwrap() as u32;
    assert_eq!(polygons.len(), scene.triangles.iter().filter(|t| t.material == upper).count());
    assert!(!polygons.is_empty());
    for polygon in polygons {
        let v: Vec<f64> = polygon.lines().skip(4).take(3).flat_map(|l| l.split_whitespace().map(|x| x.parse::<f64>().unwrap())).collect();
        let (a, b) = ([v[3] - v[0], v[4] - v[1], v[5] - v[2]], [v[6] - v[0], v[7] - v[1], v[8] - v[2]]);
        let normal_y = a[2] * b[0] - a[0] * b[2];
        assert!(normal_y > 0.0, "a BSDF window faces into the room (+y): {polygon}");
    }
}

// ---- annual ----------------------------------------------------------------------

/// `--seed` draws another Monte Carlo sample of the rays in `sweep` and
/// `annual` as it does in `sensors`; a seed that is not a number is named.
#[test]
fn sweep_and_annual_take_a_seed() {
    let room = bundled_scene("test_room");
    let room = room.to_str().unwrap();
    let sweep = |seed: &str| {
        let args = [
            "sweep",
            room,
            "--material",
            "glass",
            "--vary",
            "transmittance=0.7..0.8:0.1",
            "--sensor",
            "back",
            "--date",
            "2026-03-21",
            "--time",
            "10:00",
            "--sky",
            "overcast",
            "--format",
            "csv",
            "--seed",
            seed,
        ];
        let Run { code, out, err } = heliodon(&args, &scratch());
        assert_eq!(code, 0, "{err}");
        out
    };
    let (zero, one) = (sweep("0"), sweep("1"));
    assert_eq!(zero.lines().count(), 3, "{zero}");
    assert_eq!(zero.lines().next(), one.lines().next());
    assert_ne!(zero, one, "another sample of the rays reads otherwise");
    let Run { code, err, .. } = heliodon(&["annual", room, "--weather", "any.epw", "--seed", "abc"], &scratch());
    assert_eq!(code, 2);
    assert!(err.contains("--seed"), "{err}");
}

/// An hour whose Perez sky gendaylit refuses (a positive parameter b, the
/// sun 0.5° up) is dark in `annual`, as `sensors` reads it then, and both
/// say why in one line; `sweep` against that year says it too. Such an
/// hour read 13 million lux before.
#[test]
fn a_sky_gendaylit_refuses_reads_dark_and_is_named() {
    let dir = scratch().join("refused_dawn");
    std::fs::create_dir_all(&dir).unwrap();
    let epw = dir.join("boston.epw");
    std::fs::write(&epw, epw::boston_refused_dawn_epw()).unwrap();
    let hourly = dir.join("hourly.csv");
    let room = bundled_scene("test_room");
    let args = ["annual", room.to_str().unwrap(), "--weather", epw.to_str().unwrap(), "--hourly", hourly.to_str().unwrap()];
    let Run { code, err, .. } = heliodon(&args, &scratch());
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("1 lit hours gave no Perez sky") && err.contains("5/13 hour 5") && err.contains("positive parameter b"), "{err}");
    let hours = std::fs::read_to_string(&hourly).unwrap();
    let row = |hour: &str| {
        hours
            .lines()
            .find(|l| l.starts_with(&format!("5,13,{hour},")))
            .unwrap()
            .split(',')
            .skip(3)
            .map(|v| v.parse::<f64>().unwrap())
            .collect::<Vec<_>>()
    };
    assert!(row("5").iter().all(|&v| v == 0.0), "{:?}", row("5"));
    assert!(row("13").iter().all(|&v| v > 100.0), "{:?}", row("13"));
    let args =
        ["sensors", room.to_str().unwrap(), "--date", "2025-05-13", "--time", "04:30", "--sky", "perez", "--dni", "260", "--dhi", "23"];
    let Run { code, out, err } = heliodon(&[&args[..], &["--format", "csv"]].concat(), &scratch());
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("positive parameter b") && err.contains("gendaylit's error sky"), "{err}");
    assert!(out.lines().skip(1).all(|l| l.split(',').nth(1) == Some("0.0")), "{out}");
    let args =
        ["sweep", room.to_str().unwrap(), "--material", "glass", "--vary", "transmittance=0.7..0.8:0.1", "--sensor", "back", "--weather"];
    let Run { code, err, .. } = heliodon(&[&args[..], &[epw.to_str().unwrap()]].concat(), &scratch());
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("1 lit hours gave no Perez sky"), "{err}");
}

/// `annual` on the test room: every hour of `--hourly` is `sensors --sky
/// perez` at the hour's middle, and DA300 and UDI are the shares of the
/// occupied hours that file shows.
#[test]
fn annual_hours_are_perez_skies_and_the_metrics_count_them() {
    let (dir, epw) = folder_with_a_year("annual");
    let hourly = dir.join("hourly.csv");
    let room = bundled_scene("test_room");
    let args =
        ["annual", room.to_str().unwrap(), "--weather", epw.to_str().unwrap(), "--format", "csv", "--hourly", hourly.to_str().unwrap()];
    let Run { code, out, err } = heliodon(&args, &scratch());
    assert_eq!(code, 0, "{err}");
    assert!(!err.contains("far from"), "{err}");
    let hours: Vec<Vec<String>> =
        std::fs::read_to_string(&hourly).unwrap().lines().map(|l| l.split(',').map(String::from).collect()).collect();
    assert_eq!(hours.len(), 8761);
    let names = &hours[0][3..];
    let rows: Vec<&str> = out.lines().collect();
    assert_eq!(rows[0], "name,da300,udi_low,udi,udi_high,ase_hours");
    assert_eq!(rows.len(), names.len() + 1);
    let lux = |row: &Vec<String>, s: usize| row[3 + s].parse::<f64>().unwrap();
    let occupied: Vec<&Vec<String>> = hours[1..].iter().filter(|r| (9..=18).contains(&r[2].parse::<u32>().unwrap())).collect();
    assert_eq!(occupied.len(), 3650);
    for (s, row) in rows[1..].iter().enumerate() {
        let fields: Vec<&str> = row.split(',').collect();
        assert_eq!(fields[0], names[s]);
        let share = |keep: &dyn Fn(f64) -> bool| 100.0 * occupied.iter().filter(|r| keep(lux(r, s))).count() as f64 / 3650.0;
        let da300 = share(&|v| v >= 300.0);
        assert!((fields[1].parse::<f64>().unwrap() - da300).abs() < 0.06, "{row}: DA300 {da300:.2} from the hours");
        assert!((fields[3].parse::<f64>().unwrap() - share(&|v| (100.0..=3000.0).contains(&v))).abs() < 0.06, "{row}");
        // Only the four lit days can give light: at most 40 of 3,650 hours.
        assert!(da300 > 0.0 && da300 <= 100.0 * 40.0 / 3650.0 + 1e-9, "{row}");
    }
    // Dark days read 0; a lit hour is the Perez sky at its middle (21 June, hour 13 → 12:30).
    assert!(hours[1..].iter().filter(|r| r[1] != "21").all(|r| (0..names.len()).all(|s| lux(r, s) == 0.0)));
    let june = hours.iter().find(|r| r[0] == "6" && r[1] == "21" && r[2] == "13").unwrap();
    let args =
        ["sensors", room.to_str().unwrap(), "--date", "2025-06-21", "--time", "12:30", "--sky", "perez", "--dni", "480", "--dhi", "50"];
    let Run { code, out, err } = heliodon(&[&args[..], &["--format", "csv"]].concat(), &scratch());
    assert_eq!(code, 0, "{err}");
    for (s, line) in out.lines().skip(1).enumerate() {
        let expected: f64 = line.split(',').nth(1).unwrap().parse().unwrap();
        assert!(expected > 50.0, "{line}");
        assert!((lux(june, s) - expected).abs() <= 0.02 * expected, "{}: annual {} against sensors {expected}", names[s], lux(june, s));
    }
}

/// Bad input to `annual` is one line and a non-zero exit, before the year
/// is read: truncated or absent weather, a scene without sensors, an
/// occupied range that is backwards or holds no hour, an `--hourly` file
/// that cannot be made, shade groups that name the wrong materials. A
/// scene of area sensors alone is no error, but has no sDA or ASE to give.
#[test]
fn annual_refuses_bad_weather_and_scenes_without_sensors_in_one_line() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("annual_errors");
    std::fs::create_dir_all(&dir).unwrap();
    let room = bundled_scene("test_room");
    let truncated = dir.join("truncated.epw");
    std::fs::write(&truncated, boston_epw(5000)).unwrap();
    let Run { code, err, .. } = heliodon(&["annual", room.to_str().unwrap(), "--weather", truncated.to_str().unwrap()], &scratch());
    assert_eq!(code, 1);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("truncated.epw:5008: the file looks truncated: 5000 of 8760 hours"), "{err}");
    let absent = dir.join("absent.epw");
    let Run { code, err, .. } = heliodon(&["annual", room.to_str().unwrap(), "--weather", absent.to_str().unwrap()], &scratch());
    assert_eq!(code, 1);
    assert!(err.trim_end().lines().count() == 1 && err.contains("absent.epw"), "{err}");
    let empty = fixture("annual_no_sensors", &scene_toml(""), OBJ);
    std::fs::write(dir.join("full.epw"), boston_epw(8760)).unwrap();
    let full = dir.join("full.epw");
    let Run { code, err, .. } = heliodon(&["annual", empty.scene().to_str().unwrap(), "--weather", full.to_str().unwrap()], &scratch());
    assert_eq!(code, 1);
    assert!(err.contains("the scene has no sensors"), "{err}");
    // Area sensors only: sDA and ASE count point sensors, so the table says there are none rather than 0%.
    let area = "[[sensors]]\nname = \"patch\"\nposition = [0.5, 0.5, 0.5]\nnormal = [0.0, 0.0, 1.0]\nsize = 0.5\n";
    let area_only = fixture("annual_area_sensors", &scene_toml(area), OBJ);
    let Run { code, out, err } =
        heliodon(&["annual", area_only.scene().to_str().unwrap(), "--weather", full.to_str().unwrap()], &scratch());
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("sDA300/50%, ASE1000/250: none (they count point sensors") && !out.contains("% of"), "{out}");
    let Run { code, err, .. } =
        heliodon(&["annual", room.to_str().unwrap(), "--weather", full.to_str().unwrap(), "--occupied", "18:00-08:00"], &scratch());
    assert_eq!(code, 2);
    assert!(err.contains("--occupied") && err.contains("the end is not after the start"), "{err}");
    let Run { code, err, .. } =
        heliodon(&["annual", room.to_str().unwrap(), "--weather", full.to_str().unwrap(), "--occupied", "08:00-08:30"], &scratch());
    assert_eq!(code, 2);
    assert!(err.contains("--occupied") && err.contains("holds no hour"), "{err}");
    // The hourly file is opened before the year is read: a folder that is not there fails at once.
    let nowhere = dir.join("no-such-folder").join("hourly.csv");
    let Run { code, err, .. } = heliodon(
        &["annual", room.to_str().unwrap(), "--weather", full.to_str().unwrap(), "--hourly", nowhere.to_str().unwrap()],
        &scratch(),
    );
    assert_eq!(code, 1);
    assert!(err.lines().filter(|l| l.starts_with("error")).count() == 1 && err.contains("--hourly") && err.contains("hourly.csv"), "{err}");

    // Shade groups: checked where they are read.
    let blinds = "\n[materials.blinds]\nkind = \"glass\"\ntransmittance = 0.1\n";
    let cases = [
        ("[[shades]]\nwindows = \"wall\"\nshade = \"blinds\"\n", "shades[0].windows: 'wall' is not a window material (glass or panel)"),
        ("[[shades]]\nwindows = \"glass\"\nshade = \"curtain\"\n", "shades[0].shade: 'curtain' is not a material of [materials]"),
    ];
    for (shades, expected) in cases {
        let scene = test_room_with("annual_shades", &format!("{blinds}\n{shades}"));
        let Run { code, err, .. } = heliodon(&["annual", scene.to_str().unwrap(), "--weather", full.to_str().unwrap()], &scratch());
        assert_eq!(code, 1, "{err}");
        assert!(err.lines().filter(|l| l.starts_with("error")).count() == 1 && err.contains(expected), "{shades}: {err}");
        assert!(!err.contains("no face"), "the shade material is not unused: {err}");
    }
}

/// LM-83 operable shades: an occupied hour lowers the shade exactly when
/// more than 2% of the point sensors get 1000 lux or more of direct sun
/// through its windows (here every window); with it down the hour reads
/// less light, and ASE is counted with every shade up.
#[test]
fn annual_lowers_operable_shades_hour_by_hour() {
    let (dir, epw) = folder_with_a_year("annual_lm83");
    let shades = "\n[materials.blinds]\nkind = \"glass\"\ntransmittance = 0.1\n\n[[shades]]\nwindows = \"glass\"\nshade = \"blinds\"\n";
    let scene = test_room_with("annual_lm83", shades);
    let year = |extra: &[&str], hourly: &Path| {
        let args = [&["annual", scene.to_str().unwrap(), "--weather", epw.to_str().unwrap(), "--hourly", hourly.to_str().unwrap()], extra]
            .concat();
        let Run { code, out, err } = heliodon(&args, &scratch());
        assert_eq!(code, 0, "{err}");
        assert!(!err.contains("no face"), "the shade material is not unused: {err}");
        let hours: Vec<Vec<f64>> =
            std::fs::read_to_string(hourly).unwrap().lines().skip(1).map(|l| l.split(',').map(|v| v.parse().unwrap()).collect()).collect();
        (out, hours)
    };
    let (shaded_json, shaded) = year(&["--format", "json"], &dir.join("shaded.csv"));
    let (open_json, open) = year(&["--format", "json", "--no-shades"], &dir.join("open.csv"));
    let field = |json: &str, key: &str| -> f64 {
        let at = json.find(&format!("\"{key}\": ")).unwrap() + key.len() + 4;
        json[at..].split([',', '}']).next().unwrap().parse().unwrap()
    };
    assert_eq!(field(&open_json, "shaded_hours"), 0.0);
    // The hours the shade was down: occupied, and darker than with it up.
    let lowered: Vec<usize> = (0..8760).filter(|&k| shaded[k] != open[k]).collect();
    assert_eq!(lowered.len() as f64, field(&shaded_json, "shaded_hours"), "{shaded_json}");
    // (The synthetic year has sun on the 21st of March, June, September and
    // December; the low suns of spring, autumn and winter reach the desks.)
    assert!(!lowered.is_empty());
    for &k in &lowered {
        assert!((9.0..=18.0).contains(&shaded[k][2]), "hour {:?}", &shaded[k][..3]);
        assert!(
            shaded[k][3..].iter().zip(&open[k][3..]).all(|(s, o)| s <= o)
                && shaded[k][3..].iter().sum::<f64>() < open[k][3..].iter().sum::<f64>()
        );
    }
    // The rule, hour by hour, from `sensors`' direct sun at the point sensors
    // (the area sensors floor-centre and back-wall do not count).
    for (date, hour) in [("2025-03-21", 9), ("2025-03-21", 13), ("2025-03-21", 17), ("2025-03-21", 18), ("2025-06-21", 13)] {
        let month: usize = date[5..7].parse().unwrap();
        let k = ([0, 31, 59, 90, 120, 151][month - 1] + 20) * 24 + hour - 1;
        let time = format!("{:02}:30", hour - 1);
        let (dni, dhi) = (60.0 * (hour as f64 - 5.0), 40.0 + 10.0 * (hour % 4) as f64);
        let args = ["sensors", scene.to_str().unwrap(), "--date", date, "--time", &time, "--sky", "perez", "--no-cache"];
        let Run { code, out, err } =
            heliodon(&[&args[..], &["--dni", &dni.to_string(), "--dhi", &dhi.to_string(), "--format", "csv"]].concat(), &scratch());
        assert_eq!(code, 0, "{err}");
        let points: Vec<f64> = out
            .lines()
            .skip(1)
            .filter(|l| !l.starts_with("floor-centre,") && !l.starts_with("back-wall,"))
            .map(|l| l.split(',').nth(2).unwrap().parse().unwrap())
            .collect();
        let sunny = points.iter().filter(|&&e| e >= 1000.0).count();
        assert_eq!(
            lowered.contains(&k),
            sunny as f64 > 0.02 * points.len() as f64,
            "{date} hour {hour}: {sunny} of {} sunny",
            points.len()
        );
    }
    // ASE with every shade up: the same hours either way.
    let ase = |json: &str| json.split("\"ase_hours\": ").skip(1).map(|v| v.split('}').next().unwrap().to_string()).collect::<Vec<_>>();
    assert_eq!(ase(&shaded_json), ase(&open_json));
}

// ---- panels ----------------------------------------------------------------------

/// A scene whose material `upper` is the given panel table body.
fn panel_scene(name: &str, upper: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("panels_{name}"));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("room.obj"), PANEL_OBJ).unwrap();
    std::fs::write(dir.join("room.mtl"), PANEL_MTL).unwrap();
    let text = format!(
        "name = \"Panel room\"\n[site]\nlatitude = 42.36\nlongitude = -71.06\ntimezone = -5.0\n[model]\nobj = \"room.obj\"\n\n[materials.upper]\nkind = \"panel\"\n{upper}"
    );
    std::fs::write(dir.join("scene.toml"), text).unwrap();
    dir.join("scene.toml")
}

#[test]
fn the_executable_knows_the_built_in_panels() {
    let path = panel_scene("prismatic", "panel = \"prismatic\"\nfacet_angles = [40.0, 5.0]\n");
    let Run { code, out, err } = heliodon(&["info", path.to_str().unwrap()], &scratch());
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("panel    1"), "{out}");

    let path = panel_scene("unknown", "panel = \"lenticular\"\n");
    let Run { code, err, .. } = heliodon(&["info", path.to_str().unwrap()], &scratch());
    assert_ne!(code, 0);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(err.contains("scene.toml:11: materials.upper.panel: no panel named 'lenticular' is registered (registered: bsdf, laser_cut, prismatic, venetian)"), "{err}");
}

#[test]
fn bad_panel_keys_give_one_line_naming_the_key() {
    let cases = [
        (
            "range",
            "panel = \"prismatic\"\nfacet_angles = [40.0, 95.0]\n",
            "scene.toml:12: materials.upper.facet_angles: 95 is outside 0..89",
        ),
        ("missing", "panel = \"prismatic\"\n", "scene.toml:9: materials.upper.facet_angles: is required"),
        (
            "unknown",
            "panel = \"prismatic\"\nfacet_angles = [40.0, 5.0]\nfacet_count = 3\n",
            "materials.upper.facet_count: is not a key of panel 'prismatic'",
        ),
        (
            "type",
            "panel = \"prismatic\"\nfacet_angles = [40.0, 5.0]\nrefractive_index = \"acrylic\"\n",
            "materials.upper.refractive_index: must be a number",
        ),
    ];
    for (name, body, expected) in cases {
        let path = panel_scene(name, body);
        let Run { code, err, .. } = heliodon(&["info", path.to_str().unwrap()], &scratch());
        assert_ne!(code, 0, "{name}");
        assert_eq!(err.trim().lines().count(), 1, "{name}: {err}");
        assert!(err.contains(expected), "{name}: {err}");
    }
}

// ---- sweeps -----------------------------------------------------------------------

/// The bundled prismatic room copied into `folder` with its panel's facet
/// angles set, the scene's path (what a designer would write by hand).
fn prismatic_room_with(folder: &str, angles: [f64; 2]) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(folder);
    std::fs::create_dir_all(&dir).unwrap();
    let room = bundled_scene("prismatic_room");
    for entry in std::fs::read_dir(room.parent().unwrap()).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "obj" || e == "mtl") {
            std::fs::copy(&path, dir.join(path.file_name().unwrap())).unwrap();
        }
    }
    let text = std::fs::read_to_string(&room).unwrap();
    assert!(text.contains("facet_angles = [40.0, 5.0]"));
    let text = text.replace("facet_angles = [40.0, 5.0]", &format!("facet_angles = [{:?}, {:?}]", angles[0], angles[1]));
    std::fs::write(dir.join("scene.toml"), text).unwrap();
    dir.join("scene.toml")
}

/// Rows of a sweep's CSV: (key values, sensor, value or error).
fn sweep_rows(csv: &str) -> Vec<(Vec<String>, String, String)> {
    csv.lines()
        .skip(1)
        .filter(|l| !l.starts_with('#'))
        .map(|l| {
            let f: Vec<&str> = l.splitn(4, ',').collect();
            (vec![f[0].to_string(), f[1].to_string()], f[2].to_string(), f[3].to_string())
        })
        .collect()
}

/// Every combination of a sweep reads what `sensors` reads on a scene file
/// with those keys (within 0.5%); a combination the panel refuses is
/// reported in its rows and the run succeeds; shards merged are the
/// unsharded output, byte for byte.
#[test]
fn sweeps_read_what_scene_files_with_those_keys_read() {
    let room = bundled_scene("prismatic_room");
    let at = ["--date", "2025-12-21", "--time", "11:00", "--sky", "clear"];
    let base = [
        "sweep",
        room.to_str().unwrap(),
        "--material",
        "upper",
        "--vary",
        "facet_angles[0]=0..40:20",
        "--vary",
        "facet_angles[1]=0..10:10",
        "--all-sensors",
        "--format",
        "csv",
    ];
    let Run { code, out, err } = heliodon(&[&base[..], &at[..]].concat(), &scratch());
    assert_eq!(code, 0, "{err}");
    assert!(out.starts_with("facet_angles[0],facet_angles[1],sensor,value\n"), "{out}");
    let rows = sweep_rows(&out);
    let sensors = rows.iter().take_while(|r| r.0 == rows[0].0).count();
    assert!(sensors > 5);
    assert_eq!(rows.len(), 6 * sensors);
    // Both facets flat: the panel refuses it, in its rows.
    assert!(rows[..sensors].iter().all(|r| r.0 == ["0", "0"] && r.2.starts_with("error: facet_angles: ")), "{:?}", &rows[0]);
    for (a, b) in [(20.0, 0.0), (40.0, 10.0), (0.0, 10.0)] {
        let scene = prismatic_room_with(&format!("sweep_{a}_{b}"), [a, b]);
        let Run { code, out: read, err } =
            heliodon(&[&["sensors", scene.to_str().unwrap(), "--format", "csv"][..], &at[..]].concat(), &scratch());
        assert_eq!(code, 0, "{err}");
        let key = [format!("{a}"), format!("{b}")];
        let swept: Vec<&(Vec<String>, String, String)> = rows.iter().filter(|r| r.0 == key).collect();
        assert_eq!(swept.len(), sensors);
        for (line, row) in read.lines().skip(1).zip(swept) {
            let (name, lux) = line.split_once(',').unwrap();
            let expected: f64 = lux.split(',').next().unwrap().parse().unwrap();
            let value: f64 = row.2.parse().unwrap();
            assert_eq!(name, row.1);
            assert!((value - expected).abs() <= 0.005 * expected + 0.05, "{key:?} {name}: sweep {value} vs sensors {expected}");
        }
    }
    // Three shards, merged: the same bytes.
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("sweep_shards");
    std::fs::create_dir_all(&dir).unwrap();
    let mut parts = Vec::new();
    for k in 1..=3 {
        let shard = format!("{k}/3");
        let Run { code, out, err } = heliodon(&[&base[..], &at[..], &["--shard", &shard]].concat(), &scratch());
        assert_eq!(code, 0, "{err}");
        let part = dir.join(format!("part{k}.csv"));
        std::fs::write(&part, out).unwrap();
        parts.push(part.to_str().unwrap().to_string());
    }
    let merge: Vec<&str> = ["sweep-merge"].into_iter().chain(parts.iter().rev().map(String::as_str)).collect();
    let Run { code, out: merged, err } = heliodon(&merge, &scratch());
    assert_eq!(code, 0, "{err}");
    assert_eq!(merged, out);
    // A part of another sweep, a missing part: one line each.
    let other = dir.join("other.csv");
    let Run { out: other_out, .. } =
        heliodon(&[&base[..], &["--date", "2025-06-21", "--time", "11:00", "--shard", "1/3"]].concat(), &scratch());
    std::fs::write(&other, other_out).unwrap();
    for (files, expected) in
        [(vec![other.to_str().unwrap(), &parts[1], &parts[2]], "of another sweep"), (vec![&parts[0], &parts[1]], "part 3/3 is missing")]
    {
        let Run { code, err, .. } = heliodon(&[&["sweep-merge"][..], &files[..]].concat(), &scratch());
        assert_eq!(code, 1);
        assert!(err.lines().count() == 1 && err.contains(expected), "{err}");
    }
}

/// Over a year a sweep's DA300 and sDA are what `annual` gives for a scene
/// file with those keys, within the contract's 0.5% (the sweep reads its
/// lobes' bounces from lobe coefficients, `annual` traces them hour by
/// hour), over a year with thousands of sunny hours; the picture is written.
#[test]
fn sweeps_against_a_year_read_what_annual_reads() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("sweep_year");
    std::fs::create_dir_all(&dir).unwrap();
    let epw = dir.join("clear_thirds.epw");
    std::fs::write(&epw, boston_clear_thirds_epw()).unwrap();
    let picture = dir.join("curve.png");
    let room = bundled_scene("prismatic_room");
    let args = ["sweep", room.to_str().unwrap(), "--material", "upper", "--vary", "facet_angles[0]=30..50:20", "--all-sensors"];
    let Run { code, out, err } = heliodon(
        &[&args[..], &["--weather", epw.to_str().unwrap(), "--format", "csv", "--out", picture.to_str().unwrap()]].concat(),
        &scratch(),
    );
    assert_eq!(code, 0, "{err}");
    assert!(out.starts_with("facet_angles[0],sensor,value\n"), "{out}");
    let image = image::open(&picture).unwrap().to_rgb8();
    assert!(image.pixels().any(|p| p.0 != [255, 255, 255]) && image.width() > 400);
    let scene = prismatic_room_with("sweep_year_50", [50.0, 5.0]);
    let Run { code, out: year, err } =
        heliodon(&["annual", scene.to_str().unwrap(), "--weather", epw.to_str().unwrap(), "--format", "json"], &scratch());
    assert_eq!(code, 0, "{err}");
    let swept: Vec<(&str, f64)> = out
        .lines()
        .filter_map(|l| l.strip_prefix("50,"))
        .map(|l| l.rsplit_once(',').map(|(s, v)| (s, v.parse().unwrap())).unwrap())
        .collect();
    let mut worst: f64 = 0.0;
    for (sensor, value) in &swept {
        let expected = if *sensor == "sDA300/50%" {
            year.split("\"sda300_50\": ").nth(1).unwrap().split(',').next().unwrap().parse::<f64>().unwrap()
        } else {
            let at = year.find(&format!("\"name\": \"{sensor}\", \"da300\": ")).unwrap_or_else(|| panic!("{sensor} in {year}"));
            year[at..].split("\"da300\": ").nth(1).unwrap().split(',').next().unwrap().parse().unwrap()
        };
        worst = worst.max((value - expected).abs());
        assert!((value - expected).abs() <= 0.005 * expected, "{sensor}: sweep {value} vs annual {expected}");
    }
    println!("largest difference {worst} percentage points");
    assert!(swept.iter().any(|s| s.0 == "sDA300/50%") && swept.len() > 5, "{out}");
}

/// A sweep over a year reads the windows as modelled: with `[[shades]]` in
/// the scene it says so in one warning line (as `annual --no-shades`) and
/// still answers.
#[test]
fn a_year_sweep_says_it_leaves_the_shades_up() {
    let (_, epw) = folder_with_a_year("sweep_shades");
    let scene = prismatic_room_with("sweep_shades", [40.0, 5.0]);
    let text = std::fs::read_to_string(&scene).unwrap() + "\n[[shades]]\nwindows = \"glass\"\nshade = \"upper\"\n";
    std::fs::write(&scene, text).unwrap();
    let Run { code, err, .. } = heliodon(
        &[
            "sweep",
            scene.to_str().unwrap(),
            "--material",
            "upper",
            "--vary",
            "facet_angles[0]=40..40:5",
            "--sensor",
            "back",
            "--weather",
            epw.to_str().unwrap(),
        ],
        &scratch(),
    );
    assert_eq!(code, 0, "{err}");
    let warnings: Vec<&str> = err.lines().filter(|l| l.contains("[[shades]]")).collect();
    assert!(warnings.len() == 1 && warnings[0].starts_with("warning: ") && warnings[0].contains("--no-shades"), "{err}");
}

#[test]
fn sweeps_refuse_bad_input_in_one_line() {
    let room = bundled_scene("prismatic_room");
    let room = room.to_str().unwrap();
    let at = ["--date", "2025-12-21", "--time", "11:00", "--all-sensors"];
    let cases: [(&[&str], i32, &str); 10] = [
        (&["--material", "curtain", "--vary", "facet_angles[0]=0..10:5"], 1, "--material curtain: no face of the model uses it"),
        (&["--material", "wall", "--vary", "facet_angles[0]=0..10:5"], 1, "a diffuse material"),
        (&["--material", "upper", "--vary", "tilt=0..10:5"], 1, "'tilt' is not a key of panel 'prismatic'"),
        (&["--material", "upper", "--vary", "facet_angles[2]=0..10:5"], 1, "a list of 2 numbers"),
        (&["--material", "upper", "--vary", "facet_angles[0]=a..10:5"], 2, "LO 'a' is not a number"),
        (&["--material", "upper", "--vary", "facet_angles[0]=10..0:5"], 2, "the range is empty"),
        (&["--material", "upper", "--vary", "facet_angles[0]=0..10:0"], 2, "the step must be positive"),
        (
            &[
                "--material",
                "upper",
                "--vary",
                "facet_angles[0]=0..10:5",
                "--vary",
                "facet_angles[1]=0..10:5",
                "--vary",
                "refractive_index=1.4..1.5:0.1",
            ],
            2,
            "3 keys given",
        ),
        (&["--material", "upper", "--vary", "facet_angles[0]=0..10:5", "--shard", "0/4"], 2, "K must be from 1 to 4"),
        (&["--material", "upper", "--vary", "facet_angles[0]=0..10:5", "--shard", "5/4"], 2, "K must be from 1 to 4"),
    ];
    for (flags, expected_code, expected) in cases {
        let Run { code, err, .. } = heliodon(&[&["sweep", room][..], flags, &at[..]].concat(), &scratch());
        assert_eq!(code, expected_code, "{flags:?}: {err}");
        assert!(err.trim_end().lines().count() == 1 && err.contains(expected), "{flags:?}: {err}");
    }
}
