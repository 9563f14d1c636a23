//! The File menu: open a scene or a weather file, the scenes opened lately,
//! save the scene with the session's edits, save it elsewhere. A path is
//! typed into a small window (pre-filled from the scene shown); the
//! requests are carried out by [`crate::viewer::files`].

use std::path::PathBuf;

use bevy::ecs::system::SystemParam;
use bevy::prelude::*;
use bevy_egui::egui::{self, Ui};

use crate::ecs::ActiveScene;
use crate::viewer::files::{FileRequest, RecentScenes};

/// A path being typed for Open or Save as.
#[derive(Debug, Clone, PartialEq)]
enum Prompt {
    Open(String),
    SaveAs(String),
}

#[derive(Resource, Default)]
pub struct FilePrompt(Option<Prompt>);

#[derive(SystemParam)]
pub struct FileMenu<'w> {
    active: Res<'w, ActiveScene>,
    recent: Res<'w, RecentScenes>,
    prompt: ResMut<'w, FilePrompt>,
    requests: MessageWriter<'w, FileRequest>,
}

impl FileMenu<'_> {
    /// The menu bar's File menu, and the path window when one is open.
    pub fn show(&mut self, ui: &mut Ui) {
        let here = self.active.path.clone();
        let folder = here.as_ref().and_then(|p| p.parent()).map(|p| format!("{}/", p.display())).unwrap_or_default();
        egui::MenuBar::new().ui(ui, |ui| {
            ui.menu_button("File", |ui| {
                if ui.button("Open scene or weather…").clicked() {
                    self.prompt.0 = Some(Prompt::Open(folder.clone()));
                }
                ui.menu_button("Open recent", |ui| {
                    if self.recent.scenes.is_empty() {
                        ui.label("no scenes yet");
                    }
                    for scene in &self.recent.scenes {
                        if ui.button(scene.display().to_string()).clicked() {
                            self.requests.write(FileRequest::Open(scene.clone()));
                        }
                    }
                });
                ui.separator();
                let open = here.is_some() && self.active.scene.is_some();
                if ui
                    .add_enabled(open, egui::Button::new("Save"))
                    .on_hover_text("materials, north and saved views, into the scene file")
                    .clicked()
                {
                    self.requests.write(FileRequest::Save);
                }
                if ui.add_enabled(open, egui::Button::new("Save as…")).clicked() {
                    let stem = here.as_ref().and_then(|p| p.file_stem()).map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
                    self.prompt.0 = Some(Prompt::SaveAs(format!("{folder}{stem}-edited.toml")));
                }
            });
        });
        self.path_window(ui.ctx());
    }

    fn path_window(&mut self, ctx: &egui::Context) {
        let Some(prompt) = &mut self.prompt.0 else { return };
        let (title, text, action) = match prompt {
            Prompt::Open(text) => ("Open", text, "Open"),
            Prompt::SaveAs(text) => ("Save as", text, "Save"),
        };
        let mut done = None;
        egui::Window::new(title).collapsible(false).resizable(false).show(ctx, |ui| {
            ui.label("path (a .toml scene or, to open, an .epw weather file)");
            let field = ui.add(egui::TextEdit::singleline(text).desired_width(420.0));
            let entered = field.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
            ui.horizontal(|ui| {
                if ui.button(action).clicked() || entered {
                    done = Some(true);
                }
                if ui.button("Cancel").clicked() {
                    done = Some(false);
                }
            });
        });
        match done {
            Some(true) => {
                let request = match self.prompt.0.take() {
                    Some(Prompt::Open(path)) => FileRequest::Open(PathBuf::from(path.trim())),
                    Some(Prompt::SaveAs(path)) => FileRequest::SaveAs(PathBuf::from(path.trim())),
                    None => return,
                };
                self.requests.write(request);
            }
            Some(false) => self.prompt.0 = None,
            None => {}
        }
    }
}
