//! Throwaway scene folders for tests: a minimal model (a wall triangle and
//! a glass triangle) with a scene file around extra TOML. Included by path
//! (`#[path = ".../tests/support/fixture.rs"] mod fixture;`).

use std::path::{Path, PathBuf};

/// A throwaway scene folder with the given files.
pub struct Fixture {
    pub dir: PathBuf,
}

impl Fixture {
    pub fn new(name: &str, files: &[(&str, &str)]) -> Self {
        let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("bad_input").join(name);
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        for (file, text) in files {
            std::fs::write(dir.join(file), text).unwrap();
        }
        Self { dir }
    }

    pub fn scene(&self) -> PathBuf {
        self.dir.join("scene.toml")
    }
}

pub const SITE: &str = "[site]\nlatitude = 42.36\nlongitude = -71.06\ntimezone = -5.0\n";
pub const MTL: &str = "newmtl wall\nKd 0.5 0.5 0.5\n\nnewmtl glass\nd 0.12\n";
pub const OBJ: &str = "mtllib room.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nusemtl wall\nf 1 2 3\nusemtl glass\nf 1 3 4\n";

/// The scene file of the minimal model, with `extra` at its end.
pub fn scene_toml(extra: &str) -> String {
    format!("name = \"bad\"\n{SITE}\n[model]\nobj = \"room.obj\"\n{extra}")
}

/// A folder with `toml` as the scene file, `obj` as the model and the minimal MTL.
pub fn fixture(name: &str, toml: &str, obj: &str) -> Fixture {
    Fixture::new(name, &[("scene.toml", toml), ("room.obj", obj), ("room.mtl", MTL)])
}
