//! A scene written back to its TOML file with the designer's edits (the
//! viewer's File › Save and Save as): the materials' light, north and the
//! viewpoints saved in the session. The edits go into the file's own text
//! through `toml_edit`, so its comments, order and layout stay as written;
//! only what changed is touched. Saved elsewhere ("Save as"), the paths the
//! file gives relative to itself (the OBJ, panel data files) are rewritten
//! to point at the same files from the new place.

use std::path::{Component, Path, PathBuf};

use glam::Vec3;
use toml_edit::{Array, DocumentMut, Item, Table, Value, value};

use super::{Material, MaterialKind, ModelFrame, Scene, Viewpoint};

/// What the session changed on a scene loaded from a file.
pub struct SceneEdits<'a> {
    /// The scene as its file gives it.
    pub loaded: &'a Scene,
    /// The scene as edited: the same geometry, materials changed or added.
    pub edited: &'a Scene,
    /// North turned since loading, degrees clockwise ([`crate::site::Site::north_turn`]).
    pub north_turn: f64,
    /// Viewpoints saved in the session, added after the file's cameras.
    pub new_viewpoints: &'a [Viewpoint],
}

/// The scene file's new text, and the edits it cannot hold.
#[derive(Debug, Clone, PartialEq)]
pub struct SavedScene {
    /// The file's new text.
    pub text: String,
    /// One line per edit left out (a material of its own given to some
    /// windows: no scene key assigns a material to chosen surfaces).
    pub left_out: Vec<String>,
}

/// `text`, the scene file at `from`, with `edits` written in, to be saved at
/// `to` (the same path for Save). Fails with one line when `text` is not
/// a TOML document.
pub fn write_scene(text: &str, from: &Path, to: &Path, edits: &SceneEdits) -> Result<SavedScene, String> {
    let mut doc: DocumentMut = text.parse().map_err(|e| format!("{}: {e}", from.display()))?;
    let mut left_out = Vec::new();
    let (loaded, edited) = (edits.loaded, edits.edited);
    for (index, material) in edited.materials.iter().enumerate() {
        match loaded.materials.get(index) {
            Some(before) if same_light(&before.kind, &material.kind) => {}
            Some(_) => write_material(&mut doc, material, &loaded.frame),
            None => left_out.push(format!("material '{}' (its own for some windows): not saved, no scene key assigns it", material.name)),
        }
    }
    if edits.north_turn != 0.0 {
        let north = turned_north(&loaded.frame, edits.north_turn);
        let model = doc.entry("model").or_insert_with(|| Item::Table(Table::new()));
        model["north"] = value(numbers(north.to_array().map(f64::from)));
    }
    if !edits.new_viewpoints.is_empty() {
        let cameras = doc.entry("cameras").or_insert_with(|| Item::ArrayOfTables(Default::default()));
        if let Some(cameras) = cameras.as_array_of_tables_mut() {
            for view in edits.new_viewpoints {
                let mut camera = Table::new();
                camera["name"] = value(view.name.as_str());
                camera["eye"] = value(numbers(loaded.frame.model_point(view.eye)));
                camera["target"] = value(numbers(loaded.frame.model_point(view.target)));
                camera["fov"] = value(round(f64::from(view.fov)));
                cameras.push(camera);
            }
        }
    }
    if from.parent() != to.parent() {
        rebase_paths(&mut doc, from, to);
    }
    Ok(SavedScene { text: doc.to_string(), left_out })
}

/// Whether two kinds light the scene alike (what the file would say).
fn same_light(a: &MaterialKind, b: &MaterialKind) -> bool {
    match (a, b) {
        (MaterialKind::Diffuse { reflectance: x }, MaterialKind::Diffuse { reflectance: y }) => x == y,
        (MaterialKind::Glass { transmittance: x }, MaterialKind::Glass { transmittance: y }) => x == y,
        (MaterialKind::Panel { panel: p, up: u, parameters: k, .. }, MaterialKind::Panel { panel: q, up: v, parameters: l, .. }) => {
            p == q && u == v && k == l
        }
        _ => false,
    }
}

/// `[materials.NAME]` as `material` is now: its kind's keys set, the keys
/// of other kinds removed, comments beside the kept keys kept.
fn write_material(doc: &mut DocumentMut, material: &Material, frame: &ModelFrame) {
    let materials = doc.entry("materials").or_insert_with(|| {
        let mut table = Table::new();
        table.set_implicit(true);
        Item::Table(table)
    });
    let Some(materials) = materials.as_table_like_mut() else { return };
    let table = materials.entry(&material.name).or_insert(Item::Table(Table::new()));
    let Some(table) = table.as_table_like_mut() else { return };
    let keep: Vec<String> = match &material.kind {
        MaterialKind::Diffuse { reflectance } => {
            table.insert("kind", value("diffuse"));
            let [r, g, b] = reflectance.0.map(|c| round(f64::from(c)));
            let item = if r == g && g == b { value(r) } else { value(numbers([r, g, b])) };
            table.insert("reflectance", item);
            vec!["kind".into(), "reflectance".into()]
        }
        MaterialKind::Glass { transmittance } => {
            table.insert("kind", value("glass"));
            table.insert("transmittance", value(round(f64::from(*transmittance))));
            vec!["kind".into(), "transmittance".into()]
        }
        MaterialKind::Panel { panel, up, parameters, .. } => {
            table.insert("kind", value("panel"));
            table.insert("panel", value(panel.as_str()));
            let mut keep = vec!["kind".to_string(), "panel".to_string()];
            if let Some(up) = up {
                table.insert("up", value(numbers(frame.model_direction(*up).to_array().map(f64::from))));
                keep.push("up".into());
            }
            for (key, parameter) in parameters {
                // The file's own spelling of an unchanged value stays.
                let unchanged = table.get(key).and_then(Item::as_value).is_some_and(|v| same_value(v, parameter));
                if !unchanged {
                    table.insert(key, Item::Value(toml_value(parameter)));
                }
                keep.push(key.clone());
            }
            keep
        }
    };
    let stale: Vec<String> = table.iter().map(|(k, _)| k.to_string()).filter(|k| !keep.contains(k)).collect();
    for key in stale {
        table.remove(&key);
    }
}

/// Whether a value in the file says what `parameter` says.
fn same_value(in_file: &Value, parameter: &toml::Value) -> bool {
    toml::from_str::<toml::Table>(&format!("v = {}", in_file.to_string().trim())).is_ok_and(|t| t.get("v") == Some(parameter))
}

/// A `toml` value as a `toml_edit` one.
fn toml_value(parameter: &toml::Value) -> Value {
    match parameter {
        toml::Value::String(s) => s.as_str().into(),
        toml::Value::Integer(i) => (*i).into(),
        toml::Value::Float(f) => (*f).into(),
        toml::Value::Boolean(b) => (*b).into(),
        toml::Value::Datetime(d) => d.to_string().parse().unwrap_or_else(|_| d.to_string().into()),
        toml::Value::Array(items) => Value::Array(items.iter().map(toml_value).collect()),
        toml::Value::Table(table) => Value::InlineTable(table.iter().map(|(k, v)| (k.as_str(), toml_value(v))).collect()),
    }
}

/// The model-space north after the designer's turn of `degrees`.
fn turned_north(frame: &ModelFrame, degrees: f64) -> Vec3 {
    let (sin, cos) = degrees.to_radians().sin_cos();
    frame.model_direction(Vec3::new(sin as f32, cos as f32, 0.0))
}

/// Numbers as written by hand: six decimals at most, no `-0.0`.
fn round(v: f64) -> f64 {
    (v * 1e6).round() / 1e6 + 0.0
}

fn numbers<const N: usize>(values: [f64; N]) -> Array {
    values.into_iter().map(round).collect()
}

/// Points `model.obj` and every material's `file` at the same files from
/// `to`'s folder. Absolute paths stay.
fn rebase_paths(doc: &mut DocumentMut, from: &Path, to: &Path) {
    let from_dir = from.parent().unwrap_or(Path::new(""));
    let to_dir = to.parent().unwrap_or(Path::new(""));
    let rebase = |item: &mut Item| {
        let Some(old) = item.as_str().map(PathBuf::from) else { return };
        if old.is_absolute() {
            return;
        }
        let target = normalise(&absolute(from_dir).join(&old));
        let new = relative_to(&target, &normalise(&absolute(to_dir)));
        *item = value(new.to_string_lossy().replace('\\', "/"));
    };
    if let Some(obj) = doc.get_mut("model").and_then(|m| m.get_mut("obj")) {
        rebase(obj);
    }
    if let Some(materials) = doc.get_mut("materials").and_then(Item::as_table_like_mut) {
        for (_, material) in materials.iter_mut() {
            if let Some(file) = material.get_mut("file") {
                rebase(file);
            }
        }
    }
}

fn absolute(path: &Path) -> PathBuf {
    std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf())
}

/// `path` without `.` and `..` steps (lexically).
fn normalise(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for part in path.components() {
        match part {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop();
            }
            other => out.push(other),
        }
    }
    out
}

/// `target` as seen from the folder `base` (both absolute and normalised).
fn relative_to(target: &Path, base: &Path) -> PathBuf {
    let (t, b): (Vec<_>, Vec<_>) = (target.components().collect(), base.components().collect());
    let shared = t.iter().zip(&b).take_while(|(x, y)| x == y).count();
    // Nothing in common but the root (or the drive): the absolute path reads better.
    if shared <= 1 {
        return target.to_path_buf();
    }
    let mut out: PathBuf = b[shared..].iter().map(|_| Component::ParentDir).collect();
    out.extend(&t[shared..]);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::panel::PanelCatalog;
    use crate::scene::{Rgb, load_scene};

    fn office() -> (PathBuf, String, Scene) {
        let path = crate::bundled_scene("office");
        let text = std::fs::read_to_string(&path).unwrap();
        let scene = load_scene(&path, &PanelCatalog::new()).unwrap().scene;
        (path, text, scene)
    }

    /// Saved and loaded again, the edited scene is the one edited: the
    /// materials' light, north (the sun's azimuth over the model) and the
    /// new viewpoint; the file's comments and untouched lines stay.
    #[test]
    fn an_edited_scene_saved_and_loaded_again_is_the_one_edited() {
        let (path, text, loaded) = office();
        let mut edited = loaded.clone();
        let wall = edited.materials.iter().position(|m| matches!(m.kind, MaterialKind::Diffuse { .. })).unwrap();
        edited.materials[wall].kind = MaterialKind::Diffuse { reflectance: Rgb([0.25, 0.5, 0.75]) };
        let glass = edited.materials.iter().position(|m| matches!(m.kind, MaterialKind::Glass { .. })).unwrap();
        edited.materials[glass].kind = MaterialKind::Glass { transmittance: 0.61 };
        let view = Viewpoint { name: "desk view".into(), eye: Vec3::new(1.0, 2.0, 1.6), target: Vec3::new(5.0, 2.5, 1.2), fov: 55.0 };
        let edits = SceneEdits { loaded: &loaded, edited: &edited, north_turn: 30.0, new_viewpoints: std::slice::from_ref(&view) };
        let saved = write_scene(&text, &path, &path, &edits).unwrap();
        assert!(saved.left_out.is_empty(), "{:?}", saved.left_out);
        for line in text.lines().filter(|l| l.trim_start().starts_with('#')) {
            assert!(saved.text.contains(line), "comment '{line}' kept");
        }
        let dir = std::env::temp_dir().join(format!("heliodon-save-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let copy = dir.join("office.toml");
        let moved = write_scene(&text, &path, &copy, &edits).unwrap();
        std::fs::write(&copy, &moved.text).unwrap();
        let again = load_scene(&copy, &PanelCatalog::new()).unwrap().scene;
        assert_eq!(again.materials[wall].kind.label(), "diffuse");
        assert!(same_light(&again.materials[wall].kind, &edited.materials[wall].kind));
        assert!(same_light(&again.materials[glass].kind, &edited.materials[glass].kind));
        let others = (0..loaded.materials.len()).filter(|&i| i != wall && i != glass);
        assert!(others.into_iter().all(|i| same_light(&again.materials[i].kind, &loaded.materials[i].kind)));
        // North turned 30° clockwise in the file: the geometry turns, and
        // the saved viewpoint with it.
        assert!((again.frame.north_angle() - (loaded.frame.north_angle() + 30.0)).abs() < 1e-3, "{}", again.frame.north_angle());
        let saved_view = again.viewpoints.last().unwrap();
        assert_eq!(saved_view.name, "desk view");
        let turn = glam::Mat3::from_rotation_z(30f32.to_radians());
        assert!((saved_view.eye - turn * view.eye).length() < 1e-3, "{} vs {}", saved_view.eye, turn * view.eye);
        assert_eq!(again.viewpoints.len(), loaded.viewpoints.len() + 1);
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// Nothing changed, nothing written: the file's text comes back as it was.
    #[test]
    fn an_unedited_scene_is_saved_as_it_was() {
        let (path, text, loaded) = office();
        let edits = SceneEdits { loaded: &loaded, edited: &loaded, north_turn: 0.0, new_viewpoints: &[] };
        assert_eq!(write_scene(&text, &path, &path, &edits).unwrap().text, text);
    }

    #[test]
    fn paths_are_rebased_for_a_new_folder() {
        let base = Path::new("/a/b");
        assert_eq!(relative_to(Path::new("/a/b/c/model.obj"), base), PathBuf::from("c/model.obj"));
        assert_eq!(relative_to(Path::new("/a/model.obj"), base), PathBuf::from("../model.obj"));
        assert_eq!(relative_to(Path::new("/c/model.obj"), base), PathBuf::from("/c/model.obj"));
        assert_eq!(normalise(Path::new("/a/b/../c/./d")), PathBuf::from("/a/c/d"));
    }
}
