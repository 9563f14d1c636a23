//! The viewer in a window, under Xvfb with Mesa's software Vulkan driver:
//! `heliodon view SCENE --sensor NAME --screenshot FILE --hdr FILE` waits
//! for the light and the sensor's day, saves the window with its panels and
//! the 3D view's luminance, and exits.

#[path = "../../tests/support/epw.rs"]
mod epw;

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// `heliodon view SCENE ARGS…` in a 1280 × 800 Xvfb screen, its light
/// cache in `dir`; it must succeed.
fn view<'a>(scene: &Path, args: impl IntoIterator<Item = &'a OsStr>, dir: &Path) -> Output {
    let out = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 1280x800x24", env!("CARGO_BIN_EXE_heliodon"), "view"])
        .arg(scene)
        .args(args)
        .env("HELIODON_CACHE_DIR", dir.join("cache"))
        .output()
        .expect("xvfb-run (tools/system-deps installs it)");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    out
}

#[test]
fn view_screenshot_shows_the_panels_and_the_lit_model() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("viewer_screenshot");
    std::fs::create_dir_all(&dir).unwrap();
    let shot = dir.join("test_room.png");
    let hdr = dir.join("test_room.hdr");
    let _ = std::fs::remove_file(&shot);
    let _ = std::fs::remove_file(&hdr);
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/scenes/test_room/scene.toml");
    let args = ["--date", "2026-03-21", "--time", "10:00", "--sensor", "near-window", "--screenshot"];
    view(&scene, args.iter().map(OsStr::new).chain([shot.as_os_str(), OsStr::new("--hdr"), hdr.as_os_str()]), &dir);
    println!("wrote {}", shot.display());
    let image = image::open(&shot).expect("the screenshot").to_rgb8();
    assert_eq!(image.dimensions(), (1280, 800));
    let luminance = |x: u32, y: u32| {
        let p = image.get_pixel(x, y);
        (u32::from(p[0]) + u32::from(p[1]) + u32::from(p[2])) / 3
    };
    // The panels: egui's dark grey on both sides, with text on it.
    let dark =
        |x0: u32, x1: u32| (x0..x1).flat_map(|x| (0..800).step_by(4).map(move |y| (x, y))).filter(|&(x, y)| luminance(x, y) < 40).count();
    assert!(dark(0, 200) > 200 * 200 * 6 / 10 / 4, "left panel");
    assert!(dark(1080, 1280) > 200 * 200 * 6 / 10 / 4, "right panel");
    // The model between them: lit walls and sun patches, not a flat colour.
    let middle: Vec<u32> =
        (400..880).step_by(4).flat_map(|x| (100..700).step_by(4).map(move |y| (x, y))).map(|(x, y)| luminance(x, y)).collect();
    let bright = middle.iter().filter(|&&l| l > 200).count();
    let mid = middle.iter().filter(|&&l| (50..200).contains(&l)).count();
    assert!(bright > middle.len() / 50, "sun patches: {bright} of {}", middle.len());
    assert!(mid > middle.len() / 3, "lit surfaces: {mid} of {}", middle.len());

    // The luminance saved from the viewer is the view the window shows: the
    // headless renderer draws the same view at the same size to the same
    // values.
    let (width, height, viewed) = read_hdr(&hdr);
    assert!(
        width > 400 && width < 1280 && (760..800).contains(&height),
        "{width} × {height}: the 3D view between the panels, under the menu bar"
    );
    let rendered = dir.join("test_room_render.hdr");
    let out = Command::new(env!("CARGO_BIN_EXE_heliodon"))
        .arg("render")
        .arg(&scene)
        .args(["--date", "2026-03-21", "--time", "10:00", "--width", &width.to_string(), "--height", &height.to_string(), "--out"])
        .arg(dir.join("test_room_render.png"))
        .arg("--hdr")
        .arg(&rendered)
        .env("HELIODON_CACHE_DIR", dir.join("cache"))
        // Without a runtime folder Mesa would print error lines on success.
        .env_remove("XDG_RUNTIME_DIR")
        .output()
        .unwrap();
    let errors = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{errors}");
    assert!(!errors.lines().any(|l| l.contains("error")), "a successful render prints no error line: {errors}");
    let (w, h, reference) = read_hdr(&rendered);
    assert_eq!((w, h), (width, height));
    let sum = |p: &[f32; 3]| p[0] + p[1] + p[2];
    let lit: Vec<f32> = viewed.iter().zip(&reference).filter(|(_, r)| sum(r) > 1e-3).map(|(v, r)| (sum(v) / sum(r) - 1.0).abs()).collect();
    let close = lit.iter().filter(|e| **e < 0.02).count() as f64 / lit.len() as f64;
    let peak = reference.iter().map(sum).fold(0.0, f32::max);
    println!("viewer HDR vs render HDR: {} lit pixels, {:.2}% within 2%, peak {peak} W/sr/m²", lit.len(), 100.0 * close);
    assert!(lit.len() > viewed.len() * 9 / 10, "a lit view");
    assert!(close > 0.98, "{:.4} of the pixels within 2%", close);
}

/// A Radiance picture, read with `image`'s HDR decoder.
fn read_hdr(path: &Path) -> (usize, usize, Vec<[f32; 3]>) {
    let reader = std::io::BufReader::new(std::fs::File::open(path).unwrap());
    let image = image::ImageReader::with_format(reader, image::ImageFormat::Hdr).decode().unwrap().into_rgb32f();
    let (width, height) = (image.width() as usize, image.height() as usize);
    let pixels: Vec<[f32; 3]> = image.pixels().map(|p| p.0).collect();
    assert_eq!(pixels.len(), width * height, "{}", path.display());
    (width, height, pixels)
}

/// A test's folder (`name`) with the synthetic Boston year in it
/// ([`epw::boston_epw`]), and the bundled test room: (folder, EPW, scene).
fn test_room_and_a_year(name: &str) -> (PathBuf, PathBuf, PathBuf) {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    std::fs::create_dir_all(&dir).unwrap();
    let epw = dir.join("boston.epw");
    std::fs::write(&epw, epw::boston_epw(8760)).unwrap();
    (dir, epw, Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/scenes/test_room/scene.toml"))
}

/// `view --weather FILE --annual --screenshot`: the sky of the shown hour
/// comes from the weather file, the year runs in the background and is
/// waited for, and its sDA and ASE are those of `heliodon annual`.
#[test]
fn the_viewer_runs_the_year_of_a_weather_file() {
    let (dir, epw, scene) = test_room_and_a_year("viewer_annual");
    let shot = dir.join("annual.png");
    let _ = std::fs::remove_file(&shot);
    let args = ["--date", "2026-03-21", "--time", "10:30", "--weather"].map(OsStr::new);
    let out =
        view(&scene, args.into_iter().chain([epw.as_os_str(), OsStr::new("--annual"), OsStr::new("--screenshot"), shot.as_os_str()]), &dir);
    let said = String::from_utf8_lossy(&out.stdout);
    let annual = Command::new(env!("CARGO_BIN_EXE_heliodon"))
        .arg("annual")
        .arg(&scene)
        .arg("--weather")
        .arg(&epw)
        .args(["--format", "json"])
        .env("HELIODON_CACHE_DIR", dir.join("cache"))
        .output()
        .unwrap();
    let json = String::from_utf8_lossy(&annual.stdout);
    let field = |key: &str| json.split(&format!("\"{key}\": ")).nth(1).unwrap().split(',').next().unwrap().to_string();
    let expected =
        format!("sDA300/50% {}%, ASE1000/250 {}%, {} occupied hours", field("sda300_50"), field("ase1000_250"), field("occupied_hours"));
    assert!(said.contains(&expected), "viewer said '{said}', annual '{expected}'");
    // 21 March 10:30 is a lit hour of the weather file: the model is lit.
    let image = image::open(&shot).expect("the screenshot").to_rgb8();
    let lit = (400..880)
        .step_by(8)
        .flat_map(|x| (100..700).step_by(8).map(move |y| (x, y)))
        .filter(|&(x, y)| image.get_pixel(x, y).0.iter().map(|&c| u32::from(c)).sum::<u32>() > 150)
        .count();
    assert!(lit > 1000, "{lit} lit pixels of the view");
}

/// An hour of the weather file that is lit but whose shown time is after
/// sunset (21 March 19:30 in Boston, the hour ending at 20:00 still has
/// light): the viewer shows the dark sky `annual` reads there, and says
/// so. It used to refuse that Perez sky with no sky before it, and a
/// screenshot then waited for light forever.
#[test]
fn the_viewer_is_dark_after_sunset_in_a_lit_hour_of_the_weather() {
    let (dir, epw, scene) = test_room_and_a_year("viewer_dusk");
    let hdr = dir.join("dusk.hdr");
    let _ = std::fs::remove_file(&hdr);
    let args = ["--date", "2026-03-21", "--time", "19:30", "--weather"].map(OsStr::new);
    view(&scene, args.into_iter().chain([epw.as_os_str(), OsStr::new("--hdr"), hdr.as_os_str()]), &dir);
    // The room's surfaces: no light at all (the glass keeps its display tint).
    let (_, _, pixels) = read_hdr(&hdr);
    let dark = pixels.iter().filter(|p| p.iter().all(|&c| c == 0.0)).count();
    assert!(dark * 10 > pixels.len() * 7, "{dark} of {} pixels dark after sunset", pixels.len());
}

/// Starts `$0 view $1` and samples its CPU time (user + system, ticks of
/// 1/100 s) every 2 s for up to 3 minutes; succeeds after three samples in
/// a row under 5 ticks (2.5% of a core), fails if it never rests.
const IDLE_SAMPLER: &str = r#"
"$0" view "$1" & viewer=$!
ticks() { awk '{ print $14 + $15 }' /proc/$viewer/stat; }
before=$(ticks); quiet=0
for _ in $(seq 90); do
    sleep 2
    now=$(ticks) || exit 1
    echo "$((now - before))"
    if [ $((now - before)) -lt 5 ]; then quiet=$((quiet + 1)); else quiet=0; fi
    before=$now
    if [ $quiet -ge 3 ]; then kill $viewer; exit 0; fi
done
kill $viewer; exit 1
"#;

/// An interactive viewer left alone, once its light has settled, draws
/// nothing: its CPU time stops growing (on lavapipe it kept 1.7 cores busy
/// before it drew only on change).
#[test]
fn an_idle_viewer_rests() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("viewer_idle");
    std::fs::create_dir_all(&dir).unwrap();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/scenes/test_room/scene.toml");
    let out = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 1280x800x24", "sh", "-c", IDLE_SAMPLER, env!("CARGO_BIN_EXE_heliodon")])
        .arg(&scene)
        .env("HELIODON_CACHE_DIR", dir.join("cache"))
        .output()
        .expect("xvfb-run (tools/system-deps installs it)");
    let samples = String::from_utf8_lossy(&out.stdout).split_whitespace().collect::<Vec<_>>().join(" ");
    println!("viewer CPU ticks per 2 s: {samples}");
    assert!(out.status.success(), "the viewer never rested; CPU ticks per 2 s: {samples}\n{}", String::from_utf8_lossy(&out.stderr));
}

/// `view --plan` opens on the plan: looking down on a section under the
/// office's ceiling, in false colour. The rooms' floor (hundreds to a few
/// thousand lux: orange and yellow on the scale) fills the view where the
/// roof in the sun (over the scale's top: white) would otherwise be.
#[test]
fn the_viewer_opens_on_the_plan() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("viewer_plan");
    std::fs::create_dir_all(&dir).unwrap();
    let shot = dir.join("office_plan.png");
    let _ = std::fs::remove_file(&shot);
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/scenes/office/scene.toml");
    let args = ["--date", "2026-03-21", "--time", "14:00", "--plan", "--screenshot"].map(OsStr::new);
    view(&scene, args.into_iter().chain([shot.as_os_str()]), &dir);
    println!("wrote {}", shot.display());
    let image = image::open(&shot).expect("the screenshot").to_rgb8();
    // The 3D view between the panels, around the model's middle.
    let pixels: Vec<[u8; 3]> =
        (480..800).step_by(4).flat_map(|x| (250..550).step_by(4).map(move |y| (x, y))).map(|(x, y)| image.get_pixel(x, y).0).collect();
    let warm = pixels.iter().filter(|p| p[0] > 180 && p[2] < 120 && p[0] > p[2] + 100).count();
    let white = pixels.iter().filter(|p| p.iter().all(|&c| c > 235)).count();
    println!("plan: {warm} orange-yellow and {white} white pixels of {}", pixels.len());
    assert!(warm > pixels.len() / 2, "the floor's light in false colour: {warm} of {}", pixels.len());
    assert!(white < pixels.len() / 4, "not the roof over the scale's top: {white} of {}", pixels.len());
}
