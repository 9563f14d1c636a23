//! Sweeps in the viewer (the thesis's fig. 1.4g at the designer's desk): one
//! or two keys of a window material over a grid, judged by the selected
//! sensor now (lux) or, with a weather file open, by the scene's sDA over
//! the year; run in the background with [`crate::sweep::sweep`] on a model
//! of its own (from the light cache), the cells filling in as they come; a
//! clicked cell's keys are applied to the material (and the scene relit).

use std::sync::{Arc, Mutex};

use bevy::prelude::*;
use bevy::tasks::{AsyncComputeTaskPool, Task, block_on, futures_lite::future};

use super::annual::AnnualStudy;
use super::schedule::ViewerSystems;
use super::sensors::SelectedSensor;
use crate::ecs::{ActiveScene, EditMaterial, LightCacheDir, LightSettings, PanelRegistry, SunSky};
use crate::light::cache;
use crate::sweep::{Axis, Grid, Target, Variation, sweep};

/// The sweep's state and systems.
pub struct SweepPlugin;

impl Plugin for SweepPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<SweepStudy>()
            .add_systems(Update, (start_sweep, collect_sweep, apply_cell).chain().in_set(ViewerSystems::Sensors));
    }
}

/// One varied key as the panel edits it.
#[derive(Debug, Clone, PartialEq)]
pub struct KeyRange {
    /// `name` or `name[index]`.
    pub key: String,
    pub lo: f64,
    pub hi: f64,
    pub step: f64,
}

/// A grid's cells as they arrive: per combination (row-major) its value or
/// why it does not build.
pub type Cells = Arc<Mutex<Vec<Option<Result<f64, String>>>>>;

/// The sweep the panel sets up, and the one running or done.
#[derive(Resource, Default)]
pub struct SweepStudy {
    /// The material swept (index into the scene's materials).
    pub material: Option<u32>,
    /// One or two keys.
    pub ranges: Vec<KeyRange>,
    /// Set by the panel's button.
    pub requested: bool,
    /// The grid of the sweep running or done, with what its values are.
    pub grid: Option<(Grid, String)>,
    /// Its cells as they arrive.
    pub cells: Cells,
    task: Option<Task<Result<(), String>>>,
    variation: Option<Variation>,
    /// Why the last sweep could not run.
    pub error: Option<String>,
    /// A clicked cell whose keys go to the material.
    pub apply: Option<usize>,
}

impl SweepStudy {
    /// Whether a sweep is running.
    pub fn is_running(&self) -> bool {
        self.task.is_some()
    }

    /// Cells done and in all.
    pub fn progress(&self) -> (usize, usize) {
        let cells = self.cells.lock().expect("the sweep's cells");
        (cells.iter().filter(|c| c.is_some()).count(), cells.len())
    }
}

/// Starts a sweep when asked: the grid checked, the target chosen (the
/// selected sensor now, or the scene's sDA with a weather file open), and
/// the work on the compute pool.
#[allow(clippy::too_many_arguments)]
fn start_sweep(
    mut study: ResMut<SweepStudy>,
    active: Res<ActiveScene>,
    registry: Res<PanelRegistry>,
    selected: Res<SelectedSensor>,
    annual: Res<AnnualStudy>,
    sun_sky: Option<Res<SunSky>>,
    settings: Res<LightSettings>,
    cache_dir: Res<LightCacheDir>,
) {
    if !study.requested || study.is_running() {
        return;
    }
    study.requested = false;
    let (Some(scene), Some(material)) = (active.scene.clone(), study.material) else { return };
    let catalog = registry.catalog();
    let axes: Result<Vec<Axis>, String> =
        study.ranges.iter().map(|r| Axis::parse(&format!("{}={}..{}:{}", r.key, r.lo, r.hi, r.step))).collect();
    let prepared = axes.and_then(|axes| {
        let grid = Grid { axes };
        if grid.len() > 2_500 {
            return Err(format!("{} combinations: at most 2,500 in the viewer (the CLI takes more)", grid.len()));
        }
        let variation = Variation::new(&scene, &scene.materials[material as usize].name, &grid, &catalog)?;
        Ok((grid, variation))
    });
    let (grid, variation) = match prepared {
        Ok(ready) => ready,
        Err(e) => {
            study.error = Some(e);
            return;
        }
    };
    let weather = annual.weather.as_ref().map(|(_, w)| w.clone());
    let (sensor, sky) = (selected.0, sun_sky.map(|s| s.sky.clone()));
    let what = match (&weather, sensor) {
        (Some(_), Some(s)) => format!("DA300 at {} over the year (%)", scene.sensors[s].name),
        (Some(_), None) => "sDA300/50% over the year (%)".to_string(),
        (None, Some(s)) => format!("{} now (lux)", scene.sensors[s].name),
        (None, None) => {
            study.error = Some("select a sensor (or open a weather file for the year's sDA)".into());
            return;
        }
    };
    let cells: Cells = Arc::new(Mutex::new(vec![None; grid.len()]));
    study.cells = cells.clone();
    study.error = None;
    study.grid = Some((grid.clone(), what));
    study.variation = Some(variation.clone());
    let (settings, dir) = (settings.0, cache_dir.0.clone());
    study.task = Some(AsyncComputeTaskPool::get().spawn(async move {
        let (mut model, _) = cache::precompute_cached(scene, settings, dir.as_deref(), &|_| {})?;
        let sensors: Vec<usize> = sensor.into_iter().collect();
        let target = match (&weather, &sky) {
            (Some(weather), _) => Target::Year(weather, crate::annual::Occupancy::default()),
            (None, Some(sky)) => Target::Instant(sky),
            (None, None) => return Err("no sky yet".to_string()),
        };
        let count = grid.len();
        sweep(&mut model, &variation, &grid, 0..count, &sensors, target, &|outcome, _| {
            let value = outcome
                .result
                .as_ref()
                // The selected sensor's value (lux now, or its DA300), else the year's sDA.
                .map(|(values, sda)| values.first().copied().or(*sda).unwrap_or(0.0))
                .map_err(Clone::clone);
            // Combinations come in grid order: each fills the first empty cell.
            let mut cells = cells.lock().expect("the sweep's cells");
            if let Some(cell) = cells.iter_mut().find(|c| c.is_none()) {
                *cell = Some(value);
            }
        });
        Ok(())
    }));
}

/// Takes the sweep's end (or its failure).
fn collect_sweep(mut study: ResMut<SweepStudy>) {
    if let Some(task) = &mut study.task
        && let Some(result) = block_on(future::poll_once(task))
    {
        study.task = None;
        if let Err(e) = result {
            study.error = Some(e);
        }
    }
}

/// Applies a clicked cell's keys to the swept material.
fn apply_cell(mut study: ResMut<SweepStudy>, mut edits: MessageWriter<EditMaterial>) {
    let Some(cell) = study.apply.take() else { return };
    let (Some((grid, _)), Some(variation)) = (&study.grid, &study.variation) else { return };
    if cell >= grid.len() {
        return;
    }
    match variation.material(grid, &grid.combination(cell)) {
        Ok(material) => {
            edits.write(EditMaterial { index: variation.material, kind: material.kind });
        }
        Err(e) => study.error = Some(e),
    }
}
