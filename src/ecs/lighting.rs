//! [`LightingPlugin`]: the light engine on Bevy's `AsyncComputeTaskPool`.
//! A spawned scene starts the precomputation as a task; every
//! [`LightChanged`] (or a finished precomputation) starts a relight task that
//! sends each finished iteration back, so the view can show the light
//! settling. A newer relight supersedes the running one: the old task stops
//! at its next iteration, and its results are never applied.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, channel};
use std::sync::{Arc, Mutex};

use bevy::prelude::*;
use bevy::tasks::{AsyncComputeTaskPool, Task, block_on, futures_lite::future};

use super::{ActiveScene, HeliodonSystems, LightChanged, SceneSpawned, SunSky};
use crate::light::{self, LightModel, Lighting, cache};

pub struct LightingPlugin;

impl Plugin for LightingPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<LightSettings>()
            .init_resource::<LightCacheDir>()
            .init_resource::<LightEngine>()
            .init_resource::<LightingState>()
            .add_message::<LightingUpdated>()
            .add_message::<LightingFailed>()
            .add_systems(
                Update,
                (start_precompute, finish_precompute, start_relight, apply_relight).chain().in_set(HeliodonSystems::Lighting),
            );
    }
}

/// The light engine's settings for the next precomputation (the core's
/// [`light::LightSettings`], as a resource).
#[derive(Resource, Debug, Clone, Copy, Default, PartialEq)]
pub struct LightSettings(pub light::LightSettings);

/// Where precomputations are cached (`None`: not at all).
#[derive(Resource, Debug, Clone, PartialEq)]
pub struct LightCacheDir(pub Option<std::path::PathBuf>);

impl Default for LightCacheDir {
    fn default() -> Self {
        Self(cache::default_dir())
    }
}

/// The precomputed model and the work in flight.
#[derive(Resource, Default)]
pub struct LightEngine {
    /// The model of the active scene, once precomputed.
    pub model: Option<Arc<LightModel>>,
    precompute: Option<Task<Result<LightModel, String>>>,
    /// Generation of the newest relight; older tasks stop when they see it move on.
    generation: Arc<AtomicU64>,
    results: Option<Mutex<Receiver<RelightResult>>>,
    relight_pending: bool,
}

impl LightEngine {
    /// Whether a precomputation is running.
    pub fn is_precomputing(&self) -> bool {
        self.precompute.is_some()
    }

    /// The newest relight's generation: results of older ones are dropped.
    pub fn generation(&self) -> u64 {
        self.generation.load(Ordering::SeqCst)
    }

    /// Whether the light is still on its way to `state`: precomputing, a
    /// relight asked for, or the newest relight not yet shown converged.
    pub fn is_settling(&self, state: &LightingState) -> bool {
        self.is_precomputing()
            || self.relight_pending
            || (self.results.is_some() && !(state.converged && state.generation == self.generation()))
    }
}

struct RelightResult {
    generation: u64,
    lighting: Lighting,
    converged: bool,
}

/// The light as it stands: what the view and the sensor panel show.
#[derive(Resource, Debug, Clone, Default)]
pub struct LightingState {
    pub lighting: Option<Lighting>,
    /// The relight it comes from.
    pub generation: u64,
    /// Whether that relight has converged.
    pub converged: bool,
}

/// New light was applied to [`LightingState`].
#[derive(Message, Debug, Clone, Copy, PartialEq, Eq)]
pub struct LightingUpdated {
    pub generation: u64,
    pub converged: bool,
}

/// The precomputation failed; one line.
#[derive(Message, Debug, Clone, PartialEq)]
pub struct LightingFailed {
    pub message: String,
}

fn start_precompute(
    mut spawned: MessageReader<SceneSpawned>,
    active: Res<ActiveScene>,
    settings: Res<LightSettings>,
    cache_dir: Res<LightCacheDir>,
    mut engine: ResMut<LightEngine>,
    mut state: ResMut<LightingState>,
) {
    if spawned.read().last().is_none() {
        return;
    }
    let Some(scene) = active.scene.clone() else { return };
    let settings = settings.0;
    engine.model = None;
    engine.results = None;
    engine.generation.fetch_add(1, Ordering::SeqCst);
    *state = LightingState::default();
    let dir = cache_dir.0.clone();
    engine.precompute = Some(
        AsyncComputeTaskPool::get()
            .spawn(async move { cache::precompute_cached(scene, settings, dir.as_deref(), &|_| {}).map(|(model, _)| model) }),
    );
}

fn finish_precompute(mut engine: ResMut<LightEngine>, mut failed: MessageWriter<LightingFailed>) {
    let Some(task) = engine.precompute.as_mut() else { return };
    let Some(result) = block_on(future::poll_once(task)) else { return };
    engine.precompute = None;
    match result {
        Ok(model) => {
            engine.model = Some(Arc::new(model));
            engine.relight_pending = true;
        }
        Err(message) => {
            failed.write(LightingFailed { message });
        }
    }
}

fn start_relight(
    mut changed: MessageReader<LightChanged>,
    sun_sky: Option<Res<SunSky>>,
    state: Res<LightingState>,
    mut engine: ResMut<LightEngine>,
) {
    if changed.read().last().is_some() {
        engine.relight_pending = true;
    }
    let (Some(model), Some(sun_sky)) = (engine.model.clone(), sun_sky) else { return };
    if !engine.relight_pending {
        return;
    }
    engine.relight_pending = false;
    let generation = engine.generation.fetch_add(1, Ordering::SeqCst) + 1;
    let current = engine.generation.clone();
    let sky = sun_sky.sky.clone();
    let warm = state.lighting.clone();
    let (sender, receiver) = channel();
    engine.results = Some(Mutex::new(receiver));
    AsyncComputeTaskPool::get()
        .spawn(async move {
            let mut relight = model.relight(&sky, warm.as_ref());
            loop {
                let converged = relight.is_converged();
                if current.load(Ordering::SeqCst) != generation
                    || sender.send(RelightResult { generation, lighting: relight.lighting(), converged }).is_err()
                    || converged
                {
                    return;
                }
                relight.step();
            }
        })
        .detach();
}

fn apply_relight(engine: Res<LightEngine>, mut state: ResMut<LightingState>, mut updated: MessageWriter<LightingUpdated>) {
    let Some(results) = &engine.results else { return };
    let newest = engine.generation.load(Ordering::SeqCst);
    let latest = results.lock().expect("relight results lock").try_iter().filter(|r| r.generation == newest).last();
    if let Some(result) = latest {
        *state = LightingState { lighting: Some(result.lighting), generation: result.generation, converged: result.converged };
        updated.write(LightingUpdated { generation: result.generation, converged: result.converged });
    }
}
