//! Lobe coefficients: the interreflected light of a panel's lobes,
//! tabulated over the directions they leave the panel in, so that many
//! models of one panel on one room (a sweep's combinations, each over a
//! year of suns) read their lobes' bounces instead of tracing them hour by
//! hour.
//!
//! A lobe is a fake sun ([`SunBeam`]) whose light leaves by its panel
//! group's windows. Its interreflected light at a sensor (the first bounce
//! where the sensor's rays land, the later bounces through the sensor
//! coefficients) is linear in the lobe's normal irradiance and, with the
//! windows sunlit throughout, a function of its direction alone. The table
//! traces it at the nodes of a grid over the two tilt angles of that
//! direction in the panel's frame (α = atan(x/z), β = atan(y/z): no pole,
//! even steps about the panel's normal) and reads it between nodes
//! bilinearly: the 5-phase method's sun coefficients, for fake suns. Only
//! nodes some lobe falls among are traced, once, as lobes ask for them
//! ([`LobeTable::trace`]); a node is a sun path node's work
//! ([`super::SunPath`]) plus a first bounce.
//!
//! What is sharp is not read from the table: the lobes' direct light at
//! the sensors is traced every hour ([`SensorCoefficients::sun_response_with_lobes`];
//! on from the windows to the sun only where it lights them unevenly), and
//! so is their first bounce in an hour whose sun lights the group's windows
//! only in part (a reveal's or an overhang's shadow on them); the later
//! bounces are then read from the table, scaled by the sunlit share.

use std::collections::HashMap;

use glam::DVec3;

use super::coefficients::{LitSides, SunResponse, lit_sides};
use super::{LightModel, SURFACE_OFFSET, SensorCoefficients, SunBeam, par_map};
use crate::sky::LUMINOUS_EFFICACY;

/// The grid's step in both tilt angles, degrees.
pub const LOBE_STEP: f64 = 2.0;
/// The steepest tilt a node is traced at, in steps (88°): a lobe beyond
/// it is read from the last nodes.
const LAST_NODE: f64 = 44.0;
/// Window points whose sun decides the share of a group's windows sunlit.
const SUNLIT_POINTS: usize = 256;

/// A node: the panel group and the two tilt angles, in steps.
type Node = (u32, i32, i32);

/// How the sun lights a table's panel windows in one hour: per group, the
/// share of the sun reaching its windows (glass before them counts) and
/// whether that share is the same all over them.
pub struct Sunlit(Vec<(f64, bool)>);

impl Sunlit {
    /// Whether the sun lights every group's windows alike all over.
    pub fn is_even(&self) -> bool {
        self.0.iter().all(|&(_, even)| even)
    }
}

/// One node's interreflected light at every sensor per W/m² the lobe
/// brings to the panel's plane (its normal irradiance times the cosine to
/// the panel's normal: so near the plane, where that cosine changes fast
/// between nodes, the light read follows the window's projected area),
/// lux, the windows sunlit throughout.
struct NodeLight {
    /// The first bounce where the sensors' rays land.
    first: Vec<f32>,
    /// The later bounces.
    later: Vec<f32>,
}

/// The lobe coefficients of one panel material's groups on one model.
pub struct LobeTable {
    /// The panel groups of the material.
    groups: Vec<u32>,
    nodes: HashMap<Node, NodeLight>,
}

impl LobeTable {
    /// An empty table for the lobes of panel material `material` (an index
    /// into the scene's materials) on `model`.
    pub fn new(model: &LightModel, material: u32) -> Self {
        let groups = (0..model.panel_groups.len() as u32).filter(|&g| model.panel_groups[g as usize].material == material).collect();
        Self { groups, nodes: HashMap::new() }
    }

    /// The panel groups whose lobes the table holds.
    pub fn groups(&self) -> &[u32] {
        &self.groups
    }

    /// Nodes traced so far.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Whether no node is traced yet.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Whether `beam` is a lobe the table holds.
    fn holds(&self, beam: &SunBeam) -> bool {
        beam.panel_group.is_some_and(|g| self.groups.contains(&g))
    }

    /// Traces the nodes around every lobe of `beams` that the table holds
    /// and lacks (`threads` as [`par_map`]; each node's light does not
    /// depend on them).
    pub fn trace<'b>(
        &mut self,
        model: &LightModel,
        coefficients: &SensorCoefficients,
        beams: impl IntoIterator<Item = &'b SunBeam>,
        threads: Option<usize>,
    ) {
        let missing: std::collections::BTreeSet<Node> = beams
            .into_iter()
            .filter(|b| self.holds(b))
            .flat_map(|b| corners(b, way_out(model, b)).0)
            .filter(|node| !self.nodes.contains_key(node))
            .collect();
        let missing: Vec<Node> = missing.into_iter().collect();
        let samples = coefficients.path_sun_samples(model.settings.sun_samples_per_patch);
        let traced = par_map(threads, missing.len(), |k| {
            let (beams, cos) = node_beam(model, missing[k]);
            let beams = [beams];
            let reach = model.sides_reach(&beams, Some(1));
            let first = coefficients.first_bounce(model, &beams, &reach, Some(1));
            ((first, cos), lit_sides(&model.sun_on_sides(&beams, &|side| samples[side], false, Some(1)).irradiance))
        });
        let (firsts, sources): (Vec<(Vec<f64>, f64)>, Vec<LitSides>) = traced.into_iter().unzip();
        let mut later = vec![vec![0.0; model.sensors.len()]; missing.len()];
        coefficients.add_later_bounces(model, &mut later, &sources);
        let lights = firsts.into_iter().zip(later).map(|((first, cos), later)| {
            let per_plane = |values: Vec<f64>| values.iter().map(|&v| (v / cos) as f32).collect();
            NodeLight { first: per_plane(first), later: per_plane(later) }
        });
        self.nodes.extend(missing.into_iter().zip(lights));
    }

    /// How the sun from `sun` lights each of the table's groups' windows,
    /// from shadow rays at points spread over them. It follows the sun, not
    /// the panel model: a year's hours find it once for every model.
    pub fn sunlit(&self, model: &LightModel, sun: DVec3) -> Sunlit {
        Sunlit(
            self.groups
                .iter()
                .map(|&g| {
                    let points = &model.panel_samples[g as usize].points;
                    let stride = points.len().div_ceil(SUNLIT_POINTS).max(1);
                    let reached: Vec<f64> =
                        points.iter().step_by(stride).map(|&p| model.sun_transmittance(p + sun * SURFACE_OFFSET, sun)).collect();
                    let mean = reached.iter().sum::<f64>() / reached.len().max(1) as f64;
                    (mean, reached.iter().all(|&t| t == reached[0]))
                })
                .collect(),
        )
    }

    /// Adds one lobe's interreflected light, read from the nodes around it,
    /// times `scale` (its normal irradiance, or a share of it): the first
    /// bounce to `first` (unless `None`), the later bounces to `later`.
    fn add(&self, model: &LightModel, beam: &SunBeam, scale: f64, first: Option<&mut [f64]>, later: &mut [f64]) {
        let out = way_out(model, beam);
        let (nodes, weights) = corners(beam, out);
        // Per W/m² on the panel's plane (`NodeLight`).
        let scale = scale * out.z;
        let mut first = first;
        for (node, weight) in nodes.iter().zip(weights) {
            let light = self.nodes.get(node).expect("traced before it is read");
            let w = scale * weight;
            if let Some(first) = first.as_deref_mut() {
                first.iter_mut().zip(&light.first).for_each(|(e, &v)| *e += w * f64::from(v));
            }
            later.iter_mut().zip(&light.later).for_each(|(e, &v)| *e += w * f64::from(v));
        }
    }
}

/// A lobe's way out of its panel, in the panel's frame (z into the room).
fn way_out(model: &LightModel, beam: &SunBeam) -> DVec3 {
    model.panel_groups[beam.panel_group.expect("a lobe") as usize].frame.to_panel(-beam.to_light)
}

/// The four nodes around a lobe leaving its panel along `out` ([`way_out`])
/// and their bilinear weights.
fn corners(beam: &SunBeam, out: DVec3) -> ([Node; 4], [f64; 4]) {
    let group = beam.panel_group.expect("a lobe");
    let step = LOBE_STEP.to_radians();
    let tilt = |along: f64| (along.atan2(out.z) / step).clamp(-LAST_NODE, LAST_NODE);
    let (a, b) = (tilt(out.x), tilt(out.y));
    let (a0, b0) = (a.floor().min(LAST_NODE - 1.0), b.floor().min(LAST_NODE - 1.0));
    let (fa, fb) = (a - a0, b - b0);
    let (a0, b0) = (a0 as i32, b0 as i32);
    (
        [(group, a0, b0), (group, a0 + 1, b0), (group, a0, b0 + 1), (group, a0 + 1, b0 + 1)],
        [(1.0 - fa) * (1.0 - fb), fa * (1.0 - fb), (1.0 - fa) * fb, fa * fb],
    )
}

/// A node's unit lobe (1 W/m² normal to it, its windows sunlit
/// throughout) and its cosine to the panel's normal.
fn node_beam(model: &LightModel, (group, a, b): Node) -> (SunBeam, f64) {
    let step = LOBE_STEP.to_radians();
    let out = DVec3::new((f64::from(a) * step).tan(), (f64::from(b) * step).tan(), 1.0).normalize();
    let beam = SunBeam {
        to_light: -model.panel_groups[group as usize].frame.to_world(out).normalize(),
        normal_irradiance: 1.0,
        panel_group: Some(group),
        window_sun: None,
    };
    (beam, out.z)
}

impl SensorCoefficients {
    /// The sun's light at every sensor for a sun of 1 W/m² (as
    /// [`Self::sun_response`]; `beams`: its [`LightModel::sun_beams`]),
    /// with the interreflected light of
    /// `table`'s lobes read from it (traced first where it lacks nodes:
    /// [`LobeTable::trace`]) and that of every other beam given (`rest`,
    /// lux per W/m²: the sun through glass, other panels' lobes).
    /// `sunlit`: [`LobeTable::sunlit`] for this sun. The direct light of
    /// every beam is traced.
    pub fn sun_response_with_lobes(
        &self,
        model: &LightModel,
        beams: &[SunBeam],
        table: &LobeTable,
        sunlit: &Sunlit,
        rest: &[f32],
        threads: Option<usize>,
    ) -> SunResponse {
        let measured = model.measured_sun(beams);
        // Where the sun lights a group's windows evenly, its lobes leave every
        // point of them alike: no shadow ray from the windows to the sun.
        let evenly = |beam: &SunBeam| {
            let group = table.groups.iter().position(|&g| Some(g) == beam.panel_group)?;
            let (share, even) = sunlit.0[group];
            even.then_some(share)
        };
        let direct_beams: Vec<SunBeam> = beams
            .iter()
            .filter_map(|beam| match evenly(beam) {
                None => Some(*beam),
                Some(share) if share > 0.0 => {
                    Some(SunBeam { normal_irradiance: beam.normal_irradiance * share, window_sun: None, ..*beam })
                }
                Some(_) => None,
            })
            .collect();
        let direct_sun = model.sensors_sun(&direct_beams, &measured);
        let direct = par_map(threads, model.sensors.len(), |i| (model.sensor_direct_sun(i, &direct_sun) * LUMINOUS_EFFICACY) as f32);
        let mut first = vec![0.0; model.sensors.len()];
        let mut later = vec![0.0; model.sensors.len()];
        for (&group, &(share, even)) in table.groups.iter().zip(&sunlit.0) {
            let lobes: Vec<SunBeam> = beams.iter().filter(|b| b.panel_group == Some(group)).copied().collect();
            if share <= 0.0 || lobes.is_empty() {
                continue;
            }
            if even {
                lobes.iter().for_each(|lobe| table.add(model, lobe, lobe.normal_irradiance * share, Some(&mut first), &mut later));
            } else {
                // Windows in part shade: where on them the lobes leave is sharp.
                let reach = model.sides_reach(&lobes, threads);
                self.first_bounce(model, &lobes, &reach, threads).iter().zip(&mut first).for_each(|(v, e)| *e += v);
                lobes.iter().for_each(|lobe| table.add(model, lobe, lobe.normal_irradiance * share, None, &mut later));
            }
        }
        let interreflected = rest.iter().zip(first.iter().zip(&later)).map(|(&r, (f, l))| r + (f + l) as f32).collect();
        SunResponse { direct, interreflected }
    }
}
