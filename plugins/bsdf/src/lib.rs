//! Measured or simulated BSDF data for heliodon (thesis section 3.4): an
//! LBNL BSDF XML file (WINDOW6 format: matrices over a Klems full, half or
//! quarter basis, or Radiance's tensor trees of 3 or 4 dimensions as
//! genBSDF and bsdf2ttree write them) read once, then for each measured
//! incoming direction the transmitted light is fitted greedily with k
//! lobes of width α (thesis algorithm 2: each lobe takes the cone of
//! outgoing bins holding the most flux, which is then zeroed). The flux no
//! lobe represents stays as diffuse transmission, front reflection is
//! diffuse reflection, so energy is conserved. Between measured
//! directions, the three around the query (a Delaunay triangulation of the
//! directions' projections) are blended with barycentric weights, their
//! lobes corresponded by rank.
//!
//! A Klems file's measured directions are its patches, in and out. A
//! tensor tree's are its leaves: it is read at the middle of each incoming
//! leaf (up to 32 per axis), into 32 × 32 outgoing bins of equal projected
//! solid angle (the Shirley–Chiu square), each the mean of the tree's
//! leaves over the bin. A tree is constant over an incoming leaf and
//! Radiance reads it so, without interpolation; so does the fit: a query
//! takes the fit of the leaf holding it (of a 3-D tree, the leaf's sample
//! nearest in azimuth, turned to the query's azimuth, as the tree turns
//! with the light). A metal-slat tree's transmittance can step from 0.08
//! to 0.21 between two leaves 1° apart; a blend there would be neither.
//!
//! Each lobe is as wide as the light it stands for (2√2 times the RMS angle
//! of its flux, the bins' own extent included, at most the cone), so the
//! engine spreads it as the data does; "Reflection Back" gives the share of
//! the room's light the panel returns to it.
//!
//! Scene-file keys (`kind = "panel"`, `panel = "bsdf"`): `file` (relative
//! to the scene file), `lobes` (k, 1-8, default 3), `lobe_width` (α in
//! degrees, 1-90, default 23).
//!
//! Directions follow Radiance's reading of Klems bases (bsdf_m.c): patch
//! (θ, φ) is (cos φ sin θ, sin φ sin θ, cos θ) in the panel frame, for
//! incoming light as the way it travels and for outgoing as the way it
//! leaves into the room; and of tensor trees (bsdf_t.c): the panel frame
//! is the tree's, +z into the room.

pub mod tensor_tree;
pub mod xml;

use std::path::{Path, PathBuf};
use std::sync::Arc;

use heliodon_core::glam::{DQuat, DVec3};
use heliodon_core::panel::{Key, Lobe, MeasuredTransmission, PanelModel, PanelResponse, PanelType, ParameterError, Parameters};
use spade::{DelaunayTriangulation, FloatTriangulation, Point2, Triangulation};

use tensor_tree::{TensorTree, cell_direction};
use xml::{Basis, BsdfFile, Scattering};

const FILE: Key = Key::file("file", "LBNL BSDF XML (Klems basis or tensor tree)", "xml");
const LOBES: Key = Key::count("lobes", "specular lobes fitted per direction", (1, 8), 3);
const LOBE_WIDTH: Key = Key::number("lobe_width", "full angle of the cone each lobe takes (°)", (1.0, 90.0), 23.0);

/// The `bsdf` panel type.
pub struct Bsdf;

impl PanelType for Bsdf {
    fn name(&self) -> &str {
        "bsdf"
    }

    fn keys(&self) -> &[Key] {
        &[FILE, LOBES, LOBE_WIDTH]
    }

    fn build(&self, parameters: &Parameters) -> Result<Arc<dyn PanelModel>, ParameterError> {
        let path = parameters.path(&FILE)?;
        let lobes = parameters.count(&LOBES)? as usize;
        let width = parameters.number(&LOBE_WIDTH)?;
        let text =
            std::fs::read_to_string(&path).map_err(|e| ParameterError::new(FILE.name, format!("cannot read {}: {e}", path.display())))?;
        let file = xml::parse(&text, &path).map_err(|e| ParameterError::new(FILE.name, e))?;
        Ok(Arc::new(BsdfModel { file: Some(path), ..BsdfModel::fit(&file, lobes, width) }))
    }
}

/// The centre directions of a Klems basis's patches and their projected
/// solid angles π(cos²θlo − cos²θhi)/nφ.
pub fn klems_patches(basis: &Basis) -> Vec<(DVec3, f64)> {
    let mut out = Vec::with_capacity(basis.patch_count());
    for ring in &basis.rings {
        let (lo, hi) = (ring.theta_low.to_radians(), ring.theta_high.to_radians());
        let theta = if ring.phis == 1 { 0.0 } else { 0.5 * (lo + hi) };
        let projected = std::f64::consts::PI * (lo.cos().powi(2) - hi.cos().powi(2)) / ring.phis as f64;
        for j in 0..ring.phis {
            let phi = 2.0 * std::f64::consts::PI * j as f64 / ring.phis as f64;
            out.push((DVec3::new(phi.cos() * theta.sin(), phi.sin() * theta.sin(), theta.cos()), projected));
        }
    }
    out
}

/// The solid angles of a Klems basis's patches, 2π(cos θlo − cos θhi)/nφ.
fn klems_solid_angles(basis: &Basis) -> Vec<f64> {
    let ring = |r: &xml::Ring| std::f64::consts::TAU * (r.theta_low.to_radians().cos() - r.theta_high.to_radians().cos()) / r.phis as f64;
    basis.rings.iter().flat_map(|r| std::iter::repeat_n(ring(r), r.phis)).collect()
}

/// The fitted response to one measured incoming direction.
#[derive(Debug, Clone)]
struct Fitted {
    /// Lobes by decreasing share.
    lobes: Vec<Lobe>,
    diffuse_transmittance: f64,
    diffuse_reflectance: f64,
}

/// For every outgoing bin, the bins within the cone of full angle `width`
/// degrees around it: the candidates of a lobe centred there.
fn cones(directions: &[DVec3], width: f64) -> Vec<Vec<u32>> {
    let cos_radius = (width.to_radians() / 2.0).cos();
    directions
        .iter()
        .map(|centre| (0..directions.len() as u32).filter(|&o| directions[o as usize].dot(*centre) >= cos_radius - 1e-12).collect())
        .collect()
}

/// Greedy lobe selection (thesis algorithm 2) over the transmitted flux
/// `flux[o]` of the outgoing bins (`bins`: their directions and solid
/// angles): `count` lobes, each the cone of full angle `width` ([`cones`])
/// holding the most flux (its direction the flux-weighted mean), whose
/// bins are then zeroed. A lobe's width is the spread of that flux: 2√2
/// times its RMS angle from the lobe's direction (each bin's own extent,
/// Ω/2π, included), as light filling a cone that wide evenly would have;
/// `width` at most. Returns the lobes and what no lobe took.
fn greedy_lobes(flux: &[f64], bins: &Bins, cones: &[Vec<u32>], count: usize, width: f64) -> (Vec<Lobe>, f64) {
    let directions = &bins.directions;
    let mut remaining = flux.to_vec();
    let mut lobes = Vec::new();
    for _ in 0..count {
        let best = cones
            .iter()
            .enumerate()
            .map(|(c, cone)| (c, cone.iter().map(|&o| remaining[o as usize]).sum::<f64>()))
            .max_by(|a, b| a.1.total_cmp(&b.1).then(b.0.cmp(&a.0)));
        let Some((centre, share)) = best.filter(|b| b.1 > 1e-9) else { break };
        let mean = cones[centre].iter().map(|&o| directions[o as usize] * remaining[o as usize]).sum::<DVec3>().normalize();
        let mut squared = 0.0;
        for &o in &cones[centre] {
            let angle = directions[o as usize].angle_between(mean);
            squared += remaining[o as usize] * (angle * angle + bins.solid_angles[o as usize] / std::f64::consts::TAU);
            remaining[o as usize] = 0.0;
        }
        let spread = (2.0 * std::f64::consts::SQRT_2 * (squared / share).sqrt()).to_degrees();
        lobes.push(Lobe { direction: mean, share, width: spread.min(width) });
    }
    (lobes, remaining.iter().sum())
}

/// Outgoing bins: their directions (into the room) and solid angles (sr).
struct Bins {
    directions: Vec<DVec3>,
    solid_angles: Vec<f64>,
}

/// A file's data as the fit reads it: per measured incoming direction,
/// the transmitted flux into each outgoing bin and the hemispherical
/// reflectance, both for light from outside.
struct Measured {
    /// How a query direction finds the measured directions (the way the
    /// light travels, panel frame) it is read from.
    lookup: Lookup,
    /// The outgoing bins.
    bins: Bins,
    /// Share of the incoming flux into each bin, `[incoming][bin]`.
    flux: Vec<Vec<f64>>,
    /// Share of the incoming flux reflected back outside.
    reflected: Vec<f64>,
}

/// Incoming leaves a tensor tree is read at per axis, at most (a finer
/// tree is read at the middles of groups of its leaves).
const TREE_INCOMING: usize = 32;

/// Outgoing bins of a tensor tree per axis of its square.
const TREE_BINS: usize = 32;

/// Samples per bin and axis, at most (the mean over a bin is taken at the
/// tree's finest leaves up to this).
const TREE_SAMPLES: usize = 2;

impl Measured {
    fn of(file: &BsdfFile) -> Self {
        match &file.scattering {
            Scattering::Klems { basis, transmission, reflection, .. } => {
                let patches = klems_patches(basis);
                let directions: Vec<DVec3> = patches.iter().map(|p| p.0).collect();
                let hemisphere = |i: usize, get: &dyn Fn(usize, usize) -> f64| {
                    (0..patches.len()).map(|o| get(i, o) * patches[o].1).collect::<Vec<f64>>()
                };
                Self {
                    lookup: Lookup::blend(&directions),
                    flux: (0..patches.len()).map(|i| hemisphere(i, &|i, o| transmission.get(i, o))).collect(),
                    reflected: (0..patches.len())
                        .map(|i| reflection.as_ref().map_or(0.0, |r| hemisphere(i, &|i, o| r.get(i, o)).iter().sum()))
                        .collect(),
                    bins: Bins { directions, solid_angles: klems_solid_angles(basis) },
                }
            }
            Scattering::TensorTree { transmission, reciprocal, reflection, .. } => {
                Self::of_trees(transmission, *reciprocal, reflection.as_ref())
            }
        }
    }

    /// A tensor tree read at the middles of its incoming leaves into
    /// [`TREE_BINS`]² outgoing bins.
    fn of_trees(transmission: &TensorTree, reciprocal: bool, reflection: Option<&TensorTree>) -> Self {
        let finest = (1.0 / transmission.smallest_leaf()).round() as usize;
        // A 4-D tree's outgoing leaves line up with the bins; a 3-D tree's
        // turn with the light, so every bin takes the most samples.
        let samples = if transmission.dims() == 4 { (finest / TREE_BINS).clamp(1, TREE_SAMPLES) } else { TREE_SAMPLES };
        let side = TREE_BINS * samples;
        // Every sample of the square, made once: its direction into the
        // room, its mirror back outside, and its bin.
        let points: Vec<(DVec3, DVec3, usize)> = (0..side * side)
            .map(|k| {
                let (u, v) = (k / side, k % side);
                (cell_direction(k, side, 1.0), cell_direction(k, side, -1.0), (u / samples) * TREE_BINS + v / samples)
            })
            .collect();
        let directions: Vec<DVec3> = (0..TREE_BINS * TREE_BINS).map(|b| cell_direction(b, TREE_BINS, 1.0)).collect();
        // Equal projected solid angles: π / N² ÷ cos θ each (the rim's kept finite).
        let solid_angles = directions.iter().map(|d| std::f64::consts::PI / (TREE_BINS * TREE_BINS) as f64 / d.z.max(0.05)).collect();
        let bins = Bins { directions, solid_angles };
        // Each sample stands for π / side² of projected solid angle.
        let weight = std::f64::consts::PI / (side * side) as f64;
        // A coarse tree is read at 8 leaves per axis at least: a uniform one
        // (a single leaf) still has directions all round.
        let cells = finest.clamp(8, TREE_INCOMING);
        let incoming = tree_incoming(transmission.dims(), cells);
        let lookup = if transmission.dims() == 4 { Lookup::Square { cells } } else { Lookup::rings(cells) };
        let mut flux = Vec::with_capacity(incoming.len());
        let mut reflected = Vec::with_capacity(incoming.len());
        for &travel in &incoming {
            // Radiance's vectors point away from the surface: toward the source is −travel.
            let mut bin_flux = vec![0.0; TREE_BINS * TREE_BINS];
            for &(out, _, bin) in &points {
                let bsdf = if reciprocal { transmission.value(out, -travel) } else { transmission.value(-travel, out) };
                bin_flux[bin] += bsdf * weight;
            }
            flux.push(bin_flux);
            reflected.push(reflection.map_or(0.0, |r| points.iter().map(|&(_, back, _)| r.value(-travel, back) * weight).sum()));
        }
        Self { lookup, bins, flux, reflected }
    }
}

/// Samples per axis of each hemisphere's square for a tree's back
/// reflectance (32⁴ leaf lookups).
const BACK_SAMPLES: usize = 32;

/// The share of diffuse light from the room that a file's "Reflection
/// Back" returns to it: (1/π) ∫∫ f cos θᵢ cos θₒ dωᵢ dωₒ over the room's
/// hemisphere twice; 0 without that data.
fn back_reflectance(file: &BsdfFile) -> f64 {
    let rho = match &file.scattering {
        Scattering::Klems { basis, back_reflection: Some(matrix), .. } => {
            let patches = klems_patches(basis);
            let n = patches.len();
            (0..n).map(|i| patches[i].1 * (0..n).map(|o| matrix.get(i, o) * patches[o].1).sum::<f64>()).sum::<f64>() / std::f64::consts::PI
        }
        Scattering::TensorTree { back_reflection: Some(tree), .. } => {
            // Each sample of a square stands for π / K² of projected solid angle.
            let k = BACK_SAMPLES;
            let directions: Vec<DVec3> = (0..k * k).map(|s| cell_direction(s, k, 1.0)).collect();
            let sum: f64 = directions.iter().map(|&i| directions.iter().map(|&o| tree.value(i, o)).sum::<f64>()).sum();
            std::f64::consts::PI * sum / (k * k * k * k) as f64
        }
        _ => 0.0,
    };
    rho.clamp(0.0, 1.0)
}

/// Azimuths a 3-D tree is read at on a ring of sin θ, 3.75° apart or fewer
/// near the normal: the fit of the one nearest a query is turned to it.
fn ring_azimuths(sin: f64) -> usize {
    ((96.0 * sin).ceil() as usize).max(4)
}

/// The directions (the way light travels) at the middles of a tree's
/// incoming leaves, `cells` per axis: for a 4-D tree each cell of the
/// incoming square; for a 3-D tree each ring of its sin θ axis (½ − ½ sin θ,
/// the axis's used half), at [`ring_azimuths`].
fn tree_incoming(dims: usize, cells: usize) -> Vec<DVec3> {
    let on_hemisphere = |[x, y]: [f64; 2]| DVec3::new(x, y, (1.0 - x * x - y * y).max(0.0).sqrt());
    let middle = |k: usize| (k as f64 + 0.5) / cells as f64;
    if dims == 4 {
        (0..cells * cells).map(|k| cell_direction(k, cells, 1.0)).collect()
    } else {
        (0..cells / 2)
            .flat_map(|k| {
                let sin = 1.0 - 2.0 * middle(k);
                let azimuths = ring_azimuths(sin);
                (0..azimuths).map(move |a| {
                    let phi = std::f64::consts::TAU * a as f64 / azimuths as f64;
                    on_hemisphere([sin * phi.cos(), sin * phi.sin()])
                })
            })
            .collect()
    }
}

/// Outgoing cells per axis of a tensor tree's square, at most (its finest
/// leaves, as long as they are no finer). A 3-D tree turns its outgoing
/// square with the light, so its leaves cross the cells: twice its finest
/// leaves, up to this, keeps them within a cell's width.
const TREE_CELLS: usize = 64;

/// The Klems full basis (θ from, θ to in degrees, patches around): the
/// incoming patches a tree's light is gathered in, as `bsdf2klems` and
/// Radiance's 3-phase method take them.
const KLEMS_FULL: [(f64, f64, usize); 9] = [
    (0.0, 5.0, 1),
    (5.0, 15.0, 8),
    (15.0, 25.0, 16),
    (25.0, 35.0, 20),
    (35.0, 45.0, 24),
    (45.0, 55.0, 24),
    (55.0, 65.0, 24),
    (65.0, 75.0, 16),
    (75.0, 90.0, 12),
];

/// Incoming directions per axis of a Klems patch a tree's row is averaged over.
const PATCH_SAMPLES: usize = 4;

/// Klems patches: per ring, θ from, θ to (radians) and its first patch and count.
type KlemsRings = Vec<(f64, f64, usize, usize)>;

fn klems_rings(rings: impl Iterator<Item = (f64, f64, usize)>) -> KlemsRings {
    let mut start = 0;
    rings
        .map(|(low, high, phis)| {
            start += phis;
            (low.to_radians(), high.to_radians(), start - phis, phis)
        })
        .collect()
}

/// A file's transmission from outside into the room, looked up as
/// Radiance does: the Klems patch or tree leaf holding the directions.
enum Transmission {
    Klems {
        rings: KlemsRings,
        matrix: xml::Matrix,
    },
    Tree {
        tree: TensorTree,
        /// Only "Transmission Back" was given: read it by reciprocity.
        reciprocal: bool,
        /// Outgoing cells per axis of the square.
        cells: usize,
        /// The Klems full basis, for [`MeasuredTransmission::patch_row`].
        rings: KlemsRings,
    },
}

impl Transmission {
    fn of(file: &BsdfFile) -> Self {
        match &file.scattering {
            Scattering::Klems { basis, transmission, .. } => Self::Klems {
                rings: klems_rings(basis.rings.iter().map(|r| (r.theta_low, r.theta_high, r.phis))),
                matrix: transmission.clone(),
            },
            Scattering::TensorTree { transmission, reciprocal, .. } => {
                let finest = (1.0 / transmission.smallest_leaf()).round() as usize;
                let cells = if transmission.dims() == 4 { finest.min(TREE_CELLS) } else { (2 * finest).min(TREE_CELLS) };
                Self::Tree {
                    tree: transmission.clone(),
                    reciprocal: *reciprocal,
                    cells: cells.max(1),
                    rings: klems_rings(KLEMS_FULL.into_iter()),
                }
            }
        }
    }

    fn rings(&self) -> &KlemsRings {
        match self {
            Self::Klems { rings, .. } | Self::Tree { rings, .. } => rings,
        }
    }

    /// The Klems patch holding `direction` (bsdf_m.c: a ring by θ, then
    /// the patch whose middle φ is nearest).
    fn patch(rings: &[(f64, f64, usize, usize)], direction: DVec3) -> usize {
        let theta = direction.z.clamp(-1.0, 1.0).acos();
        let &(_, _, start, count) = rings.iter().find(|r| theta < r.1).unwrap_or(&rings[rings.len() - 1]);
        let phi = direction.y.atan2(direction.x).rem_euclid(std::f64::consts::TAU);
        start + (phi / std::f64::consts::TAU * count as f64 + 0.5) as usize % count
    }
}

impl MeasuredTransmission for Transmission {
    fn outgoing_cells(&self) -> usize {
        match self {
            Self::Klems { matrix, .. } => matrix.values.len() / matrix.incoming,
            Self::Tree { cells, .. } => cells * cells,
        }
    }

    fn incoming_patches(&self) -> usize {
        self.rings().last().map_or(0, |r| r.2 + r.3)
    }

    fn incoming_patch(&self, incoming: DVec3) -> usize {
        Self::patch(self.rings(), incoming)
    }

    fn patch_row(&self, patch: usize) -> Vec<f64> {
        let rings = self.rings();
        let Some(&(low, high, start, count)) = rings.iter().find(|r| patch < r.2 + r.3) else { return vec![0.0; self.outgoing_cells()] };
        match self {
            Self::Klems { matrix, .. } => (0..self.outgoing_cells()).map(|o| matrix.get(patch, o).max(0.0)).collect(),
            Self::Tree { .. } => {
                // The mean over the patch, its directions spread evenly in
                // projected solid angle (cos²θ) and φ.
                let mut sum = vec![0.0; self.outgoing_cells()];
                let width = std::f64::consts::TAU / count as f64;
                let middle = width * (patch - start) as f64;
                for k in 0..PATCH_SAMPLES * PATCH_SAMPLES {
                    let (a, b) = (
                        ((k / PATCH_SAMPLES) as f64 + 0.5) / PATCH_SAMPLES as f64,
                        ((k % PATCH_SAMPLES) as f64 + 0.5) / PATCH_SAMPLES as f64,
                    );
                    let cos2 = low.cos().powi(2) + a * (high.cos().powi(2) - low.cos().powi(2));
                    let (sin, phi) = ((1.0 - cos2).max(0.0).sqrt(), middle + width * (b - 0.5));
                    let row = self.row(DVec3::new(sin * phi.cos(), sin * phi.sin(), cos2.sqrt()));
                    sum.iter_mut().zip(row).for_each(|(s, f)| *s += f / (PATCH_SAMPLES * PATCH_SAMPLES) as f64);
                }
                sum
            }
        }
    }

    fn outgoing_cell(&self, outgoing: DVec3) -> usize {
        match self {
            Self::Klems { rings, .. } => Self::patch(rings, outgoing),
            Self::Tree { cells, .. } => {
                let cell = |x: f64| ((x * *cells as f64) as usize).min(cells - 1);
                let [u, v] = tensor_tree::disk_to_square(outgoing.x, outgoing.y);
                cell(u) * cells + cell(v)
            }
        }
    }

    fn row(&self, incoming: DVec3) -> Vec<f64> {
        match self {
            // A Klems file is constant over its incoming patches.
            Self::Klems { rings, .. } => self.patch_row(Self::patch(rings, incoming)),
            Self::Tree { tree, reciprocal, cells, .. } => (0..cells * cells)
                .map(|k| {
                    let out = cell_direction(k, *cells, 1.0);
                    let value = if *reciprocal { tree.value(out, -incoming) } else { tree.value(-incoming, out) };
                    value.max(0.0)
                })
                .collect(),
        }
    }
}

/// How a query direction finds the measured directions it is read from.
enum Lookup {
    /// A Klems file: the three measured directions around it, blended.
    Blend {
        /// Measured incoming directions projected on the panel plane.
        triangulation: DelaunayTriangulation<Point2<f64>>,
        /// Vertex index in the triangulation → measured direction.
        vertex_patch: Vec<usize>,
    },
    /// A 4-D tree: the incoming leaf holding it, `cells` per axis of the
    /// square (the measured directions in [`tree_incoming`]'s order).
    Square { cells: usize },
    /// A 3-D tree: the ring of sin θ holding it (each ring's first
    /// measured direction and its count, `cells` = 2 × rings), and on it
    /// the sample nearest in azimuth.
    Rings(Vec<(usize, usize)>),
}

impl Lookup {
    fn blend(incoming: &[DVec3]) -> Self {
        let mut triangulation = DelaunayTriangulation::<Point2<f64>>::new();
        let mut vertex_patch = Vec::new();
        for (i, d) in incoming.iter().enumerate() {
            if let Ok(handle) = triangulation.insert(Point2::new(d.x, d.y))
                && handle.index() == vertex_patch.len()
            {
                vertex_patch.push(i);
            }
        }
        Self::Blend { triangulation, vertex_patch }
    }

    /// The rings of a 3-D tree read at `cells` leaves per axis.
    fn rings(cells: usize) -> Self {
        let mut start = 0;
        Self::Rings(
            (0..cells / 2)
                .map(|k| {
                    let count = ring_azimuths(1.0 - 2.0 * (k as f64 + 0.5) / cells as f64);
                    start += count;
                    (start - count, count)
                })
                .collect(),
        )
    }

    /// The measured directions `incoming` (panel frame, z > 0) is read
    /// from with their weights, and the turn about z (radians) to give
    /// their lobes.
    fn find(&self, incoming: DVec3) -> (Vec<(usize, f64)>, f64) {
        match self {
            Self::Blend { triangulation, vertex_patch } => {
                let position = Point2::new(incoming.x, incoming.y);
                let mut weights = Vec::new();
                triangulation.barycentric().get_weights(position, &mut weights);
                if weights.is_empty() {
                    // Beyond the outermost measured ring: the nearest measurement.
                    if let Some(nearest) = triangulation.nearest_neighbor(position) {
                        weights.push((nearest.fix(), 1.0));
                    }
                }
                (weights.iter().map(|(v, w)| (vertex_patch[v.index()], *w)).collect(), 0.0)
            }
            Self::Square { cells } => {
                let cell = |x: f64| ((x * *cells as f64) as usize).min(cells - 1);
                let [u, v] = tensor_tree::disk_to_square(incoming.x, incoming.y);
                (vec![(cell(u) * cells + cell(v), 1.0)], 0.0)
            }
            Self::Rings(rings) => {
                // The tree's first axis, ½ − ½ sin θ, over its used half.
                let ring = (((1.0 - incoming.x.hypot(incoming.y)) * rings.len() as f64) as usize).min(rings.len() - 1);
                let (start, count) = rings[ring];
                let step = std::f64::consts::TAU / count as f64;
                let azimuth = incoming.y.atan2(incoming.x).rem_euclid(std::f64::consts::TAU);
                let nearest = (azimuth / step).round();
                (vec![(start + nearest as usize % count, 1.0)], azimuth - nearest * step)
            }
        }
    }
}

/// A BSDF fitted to lobes at every measured incoming direction.
pub struct BsdfModel {
    fitted: Vec<Fitted>,
    lookup: Lookup,
    /// The file's transmission, for [`PanelModel::transmission`].
    data: Transmission,
    /// Share of the transmitted flux the lobes represent, over all measured
    /// directions (flux-weighted): how well `lobes` of `lobe_width` fit.
    pub captured: f64,
    /// The file it was read from (for `export-radiance`).
    file: Option<PathBuf>,
    /// The share of the room's diffuse light it reflects back ("Reflection Back").
    pub back_reflectance: f64,
}

impl std::fmt::Debug for BsdfModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BsdfModel").field("directions", &self.fitted.len()).field("captured", &self.captured).finish()
    }
}

impl BsdfModel {
    /// Fits `count` lobes of full angle `width` degrees at each measured direction.
    pub fn fit(file: &BsdfFile, count: usize, width: f64) -> Self {
        let measured = Measured::of(file);
        let cones = cones(&measured.bins.directions, width);
        let (mut captured, mut transmitted) = (0.0, 0.0);
        let fitted: Vec<Fitted> = measured
            .flux
            .iter()
            .zip(&measured.reflected)
            .map(|(flux, &reflected)| {
                let total: f64 = flux.iter().sum();
                // Measurements can exceed 1 by noise; keep the balance.
                let scale = if total > 1.0 { 1.0 / total } else { 1.0 };
                let (mut lobes, rest) = greedy_lobes(flux, &measured.bins, &cones, count, width);
                lobes.iter_mut().for_each(|l| l.share *= scale);
                captured += (total - rest) * scale;
                transmitted += total * scale;
                Fitted { lobes, diffuse_transmittance: rest * scale, diffuse_reflectance: reflected.min(1.0 - total * scale).max(0.0) }
            })
            .collect();
        let captured = if transmitted > 0.0 { captured / transmitted } else { 1.0 };
        let data = Transmission::of(file);
        Self { fitted, lookup: measured.lookup, data, captured, file: None, back_reflectance: back_reflectance(file) }
    }
}

impl PanelModel for BsdfModel {
    fn response(&self, incoming: DVec3) -> PanelResponse {
        let incoming = incoming.normalize();
        if incoming.z <= 0.0 {
            return PanelResponse::default();
        }
        let (weights, turn) = self.lookup.find(incoming);
        let blend: Vec<(&Fitted, f64)> = weights.iter().map(|&(i, w)| (&self.fitted[i], w)).collect();
        let turn = DQuat::from_rotation_z(turn);
        let ranks = blend.iter().map(|(f, _)| f.lobes.len()).max().unwrap_or(0);
        let mut response = PanelResponse::default();
        for rank in 0..ranks {
            let (mut direction, mut share, mut width) = (DVec3::ZERO, 0.0, 0.0);
            for (fitted, w) in &blend {
                if let Some(lobe) = fitted.lobes.get(rank) {
                    direction += lobe.direction * *w * lobe.share.max(1e-12);
                    share += w * lobe.share;
                    width += w * lobe.width;
                }
            }
            if share > 0.0 && direction.length_squared() > 0.0 {
                response.lobes.push(Lobe { direction: turn * direction.normalize(), share, width });
            }
        }
        for (fitted, w) in &blend {
            response.diffuse_transmittance += w * fitted.diffuse_transmittance;
            response.diffuse_reflectance += w * fitted.diffuse_reflectance;
        }
        response.absorbed = (1.0 - response.total()).max(0.0);
        response
    }

    fn bsdf_file(&self) -> Option<&Path> {
        self.file.as_deref()
    }

    fn back_reflectance(&self) -> f64 {
        self.back_reflectance
    }

    fn measured(&self) -> Option<&dyn MeasuredTransmission> {
        Some(&self.data)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tensor_tree::square_to_disk;
    use std::path::{Path, PathBuf};

    fn sample(name: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/bsdf").join(name)
    }

    fn load(name: &str) -> BsdfFile {
        let path = sample(name);
        xml::parse(&std::fs::read_to_string(&path).unwrap(), &path).unwrap()
    }

    fn basis(file: &BsdfFile) -> &Basis {
        match &file.scattering {
            Scattering::Klems { basis, .. } => basis,
            Scattering::TensorTree { .. } => panic!("not a Klems file"),
        }
    }

    /// The hemispherical transmittance of a BSDF `f(toward source,
    /// outgoing)` (Radiance's vectors) for light travelling along `travel`:
    /// a midpoint sum over 256² cells of equal projected solid angle.
    fn transmittance(f: impl Fn(DVec3, DVec3) -> f64, travel: DVec3) -> f64 {
        let n = 256;
        (0..n * n).map(|k| f(-travel, cell_direction(k, n, 1.0))).sum::<f64>() * std::f64::consts::PI / (n * n) as f64
    }

    /// The middle of the incoming leaf holding `travel` in a tree whose
    /// incoming axes have `cells` leaves: the directions the fit reads a
    /// tree at.
    fn leaf_middle(travel: DVec3, dims: usize, cells: f64) -> DVec3 {
        let middle = |x: f64| ((x * cells).floor() + 0.5) / cells;
        let [x, y] = if dims == 4 {
            let [u, v] = tensor_tree::disk_to_square(travel.x, travel.y);
            square_to_disk(middle(u), middle(v))
        } else {
            // The first axis is ½ − ½ sin θ.
            let sin = 1.0 - 2.0 * middle(0.5 - 0.5 * travel.x.hypot(travel.y));
            let phi = travel.y.atan2(travel.x);
            [sin * phi.cos(), sin * phi.sin()]
        };
        DVec3::new(x, y, (1.0 - x * x - y * y).max(0.0).sqrt())
    }

    /// Tensor trees (4-D with front or only back transmission, and 3-D,
    /// made by bsdf2ttree from assets/bsdf/redirect.cal and bend.cal) read
    /// as they hold: at incoming directions all round (a 3-D tree turns
    /// with the light's azimuth), the fit transmits what the tree does
    /// (integrated here leaf by leaf, apart from the fit), and its main
    /// lobe goes where the tree's function sends the light.
    #[test]
    fn tensor_trees_read_as_the_functions_they_hold() {
        // Each function: a lobe of 0.01 in 1 − cos around a direction over a constant.
        let mirrored = |t: DVec3| DVec3::new(t.x, -t.y, t.z);
        let bent = |t: DVec3| DVec3::new(t.x, t.y, 2.0 * t.z);
        type Centre<'f> = &'f dyn Fn(DVec3) -> DVec3;
        let cases: [(&str, Centre, f64, f64, f64); 3] = [
            // Redirecting: the travel direction mirrored in y (-g 4: 16 leaves per axis).
            ("redirect_tt4.xml", &mirrored, 0.05, 5.0, 16.0),
            // The same with only "Transmission Back", read by reciprocity.
            ("redirect_back_tt4.xml", &mirrored, 0.05, 5.0, 16.0),
            // Isotropic: bent toward the normal, tangent halved (-g 5).
            ("bend_tt3.xml", &bent, 0.04, 4.0, 32.0),
        ];
        for (name, centre, base, peak, cells) in cases {
            let file = load(name);
            let Scattering::TensorTree { transmission: tree, reciprocal, .. } = &file.scattering else { panic!("{name}: not a tree") };
            let model = BsdfModel::fit(&file, 3, 23.0);
            let function =
                |toward_source: DVec3, out: DVec3| base + peak * ((out.dot(centre(-toward_source).normalize()) - 1.0) / 0.01).exp();
            let tree_value = |toward_source: DVec3, out: DVec3| {
                if *reciprocal { tree.value(out, toward_source) } else { tree.value(toward_source, out) }
            };
            for (theta, phi) in [(0.0, 0.0), (20.0, 270.0), (40.0, 250.0), (35.0, 30.0), (50.0, 120.0), (60.0, 200.0)] {
                let (theta, phi): (f64, f64) = (f64::to_radians(theta), f64::to_radians(phi));
                let travel = leaf_middle(DVec3::new(phi.cos() * theta.sin(), phi.sin() * theta.sin(), theta.cos()), tree.dims(), cells);
                let r = model.response(travel);
                let (held, made_from) = (transmittance(tree_value, travel), transmittance(function, travel));
                let error = r.transmitted() / held - 1.0;
                let off = r.lobes[0].direction.angle_between(centre(travel).normalize()).to_degrees();
                println!(
                    "{name} θ {:.0} φ {:.0}: τ {:.4}, the tree's {held:.4} ({:+.2}%), its function's {made_from:.4}; main lobe {off:.1}° off",
                    theta.to_degrees(),
                    phi.to_degrees(),
                    r.transmitted(),
                    100.0 * error
                );
                assert!(error.abs() < 0.01, "{name} {travel}: {} vs {held}", r.transmitted());
                assert!(off < 3.0, "{name} {travel}: main lobe {} is {off:.1}° off", r.lobes[0].direction);
            }
        }
    }

    #[test]
    fn energy_is_conserved() {
        for name in ["clear.xml", "ven45.xml", "blinds.xml", "redirect_tt4.xml", "bend_tt3.xml"] {
            let model = BsdfModel::fit(&load(name), 3, 23.0);
            for k in 0..200 {
                let theta = (k as f64 * 0.437).rem_euclid(1.0) * 1.5;
                let phi = k as f64 * 2.399;
                let d = DVec3::new(phi.cos() * theta.sin(), phi.sin() * theta.sin(), theta.cos());
                let r = model.response(d);
                let total = r.total() + r.absorbed;
                assert!((total - 1.0).abs() < 0.01, "{name} {d}: {total}");
                assert!(r.lobes.iter().all(|l| l.share >= 0.0) && r.diffuse_transmittance >= 0.0);
            }
        }
    }

    #[test]
    fn interpolation_is_continuous() {
        let model = BsdfModel::fit(&load("ven45.xml"), 3, 23.0);
        let mut previous: Option<PanelResponse> = None;
        // Sweep the incoming direction in small steps: lobes change little per step.
        for k in 0..=400 {
            let theta = 60f64.to_radians() * k as f64 / 400.0;
            let d = DVec3::new(0.3 * theta.sin(), -theta.sin(), theta.cos()).normalize();
            let r = model.response(d);
            if let Some(p) = &previous {
                assert!((r.transmitted() - p.transmitted()).abs() < 0.02, "step {k}: {} -> {}", p.transmitted(), r.transmitted());
                let share = |r: &PanelResponse| r.lobes.first().map_or(0.0, |l| l.share);
                assert!((share(&r) - share(p)).abs() < 0.02, "step {k}");
            }
            previous = Some(r);
        }
    }

    /// A Klems quarter basis (41 patches) file written here: clear glass of
    /// 0.8 transmittance (diagonal BSDF 0.8 / projected solid angle).
    fn quarter_basis_glass() -> String {
        let rings = [(0.0, 9.0, 1), (9.0, 27.0, 8), (27.0, 46.0, 12), (46.0, 66.0, 12), (66.0, 90.0, 8)];
        let mut blocks = String::new();
        let mut projected = Vec::new();
        for (lo, hi, phis) in rings {
            blocks.push_str(&format!(
                "<AngleBasisBlock><Theta>{}</Theta><nPhis>{phis}</nPhis><ThetaBounds><LowerTheta>{lo}</LowerTheta><UpperTheta>{hi}</UpperTheta></ThetaBounds></AngleBasisBlock>\n",
                0.5 * (lo + hi)
            ));
            let (l, h): (f64, f64) = (f64::to_radians(lo), f64::to_radians(hi));
            projected.extend(std::iter::repeat_n(std::f64::consts::PI * (l.cos().powi(2) - h.cos().powi(2)) / phis as f64, phis));
        }
        let n = projected.len();
        let values: Vec<String> =
            (0..n * n).map(|k| if k / n == k % n { format!("{}", 0.8 / projected[k % n]) } else { "0".into() }).collect();
        format!(
            "<?xml version=\"1.0\"?>\n<WindowElement><Optical><Layer><DataDefinition><IncidentDataStructure>Columns</IncidentDataStructure>\n<AngleBasis><AngleBasisName>LBNL/Klems Quarter</AngleBasisName>\n{blocks}</AngleBasis></DataDefinition>\n<WavelengthData><Wavelength unit=\"Integral\">Visible</Wavelength><WavelengthDataBlock><WavelengthDataDirection>Transmission Front</WavelengthDataDirection><ColumnAngleBasis>LBNL/Klems Quarter</ColumnAngleBasis><RowAngleBasis>LBNL/Klems Quarter</RowAngleBasis><ScatteringDataType>BTDF</ScatteringDataType><ScatteringData>{}</ScatteringData></WavelengthDataBlock></WavelengthData>\n</Layer></Optical></WindowElement>\n",
            values.join(",")
        )
    }

    #[test]
    fn a_quarter_basis_file_reads_and_fits() {
        let file = xml::parse(&quarter_basis_glass(), Path::new("quarter.xml")).unwrap();
        assert_eq!(basis(&file).patch_count(), 41);
        let model = BsdfModel::fit(&file, 3, 23.0);
        assert!((model.captured - 1.0).abs() < 1e-9, "{}", model.captured);
        // At a measured direction, one lobe straight through with 0.8 of the light.
        let d = klems_patches(basis(&file))[5].0;
        let r = model.response(d);
        assert!(r.lobes[0].direction.angle_between(d) < 1e-6 && (r.lobes[0].share - 0.8).abs() < 1e-9, "{:?}", r.lobes);
        assert!((r.absorbed - 0.2).abs() < 1e-9);
    }

    /// A fixed-seed fuzzer over a real file: cut anywhere, bytes dropped,
    /// numbers and tags put in. Every input parses or gives one error line
    /// naming the file, never a panic.
    #[test]
    fn mutated_files_never_crash_the_reader() {
        for name in ["clear.xml", "bend_tt3.xml"] {
            mutate_and_read(&std::fs::read_to_string(sample(name)).unwrap());
        }
    }

    fn mutate_and_read(text: &str) {
        let tokens =
            ["nan", "1e39", "-1", "<", ">", "</ScatteringData>", "<nPhis>", "999999999", "\u{feff}", ",", "&amp;", "{", "}", "{ 1 }"];
        let mut state: u64 = 2026;
        let mut next = |n: usize| {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((state >> 33) as usize) % n.max(1)
        };
        for case in 0..200 {
            let mut input = text.to_string();
            for _ in 0..1 + next(3) {
                let mut at = next(input.len());
                while !input.is_char_boundary(at) {
                    at -= 1;
                }
                match next(3) {
                    0 => input.truncate(at),
                    1 => input.insert_str(at, tokens[next(tokens.len())]),
                    _ => {
                        let mut end = (at + 1 + next(40)).min(input.len());
                        while !input.is_char_boundary(end) {
                            end -= 1;
                        }
                        input.replace_range(at..end, "");
                    }
                }
            }
            let outcome = std::panic::catch_unwind(|| xml::parse(&input, Path::new("fuzz.xml")));
            match outcome {
                Ok(Ok(_)) => {}
                Ok(Err(e)) => assert!(e.starts_with("fuzz.xml") && !e.contains('\n'), "case {case}: {e}"),
                Err(_) => panic!("case {case} panicked"),
            }
        }
    }

    /// A tensor tree file written here: `data` as its "Transmission Front".
    fn tree_file(structure: &str, data: &str) -> String {
        format!(
            "<?xml version=\"1.0\"?>\n<WindowElement><Optical><Layer><DataDefinition><IncidentDataStructure>{structure}</IncidentDataStructure></DataDefinition>\n<WavelengthData><Wavelength unit=\"Integral\">Visible</Wavelength><WavelengthDataBlock><WavelengthDataDirection>Transmission Front</WavelengthDataDirection><AngleBasis>LBNL/Shirley-Chiu</AngleBasis><ScatteringDataType>BTDF</ScatteringDataType>\n<ScatteringData>\n{data}\n</ScatteringData></WavelengthDataBlock></WavelengthData>\n</Layer></Optical></WindowElement>\n"
        )
    }

    /// A one-leaf tree is a Lambertian diffuser: π × its value transmitted
    /// from every direction.
    #[test]
    fn a_uniform_tree_transmits_the_same_everywhere() {
        for structure in ["TensorTree3", "TensorTree4"] {
            let file = xml::parse(&tree_file(structure, "{ 0.1 }"), Path::new("uniform.xml")).unwrap();
            let model = BsdfModel::fit(&file, 3, 23.0);
            for d in [DVec3::Z, DVec3::new(0.5, 0.2, 0.84).normalize(), DVec3::new(-0.7, -0.6, 0.39).normalize()] {
                let r = model.response(d);
                assert!((r.transmitted() - 0.1 * std::f64::consts::PI).abs() < 1e-6, "{structure} {d}: {}", r.transmitted());
            }
        }
    }

    /// A tree is constant over an incoming leaf, as Radiance reads it: where
    /// its transmittance steps between two leaves, 1° either side of the
    /// edge reads the one leaf or the other, not a blend. 4-D: 0.1 where
    /// the light travels toward −x, 0.3 toward +x (the square's first axis
    /// halved); 3-D: 0.1 within 30° of the normal, 0.3 beyond (its first
    /// axis, ½ − ½ sin θ, halved twice).
    #[test]
    fn a_tree_steps_where_its_incoming_leaves_do() {
        let uniform = |v: f64| format!("{{ {v} }}");
        let square: String = (0..16).map(|c| uniform(if c & 1 == 0 { 0.1 } else { 0.3 })).collect();
        let ring: String = (0..8).map(|c| uniform(if c & 1 == 0 { 0.3 } else { 0.1 })).collect();
        let rings: String = (0..8).map(|c| if c & 1 == 0 { format!("{{ {ring} }}") } else { uniform(0.0) }).collect();
        let around = |theta: f64, phi: f64| {
            let (theta, phi) = (theta.to_radians(), phi.to_radians());
            DVec3::new(phi.cos() * theta.sin(), phi.sin() * theta.sin(), theta.cos())
        };
        // (Where the light travels, the value it reads.)
        type Queries = [(DVec3, f64); 4];
        let cases: [(&str, String, Queries); 2] = [
            (
                "TensorTree4",
                square,
                [(around(1.0, 180.0), 0.1), (around(1.0, 0.0), 0.3), (around(40.0, 91.0), 0.1), (around(40.0, 89.0), 0.3)],
            ),
            (
                "TensorTree3",
                rings,
                [(around(29.0, 17.0), 0.1), (around(31.0, 17.0), 0.3), (around(29.0, 250.0), 0.1), (around(31.0, 250.0), 0.3)],
            ),
        ];
        for (structure, data, queries) in cases {
            let file = xml::parse(&tree_file(structure, &format!("{{ {data} }}")), Path::new("step.xml")).unwrap();
            let model = BsdfModel::fit(&file, 3, 23.0);
            for (travel, value) in queries {
                let expected = value * std::f64::consts::PI;
                let got = model.response(travel).transmitted();
                assert!((got - expected).abs() < 1e-6, "{structure} {travel}: {got} vs {expected}");
            }
        }
    }

    /// The measured transmission is the file's, cell by cell: a Klems
    /// file's row for a patch holds its matrix column, each outgoing patch
    /// found from its middle; a 4-D tree's (front, or back read by
    /// reciprocity) is its leaf value at any pair of directions.
    #[test]
    fn the_measured_transmission_reads_the_file() {
        let file = load("ven45.xml");
        let Scattering::Klems { basis, transmission, .. } = &file.scattering else { panic!("not Klems") };
        let model = BsdfModel::fit(&file, 3, 23.0);
        let data = model.measured().unwrap();
        let patches = klems_patches(basis);
        assert_eq!(data.outgoing_cells(), patches.len());
        for i in [0, 9, 40, 77, 120, 144] {
            let row = data.row(patches[i].0);
            for (o, patch) in patches.iter().enumerate() {
                assert_eq!(row[data.outgoing_cell(patch.0)], transmission.get(i, o), "patch {i} → {o}");
            }
        }
        for name in ["redirect_tt4.xml", "redirect_back_tt4.xml"] {
            let file = load(name);
            let Scattering::TensorTree { transmission: tree, reciprocal, .. } = &file.scattering else { panic!("{name}") };
            let model = BsdfModel::fit(&file, 3, 23.0);
            let data = model.measured().unwrap();
            let mut rng = 0.37f64;
            let mut next = || {
                rng = (rng * 997.0 + 0.123).fract();
                rng
            };
            for _ in 0..200 {
                let hemisphere = |a: f64, b: f64| {
                    let [x, y] = square_to_disk(a, b);
                    DVec3::new(x, y, (1.0 - x * x - y * y).max(0.0).sqrt())
                };
                let (travel, out) = (hemisphere(next(), next()), hemisphere(next(), next()));
                let held = if *reciprocal { tree.value(out, -travel) } else { tree.value(-travel, out) };
                assert_eq!(data.row(travel)[data.outgoing_cell(out)], held, "{name} {travel} → {out}");
            }
        }
    }

    /// A lobe is as wide as the light it stands for: clear glass puts all of
    /// it in the normal Klems patch (a cap of 5°: as wide as an even cone
    /// of 2√2·√(1 − cos 5°) rad, 10.0°); the redirecting tree's lobe is a
    /// Gaussian of 8.1° RMS (even-cone width 22.9°) seen through 16 leaves
    /// per axis and cut by the 23° cone.
    #[test]
    fn lobes_are_as_wide_as_the_light_they_stand_for() {
        let clear = BsdfModel::fit(&load("clear.xml"), 3, 23.0).response(DVec3::Z);
        let cap = 2.0 * std::f64::consts::SQRT_2 * (1.0 - 5f64.to_radians().cos()).sqrt();
        assert!((clear.lobes[0].width - cap.to_degrees()).abs() < 0.01, "{:?}", clear.lobes[0]);
        let tree = BsdfModel::fit(&load("redirect_tt4.xml"), 3, 23.0);
        for travel in [DVec3::Z, leaf_middle(DVec3::new(0.0, -0.5, 0.866), 4, 16.0)] {
            let width = tree.response(travel).lobes[0].width;
            println!("redirect_tt4.xml {travel}: main lobe {width:.1}° wide");
            assert!((15.0..=23.0).contains(&width), "{travel}: {width}");
        }
    }

    /// The share of the room's light a panel returns: figures computed
    /// apart from this code (Python over the files' visible "Reflection
    /// Back" matrices: ven45 0.35658, blinds 0.15757).
    #[test]
    fn back_reflectance_is_the_hemispherical_mean_of_reflection_back() {
        let of = |file: &BsdfFile| BsdfModel::fit(file, 3, 23.0).back_reflectance;
        assert!((of(&load("ven45.xml")) - 0.35658).abs() < 1e-4, "{}", of(&load("ven45.xml")));
        assert!((of(&load("blinds.xml")) - 0.15757).abs() < 1e-4, "{}", of(&load("blinds.xml")));
        // A one-leaf tree of 0.1/sr reflects π × 0.1 back.
        let back = "<WavelengthDataBlock><WavelengthDataDirection>Reflection Back</WavelengthDataDirection><AngleBasis>LBNL/Shirley-Chiu</AngleBasis><ScatteringData>{ 0.1 }</ScatteringData></WavelengthDataBlock></WavelengthData>";
        let text = tree_file("TensorTree3", "{ 0.2 }").replace("</WavelengthData>", back);
        assert!((of(&xml::parse(&text, Path::new("back.xml")).unwrap()) - 0.1 * std::f64::consts::PI).abs() < 1e-6);
        // Without "Reflection Back" nothing returns.
        assert_eq!(of(&load("redirect_tt4.xml")), 0.0);
    }

    #[test]
    fn malformed_tensor_trees_name_file_and_line() {
        let path = Path::new("tree.xml");
        // The data's first line is the file's line 5; a bad value on its second.
        let error = xml::parse(&tree_file("TensorTree3", "{\n 0.1 x 0.1 0.1 0.1 0.1 0.1 0.1 }"), path).unwrap_err();
        assert_eq!(error, "tree.xml:6: tensor tree value 'x' is not a finite number");
        let error = xml::parse(&tree_file("TensorTree4", "{ 0.1 0.2 }"), path).unwrap_err();
        assert!(error.starts_with("tree.xml:5: a leaf grid of 2 values"), "{error}");
        let error = xml::parse(&tree_file("TensorTree4", "{ { 0.1 }"), path).unwrap_err();
        assert!(error.starts_with("tree.xml:") && error.contains("where a node's '{' should be"), "{error}");
        let error = xml::parse(&tree_file("TensorTree5", "{ 0.1 }"), path).unwrap_err();
        assert!(error.contains("IncidentDataStructure 'TensorTree5'"), "{error}");
        let error = xml::parse(&tree_file("TensorTree3", "{ 0.1 }").replace("Shirley-Chiu", "Klems Full"), path).unwrap_err();
        assert!(error.contains("must be LBNL/Shirley-Chiu"), "{error}");
        let error = xml::parse(&tree_file("TensorTree3", "{ 0.1 }").replace("Transmission Front", "Reflection Front"), path).unwrap_err();
        assert_eq!(error, "tree.xml: no transmission tree (Visible)");
    }

    #[test]
    fn malformed_files_give_clear_errors() {
        let text = std::fs::read_to_string(sample("clear.xml")).unwrap();
        let path = Path::new("bad.xml");
        let truncated = &text[..text.len() / 2];
        assert!(xml::parse(truncated, path).unwrap_err().contains("truncated"));
        let data_start = text.find("<ScatteringData>").unwrap() + "<ScatteringData>".len();
        // One value fewer: wrong basis size.
        let first_value_end = data_start + text[data_start..].find(',').unwrap() + 1;
        let missing = format!("{}{}", &text[..data_start], &text[first_value_end..]);
        let error = xml::parse(&missing, path).unwrap_err();
        assert!(error.contains("needs 145 × 145 = 21025"), "{error}");
        assert!(error.starts_with("bad.xml:"), "{error}");
        let nan = format!("{}NaN,{}", &text[..data_start], &text[first_value_end..]);
        let error = xml::parse(&nan, path).unwrap_err();
        assert!(error.contains("'NaN' is not a finite number"), "{error}");
        // An absurd basis is refused before anything is allocated for it.
        let huge = text.replacen("<nPhis>1</nPhis>", "<nPhis>1000000000</nPhis>", 1);
        assert!(xml::parse(&huge, path).unwrap_err().contains("bad angle basis block (nPhis 1000000000"));
        // genBSDF's "Recover using" line before the declaration is skipped, and lines still count from the file's start.
        let error = xml::parse(&format!("Recover using: genBSDF -recover x\n{nan}"), path).unwrap_err();
        let nan_line = nan[..data_start].lines().count();
        assert!(error.starts_with(&format!("bad.xml:{}:", nan_line + 1)), "{error}");
        let tree = text.replace("LBNL/Klems Full", "LBNL/Shirley-Chiu");
        assert!(xml::parse(&tree, path).unwrap_err().contains("is not a Klems basis (nor is the file a tensor tree"));
    }

    #[test]
    fn keys_are_checked() {
        assert_eq!(heliodon_core::panel::check_keys(Bsdf.keys()), Ok(()));
        let folder = sample("clear.xml").parent().unwrap().to_path_buf();
        let build = |text: &str| Bsdf.build(&Parameters::from_toml(text, folder.clone()).unwrap());
        assert!(build("file = \"clear.xml\"").is_ok());
        assert_eq!(build("file = \"missing.xml\"").unwrap_err().key, "file");
        assert_eq!(build("file = \"clear.xml\"\nlobes = 0").unwrap_err().key, "lobes");
        assert_eq!(build("file = \"clear.xml\"\nlobe_width = 120.0").unwrap_err().key, "lobe_width");
    }
}
