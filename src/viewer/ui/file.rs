//! The File menu: open a scene or a weather file, the scenes opened lately,
//! save the scene with the session's edits, save it elsewhere. The path
//! comes from the desktop's own file dialog (rfd through the XDG portal,
//! asynchronous: the frame loop goes on while it is open), or, where there
//! is no desktop session to ask, is typed into a small window pre-filled
//! from the scene shown; the requests are carried out by
//! [`crate::viewer::files`].

use std::path::PathBuf;

use bevy::ecs::system::SystemParam;
use bevy::prelude::*;
use bevy::tasks::{IoTaskPool, Task, block_on, futures_lite::future};
use bevy_egui::egui::{self, Ui};

use crate::ecs::ActiveScene;
use crate::viewer::files::{FileRequest, RecentScenes};

/// A path being typed for Open or Save as.
#[derive(Debug, Clone, PartialEq)]
enum Prompt {
    Open(String),
    SaveAs(String),
}

/// The path being typed, or the native dialog open.
#[derive(Resource, Default)]
pub struct FilePrompt {
    typed: Option<Prompt>,
    /// The desktop's dialog: its answer (`None`: cancelled), the request it
    /// makes, what was asked and when.
    dialog: Option<Dialog>,
}

/// A desktop file dialog being shown.
struct Dialog {
    answer: Task<Option<PathBuf>>,
    request: fn(PathBuf) -> FileRequest,
    asked: Prompt,
    since: std::time::Instant,
}

/// An answer of "none" sooner than this was no dialog at all (no portal
/// behind the session bus): nobody cancels that fast.
const NO_DIALOG: std::time::Duration = std::time::Duration::from_millis(400);

#[derive(SystemParam)]
pub struct FileMenu<'w> {
    active: Res<'w, ActiveScene>,
    recent: Res<'w, RecentScenes>,
    prompt: ResMut<'w, FilePrompt>,
    requests: MessageWriter<'w, FileRequest>,
    redraw: MessageWriter<'w, bevy::window::RequestRedraw>,
}

/// Whether a desktop session is there to show its own file dialogs (the
/// XDG portal answers on the session bus).
fn desktop_dialogs() -> bool {
    std::env::var_os("DBUS_SESSION_BUS_ADDRESS").is_some_and(|a| !a.is_empty())
}

impl FileMenu<'_> {
    /// The menu bar's File menu, and the path window when one is open.
    pub fn show(&mut self, ui: &mut Ui) {
        let here = self.active.path.clone();
        let folder = here.as_ref().and_then(|p| p.parent()).map(|p| format!("{}/", p.display())).unwrap_or_default();
        egui::MenuBar::new().ui(ui, |ui| {
            ui.menu_button("File", |ui| {
                if ui.button("Open scene or weather…").clicked() {
                    self.ask(Prompt::Open(folder.clone()));
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
                    self.ask(Prompt::SaveAs(format!("{folder}{stem}-edited.toml")));
                }
            });
        });
        self.dialog_answer();
        self.path_window(ui.ctx());
    }

    /// Asks for a path: the desktop's dialog where there is one, else the path window.
    fn ask(&mut self, prompt: Prompt) {
        if !desktop_dialogs() {
            self.prompt.typed = Some(prompt);
            return;
        }
        type Answer = std::pin::Pin<Box<dyn std::future::Future<Output = Option<rfd::FileHandle>> + Send>>;
        let (dialog, request): (Answer, fn(PathBuf) -> FileRequest) = match &prompt {
            Prompt::Open(folder) => (
                Box::pin(
                    rfd::AsyncFileDialog::new()
                        .set_title("Open a scene or a weather file")
                        .add_filter("scene or weather", &["toml", "epw"])
                        .set_directory(folder)
                        .pick_file(),
                ),
                FileRequest::Open,
            ),
            Prompt::SaveAs(suggested) => {
                let path = PathBuf::from(suggested);
                let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
                let folder = path.parent().map(PathBuf::from).unwrap_or_default();
                (
                    Box::pin(
                        rfd::AsyncFileDialog::new()
                            .set_title("Save the scene as")
                            .add_filter("scene", &["toml"])
                            .set_directory(folder)
                            .set_file_name(name)
                            .save_file(),
                    ),
                    FileRequest::SaveAs,
                )
            }
        };
        let answer = IoTaskPool::get().spawn(async move { dialog.await.map(|file| file.path().to_path_buf()) });
        self.prompt.dialog = Some(Dialog { answer, request, asked: prompt, since: std::time::Instant::now() });
    }

    /// The desktop dialog's answer, once given; the path window when no
    /// dialog could be shown.
    fn dialog_answer(&mut self) {
        let Some(dialog) = &mut self.prompt.dialog else { return };
        let Some(answer) = block_on(future::poll_once(&mut dialog.answer)) else {
            // Until a dialog has shown, look again next frame; after, the
            // window's focus coming back wakes the viewer.
            if dialog.since.elapsed() < 2 * NO_DIALOG {
                self.redraw.write(bevy::window::RequestRedraw);
            }
            return;
        };
        let Some(dialog) = self.prompt.dialog.take() else { return };
        match answer {
            Some(path) => {
                self.requests.write((dialog.request)(path));
            }
            None if dialog.since.elapsed() < NO_DIALOG => self.prompt.typed = Some(dialog.asked),
            None => {}
        }
    }

    fn path_window(&mut self, ctx: &egui::Context) {
        let Some(prompt) = &mut self.prompt.typed else { return };
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
                let request = match self.prompt.typed.take() {
                    Some(Prompt::Open(path)) => FileRequest::Open(PathBuf::from(path.trim())),
                    Some(Prompt::SaveAs(path)) => FileRequest::SaveAs(PathBuf::from(path.trim())),
                    None => return,
                };
                self.requests.write(request);
            }
            Some(false) => self.prompt.typed = None,
            None => {}
        }
    }
}
