//! A room on a ground (the case of real site models: Radiance's tutorial
//! room stands on 400 × 300 m), for the tests and the light benchmark.
//! Included by path next to `quad_obj.rs`, which it uses as `super::quad_obj`.

use std::path::{Path, PathBuf};

use super::quad_obj::QuadObj;

/// A 4 × 6 × 3 m room with a 2 × 1.4 m south window and a grid of desk
/// sensors, on a ground `width` × `depth` m centred on it (10 cm below its
/// floor), as real exports come: `adaptive = false` cuts every surface
/// into `patch_size` patches.
pub fn room_on_a_ground(dir: &Path, width: f64, depth: f64, adaptive: bool) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    let mut obj = QuadObj::new("room.mtl");
    let (w, d, h) = (4.0, 6.0, 3.0);
    obj.quad(
        "ground",
        [
            [2.0 - width / 2.0, 3.0 - depth / 2.0, -0.1],
            [2.0 + width / 2.0, 3.0 - depth / 2.0, -0.1],
            [2.0 + width / 2.0, 3.0 + depth / 2.0, -0.1],
            [2.0 - width / 2.0, 3.0 + depth / 2.0, -0.1],
        ],
    );
    room_open_to_south(&mut obj, w, d, h);
    obj.quad("wall", [[0.0, 0.0, 0.0], [w, 0.0, 0.0], [w, 0.0, 0.9], [0.0, 0.0, 0.9]]);
    obj.quad("wall", [[0.0, 0.0, 2.3], [w, 0.0, 2.3], [w, 0.0, h], [0.0, 0.0, h]]);
    obj.quad("wall", [[0.0, 0.0, 0.9], [1.0, 0.0, 0.9], [1.0, 0.0, 2.3], [0.0, 0.0, 2.3]]);
    obj.quad("wall", [[3.0, 0.0, 0.9], [w, 0.0, 0.9], [w, 0.0, 2.3], [3.0, 0.0, 2.3]]);
    obj.quad("glass", [[1.0, 0.0, 0.9], [3.0, 0.0, 0.9], [3.0, 0.0, 2.3], [1.0, 0.0, 2.3]]);
    std::fs::write(dir.join("room.obj"), obj.text()).unwrap();
    let mtl = "newmtl ground\nKd 0.2 0.2 0.2\nnewmtl floor\nKd 0.3 0.3 0.3\nnewmtl ceiling\nKd 0.8 0.8 0.8\nnewmtl wall\nKd 0.5 0.5 0.5\nnewmtl glass\nd 0.12\n";
    std::fs::write(dir.join("room.mtl"), mtl).unwrap();
    let lighting = if adaptive { "" } else { "[lighting]\nadaptive = false\n" };
    let scene = format!(
        "name = \"Room on a ground\"\n[site]\nlatitude = 40.78\nlongitude = -73.97\ntimezone = -5.0\n{lighting}[model]\nobj = \"room.obj\"\n\n[[sensor_grids]]\nname = \"desks\"\nmin = [0.5, 0.5]\nmax = [3.5, 5.5]\nheight = 0.8\nspacing = 1.0\n"
    );
    std::fs::write(dir.join("scene.toml"), scene).unwrap();
    dir.join("scene.toml")
}

/// A `w` × `d` × `h` m room from the origin, x east, y north, z up, into
/// `obj`: its floor, ceiling and north, west and east walls (materials
/// "floor", "ceiling", "wall"), facing in; the south side (y = 0) is left
/// for the caller's façade.
pub fn room_open_to_south(obj: &mut QuadObj, w: f64, d: f64, h: f64) {
    obj.quad("floor", [[0.0, 0.0, 0.0], [w, 0.0, 0.0], [w, d, 0.0], [0.0, d, 0.0]]);
    obj.quad("ceiling", [[0.0, 0.0, h], [0.0, d, h], [w, d, h], [w, 0.0, h]]);
    obj.quad("wall", [[0.0, d, 0.0], [w, d, 0.0], [w, d, h], [0.0, d, h]]);
    obj.quad("wall", [[0.0, 0.0, 0.0], [0.0, d, 0.0], [0.0, d, h], [0.0, 0.0, h]]);
    obj.quad("wall", [[w, d, 0.0], [w, 0.0, 0.0], [w, 0.0, h], [w, d, h]]);
}
