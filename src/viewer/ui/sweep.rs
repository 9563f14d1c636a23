//! The sweep panel: a window material, one or two of its keys with their
//! ranges, run in the background; the curve or heat map fills in, hovering
//! reads a cell, clicking one applies its keys to the material.

use bevy::ecs::system::SystemParam;
use bevy::prelude::*;
use bevy_egui::egui::{self, Ui};
use egui_plot::{Heatmap, Line, Plot, PlotPoint, PlotPoints, Points};

use crate::ecs::{ActiveScene, PanelRegistry};
use crate::panel::KeyKind;
use crate::scene::MaterialKind;
use crate::viewer::sweep::{KeyRange, SweepStudy};

/// What the sweep panel reads and writes.
#[derive(SystemParam)]
pub struct SweepPanel<'w> {
    study: ResMut<'w, SweepStudy>,
    active: Res<'w, ActiveScene>,
    registry: Res<'w, PanelRegistry>,
}

impl SweepPanel<'_> {
    /// Draws the panel.
    pub fn show(&mut self, ui: &mut Ui) {
        let Some(scene) = self.active.scene.clone() else { return };
        let study = &mut *self.study;
        ui.heading("Sweep (a window material's keys)");
        let windows: Vec<(u32, String)> =
            scene.materials.iter().enumerate().filter(|(_, m)| m.kind.transmits()).map(|(i, m)| (i as u32, m.name.clone())).collect();
        if windows.is_empty() {
            ui.label("The scene has no windows.");
            return;
        }
        let current = study.material.and_then(|m| windows.iter().find(|w| w.0 == m)).map_or("choose", |w| w.1.as_str()).to_string();
        let before = study.material;
        egui::ComboBox::from_label("material").selected_text(current).show_ui(ui, |ui| {
            for (index, name) in &windows {
                ui.selectable_value(&mut study.material, Some(*index), name);
            }
        });
        let Some(material) = study.material else { return };
        // The numeric keys of the material, with their ranges.
        let catalog = self.registry.catalog();
        let keys: Vec<(String, f64, f64)> = match &scene.materials[material as usize].kind {
            MaterialKind::Glass { .. } => vec![("transmittance".into(), 0.0, 1.0)],
            MaterialKind::Panel { panel, .. } => catalog
                .get(panel)
                .map(|t| {
                    t.keys()
                        .iter()
                        .flat_map(|k| match k.kind {
                            KeyKind::Number { range, .. } => vec![(k.name.to_string(), range.0, range.1)],
                            KeyKind::Count { range, .. } => vec![(k.name.to_string(), range.0 as f64, range.1 as f64)],
                            KeyKind::Numbers { range, default } => {
                                (0..default.len()).map(|i| (format!("{}[{i}]", k.name), range.0, range.1)).collect()
                            }
                            KeyKind::File { .. } => vec![],
                        })
                        .collect()
                })
                .unwrap_or_default(),
            MaterialKind::Diffuse { .. } => vec![],
        };
        if before != study.material || study.ranges.is_empty() {
            study.ranges =
                keys.iter().take(1).map(|(k, lo, hi)| KeyRange { key: k.clone(), lo: *lo, hi: *hi, step: (hi - lo) / 10.0 }).collect();
        }
        for slot in 0..2 {
            ui.horizontal(|ui| {
                let chosen = study.ranges.get(slot).map_or("none".to_string(), |r| r.key.clone());
                egui::ComboBox::from_id_salt(("sweep key", slot)).selected_text(chosen).show_ui(ui, |ui| {
                    if slot == 1 && ui.selectable_label(study.ranges.len() < 2, "none").clicked() {
                        study.ranges.truncate(1);
                    }
                    for (key, lo, hi) in &keys {
                        if ui.selectable_label(study.ranges.get(slot).is_some_and(|r| &r.key == key), key).clicked() {
                            let range = KeyRange { key: key.clone(), lo: *lo, hi: *hi, step: (hi - lo) / 10.0 };
                            if slot < study.ranges.len() {
                                study.ranges[slot] = range;
                            } else {
                                study.ranges.push(range);
                            }
                        }
                    }
                });
                if let Some(range) = study.ranges.get_mut(slot) {
                    ui.add(egui::DragValue::new(&mut range.lo).speed(0.5).prefix("from "));
                    ui.add(egui::DragValue::new(&mut range.hi).speed(0.5).prefix("to "));
                    ui.add(egui::DragValue::new(&mut range.step).speed(0.1).prefix("by "));
                }
            });
        }
        if study.is_running() {
            let (done, all) = study.progress();
            ui.add(egui::ProgressBar::new(done as f32 / all.max(1) as f32).text(format!("{done} of {all} combinations")));
        } else if ui.button("Run the sweep (the selected sensor: now, or its DA300 with a weather file; no sensor: the sDA)").clicked() {
            study.requested = true;
        }
        if let Some(e) = &study.error {
            ui.colored_label(egui::Color32::LIGHT_RED, e);
        }
        plot(ui, study);
    }
}

/// The curve or heat map of the cells in so far; hover reads a cell, a
/// click applies it.
fn plot(ui: &mut Ui, study: &mut SweepStudy) {
    let Some((grid, what)) = &study.grid else { return };
    let cells: Vec<Option<Result<f64, String>>> = study.cells.lock().expect("the sweep's cells").clone();
    let values: Vec<f64> = cells.iter().map(|c| c.as_ref().and_then(|v| v.as_ref().ok()).copied().unwrap_or(f64::NAN)).collect();
    let known: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
    let (lo, hi) = known.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
    let best = values.iter().enumerate().filter(|(_, v)| v.is_finite()).max_by(|a, b| a.1.total_cmp(b.1)).map(|(i, _)| i);
    ui.label(what.as_str());
    let xs = &grid.axes[0].values;
    let response = match grid.axes.get(1) {
        None => Plot::new("sweep_curve")
            .height(170.0)
            .x_axis_label(grid.axes[0].key.clone())
            .y_axis_label(what.clone())
            .allow_scroll(false)
            .show(ui, |plot| {
                let points: Vec<[f64; 2]> = xs.iter().zip(&values).filter(|(_, v)| v.is_finite()).map(|(x, v)| [*x, *v]).collect();
                plot.line(Line::new("value", PlotPoints::from(points.clone())));
                plot.points(Points::new("combinations", points).radius(3.0));
                if let Some(b) = best {
                    plot.points(Points::new("best", vec![[xs[b], values[b]]]).radius(6.0).color(egui::Color32::RED));
                }
                plot.pointer_coordinate().map(|p| nearest(xs, p.x))
            }),
        Some(second) => {
            let ys = &second.values;
            let (dx, dy) = (step(xs), step(ys));
            // Rows bottom up are the second key's values, columns the first's.
            let tiles: Vec<f64> =
                (0..ys.len()).flat_map(|j| (0..xs.len()).map(move |i| (i, j))).map(|(i, j)| values[i * ys.len() + j]).collect();
            let span = (hi - lo).max(1e-9);
            let colour = move |v: f64| {
                if !v.is_finite() {
                    return egui::Color32::from_gray(60);
                }
                let [r, g, b] = crate::viewer::annual::metric_colour((v - lo) / span);
                egui::Color32::from(egui::Rgba::from_rgb(r, g, b))
            };
            let map = Heatmap::new(tiles, xs.len())
                .at(PlotPoint::new(xs[0] - dx / 2.0, ys[0] - dy / 2.0))
                .tile_size(dx as f32, dy as f32)
                .custom_mapping(Box::new(colour))
                .show_labels(false)
                .name(what.clone());
            Plot::new("sweep_map")
                .height(220.0)
                .x_axis_label(grid.axes[0].key.clone())
                .y_axis_label(second.key.clone())
                .allow_scroll(false)
                .show(ui, |plot| {
                    plot.heatmap(map);
                    if let Some(b) = best {
                        let (i, j) = (b / ys.len(), b % ys.len());
                        plot.points(Points::new("best", vec![[xs[i], ys[j]]]).radius(6.0).color(egui::Color32::WHITE));
                    }
                    plot.pointer_coordinate().map(|p| nearest(xs, p.x) * ys.len() + nearest(ys, p.y))
                })
        }
    };
    if let Some(cell) = response.inner {
        let keys: Vec<String> = grid.axes.iter().zip(grid.combination(cell)).map(|(a, v)| format!("{} = {v}", a.key)).collect();
        let value = match &cells[cell] {
            Some(Ok(v)) => format!("{v:.1}"),
            Some(Err(e)) => format!("does not build: {e}"),
            None => "not yet".into(),
        };
        ui.label(format!("{}: {value} (click to apply)", keys.join(", ")));
        if response.response.clicked() && matches!(cells[cell], Some(Ok(_))) {
            study.apply = Some(cell);
        }
    } else if let Some(b) = best {
        let keys: Vec<String> = grid.axes.iter().zip(grid.combination(b)).map(|(a, v)| format!("{} = {v}", a.key)).collect();
        ui.label(format!("best so far: {}: {:.1}", keys.join(", "), values[b]));
    }
}

/// The spacing of a key's values (1 for a single value).
fn step(values: &[f64]) -> f64 {
    if values.len() > 1 { values[1] - values[0] } else { 1.0 }
}

/// The index of the value nearest to `x`.
fn nearest(values: &[f64], x: f64) -> usize {
    values.iter().enumerate().min_by(|a, b| (a.1 - x).abs().total_cmp(&(b.1 - x).abs())).map_or(0, |(i, _)| i)
}
