//! [`LightingPlugin`]: the light engine on Bevy's `AsyncComputeTaskPool`.
//! A spawned scene starts the precomputation as a task; every
//! [`LightChanged`] (or a finished precomputation) starts a relight task that
//! hands each finished iteration back (replacing one not yet shown), so the
//! view can show the light settling. A newer relight supersedes the running one: the old task stops
//! at its next iteration, and its results are never applied. Where the light
//! is refined for display ([`RefineForDisplay`], the viewer), a second
//! precomputation with more patch rays follows once the first light is
//! shown, in the background, and the light shown comes from it when done:
//! the light appears as fast as before and then loses its Monte Carlo
//! blotches. The settings' own model stays what the numbers come from (the
//! sensors' readings, a sensor's day and year, the annual study, sweeps),
//! as `sensors` and `annual` compute them.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

use bevy::ecs::system::SystemParam;
use bevy::prelude::*;
use bevy::tasks::{AsyncComputeTaskPool, Task};

use super::{ActiveScene, HeliodonSystems, LightChanged, RayModel, SceneSpawned, SunSky};
use crate::light::{self, LightModel, Lighting, cache};

pub struct LightingPlugin;

impl Plugin for LightingPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<LightSettings>()
            .init_resource::<RefineForDisplay>()
            .init_resource::<LightCacheDir>()
            .init_resource::<LightEngine>()
            .init_resource::<LightingState>()
            .add_message::<LightingUpdated>()
            .add_message::<LightingFailed>()
            .add_systems(
                Update,
                (start_precompute, finish_precompute, start_relight, apply_relight, start_refinement)
                    .chain()
                    .in_set(HeliodonSystems::Lighting),
            );
    }
}

/// The light engine's settings for the next precomputation (the core's
/// [`light::LightSettings`], as a resource).
#[derive(Resource, Debug, Clone, Copy, Default, PartialEq)]
pub struct LightSettings(pub light::LightSettings);

/// Whether the light shown is refined past [`LightSettings`]' patch rays
/// ([`light::LightSettings::for_display`]) once its first light is shown.
/// The first precomputation keeps the settings as `sensors` and `annual`
/// use them (and their light cache).
#[derive(Resource, Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct RefineForDisplay(pub bool);

/// Where precomputations are cached (`None`: not at all).
#[derive(Resource, Debug, Clone, PartialEq)]
pub struct LightCacheDir(pub Option<std::path::PathBuf>);

impl Default for LightCacheDir {
    fn default() -> Self {
        Self(cache::default_dir())
    }
}

/// Called from a precomputation's task once its result is ready: a window
/// that draws only when asked (the viewer) need not draw frame after frame
/// to see a precomputation end (on a software rasterizer those frames took
/// a third of the cores from it). Without one, the app updates anyway.
#[derive(Resource, Clone)]
pub struct LightWaker(pub Arc<dyn Fn() + Send + Sync>);

/// A precomputation in flight: its task (dropped, it is cancelled if not
/// yet started) and where it leaves its model before it wakes the app.
struct Precompute {
    _task: Task<()>,
    result: Arc<Mutex<Option<Result<LightModel, String>>>>,
}

/// The precomputed model and the work in flight.
#[derive(Resource, Default)]
pub struct LightEngine {
    /// The model of the active scene with the settings as they are, once
    /// precomputed.
    pub model: Option<Arc<LightModel>>,
    /// The same with the display's patch rays, once precomputed
    /// ([`RefineForDisplay`]): the light shown comes from it.
    pub smoothed: Option<Arc<LightModel>>,
    precompute: Option<Precompute>,
    /// The precomputation for display still to start (once the first
    /// light is shown). One in flight while `model` is there is it.
    refinement: Option<(Arc<crate::scene::Scene>, light::LightSettings)>,
    /// Generation of the newest relight; older tasks stop when they see it move on.
    generation: Arc<AtomicU64>,
    /// The newest relight's newest iteration not yet applied: each replaces
    /// the one before, so a view drawing slower than the light settles
    /// (a large model on a software rasterizer) holds one, not a queue of
    /// them (AC20-Institute-Var-2: 11 MB each, 25 waiting).
    results: Option<Arc<Mutex<Option<RelightResult>>>>,
    relight_pending: bool,
}

impl LightEngine {
    /// Whether a precomputation is running.
    pub fn is_precomputing(&self) -> bool {
        self.precompute.is_some()
    }

    /// Whether the light is yet to be refined for display (its model
    /// precomputed again with more patch rays), or being refined.
    pub fn is_smoothing(&self) -> bool {
        self.refinement.is_some() || (self.precompute.is_some() && self.model.is_some())
    }

    /// The newest relight's generation: results of older ones are dropped.
    pub fn generation(&self) -> u64 {
        self.generation.load(Ordering::SeqCst)
    }

    /// Whether the light is still on its way to `state`: precomputing (for
    /// display too) or relighting.
    pub fn is_settling(&self, state: &LightingState) -> bool {
        self.is_precomputing() || self.is_relighting(state)
    }

    /// Whether the light shown is changing: a relight asked for with a
    /// model to relight, or the newest relight not yet shown converged. (A
    /// precomputation changes nothing shown until it ends; a relight asked
    /// for before there is a model waits for it.)
    pub fn is_relighting(&self, state: &LightingState) -> bool {
        (self.relight_pending && self.model.is_some())
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

#[allow(clippy::too_many_arguments)]
fn start_precompute(
    mut spawned: MessageReader<SceneSpawned>,
    ray_model: Option<Res<RayModel>>,
    active: Res<ActiveScene>,
    settings: Res<LightSettings>,
    refine: Res<RefineForDisplay>,
    precomputer: Precomputer,
    mut engine: ResMut<LightEngine>,
    mut state: ResMut<LightingState>,
) {
    if spawned.read().last().is_none() {
        return;
    }
    let Some(scene) = active.scene.clone() else { return };
    let settings = settings.0;
    engine.model = None;
    engine.smoothed = None;
    engine.results = None;
    engine.generation.fetch_add(1, Ordering::SeqCst);
    *state = LightingState::default();
    let display = settings.for_display(scene.patches.patches.len());
    engine.refinement = (refine.0 && display != settings).then(|| (scene.clone(), display));
    // The scene's ray-query model lends its tracers.
    let ray_model = ray_model.and_then(|m| m.of(&scene).cloned());
    engine.precompute = Some(precomputer.spawn(scene, settings, ray_model));
}

/// What a precomputation needs besides its scene and settings: where it
/// is cached, and whom it wakes.
#[derive(SystemParam)]
struct Precomputer<'w> {
    cache_dir: Res<'w, LightCacheDir>,
    waker: Option<Res<'w, LightWaker>>,
}

impl Precomputer<'_> {
    /// The precomputation of `scene` with `settings` (or its cached model)
    /// as a task, which wakes the app when its model is there to take;
    /// what it has alike with the model `beside` (the tracers, the sensors,
    /// most patch sides of a large model) is that model's, shared.
    fn spawn(&self, scene: Arc<crate::scene::Scene>, settings: light::LightSettings, beside: Option<Arc<LightModel>>) -> Precompute {
        let dir = self.cache_dir.0.clone();
        let waker = self.waker.as_deref().cloned();
        let result = Arc::new(Mutex::new(None));
        let slot = result.clone();
        let task = AsyncComputeTaskPool::get().spawn(async move {
            // The viewer meters exposure by tracing the model in a frame.
            let model = cache::precompute_cached_beside(scene, settings, beside.as_deref(), dir.as_deref(), &|_| {})
                .map(|(model, _)| model.with_tracer());
            *slot.lock().expect("precomputation result lock") = Some(model);
            if let Some(LightWaker(wake)) = waker {
                wake();
            }
        });
        Precompute { _task: task, result }
    }
}

fn finish_precompute(mut engine: ResMut<LightEngine>, mut failed: MessageWriter<LightingFailed>) {
    let Some(precompute) = engine.precompute.as_ref() else { return };
    let Some(result) = precompute.result.lock().expect("precomputation result lock").take() else { return };
    engine.precompute = None;
    match result {
        Ok(model) => {
            // The settings' own model lands first; the refinement starts after it.
            let model = Some(Arc::new(model));
            if engine.model.is_some() {
                engine.smoothed = model
            } else {
                engine.model = model
            }
            engine.relight_pending = true;
        }
        Err(message) => {
            engine.refinement = None;
            failed.write(LightingFailed { message });
        }
    }
}

/// Starts the precomputation for display once the first light is shown
/// (converged), so that it never holds that light back.
fn start_refinement(state: Res<LightingState>, precomputer: Precomputer, mut engine: ResMut<LightEngine>) {
    let shown = state.converged && state.generation == engine.generation() && !engine.relight_pending;
    if engine.precompute.is_some() || !shown {
        return;
    }
    if let Some((scene, settings)) = engine.refinement.take() {
        engine.precompute = Some(precomputer.spawn(scene, settings, engine.model.clone()));
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
    let (Some(model), Some(sun_sky)) = (engine.smoothed.clone().or_else(|| engine.model.clone()), sun_sky) else { return };
    if !engine.relight_pending {
        return;
    }
    engine.relight_pending = false;
    let generation = engine.generation.fetch_add(1, Ordering::SeqCst) + 1;
    let current = engine.generation.clone();
    let sky = sun_sky.sky.clone();
    let warm = state.lighting.clone();
    // Where the light shown is the smoothed model's, the converged sensors
    // still read as `sensors` reads them: from the settings' own model.
    let numbers = engine.smoothed.as_ref().and(engine.model.clone());
    let newest = Arc::new(Mutex::new(None));
    engine.results = Some(newest.clone());
    AsyncComputeTaskPool::get()
        .spawn(async move {
            let mut relight = model.relight(&sky, warm.as_ref());
            loop {
                let converged = relight.is_converged();
                let mut lighting = relight.lighting();
                if converged && let Some(numbers) = &numbers {
                    lighting.sensors = numbers.solve(&sky, None).sensors;
                }
                // Gone: a newer relight, another scene, or the app closed.
                if current.load(Ordering::SeqCst) != generation || Arc::strong_count(&newest) == 1 {
                    return;
                }
                *newest.lock().expect("relight results lock") = Some(RelightResult { generation, lighting, converged });
                if converged {
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
    let latest = results.lock().expect("relight results lock").take().filter(|r| r.generation == newest);
    if let Some(result) = latest {
        *state = LightingState { lighting: Some(result.lighting), generation: result.generation, converged: result.converged };
        updated.write(LightingUpdated { generation: result.generation, converged: result.converged });
    }
}
