//! The viewer in a window, under Xvfb with Mesa's software Vulkan driver:
//! `heliodon view SCENE --screenshot FILE` waits for the light, saves the
//! window with its panels and exits.

use std::path::Path;
use std::process::Command;

#[test]
fn view_screenshot_shows_the_panels_and_the_lit_model() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("viewer_screenshot");
    std::fs::create_dir_all(&dir).unwrap();
    let shot = dir.join("test_room.png");
    let _ = std::fs::remove_file(&shot);
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/scenes/test_room/scene.toml");
    let out = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 1280x800x24", env!("CARGO_BIN_EXE_heliodon"), "view"])
        .arg(&scene)
        .args(["--date", "2026-03-21", "--time", "10:00", "--screenshot"])
        .arg(&shot)
        .env("HELIODON_CACHE_DIR", dir.join("cache"))
        .output()
        .expect("xvfb-run (tools/system-deps installs it)");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    println!("wrote {}", shot.display());
    let image = image::open(&shot).expect("the screenshot").to_rgb8();
    assert_eq!(image.dimensions(), (1280, 800));
    let luminance = |x: u32, y: u32| {
        let p = image.get_pixel(x, y);
        (u32::from(p[0]) + u32::from(p[1]) + u32::from(p[2])) / 3
    };
    // The panels: egui's dark grey on both sides, with text on it.
    let dark = |x0: u32, x1: u32| (x0..x1).flat_map(|x| (0..800).step_by(4).map(move |y| (x, y))).filter(|&(x, y)| luminance(x, y) < 40).count();
    assert!(dark(0, 200) > 200 * 200 * 6 / 10 / 4, "left panel");
    assert!(dark(1080, 1280) > 200 * 200 * 6 / 10 / 4, "right panel");
    // The model between them: lit walls and sun patches, not a flat colour.
    let middle: Vec<u32> = (400..880).step_by(4).flat_map(|x| (100..700).step_by(4).map(move |y| (x, y))).map(|(x, y)| luminance(x, y)).collect();
    let bright = middle.iter().filter(|&&l| l > 200).count();
    let mid = middle.iter().filter(|&&l| (50..200).contains(&l)).count();
    assert!(bright > middle.len() / 50, "sun patches: {bright} of {}", middle.len());
    assert!(mid > middle.len() / 3, "lit surfaces: {mid} of {}", middle.len());
}
