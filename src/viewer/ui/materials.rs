//! The materials panel: every group of windows (panes of one material
//! facing one way) with its material, plain glass or any registered panel
//! with one widget per key the panel declares; a group that shares its
//! material can take a copy of its own ([`GiveOwnMaterial`]); and the
//! reflectances of the opaque materials. Every change sends
//! [`EditMaterial`] (the scene is respawned and relit); a panel whose keys
//! do not build keeps the material it had, and the panel says why.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use bevy::ecs::system::SystemParam;
use bevy::prelude::*;
use bevy_egui::egui::{self, Ui};

use crate::ecs::{ActiveScene, EditMaterial, GiveOwnMaterial, MaterialEditRejected, PanelRegistry, RayModel};
use crate::light::WindowGroups;
use crate::panel::{Key, KeyKind, PanelCatalog, Parameters, default_values};
use crate::scene::{MaterialKind, Rgb, Scene};
use crate::viewer::widgets::{bounded, clamp_noted};

/// Transmittance a window gets when switched back to plain glass.
const CLEAR_GLASS: f32 = 0.88;
/// How deep below the scene's folder (and its two parents) panel data files
/// are looked for, and how many folder entries at most are read doing so.
const FILE_SEARCH_DEPTH: usize = 3;
const FILE_SEARCH_ENTRIES: usize = 5000;

/// What the materials panel keeps between frames.
#[derive(Resource, Debug, Clone, Default)]
pub struct MaterialEdits {
    /// Panel keys being edited, by material: what the material had when the
    /// editing started, and the values in the widgets.
    pending: HashMap<u32, PendingKeys>,
    /// Data files offered for file keys, by extension (relative to the scene's folder).
    files: HashMap<&'static str, Vec<String>>,
}

#[derive(Debug, Clone)]
struct PendingKeys {
    panel: String,
    applied: toml::Table,
    values: toml::Table,
}

/// What the materials panel reads and writes.
#[derive(SystemParam)]
pub struct MaterialPanel<'w, 's> {
    edits_state: ResMut<'w, MaterialEdits>,
    active: Res<'w, ActiveScene>,
    ray_model: Option<Res<'w, RayModel>>,
    registry: Option<Res<'w, PanelRegistry>>,
    edits: MessageWriter<'w, EditMaterial>,
    splits: MessageWriter<'w, GiveOwnMaterial>,
    rejected: MessageReader<'w, 's, MaterialEditRejected>,
}

/// A row of the windows panel: the window groups of one material whose
/// outward normals ([`crate::light::windows`], the one grouping rule) fall
/// on one compass point, shown together.
#[derive(Debug, Clone, PartialEq)]
pub struct WindowRow {
    pub material: u32,
    /// Compass point the panes look out to (true north at `north_turn`),
    /// "skylight", or "enclosed" (glazing that sees no sky).
    pub facing: &'static str,
    pub panes: usize,
    /// m².
    pub area: f64,
    /// The panes' surfaces (indices into [`Scene::surfaces`]).
    pub surfaces: Vec<u32>,
}

/// The windows panel's rows, in material order; `north_turn` is where true
/// north is, in degrees clockwise from +y.
pub fn window_rows(scene: &Scene, windows: &WindowGroups, north_turn: f64) -> Vec<WindowRow> {
    const COMPASS: [&str; 8] = ["north", "north-east", "east", "south-east", "south", "south-west", "west", "north-west"];
    let mut rows: Vec<WindowRow> = Vec::new();
    for group in &windows.groups {
        let out = group.outward;
        let facing = if group.enclosed {
            "enclosed"
        } else if out.z.abs() > 0.7 {
            "skylight"
        } else {
            let azimuth = out.x.atan2(out.y).to_degrees() - north_turn;
            COMPASS[((azimuth.rem_euclid(360.0) + 22.5) / 45.0) as usize % 8]
        };
        let panes = group.windows.iter().map(|&w| &scene.windows[w as usize]);
        let area: f64 = panes.clone().map(|w| f64::from(w.area)).sum();
        let surfaces = panes.map(|w| w.surface);
        match rows.iter_mut().find(|row| row.material == group.material && row.facing == facing) {
            Some(row) => {
                row.panes += group.windows.len();
                row.area += area;
                row.surfaces.extend(surfaces);
            }
            None => {
                rows.push(WindowRow { material: group.material, facing, panes: group.windows.len(), area, surfaces: surfaces.collect() })
            }
        }
    }
    rows.sort_by_key(|row| row.material);
    rows
}

impl MaterialPanel<'_, '_> {
    /// Draws the panel (once the scene and its ray model are there).
    pub fn show(&mut self, ui: &mut Ui, note: &mut Option<String>, north_turn: f64) {
        let (Some(scene), Some(model)) = (self.active.scene.clone(), self.ray_model.as_ref().map(|m| m.0.clone())) else { return };
        let rows = window_rows(&scene, &model.windows, north_turn);
        let mut edits = std::mem::take(&mut *self.edits_state);
        material_panel(ui, &mut edits, note, &scene, &rows, self);
        *self.edits_state = edits;
    }
}

/// The windows, then the opaque materials.
fn material_panel(
    ui: &mut Ui,
    edits: &mut MaterialEdits,
    note: &mut Option<String>,
    scene: &Scene,
    groups: &[WindowRow],
    panel: &mut MaterialPanel,
) {
    for rejected in panel.rejected.read() {
        *note = Some(rejected.message.clone());
    }
    let catalog = panel.registry.as_ref().map(|r| r.catalog()).unwrap_or_default();
    let base = crate::panel::base_dir(&scene.files.scene);
    egui::CollapsingHeader::new("Windows").default_open(true).show(ui, |ui| {
        let mut shown = Vec::new();
        for group in groups {
            if shown.contains(&group.material) {
                continue;
            }
            shown.push(group.material);
            let material = &scene.materials[group.material as usize];
            let sharing: Vec<&WindowRow> = groups.iter().filter(|g| g.material == group.material).collect();
            for g in &sharing {
                ui.horizontal_wrapped(|ui| {
                    ui.label(format!("{} windows: {} panes, {:.1} m²", g.facing, g.panes, g.area));
                    // A group sharing its material can take one of its own, to be changed alone.
                    if sharing.len() > 1
                        && ui
                            .small_button("own material")
                            .on_hover_text("give these windows a copy of the material, to change them alone")
                            .clicked()
                    {
                        let name = unique_name(scene, &format!("{} ({})", material.name, g.facing));
                        panel.splits.write(GiveOwnMaterial { surfaces: g.surfaces.clone(), name });
                    }
                });
            }
            ui.horizontal(|ui| {
                ui.label("material");
                ui.strong(&material.name);
            });
            if let Some(kind) = window_material(ui, edits, note, group.material, &material.kind, &catalog, &base) {
                panel.edits.write(EditMaterial { index: group.material, kind });
            }
            ui.separator();
        }
    });
    egui::CollapsingHeader::new("Opaque materials").default_open(false).show(ui, |ui| {
        for (index, material) in scene.materials.iter().enumerate() {
            let MaterialKind::Diffuse { reflectance } = &material.kind else { continue };
            let mut rgb = reflectance.0;
            let changed = ui
                .horizontal(|ui| {
                    ui.label(&material.name);
                    let mut changed = false;
                    for (c, label) in ["R ", "G ", "B "].iter().enumerate() {
                        changed |= committed(&bounded(ui, &mut rgb[c], 0.0..=1.0, 0.005, label, "", note));
                    }
                    changed
                })
                .inner;
            if changed {
                panel.edits.write(EditMaterial { index: index as u32, kind: MaterialKind::Diffuse { reflectance: Rgb(rgb) } });
            }
        }
    });
}

/// `name`, or with a number after it if a material has that name.
fn unique_name(scene: &Scene, name: &str) -> String {
    (1..)
        .map(|k| if k == 1 { name.to_string() } else { format!("{name} {k}") })
        .find(|n| scene.materials.iter().all(|m| m.name != *n))
        .expect("a free name")
}

/// A value is committed when typed, or when a drag ends: relighting on every
/// step of a drag would restart the light each frame.
fn committed(response: &egui::Response) -> bool {
    response.drag_stopped() || (response.changed() && !response.dragged())
}

/// One window material: glass or a panel from the dropdown, then its
/// transmittance or the panel's keys. The new material, when one is chosen
/// and builds.
fn window_material(
    ui: &mut Ui,
    edits: &mut MaterialEdits,
    note: &mut Option<String>,
    index: u32,
    kind: &MaterialKind,
    catalog: &PanelCatalog,
    base: &Path,
) -> Option<MaterialKind> {
    let current = match kind {
        MaterialKind::Panel { panel, .. } => panel.clone(),
        _ => "glass".to_string(),
    };
    let mut chosen = current.clone();
    egui::ComboBox::from_id_salt(("window_material", index)).selected_text(&chosen).show_ui(ui, |ui| {
        ui.selectable_value(&mut chosen, "glass".to_string(), "glass");
        for name in catalog.names() {
            ui.selectable_value(&mut chosen, name.to_string(), name);
        }
    });
    if chosen != current {
        edits.pending.remove(&index);
        if chosen == "glass" {
            return Some(MaterialKind::Glass { transmittance: CLEAR_GLASS });
        }
        let keys = catalog.get(&chosen).map(|p| p.keys()).unwrap_or_default();
        let mut values = default_values(keys);
        for key in keys {
            if let KeyKind::File { extension } = key.kind
                && let Some(first) = edits.offered_files(base, extension).first()
            {
                values.insert(key.name.to_string(), toml::Value::String(first.clone()));
            }
        }
        let up = match kind {
            MaterialKind::Panel { up, .. } => *up,
            _ => None,
        };
        return build(note, catalog, &chosen, values, up, base);
    }
    match kind {
        MaterialKind::Glass { transmittance } => {
            let mut t = *transmittance;
            let response = ui.add(egui::Slider::new(&mut t, 0.0..=1.0).text("transmittance").clamping(egui::SliderClamping::Never));
            clamp_noted(&mut t, 0.0..=1.0, "transmittance ", "", note);
            committed(&response).then_some(MaterialKind::Glass { transmittance: t })
        }
        MaterialKind::Panel { panel, up, parameters, .. } => {
            let keys = catalog.get(panel).map(|p| p.keys()).unwrap_or_default();
            let stale = edits.pending.get(&index).is_none_or(|p| p.panel != *panel || p.applied != *parameters);
            if stale {
                edits.pending.insert(index, PendingKeys { panel: panel.clone(), applied: parameters.clone(), values: parameters.clone() });
            }
            let mut values = edits.pending[&index].values.clone();
            let mut changed = false;
            let note_before = note.clone();
            for key in keys {
                let files = match key.kind {
                    KeyKind::File { extension } => edits.offered_files(base, extension).to_vec(),
                    _ => Vec::new(),
                };
                changed |= key_widget(ui, index, key, &mut values, &files, note);
            }
            if let Some(pending) = edits.pending.get_mut(&index) {
                pending.values = values.clone();
            }
            if !changed {
                return None;
            }
            let built = build(note, catalog, panel, values, *up, base);
            if built.is_some() && *note == note_before {
                // An earlier note (say, why an edit was refused) is out of date;
                // one this edit made (a clamped value) stays.
                *note = None;
            }
            built
        }
        MaterialKind::Diffuse { .. } => None,
    }
}

/// The panel material from `values`, or `None` with the reason in `note`
/// (the material then keeps what it had).
fn build(
    note: &mut Option<String>,
    catalog: &PanelCatalog,
    panel: &str,
    values: toml::Table,
    up: Option<Vec3>,
    base: &Path,
) -> Option<MaterialKind> {
    let parameters = Parameters::new(values, base);
    match catalog.build(panel, &parameters) {
        Ok(model) => Some(MaterialKind::Panel {
            panel: panel.to_string(),
            up,
            parameters: parameters.values,
            model: crate::panel::PanelHandle(model),
        }),
        Err(e) => {
            *note = Some(format!("{panel}: {}: {} (the window keeps its material)", e.key, e.message));
            None
        }
    }
}

/// The widget of one panel key of window material `material`, editing
/// `values`; true when a change is committed. Values typed outside the key's range are clamped, with a note.
fn key_widget(ui: &mut Ui, material: u32, key: &Key, values: &mut toml::Table, files: &[String], note: &mut Option<String>) -> bool {
    let number = |v: &toml::Value| v.as_float().or_else(|| v.as_integer().map(|i| i as f64));
    let given = values.get(key.name).cloned();
    let label = format!("{} ", key.name);
    ui.horizontal(|ui| match key.kind {
        KeyKind::Number { range, default } => {
            let mut v = given.as_ref().and_then(number).unwrap_or(default);
            let response = bounded(ui, &mut v, range.0..=range.1, (range.1 - range.0) / 500.0, &label, "", note).on_hover_text(key.help);
            let commit = committed(&response);
            values.insert(key.name.into(), toml::Value::Float(v));
            commit
        }
        KeyKind::Numbers { range, default } => {
            let mut list: Vec<f64> = match &given {
                Some(toml::Value::Array(items)) if items.len() == default.len() => {
                    items.iter().map(|i| number(i).unwrap_or(range.0)).collect()
                }
                _ => default.to_vec(),
            };
            ui.label(&label).on_hover_text(key.help);
            let mut commit = false;
            for (i, v) in list.iter_mut().enumerate() {
                let response = ui.add(egui::DragValue::new(v).speed((range.1 - range.0) / 500.0));
                clamp_noted(v, range.0..=range.1, &format!("{}[{i}] ", key.name), "", note);
                commit |= committed(&response);
            }
            values.insert(key.name.into(), toml::Value::Array(list.into_iter().map(toml::Value::Float).collect()));
            commit
        }
        KeyKind::Count { range, default } => {
            let mut v = given.as_ref().and_then(toml::Value::as_integer).unwrap_or(default);
            let response = bounded(ui, &mut v, range.0..=range.1, 0.05, &label, "", note).on_hover_text(key.help);
            values.insert(key.name.into(), toml::Value::Integer(v));
            committed(&response)
        }
        KeyKind::File { .. } => {
            let mut file = given.as_ref().and_then(toml::Value::as_str).unwrap_or_default().to_string();
            ui.label(&label).on_hover_text(key.help);
            let mut commit = false;
            egui::ComboBox::from_id_salt(("key_file", material, key.name)).selected_text(&file).show_ui(ui, |ui| {
                for offered in files {
                    commit |= ui.selectable_value(&mut file, offered.clone(), offered).clicked();
                }
            });
            values.insert(key.name.into(), toml::Value::String(file));
            commit
        }
    })
    .inner
}

impl MaterialEdits {
    /// Files with `extension` in the scene's folder or its two parents (a few
    /// levels down), as paths relative to the scene's folder; found once.
    fn offered_files(&mut self, base: &Path, extension: &'static str) -> &[String] {
        self.files.entry(extension).or_insert_with(|| {
            let mut found = Vec::new();
            let mut seen = std::collections::HashSet::new();
            let Ok(mut folder) = std::fs::canonicalize(if base.as_os_str().is_empty() { Path::new(".") } else { base }) else {
                return found;
            };
            let mut relative = PathBuf::new();
            let mut budget = FILE_SEARCH_ENTRIES;
            for _ in 0..3 {
                collect_files(&folder, &relative, extension, FILE_SEARCH_DEPTH, &mut budget, &mut seen, &mut found);
                let Some(parent) = folder.parent() else { break };
                folder = parent.to_path_buf();
                relative.push("..");
            }
            // The scene's own folder first, then further up.
            found.sort_by_key(|name| (name.matches("../").count(), name.clone()));
            found
        })
    }
}

/// Files with `extension` under `dir` (down to `depth` folders), named
/// relative to the scene's folder; each file once, by its first name.
fn collect_files(
    dir: &Path,
    relative: &Path,
    extension: &str,
    depth: usize,
    budget: &mut usize,
    seen: &mut std::collections::HashSet<PathBuf>,
    found: &mut Vec<String>,
) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for entry in entries.flatten() {
        if *budget == 0 {
            return;
        }
        *budget -= 1;
        let path = entry.path();
        let name = relative.join(entry.file_name());
        if path.is_dir() && depth > 0 {
            collect_files(&path, &name, extension, depth - 1, budget, seen, found);
        } else if path.extension().is_some_and(|e| e.eq_ignore_ascii_case(extension)) && seen.insert(path) {
            found.push(name.to_string_lossy().replace('\\', "/"));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::panel::{PanelModel, PanelResponse, PanelType, ParameterError};
    use std::sync::Arc;

    /// A panel whose two shares may not add up to more than 1.
    struct Shares;
    const A: Key = Key::number("a", "", (0.0, 1.0), 0.5);
    const B: Key = Key::number("b", "", (0.0, 1.0), 0.25);

    impl PanelType for Shares {
        fn name(&self) -> &str {
            "shares"
        }
        fn keys(&self) -> &[Key] {
            &[A, B]
        }
        fn build(&self, p: &Parameters) -> Result<Arc<dyn PanelModel>, ParameterError> {
            let (a, b) = (p.number(&A)?, p.number(&B)?);
            if a + b > 1.0 {
                return Err(ParameterError::new("b", format!("a + b = {} is more than 1", a + b)));
            }
            Ok(Arc::new(Open))
        }
    }

    #[derive(Debug)]
    struct Open;
    impl PanelModel for Open {
        fn response(&self, _: glam::DVec3) -> PanelResponse {
            PanelResponse { absorbed: 1.0, ..Default::default() }
        }
    }

    #[test]
    fn panel_keys_out_of_range_are_clamped_and_failed_builds_keep_the_material() {
        let mut catalog = PanelCatalog::new();
        catalog.register(Arc::new(Shares));
        let mut note = None;
        // The defaults build.
        assert!(build(&mut note, &catalog, "shares", default_values(Shares.keys()), None, Path::new("")).is_some());
        // A value past its range is clamped, with a note.
        let mut values: toml::Table = toml::from_str("a = 5.0\nb = 0.0").unwrap();
        let ctx = egui::Context::default();
        let mut output = ctx.run_ui(egui::RawInput::default(), |ui| {
            key_widget(ui, 0, &A, &mut values, &[], &mut note);
        });
        output.textures_delta.clear();
        assert_eq!(values["a"].as_float(), Some(1.0));
        assert_eq!(note.as_deref(), Some("a 5 is outside 0..1: 1 is used"));
        // Keys that do not build together: no material, and why.
        values.insert("b".into(), toml::Value::Float(0.5));
        assert!(build(&mut note, &catalog, "shares", values, None, Path::new("")).is_none());
        assert_eq!(note.as_deref(), Some("shares: b: a + b = 1.5 is more than 1 (the window keeps its material)"));
    }

    #[test]
    fn windows_are_grouped_by_material_and_the_way_they_face() {
        let scene = crate::scene::load_scene(&crate::bundled_scene("office"), &PanelCatalog::new()).unwrap().scene;
        let windows = crate::light::LightModel::unlit(std::sync::Arc::new(scene.clone())).windows;
        let window_groups = |north_turn| window_rows(&scene, &windows, north_turn);
        let name = |g: &WindowRow| scene.materials[g.material as usize].name.clone();
        let groups: Vec<(String, &str)> = window_groups(0.0).iter().map(|g| (name(g), g.facing)).collect();
        for expected in [("upper_glass", "west"), ("view_glass", "west")] {
            assert!(groups.iter().any(|(n, f)| n == expected.0 && *f == expected.1), "{groups:?}");
        }
        assert!(groups.iter().any(|(_, f)| *f == "skylight"), "{groups:?}");
        let area: f64 = window_groups(0.0).iter().map(|g| g.area).sum();
        assert!((area - scene.windows.iter().map(|w| f64::from(w.area)).sum::<f64>()).abs() < 1e-6);
        // True north turned to the model's +x: the west windows face south.
        let turned: Vec<&str> = window_groups(90.0).iter().filter(|g| name(g) == "upper_glass").map(|g| g.facing).collect();
        assert_eq!(turned, ["south"]);
    }
}
