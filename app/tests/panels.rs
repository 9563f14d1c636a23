//! Panels through the `heliodon` executable and the registry: the built-in
//! panels are known by name, a panel from a crate that only tests use is
//! found the same way, and bad panel input gives one line naming the key.

use std::path::{Path, PathBuf};
use std::process::Command;

use heliodon::bevy::prelude::App;
use heliodon::ecs::panel_catalog;
use heliodon::scene::{MaterialKind, load_scene};
use heliodon_panel_fixture::GreyFilterPlugin;

const OBJ: &str = "mtllib room.mtl\nusemtl floor\nv 0 0 0\nv 4 0 0\nv 4 6 0\nv 0 6 0\nf 1 2 3 4\nusemtl upper\nv 0 0 2\nv 4 0 2\nv 4 0 3\nv 0 0 3\nf 5 6 7 8\n";
const MTL: &str = "newmtl floor\nKd 0.3 0.3 0.3\nnewmtl upper\nKd 0.5 0.5 0.5\n";

/// A scene whose material `upper` is the given panel table body.
fn scene(name: &str, upper: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("panels_{name}"));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("room.obj"), OBJ).unwrap();
    std::fs::write(dir.join("room.mtl"), MTL).unwrap();
    let text = format!(
        "name = \"Panel room\"\n[site]\nlatitude = 42.36\nlongitude = -71.06\ntimezone = -5.0\n[model]\nobj = \"room.obj\"\n\n[materials.upper]\nkind = \"panel\"\n{upper}"
    );
    std::fs::write(dir.join("scene.toml"), text).unwrap();
    dir.join("scene.toml")
}

fn heliodon(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_heliodon")).args(args).output().expect("run heliodon");
    (out.status.code().unwrap_or(-1), String::from_utf8_lossy(&out.stdout).into(), String::from_utf8_lossy(&out.stderr).into())
}

#[test]
fn a_panel_from_a_test_only_crate_is_found_by_name() {
    let path = scene("fixture", "panel = \"grey_filter\"\ntransmittance = 0.4\n");
    let add: fn(&mut App) = |app| {
        app.add_plugins(GreyFilterPlugin);
    };
    let loaded = load_scene(&path, &panel_catalog(add)).expect("the fixture's panel is registered");
    let upper = loaded.scene.materials.iter().find(|m| m.name == "upper").unwrap();
    let MaterialKind::Panel { panel, model, .. } = &upper.kind else { panic!("{upper:?}") };
    assert_eq!(panel, "grey_filter");
    let response = model.0.response(heliodon::glam::DVec3::new(0.0, -0.6, 0.8));
    assert!((response.transmitted() - 0.4).abs() < 1e-12);
    assert_eq!(loaded.scene.windows.len(), 1);
    // Without the plugin the same file names the panels that are known.
    let error = load_scene(&path, &panel_catalog(|_| {})).unwrap_err().to_string();
    assert!(error.contains("no panel named 'grey_filter' is registered (registered: none)"), "{error}");
}

#[test]
fn the_executable_knows_the_built_in_panels() {
    let path = scene("prismatic", "panel = \"prismatic\"\nfacet_angles = [40.0, 5.0]\n");
    let (code, out, err) = heliodon(&["info", path.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("panel    1"), "{out}");

    let path = scene("unknown", "panel = \"lenticular\"\n");
    let (code, _, err) = heliodon(&["info", path.to_str().unwrap()]);
    assert_ne!(code, 0);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(err.contains("scene.toml:11: materials.upper.panel: no panel named 'lenticular' is registered (registered: prismatic"), "{err}");
}

#[test]
fn bad_panel_keys_give_one_line_naming_the_key() {
    let cases = [
        ("range", "panel = \"prismatic\"\nfacet_angles = [40.0, 95.0]\n", "scene.toml:12: materials.upper.facet_angles: 95 is outside 0..89"),
        ("missing", "panel = \"prismatic\"\n", "scene.toml:9: materials.upper.facet_angles: is required"),
        ("unknown", "panel = \"prismatic\"\nfacet_angles = [40.0, 5.0]\nfacet_count = 3\n", "materials.upper.facet_count: is not a key of panel 'prismatic'"),
        ("type", "panel = \"prismatic\"\nfacet_angles = [40.0, 5.0]\nrefractive_index = \"acrylic\"\n", "materials.upper.refractive_index: must be a number"),
    ];
    for (name, body, expected) in cases {
        let path = scene(name, body);
        let (code, _, err) = heliodon(&["info", path.to_str().unwrap()]);
        assert_ne!(code, 0, "{name}");
        assert_eq!(err.trim().lines().count(), 1, "{name}: {err}");
        assert!(err.contains(expected), "{name}: {err}");
    }
}
