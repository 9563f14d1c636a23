//! Drawing only when something changes. The window is reactive (Bevy's
//! desktop update mode): a frame comes on input and window events, egui's
//! own repaint requests, or a [`RequestRedraw`]; an idle viewer draws
//! nothing. While something moves on its own, it asks for the next frame:
//! the scene loading, the light settling, a sensor's day or year, the
//! annual study or a sweep in the background. (The day playing asks in
//! `ui::sun_and_sky::play_the_day`.) A precomputation of the light shows
//! nothing until it ends, so the window sleeps through it and its task
//! wakes the window when done ([`LightWaker`]): frames drawn meanwhile
//! only took cores from it (on a software rasterizer a third of them, KIT's
//! early-design institute). bevy_egui's every-frame modifier event is
//! filtered, or egui would never let the window rest. The batch flow
//! (`view --screenshot/--hdr`) draws continuously but for the same sleep.

use std::collections::VecDeque;
use std::sync::Arc;

use bevy::ecs::system::SystemParam;
use bevy::prelude::*;
use bevy::window::RequestRedraw;
use bevy::winit::{EventLoopProxyWrapper, WinitSettings, WinitUserEvent};
use bevy_egui::{EguiInput, EguiPreUpdateSet, egui};

use super::ViewStart;
use super::annual::AnnualStudy;
use super::sensors::{DaySeries, YearMap};
use super::sweep::SweepStudy;
use crate::ecs::{ActiveScene, LightEngine, LightWaker, LightingState};

/// Reactive drawing for a person at the window, continuous for a batch job.
pub struct RedrawPlugin;

impl Plugin for RedrawPlugin {
    fn build(&self, app: &mut App) {
        app.insert_resource(WinitSettings::desktop_app())
            .add_systems(Startup, wake_for_the_light)
            .add_systems(Last, draw_continuously_for_batch)
            .add_systems(PreUpdate, drop_unchanged_modifiers.after(EguiPreUpdateSet::ProcessInput).before(EguiPreUpdateSet::BeginPass))
            .init_resource::<DrawnFrameTimes>()
            .add_systems(First, time_drawn_frames)
            .add_systems(Last, keep_drawing_while_busy);
    }
}

/// Frame times (ms) of frames drawn back to back: a frame that follows an
/// idle wait measures the wait, not the drawing, and is left out. A frame
/// asked for may still wait for the next event (winit under X without a
/// window manager was seen to), so gaps past the focused wait are left out too.
#[derive(Resource, Debug, Default)]
pub struct DrawnFrameTimes(VecDeque<f64>);

impl DrawnFrameTimes {
    const KEPT: usize = 120;
    /// The focused window's longest wait between frames (`WinitSettings::desktop_app`).
    const LONGEST_MS: f64 = 5000.0;

    /// The mean of the last 20 and the worst kept, ms.
    pub fn mean_and_worst(&self) -> Option<(f64, f64)> {
        let recent: Vec<f64> = self.0.iter().rev().take(20).copied().collect();
        (!recent.is_empty()).then(|| (recent.iter().sum::<f64>() / recent.len() as f64, self.0.iter().copied().fold(0.0, f64::max)))
    }
}

/// Keeps this frame's time when the last frame asked for it.
fn time_drawn_frames(time: Res<Time<Real>>, mut asked: MessageReader<RequestRedraw>, mut times: ResMut<DrawnFrameTimes>) {
    let ms = time.delta_secs_f64() * 1000.0;
    if asked.read().count() > 0 && ms < DrawnFrameTimes::LONGEST_MS {
        if times.0.len() == DrawnFrameTimes::KEPT {
            times.0.pop_front();
        }
        times.0.push_back(ms);
    }
}

/// A precomputation's task wakes the window when its light is ready.
fn wake_for_the_light(proxy: Option<Res<EventLoopProxyWrapper>>, mut commands: Commands) {
    let Some(proxy) = proxy else { return };
    // A resource already, so shared across threads as it is.
    let proxy = (**proxy).clone();
    commands.insert_resource(LightWaker(Arc::new(move || {
        // Fails only once the event loop is gone: nothing left to wake.
        let _ = proxy.send_event(WinitUserEvent::WakeUp);
    })));
}

/// The batch flow draws frame after frame, but for while only a
/// precomputation runs: then it sleeps as a window at rest does.
fn draw_continuously_for_batch(start: Option<Res<ViewStart>>, movers: Movers, mut settings: ResMut<WinitSettings>) {
    if !start.is_some_and(|s| s.screenshot.is_some() || s.hdr.is_some()) {
        return;
    }
    let wanted = if movers.engine.is_precomputing() && !movers.any() { WinitSettings::desktop_app() } else { WinitSettings::continuous() };
    if settings.focused_mode != wanted.focused_mode {
        *settings = wanted;
    }
}

/// What moves on its own, frame after frame.
#[derive(SystemParam)]
struct Movers<'w> {
    active: Res<'w, ActiveScene>,
    engine: Res<'w, LightEngine>,
    state: Res<'w, LightingState>,
    day: Res<'w, DaySeries>,
    year: Res<'w, YearMap>,
    annual: Res<'w, AnnualStudy>,
    sweep: Res<'w, SweepStudy>,
}

impl Movers<'_> {
    fn any(&self) -> bool {
        self.active.is_loading()
            || self.engine.is_relighting(&self.state)
            || self.day.0.is_running()
            || self.year.map.is_running()
            || self.annual.result.is_running()
            || self.sweep.is_running()
    }
}

fn keep_drawing_while_busy(movers: Movers, mut redraw: MessageWriter<RequestRedraw>) {
    if movers.any() {
        redraw.write(RequestRedraw);
    }
}

/// bevy_egui 0.42 hands egui the modifier keys as an event every frame,
/// and any event makes egui ask for another frame: the window would never
/// rest. Only a change of the modifiers is passed on.
fn drop_unchanged_modifiers(mut inputs: Query<&mut EguiInput>, mut last: Local<Option<egui::Modifiers>>) {
    for mut input in &mut inputs {
        input.events.retain(|event| match event {
            egui::Event::ModifiersChanged(modifiers) => last.replace(*modifiers) != Some(*modifiers),
            _ => true,
        });
    }
}
