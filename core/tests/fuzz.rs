//! Fuzzing the readers with a fixed seed and a bounded number of cases (the
//! same inputs every run, at any thread count): scene files, OBJ, MTL and
//! EPW weather files mutated from valid ones, byte by byte and with the tokens that broke
//! readers before (huge and non-finite numbers, byte-order marks, missing
//! numbers, stray brackets). Every input must give a scene or one error
//! line, never a panic. Inputs that once crashed are kept below as
//! regression cases.

use std::collections::HashMap;
use std::io;
use std::path::{Path, PathBuf};

use heliodon_core::panel::PanelCatalog;
use heliodon_core::scene::{SceneReader, load_scene_with};
use heliodon_core::weather::{HOURS, Weather, calendar};

/// Files served from memory.
struct Files(HashMap<PathBuf, Vec<u8>>);

impl SceneReader for Files {
    async fn read(&mut self, path: &Path) -> io::Result<Vec<u8>> {
        self.0.get(path).cloned().ok_or_else(|| io::Error::new(io::ErrorKind::NotFound, "not found"))
    }
}

/// SplitMix64: the fuzzer's own seeded generator.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// What broke readers before, and what breaks them in general.
const TOKENS: [&str; 24] = [
    "nan",
    "inf",
    "-inf",
    "1e39",
    "-1e300",
    "0",
    "-0",
    "1e-45",
    "\u{feff}",
    "\n",
    "\r\n",
    " ",
    "#",
    "[",
    "]",
    "\"",
    "=",
    ",",
    "f 1 2",
    "f 1 2 3 4 5",
    "usemtl",
    "Ks 0",
    "d 2",
    "v 1 2",
];

/// `text` with a few random edits: a byte dropped or repeated, a token put
/// in, a line dropped or repeated.
fn mutate(text: &str, rng: &mut Rng) -> String {
    let mut out = text.to_string();
    for _ in 0..1 + rng.below(4) {
        let boundaries: Vec<usize> = (0..=out.len()).filter(|&i| out.is_char_boundary(i)).collect();
        let at = boundaries[rng.below(boundaries.len())];
        match rng.below(5) {
            0 => {
                let end = boundaries.iter().copied().find(|&b| b > at).unwrap_or(at);
                out.replace_range(at..end, "");
            }
            1 | 2 => out.insert_str(at, TOKENS[rng.below(TOKENS.len())]),
            3 => {
                let lines: Vec<&str> = out.lines().collect();
                let k = rng.below(lines.len());
                out = lines.iter().enumerate().filter(|&(i, _)| i != k).map(|(_, l)| *l).collect::<Vec<_>>().join("\n");
            }
            _ => {
                let lines: Vec<&str> = out.lines().collect();
                let k = rng.below(lines.len());
                let mut copy = lines.clone();
                copy.insert(k, lines[k]);
                out = copy.join("\n");
            }
        }
    }
    out
}

const SCENE: &str = "name = \"fuzz\"\n[site]\nlatitude = 42.36\nlongitude = -71.06\ntimezone = -5.0\n[model]\nobj = \"room.obj\"\n\n[materials.wall]\nkind = \"diffuse\"\nreflectance = 0.5\n\n[[sensors]]\nname = \"s\"\nposition = [0.5, 0.5, 0.8]\nnormal = [0.0, 0.0, 1.0]\nsize = 0.2\n\n[[sensor_grids]]\nname = \"g\"\nmin = [0.0, 0.0]\nmax = [1.0, 1.0]\nheight = 0.8\nspacing = 0.5\n\n[lighting]\npatch_size = 0.5\n";
const OBJ: &str =
    "mtllib room.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nusemtl wall\nf 1 2 3 4\nf 1 2 6 5\nusemtl glass\nf 4 3 6 5\n";
const MTL: &str = "newmtl wall\nKd 0.5 0.5 0.5\nKs 0 0 0\nNs 10\n\nnewmtl glass\nKd 0 0 0\nd 0.12\n";

/// Loads the three texts; an error must be one line.
fn load(scene: &str, obj: &str, mtl: &str) -> Result<(), String> {
    let dir = Path::new("/fuzz");
    let files = [("scene.toml", scene), ("room.obj", obj), ("room.mtl", mtl)];
    let mut reader = Files(files.iter().map(|(name, text)| (dir.join(name), text.as_bytes().to_vec())).collect());
    match futures_lite::future::block_on(load_scene_with(&dir.join("scene.toml"), &PanelCatalog::new(), &mut reader)) {
        Ok(_) => Ok(()),
        Err(e) if !e.to_string().contains('\n') && !e.message.is_empty() => Ok(()),
        Err(e) => Err(format!("an error of more than one line: {e:?}")),
    }
}

fn survives(scene: &str, obj: &str, mtl: &str) -> Result<(), String> {
    std::panic::catch_unwind(|| load(scene, obj, mtl)).unwrap_or_else(|_| Err("panicked".into()))
}

#[test]
fn mutated_scene_obj_and_mtl_files_never_crash_the_loader() {
    let mut rng = Rng(2026);
    let mut failures = Vec::new();
    for case in 0..3000 {
        let (scene, obj, mtl) = match case % 3 {
            0 => (mutate(SCENE, &mut rng), OBJ.to_string(), MTL.to_string()),
            1 => (SCENE.to_string(), mutate(OBJ, &mut rng), MTL.to_string()),
            _ => (SCENE.to_string(), OBJ.to_string(), mutate(MTL, &mut rng)),
        };
        if let Err(why) = survives(&scene, &obj, &mtl) {
            failures.push(format!("case {case}: {why}\n--- scene\n{scene}\n--- obj\n{obj}\n--- mtl\n{mtl}"));
        }
    }
    assert!(failures.is_empty(), "{} of 3000 inputs failed; the first:\n{}", failures.len(), failures[0]);
}

/// Inputs that crashed heliodon once (the probes and what this
/// fuzzer found), kept as they were.
#[test]
fn inputs_that_once_crashed_stay_fixed() {
    let cases = [
        // tobj 4 panicked on a colour with fewer than three numbers.
        (SCENE.to_string(), OBJ.to_string(), MTL.replace("Ks 0 0 0", "Ks 0")),
        // An hour count past u32 seconds wrapped; a huge vertex overflowed f32.
        (SCENE.to_string(), OBJ.replace("v 1 1 0", "v 1e39 1 0"), MTL.to_string()),
        // A byte-order mark before the MTL and the OBJ.
        (SCENE.to_string(), format!("\u{feff}{OBJ}"), format!("\u{feff}{MTL}")),
        // `newmtl` with multi-byte names and a face with a repeated corner.
        (SCENE.to_string(), OBJ.replace("f 1 2 3 4", "f 1 2 2 3"), MTL.replace("newmtl glass", "newmtl glass\nnewmtl  é")),
    ];
    for (scene, obj, mtl) in cases {
        assert_eq!(survives(&scene, &obj, &mtl), Ok(()), "{mtl}");
    }
}

/// A valid EPW year, written here (no file needed).
fn epw() -> String {
    let mut text = String::from(
        "LOCATION,Fuzz,ST,USA,TMY3,1,42.36,-71.06,-5.0,10.0\nDESIGN CONDITIONS,0\nTYPICAL/EXTREME PERIODS,0\nGROUND TEMPERATURES,0\nHOLIDAYS/DAYLIGHT SAVINGS,No,0,0,0\nCOMMENTS 1,x\nCOMMENTS 2,y\nDATA PERIODS,1,1,Data,Sunday, 1/ 1,12/31\n",
    );
    for index in 0..HOURS {
        let (month, day, hour) = calendar(index);
        text.push_str(&format!("2024,{month},{day},{hour},0,?,1,1,1,1,0,0,0,0,{},{}\n", 50 * (hour % 12), 20 * (hour % 7)));
    }
    text
}

#[test]
fn mutated_weather_files_never_crash_the_reader() {
    let good = epw();
    assert!(Weather::parse_epw(&good, Path::new("fuzz.epw")).is_ok());
    let mut rng = Rng(15);
    for case in 0..300 {
        let text = mutate(&good, &mut rng);
        let outcome = std::panic::catch_unwind(|| Weather::parse_epw(&text, Path::new("fuzz.epw")));
        match outcome {
            Ok(Ok(weather)) => assert_eq!(weather.hours.len(), HOURS, "case {case}"),
            Ok(Err(e)) => assert!(e.starts_with("fuzz.epw") && !e.contains('\n'), "case {case}: {e}"),
            Err(_) => panic!("case {case} panicked"),
        }
    }
}
