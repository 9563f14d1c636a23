//! Opening and saving files from the window: a scene (`.toml`) or a
//! weather file (`.epw`) dropped on it or opened from the File menu
//! ([`FileRequest::Open`]); the scene saved with the session's edits
//! ([`FileRequest::Save`], [`FileRequest::SaveAs`]: materials, north and
//! saved viewpoints written into the file's own text by
//! [`crate::scene::save`], comments kept); and the scenes opened lately
//! ([`RecentScenes`], kept between sessions).

use std::path::{Path, PathBuf};

use bevy::prelude::*;
use bevy::window::FileDragAndDrop;

use super::annual::AnnualStudy;
use super::camera::CameraControl;
use super::widgets::Note;
use crate::ecs::{ActiveScene, HeliodonSystems, OpenScene, SceneSpawned, Site};
use crate::scene::save::{SceneEdits, write_scene};

pub struct FilesPlugin;

impl Plugin for FilesPlugin {
    fn build(&self, app: &mut App) {
        app.add_message::<FileRequest>()
            .insert_resource(RecentScenes::load(RecentScenes::default_file()))
            .add_systems(Update, (open_dropped_files, carry_out_requests).chain().before(HeliodonSystems::SpawnScene))
            .add_systems(Update, remember_opened_scenes.after(HeliodonSystems::SpawnScene));
    }
}

/// What the File menu asks for.
#[derive(Message, Debug, Clone, PartialEq)]
pub enum FileRequest {
    /// A scene in place of the one shown, or a weather file.
    Open(PathBuf),
    /// The scene with the session's edits, over its file.
    Save,
    /// The scene with the session's edits, to another file.
    SaveAs(PathBuf),
}

/// Scene files opened lately, the latest first.
#[derive(Resource, Debug, Clone, Default, PartialEq)]
pub struct RecentScenes {
    pub scenes: Vec<PathBuf>,
    /// Where the list is kept (none: not kept).
    file: Option<PathBuf>,
}

impl RecentScenes {
    /// How many are kept.
    const KEPT: usize = 8;

    /// `$HELIODON_CONFIG_DIR/recent-scenes`, else under `$XDG_CONFIG_HOME/heliodon`
    /// or `~/.config/heliodon`.
    fn default_file() -> Option<PathBuf> {
        let dir = std::env::var_os("HELIODON_CONFIG_DIR").map(PathBuf::from).or_else(|| {
            std::env::var_os("XDG_CONFIG_HOME")
                .map(PathBuf::from)
                .or_else(|| std::env::var_os("HOME").map(|home| PathBuf::from(home).join(".config")))
                .map(|dir| dir.join("heliodon"))
        });
        dir.map(|dir| dir.join("recent-scenes"))
    }

    /// The list kept in `file`, one path a line (none or unreadable: empty).
    fn load(file: Option<PathBuf>) -> Self {
        let text = file.as_ref().and_then(|f| std::fs::read_to_string(f).ok()).unwrap_or_default();
        Self { scenes: text.lines().filter(|l| !l.trim().is_empty()).map(PathBuf::from).take(Self::KEPT).collect(), file }
    }

    /// `path` first; the list written back (a failure only costs the list).
    fn opened(&mut self, path: &Path) {
        let path = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
        self.scenes.retain(|p| *p != path);
        self.scenes.insert(0, path);
        self.scenes.truncate(Self::KEPT);
        if let Some(file) = &self.file {
            let text: String = self.scenes.iter().map(|p| format!("{}\n", p.display())).collect();
            let _ = file.parent().map(std::fs::create_dir_all);
            let _ = std::fs::write(file, text);
        }
    }
}

/// A file dropped on the window opens as if asked for from the File menu.
fn open_dropped_files(mut drops: MessageReader<FileDragAndDrop>, mut requests: MessageWriter<FileRequest>) {
    for drop in drops.read() {
        if let FileDragAndDrop::DroppedFile { path_buf, .. } = drop {
            requests.write(FileRequest::Open(path_buf.clone()));
        }
    }
}

/// Opens and saves as asked; each outcome is one line in the note.
fn carry_out_requests(
    mut requests: MessageReader<FileRequest>,
    mut open: MessageWriter<OpenScene>,
    mut study: ResMut<AnnualStudy>,
    mut note: ResMut<Note>,
    active: Res<ActiveScene>,
    site: Option<Res<Site>>,
    mut cameras: Option<ResMut<CameraControl>>,
) {
    for request in requests.read() {
        note.0 = Some(match request {
            FileRequest::Open(path) => open_file(path, &mut open, &mut study),
            FileRequest::Save | FileRequest::SaveAs(_) => {
                let to = if let FileRequest::SaveAs(to) = request { Some(to.as_path()) } else { None };
                let north_turn = site.as_ref().map_or(0.0, |s| s.north_turn);
                let new_viewpoints = cameras.as_ref().map(|c| c.saved_views.clone()).unwrap_or_default();
                match save(&active, to, north_turn, &new_viewpoints) {
                    Ok((to, left_out)) => {
                        // The file now holds north and the viewpoints: read
                        // again, the session starts from it.
                        if let Some(cameras) = cameras.as_mut() {
                            cameras.saved_views.clear();
                        }
                        open.write(OpenScene(to.clone()));
                        std::iter::once(format!("saved {}", to.display())).chain(left_out).collect::<Vec<_>>().join("; ")
                    }
                    Err(e) => e,
                }
            }
        });
    }
}

/// A scene (`.toml`) opens in place of the one shown, a weather file
/// (`.epw`) for the annual study and the sky; anything else is refused.
fn open_file(path: &Path, open: &mut MessageWriter<OpenScene>, study: &mut AnnualStudy) -> String {
    let extension = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    match extension.as_deref() {
        Some("toml") => {
            open.write(OpenScene(path.to_path_buf()));
            format!("opening {}", path.display())
        }
        Some("epw") => match study.open(path) {
            Ok(()) => format!("weather: {}", path.display()),
            Err(e) => e,
        },
        _ => format!("{}: heliodon opens scene files (.toml) and weather files (.epw)", path.display()),
    }
}

/// Writes the active scene with the session's edits to `to` (none: over
/// its own file), whole, then renamed into place; where it went and the
/// edits left out.
fn save(
    active: &ActiveScene,
    to: Option<&Path>,
    north_turn: f64,
    new_viewpoints: &[crate::scene::Viewpoint],
) -> Result<(PathBuf, Vec<String>), String> {
    let (Some(from), Some(loaded), Some(edited)) = (&active.path, &active.loaded, &active.scene) else {
        return Err("no scene is open".into());
    };
    let to = to.unwrap_or(from);
    let to = if to.extension().is_none() { to.with_extension("toml") } else { to.to_path_buf() };
    let text = std::fs::read_to_string(from).map_err(|e| format!("{}: cannot read: {e}", from.display()))?;
    let edits = SceneEdits { loaded, edited, north_turn, new_viewpoints };
    let saved = write_scene(&text, from, &to, &edits)?;
    let partial = to.with_extension("toml.saving");
    std::fs::write(&partial, &saved.text)
        .and_then(|()| std::fs::rename(&partial, &to))
        .map_err(|e| format!("{}: cannot write: {e}", to.display()))?;
    Ok((to, saved.left_out))
}

/// Every scene opened from a file goes to the front of the recent list.
fn remember_opened_scenes(mut spawned: MessageReader<SceneSpawned>, active: Res<ActiveScene>, mut recent: ResMut<RecentScenes>) {
    if spawned.read().any(|s| !s.edited)
        && let Some(path) = &active.path
    {
        recent.opened(path);
    }
}

#[cfg(test)]
#[path = "../../tests/support/epw.rs"]
pub(super) mod epw;

#[cfg(test)]
mod tests {
    use super::*;

    /// Drops `file` on a window and runs the drop handler once.
    fn drop_file(file: &std::path::Path) -> App {
        let mut app = App::new();
        app.add_message::<FileDragAndDrop>()
            .add_message::<FileRequest>()
            .add_message::<OpenScene>()
            .init_resource::<AnnualStudy>()
            .init_resource::<Note>()
            .init_resource::<ActiveScene>()
            .add_systems(Update, (open_dropped_files, carry_out_requests).chain());
        let window = app.world_mut().spawn_empty().id();
        app.world_mut().write_message(FileDragAndDrop::DroppedFile { window, path_buf: file.to_path_buf() });
        app.update();
        app
    }

    fn note(app: &App) -> String {
        app.world().resource::<Note>().0.clone().unwrap_or_default()
    }

    #[test]
    fn a_dropped_scene_opens_a_dropped_weather_file_drives_the_sky() {
        let scene = std::path::Path::new("assets/scenes/test_room/scene.toml");
        let mut app = drop_file(scene);
        let opened: Vec<PathBuf> = app.world_mut().resource_mut::<Messages<OpenScene>>().drain().map(|o| o.0).collect();
        assert_eq!(opened, vec![scene.to_path_buf()]);

        let dir = std::env::temp_dir().join(format!("heliodon-drop-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let epw = dir.join("boston.EPW");
        std::fs::write(&epw, epw::boston_epw(8760)).unwrap();
        let app = drop_file(&epw);
        let study = app.world().resource::<AnnualStudy>();
        assert!(study.weather.as_ref().is_some_and(|(path, _)| *path == epw) && study.weather_sky, "{}", note(&app));

        // A truncated weather file is refused with its line, in the note.
        std::fs::write(&epw, epw::boston_epw(100)).unwrap();
        let app = drop_file(&epw);
        assert!(app.world().resource::<AnnualStudy>().weather.is_none());
        assert!(note(&app).contains("boston.EPW"), "{}", note(&app));

        let app = drop_file(&dir.join("picture.png"));
        assert!(note(&app).contains("opens scene files (.toml) and weather files (.epw)"), "{}", note(&app));
        assert!(app.world().resource::<Messages<OpenScene>>().is_empty());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// Save as writes the scene with its edits where asked and opens it
    /// from there; the note says where it went.
    #[test]
    fn save_as_writes_the_edited_scene_and_opens_it() {
        let path = std::path::absolute("assets/scenes/test_room/scene.toml").unwrap();
        let loaded = std::sync::Arc::new(crate::scene::load_scene(&path, &crate::panel::PanelCatalog::new()).unwrap().scene);
        let mut edited = (*loaded).clone();
        let wall = edited.materials.iter().position(|m| matches!(m.kind, crate::scene::MaterialKind::Diffuse { .. })).unwrap();
        edited.materials[wall].kind = crate::scene::MaterialKind::Diffuse { reflectance: crate::scene::Rgb([0.3; 3]) };
        let mut app = App::new();
        app.add_message::<FileRequest>().add_message::<OpenScene>().init_resource::<AnnualStudy>().init_resource::<Note>();
        let mut active = ActiveScene::default();
        (active.scene, active.loaded, active.path) = (Some(std::sync::Arc::new(edited)), Some(loaded), Some(path));
        app.insert_resource(active).add_systems(Update, carry_out_requests);
        let dir = std::env::temp_dir().join(format!("heliodon-save-as-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let to = dir.join("room.toml");
        app.world_mut().write_message(FileRequest::SaveAs(to.clone()));
        app.update();
        assert_eq!(app.world().resource::<Note>().0.as_deref(), Some(format!("saved {}", to.display()).as_str()));
        let opened: Vec<PathBuf> = app.world_mut().resource_mut::<Messages<OpenScene>>().drain().map(|o| o.0).collect();
        assert_eq!(opened, vec![to.clone()]);
        let again = crate::scene::load_scene(&to, &crate::panel::PanelCatalog::new()).unwrap().scene;
        assert!(matches!(again.materials[wall].kind, crate::scene::MaterialKind::Diffuse { reflectance } if reflectance.0 == [0.3; 3]));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
