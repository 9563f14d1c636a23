//! A floor of offices, bare or furnished as real exports are (≈ 100,000
//! triangles of clutter): the large model of the light and render
//! benchmarks. Included by path next to `quad_obj.rs`, which it uses as
//! `super::quad_obj`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::quad_obj::QuadObj;

/// A floor of offices: 60 × 30 m, a corridor down the middle, 15 offices of
/// 4 × 12 m on each side with two windows each, a desk per office; patches
/// of 0.25 m. Written as OBJ + scene files into `dir`.
pub fn office_floor(dir: &Path, furnished: bool) -> PathBuf {
    let (w, d, h) = (60.0f64, 30.0f64, 3.0f64);
    let mut obj = QuadObj::new("model.mtl");
    obj.quad("floor", [[0.0, 0.0, 0.0], [w, 0.0, 0.0], [w, d, 0.0], [0.0, d, 0.0]]);
    obj.quad("ceiling", [[0.0, 0.0, h], [0.0, d, h], [w, d, h], [w, 0.0, h]]);
    obj.quad("wall", [[0.0, 0.0, 0.0], [0.0, d, 0.0], [0.0, d, h], [0.0, 0.0, h]]);
    obj.quad("wall", [[w, d, 0.0], [w, 0.0, 0.0], [w, 0.0, h], [w, d, h]]);
    for (y, inward) in [(0.0, 1.0), (d, -1.0)] {
        for k in 0..15 {
            let x0 = 4.0 * k as f64;
            // Façade: sill wall, two windows, head wall.
            let facade = |z0: f64, z1: f64, xa: f64, xb: f64| {
                if inward > 0.0 {
                    [[xb, y, z0], [xa, y, z0], [xa, y, z1], [xb, y, z1]]
                } else {
                    [[xa, y, z0], [xb, y, z0], [xb, y, z1], [xa, y, z1]]
                }
            };
            obj.quad("wall", facade(0.0, 0.9, x0, x0 + 4.0));
            obj.quad("wall", facade(2.4, h, x0, x0 + 4.0));
            for (xa, xb, material) in [
                (x0, x0 + 0.3, "wall"),
                (x0 + 0.3, x0 + 1.9, "glass"),
                (x0 + 1.9, x0 + 2.1, "wall"),
                (x0 + 2.1, x0 + 3.7, "glass"),
                (x0 + 3.7, x0 + 4.0, "wall"),
            ] {
                obj.quad(material, facade(0.9, 2.4, xa, xb));
            }
            // Partition to the next office and the corridor wall.
            let (ya, yb) = if inward > 0.0 { (0.0, 12.0) } else { (d - 12.0, d) };
            if k > 0 {
                obj.quad("partition", [[x0, ya, 0.0], [x0, yb, 0.0], [x0, yb, h], [x0, ya, h]]);
            }
            let yc = if inward > 0.0 { 12.0 } else { d - 12.0 };
            obj.quad("partition", [[x0, yc, 0.0], [x0 + 4.0, yc, 0.0], [x0 + 4.0, yc, h], [x0, yc, h]]);
            // A desk top.
            let yd = y + inward * 3.0;
            if furnished {
                furnish(&mut obj, x0, yd);
            }
            obj.quad(
                "desk",
                [[x0 + 1.0, yd - 0.4, 0.75], [x0 + 3.0, yd - 0.4, 0.75], [x0 + 3.0, yd + 0.4, 0.75], [x0 + 1.0, yd + 0.4, 0.75]],
            );
        }
    }
    std::fs::create_dir_all(dir).unwrap();
    std::fs::write(dir.join("model.obj"), obj.text()).unwrap();
    std::fs::write(
        dir.join("model.mtl"),
        "newmtl floor\nKd 0.2 0.2 0.2\nnewmtl ceiling\nKd 0.8 0.8 0.8\nnewmtl wall\nKd 0.5 0.5 0.5\nnewmtl partition\nKd 0.6 0.6 0.6\nnewmtl desk\nKd 0.4 0.35 0.3\nnewmtl chair\nKd 0.3 0.3 0.35\nnewmtl books\nKd 0.5 0.3 0.2\nnewmtl glass\nd 0.12\n",
    )
    .unwrap();
    let mut scene = String::from(
        "name = \"Office floor\"\n[site]\nlatitude = 42.36\nlongitude = -71.06\ntimezone = -5.0\n[model]\nobj = \"model.obj\"\n",
    );
    // The furnished floor keeps the default patch size; the bare one 0.25 m.
    if !furnished {
        scene.push_str("[lighting]\npatch_size = 0.25\n");
    }
    let _ = writeln!(scene, "[[sensor_grids]]\nname = \"workplane\"\nmin = [0.0, 0.0]\nmax = [60.0, 30.0]\nheight = 0.8\nspacing = 2.0");
    std::fs::write(dir.join("scene.toml"), scene).unwrap();
    dir.join("scene.toml")
}

/// An office's clutter as real exports have it: two chairs on five round
/// legs (16-sided, 8 rings), a shelf of 60 books (boxes) and a monitor with a
/// faceted stand, about 3,400 triangles.
fn furnish(obj: &mut QuadObj, x0: f64, yd: f64) {
    let cylinder = |obj: &mut QuadObj, centre: [f64; 2], radius: f64, z0: f64, z1: f64| {
        let (sides, rings) = (16, 8);
        for k in 0..sides {
            let (a0, a1) = (std::f64::consts::TAU * k as f64 / sides as f64, std::f64::consts::TAU * (k + 1) as f64 / sides as f64);
            let (p0, p1) = (
                [centre[0] + radius * a0.cos(), centre[1] + radius * a0.sin()],
                [centre[0] + radius * a1.cos(), centre[1] + radius * a1.sin()],
            );
            for ring in 0..rings {
                let (za, zb) = (z0 + (z1 - z0) * ring as f64 / rings as f64, z0 + (z1 - z0) * (ring + 1) as f64 / rings as f64);
                obj.quad("chair", [[p0[0], p0[1], za], [p1[0], p1[1], za], [p1[0], p1[1], zb], [p0[0], p0[1], zb]]);
            }
        }
    };
    let cuboid = |obj: &mut QuadObj, material: &str, lo: [f64; 3], hi: [f64; 3]| {
        let [x0, y0, z0] = lo;
        let [x1, y1, z1] = hi;
        obj.quad(material, [[x0, y0, z1], [x1, y0, z1], [x1, y1, z1], [x0, y1, z1]]);
        obj.quad(material, [[x0, y0, z0], [x1, y0, z0], [x1, y0, z1], [x0, y0, z1]]);
        obj.quad(material, [[x1, y1, z0], [x0, y1, z0], [x0, y1, z1], [x1, y1, z1]]);
        obj.quad(material, [[x0, y1, z0], [x0, y0, z0], [x0, y0, z1], [x0, y1, z1]]);
        obj.quad(material, [[x1, y0, z0], [x1, y1, z0], [x1, y1, z1], [x1, y0, z1]]);
    };
    for chair in 0..2 {
        let cx = x0 + 1.5 + chair as f64;
        let cy = yd + 0.8 * if yd < 15.0 { 1.0 } else { -1.0 };
        for leg in 0..5 {
            let a = std::f64::consts::TAU * leg as f64 / 5.0;
            cylinder(obj, [cx + 0.25 * a.cos(), cy + 0.25 * a.sin()], 0.015, 0.0, 0.45);
        }
        cuboid(obj, "chair", [cx - 0.22, cy - 0.22, 0.45], [cx + 0.22, cy + 0.22, 0.5]);
        cuboid(obj, "chair", [cx - 0.22, cy + 0.18, 0.5], [cx + 0.22, cy + 0.22, 0.95]);
    }
    for book in 0..60 {
        let (shelf, slot) = (book / 20, book % 20);
        let x = x0 + 0.3 + 0.04 * slot as f64;
        cuboid(obj, "books", [x, yd + 1.5, 0.3 + 0.4 * shelf as f64], [x + 0.03, yd + 1.75, 0.55 + 0.4 * shelf as f64]);
    }
    for facet in 0..24 {
        let a = std::f64::consts::TAU * facet as f64 / 24.0;
        cylinder(obj, [x0 + 2.0 + 0.1 * a.cos(), yd + 0.1 * a.sin()], 0.01, 0.75, 0.8);
    }
}
