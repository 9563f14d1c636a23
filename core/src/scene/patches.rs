//! The patch mesh for lighting. Patches are fine where the light needs
//! them and coarse where it does not: each surface is cut by a quadtree of
//! square cells in its plane, on the `patch_size` grid laid from the
//! surface's corner. A cell is split while it is larger than
//! the size allowed where it lies ([`PatchSizing`]): `patch_size` in the
//! *focus* (around the sensors and the windows within a few metres of
//! them, with a margin; around all the windows when there are no
//! sensors), and growing with the distance from it (a quarter of that
//! distance, at most 64 × `patch_size`); away from the windows, patches
//! may be as wide as their distance from the sensors, at most twice
//! `patch_size` (a tall room's ceiling over its grid). So a room keeps
//! today's grid, while the far ground, the site's context, the outside of the building
//! far from its windows and the wings and storeys where no sensor reads
//! get a few large patches. A patch is one leaf cell's part of the surface;
//! the pieces of triangles inside the cell are its render triangles.
//! Triangles smaller than their cell are not cut: they join the cell that
//! holds their centroid (small coplanar triangles gather into patches).
//! A cell holding less than a quarter of its area of the surface (the
//! strip along a surface's edge, a frame's profile, the corner a cut plane
//! leaves) joins a neighbouring cell on the same sides of every cut, as
//! long as the patch stays within two cells each way and one and a half
//! cells' area ([`merge_small_cells`]): real exports are full of such
//! pieces.
//!
//! Under a sensor close to a surface (a grid point just under an attic's
//! slope, a desk sensor under a shelf) the patches are finer still, down to
//! an eighth of `patch_size`, no wider than twice their distance from it:
//! such a sensor sees little but the spot above it, and reads the light
//! there, not the mean of a patch ([`NearSensor`]).
//!
//! A window's plane also cuts the surfaces that pass through it near the
//! window — reveals, sills, lintels, frames, the floor under a door: the
//! light on them steps there from the outside's to the room's, so no patch
//! straddles it ([`CutPlane`]). A reveal cut by a thick wall's glass
//! plane would otherwise be one patch, lit as the mean of its sunlit outer
//! half and its inner half, and the room would read that mean: light
//! leaking round the glass.
//!
//! Clutter (furniture, frames, mullions: diffuse surfaces much smaller than
//! the patch size allowed where they are) would otherwise be one patch per
//! surface. Such surfaces are gathered into *clusters*: per material, per
//! cube of the allowed size and per main direction of their normals (±x,
//! ±y, ±z), one patch holding all their triangles, with the area-weighted
//! mean normal. The cluster's patch is listed under its first surface; the
//! others have none of their own.

use std::collections::{BTreeMap, HashMap};
use std::ops::Range;

use glam::Vec3;

use super::contacts::{LargeFaces, Plane, contact_cuts};
use super::cut_plane::CutPlane;
use super::{Sensor, Surface, Triangle};
use crate::parallel::par_map;

/// One lighting patch.
#[derive(Debug, Clone, PartialEq)]
pub struct Patch {
    /// Index into [`super::Scene::surfaces`].
    pub surface: u32,
    /// Index into [`super::Scene::materials`]: the surface's.
    pub material: u32,
    /// Sum of its render triangles' areas, m².
    pub area: f32,
    /// The surface's normal.
    pub normal: Vec3,
    /// Area-weighted centroid of the patch's render triangles.
    pub centroid: Vec3,
    /// Range into [`PatchMesh::triangles`].
    pub triangles: Range<u32>,
}

impl Patch {
    /// Its render triangles' indices into [`PatchMesh::triangles`].
    pub fn triangle_indices(&self) -> Range<usize> {
        self.triangles.start as usize..self.triangles.end as usize
    }
}

/// Patches and the render triangles they cover.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PatchMesh {
    /// Ordered by surface: each [`super::Surface::patches`] range indexes here.
    pub patches: Vec<Patch>,
    /// Render triangles in the canonical frame, ordered by patch, with the
    /// winding of the model triangle they came from.
    pub triangles: Vec<[Vec3; 3]>,
    /// Per cluster of clutter, its patch and the surfaces it holds (the
    /// first lists the patch; every other patch is its surface's part).
    pub clusters: Vec<(u32, Vec<u32>)>,
}

impl PatchMesh {
    /// Adds one patch holding the cluster's `members` (whole surfaces or
    /// their pieces), listed under the first member's surface.
    fn push_cluster(&mut self, triangles: &[Triangle], surfaces: &[Surface], members: Vec<Member>) {
        let start = self.triangles.len() as u32;
        let (mut area, mut moment, mut normal) = (0.0, Vec3::ZERO, Vec3::ZERO);
        let mut held: Vec<u32> = Vec::new();
        for member in members {
            let (surface, pieces) = match member {
                Member::Whole(s) => (s, triangles[surfaces[s as usize].triangle_indices()].iter().map(|t| t.vertices).collect()),
                Member::Piece(s, pieces) => (s, pieces),
            };
            for piece in pieces {
                let a = piece_area(&piece);
                area += a;
                moment += a * (piece[0] + piece[1] + piece[2]) / 3.0;
                normal += a * surfaces[surface as usize].normal;
                self.triangles.push(piece);
            }
            if !held.contains(&surface) {
                held.push(surface);
            }
        }
        let first = &surfaces[held[0] as usize];
        self.patches.push(Patch {
            surface: held[0],
            material: first.material,
            area,
            normal: normal.try_normalize().unwrap_or(first.normal),
            centroid: moment / area.max(f32::MIN_POSITIVE),
            triangles: start..self.triangles.len() as u32,
        });
        self.clusters.push((self.patches.len() as u32 - 1, held));
    }

    /// The surfaces whose triangles patch `patch` holds.
    pub fn surfaces_of(&self, patch: u32) -> &[u32] {
        match self.clusters.binary_search_by_key(&patch, |c| c.0) {
            Ok(k) => &self.clusters[k].1,
            Err(_) => std::slice::from_ref(&self.patches[patch as usize].surface),
        }
    }

    /// The patch each render triangle belongs to.
    pub fn triangle_patches(&self) -> Vec<u32> {
        let mut owner = vec![0; self.triangles.len()];
        for (p, patch) in self.patches.iter().enumerate() {
            owner[patch.triangle_indices()].fill(p as u32);
        }
        owner
    }
}

/// Pieces smaller than this (m²) are rounding slivers of clipping.
const SLIVER_AREA: f32 = 1e-8;

/// The area of a render triangle.
fn piece_area(piece: &[Vec3; 3]) -> f32 {
    0.5 * (piece[1] - piece[0]).cross(piece[2] - piece[0]).length()
}

/// The area-weighted centroid of render triangles, and their box.
fn centroid_and_bounds(pieces: impl Iterator<Item = [Vec3; 3]> + Clone) -> (Vec3, Bounds) {
    let area: f32 = pieces.clone().map(|t| piece_area(&t)).sum();
    let centroid = pieces.clone().map(|t| piece_area(&t) * (t[0] + t[1] + t[2]) / 3.0).sum::<Vec3>() / area.max(f32::MIN_POSITIVE);
    let bounds = pieces.flatten().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| (lo.min(p), hi.max(p)));
    (centroid, bounds)
}

/// Beyond the focus, the allowed patch side grows by this much per metre.
const GROWTH: f32 = 0.25;
/// The largest patch side, in finest sizes.
const COARSEST: f32 = 64.0;
/// The focus reaches this far (m) beyond the windows and sensors.
const FOCUS_MARGIN: f32 = 1.5;
/// Sensors in one cube of this side (m) share one focus box.
const SENSOR_CUBE: f32 = 2.0;
/// A window lights the sensors when it lies within this distance (m) of
/// one: the windows of a sensor's room.
const WINDOW_REACH: f32 = 5.0;
/// Away from the windows, a patch around the sensors is no wider than this
/// many times its distance from them ([`PatchSizing`]).
const SENSOR_SLOPE: f32 = 1.0;
/// ... and no wider than this many finest sides there, nor where no sensor
/// sees.
const SENSOR_COARSEST: f32 = 2.0;
/// Sensors whose normals' cosine is above this read on one plane.
const SAME_READING_PLANE: f32 = 0.9999;
/// Where the sizing allows patches this many finest sides wide or more (at
/// the default `patch_size`, 2 m: 6 m and more beyond the focus boxes'
/// margins), the light reaches the sensors only after bounces that average
/// many patches. Clutter there clusters whether other faces meet it or not
/// ([`super::contacts`]), across window planes and large faces: kept apart,
/// the far wings of a building were thousands of patches of a few
/// centimetres (Revit's Office_A with one office's sensors: 30,288 →
/// 20,649 patches). Larger surfaces there are still cut where other faces
/// meet them: uncut too, 18,610 patches, but a large open office three
/// rooms away read 0.5% brighter against rtrace.
const FAR_SIDES: f32 = 4.0;

/// Cells may be this many times finer than `patch_size`, under sensors
/// close to a surface ([`NearSensor`]).
const FINER: f32 = 8.0;
/// Near a sensor, a patch is no wider than this many times its distance
/// from it.
const NEAR_GROWTH: f32 = 2.0;
/// A place lies in front of a sensor when it is this far (m) or more above
/// the sensor's plane: a desk sensor lying on its desk (read 1 cm above
/// it) does not refine the desk.
const NEAR_IN_FRONT: f32 = 0.01;

/// A sensor as the patches near it see it: patches it looks at from closer
/// than half of `patch_size` are no wider than [`NEAR_GROWTH`] times their
/// distance from it. A sensor reads the light of the patches it sees, each
/// as its mean; under a surface a few centimetres away it sees one patch
/// and reads that patch's mean where Radiance reads the spot above it
/// (SampleHouse's attic under its roof's slope: 26 sensors seeing one side
/// as half their view or more read 8% high on average against rtrace, up to
/// 35%, where the others read −1%; with the patches finer there, the median
/// error of those seeing an eighth or more went 8.9 → 1.8%).
#[derive(Debug, Clone, Copy, PartialEq)]
struct NearSensor {
    position: Vec3,
    normal: Vec3,
    /// Half its square's diagonal (0 for a point sensor).
    reach: f32,
}

impl NearSensor {
    /// The side this sensor allows for `square`: none where the square lies
    /// wholly behind it.
    fn allowed(&self, square: Square, finest: f32) -> Option<f32> {
        if square.highest(self.normal) - self.position.dot(self.normal) < NEAR_IN_FRONT {
            return None;
        }
        let to = square.centre - self.position;
        let (a, b) = (to.dot(square.u), to.dot(square.v));
        let across = (to - a * square.u - b * square.v).length();
        let gap = Vec3::new((a.abs() - square.half).max(0.0), (b.abs() - square.half).max(0.0), across).length();
        Some((NEAR_GROWTH * (gap - self.reach).max(0.0)).max(finest / FINER))
    }
}

/// The plane a focus box's sensors all read on (a grid's work plane):
/// what lies wholly behind it, `normal · p` under `offset` plus
/// [`NEAR_IN_FRONT`], none of them sees.
#[derive(Debug, Clone, Copy, PartialEq)]
struct ReadingPlane {
    normal: Vec3,
    /// The least `normal · p` of the box's sensors.
    offset: f32,
}

impl ReadingPlane {
    /// Whether `square` lies wholly behind the plane.
    fn hides(&self, square: Square) -> bool {
        square.highest(self.normal) - self.offset < NEAR_IN_FRONT
    }
}

/// A square in a surface's plane (a quadtree's cell), or a point (`half` 0).
#[derive(Debug, Clone, Copy)]
struct Square {
    centre: Vec3,
    /// Its edges' directions.
    u: Vec3,
    v: Vec3,
    /// Half its side.
    half: f32,
}

impl Square {
    fn point(centre: Vec3) -> Self {
        Square { centre, u: Vec3::X, v: Vec3::Y, half: 0.0 }
    }

    /// The most `direction · p` over the square.
    fn highest(&self, direction: Vec3) -> f32 {
        self.centre.dot(direction) + self.half * (self.u.dot(direction).abs() + self.v.dot(direction).abs())
    }
}

/// The fewest of a patch side's rays traced far from the focus, as a share
/// ([`PatchSizing::ray_share`]): 16 of the default 256. (AC20-Institute-Var-2
/// with one office's sensors: cold 8.2 s at a quarter, 6.9 s at this, the
/// office's readings within 0.05%.)
const MIN_RAY_SHARE: f64 = 0.0625;

/// An axis-aligned box: (min, max).
type Bounds = (Vec3, Vec3);

/// The patch side allowed at each place: `finest` in the focus, larger with
/// the distance from it.
///
/// The focus is where the readings are made and the light they see comes
/// in: boxes around the sensors (one per grid, one per [`SENSOR_CUBE`]
/// other sensors occupy) and around each window within [`WINDOW_REACH`] of
/// them. Light far from every sensor reaches them only after bounces that
/// average it, so a wing or a storey without sensors is coarse: a building
/// with one room of sensors does not pay for the rest of it. A scene
/// without sensors focuses on the box around all its windows (what the
/// viewer shows lit).
///
/// Within the sensors' boxes, away from the windows, a patch may be as
/// wide as [`SENSOR_SLOPE`] times its distance from the sensors (at most
/// [`SENSOR_COARSEST`] finest sides): a ceiling 1 m and more above a grid
/// of desk sensors, and the walls' upper parts, are seen from every sensor
/// as finely as the desks around them, in a quarter of the patches. (At
/// half the distance, Revit's Office_A, sensors in all its 98 spaces, was
/// 120,959 patches, now 101,169, its 144 rtrace-referenced sensors' median
/// error over three seeds 0.41/0.30% → 0.35/0.32% clear/overcast.)
///
/// What lies behind the plane a box's sensors read on (the floor and the
/// walls' foot under a grid of desk sensors, the desks) is not in their
/// view, so their slope does not hold there and it may be
/// [`SENSOR_COARSEST`] finest sides wide; the windows' focus still does:
/// the floor's sun patch by a window lights the ceiling the sensors see,
/// and where it lands matters (with 1 m floor patches by the windows too,
/// SampleHouse's attic read +1.3%, up to +6.8% under its roof windows).
#[derive(Debug, Clone, PartialEq)]
pub struct PatchSizing {
    /// `patch_size`: the side of the finest patches, m.
    pub finest: f32,
    /// The boxes around the sensors, margin included.
    focus: Vec<Bounds>,
    /// Per box of `focus`: the plane its sensors read on, where they share one.
    reading_planes: Vec<Option<ReadingPlane>>,
    /// The boxes around the windows that light them (around all the
    /// windows without sensors), margin included. Both empty: finest
    /// everywhere.
    lighting: Vec<Bounds>,
    /// The sensors, by their x, for the patches close to them.
    near: Vec<NearSensor>,
    /// The largest reach of theirs.
    near_reach: f32,
}

impl PatchSizing {
    /// Finest everywhere: the uniform `size` grid.
    pub fn uniform(size: f32) -> Self {
        Self { finest: size, focus: Vec::new(), reading_planes: Vec::new(), lighting: Vec::new(), near: Vec::new(), near_reach: 0.0 }
    }

    /// Finest within [`FOCUS_MARGIN`] of the `sensors` and of the `windows`
    /// (their bounds) that light them, or of the box around every window
    /// when there is no sensor; finest everywhere with neither. A grid's
    /// points make one box (a grid is a rectangle), other sensors one per
    /// [`SENSOR_CUBE`] they occupy.
    pub fn around(size: f32, sensors: &[Sensor], windows: &[Bounds]) -> Self {
        // Per grid, or per cube other sensors occupy: their bounds and shared plane.
        type Key<'a> = (Option<&'a str>, [i32; 3]);
        let mut cubes: BTreeMap<Key, (Bounds, Option<ReadingPlane>)> = BTreeMap::new();
        for sensor in sensors {
            let p = sensor.position;
            let key = match &sensor.grid {
                Some(grid) => (Some(grid.as_str()), [0; 3]),
                None => (None, (p / SENSOR_CUBE).floor().as_ivec3().to_array()),
            };
            let plane = ReadingPlane { normal: sensor.normal, offset: p.dot(sensor.normal) };
            let ((lo, hi), shared) = cubes.entry(key).or_insert(((p, p), Some(plane)));
            (*lo, *hi) = (lo.min(p), hi.max(p));
            *shared = shared
                .filter(|s| s.normal.dot(plane.normal) > SAME_READING_PLANE)
                .map(|s| ReadingPlane { offset: s.offset.min(plane.offset), ..s });
        }
        let (focus, reading_planes): (Vec<Bounds>, Vec<Option<ReadingPlane>>) = cubes.into_values().unzip();
        let lighting: Vec<Bounds> = if focus.is_empty() {
            windows.iter().copied().reduce(|(lo, hi), (a, b)| (lo.min(a), hi.max(b))).into_iter().collect()
        } else {
            windows.iter().copied().filter(|&w| focus.iter().any(|&s| box_gap(w, s) <= WINDOW_REACH)).collect()
        };
        let margin = Vec3::splat(FOCUS_MARGIN);
        let widen = |boxes: Vec<Bounds>| boxes.into_iter().map(|(lo, hi)| (lo - margin, hi + margin)).collect();
        let mut near: Vec<NearSensor> = sensors
            .iter()
            .map(|s| NearSensor { position: s.position, normal: s.normal, reach: s.size.unwrap_or(0.0) * std::f32::consts::FRAC_1_SQRT_2 })
            .collect();
        near.sort_by(|a, b| a.position.x.total_cmp(&b.position.x));
        let near_reach = near.iter().map(|s| s.reach).fold(0.0, f32::max);
        Self { finest: size, focus: widen(focus), reading_planes, lighting: widen(lighting), near, near_reach }
    }

    /// The sensors that may make patches within `reach` of `centre` finer:
    /// those closer than half of `patch_size` (beyond, [`NEAR_GROWTH`] allows
    /// `patch_size`) plus their own reach.
    fn near_sensors(&self, centre: Vec3, reach: f32) -> impl Iterator<Item = &NearSensor> {
        let within = reach + self.finest / NEAR_GROWTH + self.near_reach;
        let first = self.near.partition_point(|s| s.position.x < centre.x - within);
        self.near[first..].iter().take_while(move |s| s.position.x <= centre.x + within)
    }

    /// The same sizing for places within `region`: only the boxes that can
    /// be the nearest to some point of it (a large model's surfaces each
    /// test a few, not all), and the sensors' boxes within the slope's reach
    /// of it (the nearest may not see a place, [`ReadingPlane`]), nearest
    /// first.
    fn within(&self, region: Bounds) -> Self {
        let reach = 0.5 * (region.1 - region.0).length();
        let centre = 0.5 * (region.0 + region.1);
        // The indices of the boxes, nearest first; at least those within
        // `slope_reach` of the region.
        let nearest_first = |boxes: &[Bounds], slope_reach: f32| -> Vec<usize> {
            let farthest = boxes.iter().map(|&b| point_gap(centre, b) + reach).fold(f32::INFINITY, f32::min).max(slope_reach);
            let mut near: Vec<(f32, usize)> =
                (0..boxes.len()).filter(|&k| box_gap(region, boxes[k]) <= farthest).map(|k| (point_gap(centre, boxes[k]), k)).collect();
            // Nearest first: a cell in the focus stops at the first box holding it.
            near.sort_by(|a, b| a.0.total_cmp(&b.0));
            near.into_iter().map(|(_, k)| k).collect()
        };
        // The sensors' slope may make any box within this of the region the
        // one that settles a cell (the nearer ones not seeing it).
        let slope_reach = (SENSOR_COARSEST * self.finest / SENSOR_SLOPE - FOCUS_MARGIN).max(0.0);
        let focus = nearest_first(&self.focus, slope_reach);
        let near = self
            .near_sensors(centre, reach)
            .filter(|s| point_gap(s.position, region) <= self.finest / NEAR_GROWTH + s.reach)
            .copied()
            .collect();
        Self {
            finest: self.finest,
            focus: focus.iter().map(|&k| self.focus[k]).collect(),
            reading_planes: focus.iter().map(|&k| self.reading_planes[k]).collect(),
            lighting: nearest_first(&self.lighting, 0.0).into_iter().map(|k| self.lighting[k]).collect(),
            near,
            near_reach: self.near_reach,
        }
    }

    /// The same sizing for places on the plane `normal · p = offset`: without
    /// the sensors it lies behind, parallel to them (the desk a sensor lies
    /// on, read 1 cm above it; the floor under a grid), for the patches
    /// close to them.
    fn in_plane(mut self, normal: Vec3, offset: f32) -> Self {
        self.near.retain(|s| {
            let facing = s.normal.dot(normal);
            facing.abs() < 0.999 || (offset - s.position.dot(normal)) * facing.signum() >= NEAR_IN_FRONT
        });
        self
    }

    /// The numbers the sizing is made of (for cache keys): the finest side,
    /// every box's corners and the sensors.
    pub fn as_floats(&self) -> Vec<f32> {
        let corners = self.focus.iter().chain(&self.lighting).flat_map(|(lo, hi)| lo.to_array().into_iter().chain(hi.to_array()));
        let near = self.near.iter().flat_map(|s| s.position.to_array().into_iter().chain(s.normal.to_array()).chain([s.reach]));
        let counts = [self.focus.len() as f32, self.lighting.len() as f32];
        std::iter::once(self.finest).chain(counts).chain(corners).chain(near).collect()
    }

    /// The share of a patch side's rays that a patch at `centroid` traces:
    /// all in the focus, fewer beyond it (the finest size over the size
    /// the distance from the focus allows there, at least
    /// [`MIN_RAY_SHARE`]). Light far from every sensor reaches them only
    /// through bounces that average many patches, so its noise averages
    /// out too. Within the focus the sensors' slope makes patches coarser
    /// but not their rays: the sensors see those patches, and a ceiling's
    /// sun over a grid read at half the points differed by up to 2% from
    /// the annual path's, which samples it fully.
    pub fn ray_share(&self, centroid: Vec3) -> f64 {
        f64::from(self.finest / self.beyond_focus(centroid)).clamp(MIN_RAY_SHARE, 1.0)
    }

    /// The side allowed at `p` by its distance from the focus boxes alone,
    /// without the sensors' slope ([`Self::by_slope`]) or the patches close
    /// in front of a sensor.
    fn beyond_focus(&self, p: Vec3) -> f32 {
        if self.focus.is_empty() && self.lighting.is_empty() {
            return self.finest;
        }
        self.beyond(&self.lighting, p, 0.0).min(self.beyond(&self.focus, p, 0.0)).max(self.finest)
    }

    /// [`Self::ray_share`] of every patch (ordered by surface, as
    /// [`PatchMesh`] holds them), each surface's asked of the sizing
    /// [`Self::within`] the box of its patches' centroids: the same shares,
    /// as that sizing keeps every box and sensor that can settle a place in
    /// the box, without testing each patch against all of them (Revit's
    /// Office_A, 121,077 patches and about 1,500 focus boxes: 16% of a warm
    /// `sensors` run's samples).
    pub fn ray_shares(&self, patches: &[Patch], threads: Option<usize>) -> Vec<f64> {
        let surfaces: Vec<&[Patch]> = patches.chunk_by(|a, b| a.surface == b.surface).collect();
        let shares = par_map(threads, surfaces.len(), |k| {
            let region =
                surfaces[k].iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| (lo.min(p.centroid), hi.max(p.centroid)));
            let local = self.within(region);
            surfaces[k].iter().map(|p| local.ray_share(p.centroid)).collect::<Vec<_>>()
        });
        shares.concat()
    }

    /// The side allowed at `centre`, for a cell of half-diagonal `reach`
    /// around it.
    fn allowed(&self, centre: Vec3, reach: f32) -> f32 {
        self.allowed_for(Square::point(centre), reach)
    }

    /// The side allowed for `square`, of half-diagonal `reach`: set by its
    /// nearest point to the windows' and the sensors' boxes, wider with its
    /// distance from the sensors within theirs ([`Self::by_slope`]), and
    /// finer where it lies close in front of a sensor ([`NearSensor`]).
    fn allowed_for(&self, square: Square, reach: f32) -> f32 {
        let centre = square.centre;
        let near = self.near_sensors(centre, reach).filter_map(|s| s.allowed(square, self.finest)).fold(self.finest, f32::min);
        if near < self.finest {
            return near;
        }
        if self.focus.is_empty() && self.lighting.is_empty() {
            return self.finest;
        }
        let by_windows = self.beyond(&self.lighting, centre, reach);
        if by_windows <= self.finest {
            return self.finest;
        }
        let by_sensors = self.beyond(&self.focus, centre, reach).max(self.by_slope(square));
        by_windows.min(by_sensors).max(self.finest)
    }

    /// The side [`SENSOR_SLOPE`] allows for `square` (a point or a cell),
    /// at most [`SENSOR_COARSEST`] finest sides, by its distance from the
    /// sensors' own boxes (a grid's rectangle, the bounds of the others in
    /// a cube: no farther than the nearest of their sensors, so never
    /// coarser than the sensors allow), leaving out the boxes whose reading
    /// plane the square lies behind. It decides nothing for a cell of
    /// `finest` or less, or wider than that most, and is not computed for
    /// them: the quadtree asks of every cell along every triangle's path.
    fn by_slope(&self, square: Square) -> f32 {
        let (side, widest) = (2.0 * square.half, SENSOR_COARSEST * self.finest);
        if square.half > 0.0 && (side <= self.finest || side > widest) {
            return self.finest;
        }
        // A cell is allowed or not; a point's side counts from `finest`.
        let settled = if square.half > 0.0 { side } else { self.finest };
        let extent = square.half * (square.u.abs() + square.v.abs());
        let cell = (square.centre - extent, square.centre + extent);
        let margin = Vec3::splat(FOCUS_MARGIN);
        let mut gap = f32::INFINITY;
        // Nearest first ([`PatchSizing::within`]): one too close settles it.
        for (&(lo, hi), plane) in self.focus.iter().zip(&self.reading_planes) {
            if plane.is_some_and(|p| p.hides(square)) {
                continue;
            }
            gap = gap.min(box_gap(cell, (lo + margin, hi - margin)));
            if SENSOR_SLOPE * gap < settled {
                return self.finest;
            }
        }
        (SENSOR_SLOPE * gap).min(widest)
    }

    /// The side `boxes` allow for a cell of half-diagonal `reach` around
    /// `centre`: `finest` when it meets one, larger by [`GROWTH`] per metre
    /// beyond the nearest (at most [`COARSEST`] finest sides), unbounded
    /// without boxes.
    fn beyond(&self, boxes: &[Bounds], centre: Vec3, reach: f32) -> f32 {
        let mut outside = f32::INFINITY;
        for &b in boxes {
            outside = outside.min(point_gap(centre, b));
            if outside <= reach {
                return self.finest;
            }
        }
        (self.finest + GROWTH * (outside - reach)).min(self.finest * COARSEST)
    }
}

/// The distance from `p` to the box `b` (0 inside it).
fn point_gap(p: Vec3, (lo, hi): Bounds) -> f32 {
    (lo - p).max(p - hi).max(Vec3::ZERO).length()
}

/// The distance between two boxes (0 when they meet).
fn box_gap(a: Bounds, b: Bounds) -> f32 {
    (b.0 - a.1).max(a.0 - b.1).max(Vec3::ZERO).length()
}

/// Splits a convex `polygon` by `planes` (at most 64), handing each part to
/// `out` with the set of planes it lies above (bit k for `planes[k]`). A
/// plane whose `near` box the part does not meet leaves it whole, on the
/// side of its centroid.
fn split_by_planes(polygon: Vec<Vec3>, planes: &[&CutPlane], out: &mut impl FnMut(u64, Vec<Vec3>)) {
    fn split(polygon: Vec<Vec3>, planes: &[&CutPlane], k: usize, above: u64, out: &mut impl FnMut(u64, Vec<Vec3>)) {
        let Some(plane) = planes.get(k) else {
            return out(above, polygon);
        };
        let bit = 1 << k;
        let heights = polygon.iter().map(|&p| plane.height(p));
        let bounds = polygon.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)));
        let whole_above = if !plane.is_near(bounds) {
            Some(plane.height(polygon.iter().copied().sum::<Vec3>() / polygon.len() as f32) > 0.0)
        } else if heights.clone().all(|h| h >= 0.0) {
            Some(true)
        } else if heights.clone().all(|h| h <= 0.0) {
            Some(false)
        } else {
            None
        };
        if let Some(whole_above) = whole_above {
            return split(polygon, planes, k + 1, if whole_above { above | bit } else { above }, out);
        }
        for (keep_above, mask) in [(true, bit), (false, 0)] {
            let part = clip(&polygon, plane.normal, plane.offset, keep_above);
            if part.len() >= 3 {
                split(part, planes, k + 1, above | mask, out);
            }
        }
    }
    split(polygon, &planes[..planes.len().min(64)], 0, 0, out);
}

/// A square cell of a surface's quadtree, in units of the quadtree's grid
/// ([`FINER`] times finer than `patch_size`) from the surface's corner:
/// columns `i..i + 2^level`, rows `j..j + 2^level`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
struct Cell {
    i: i64,
    j: i64,
    level: u32,
}

/// The grid's cells (i, j) from the first corner to the second, both in.
type CellSpan = ((i64, i64), (i64, i64));

/// A surface's plane and its quadtree's leaves.
struct Quadtree {
    /// The sizing near the surface ([`PatchSizing::within`]).
    sizing: PatchSizing,
    u: Vec3,
    v: Vec3,
    /// The plane's offset along its normal, and the normal.
    offset: f32,
    normal: Vec3,
    /// The grid's corner (u, v).
    origin: (f32, f32),
    /// The grid's side: `patch_size` / [`FINER`].
    unit: f32,
    root: Cell,
}

impl Quadtree {
    /// The quadtree of `surface` (made of `tris`), rooted at its corner.
    fn for_surface(sizing: &PatchSizing, surface: &Surface, tris: &[Triangle]) -> Self {
        let (u, v) = plane_axes(surface.normal);
        let origin =
            tris.iter().flat_map(|t| t.vertices).fold((f32::INFINITY, f32::INFINITY), |(a, b), p| (a.min(p.dot(u)), b.min(p.dot(v))));
        let unit = sizing.finest / FINER;
        let extent = tris
            .iter()
            .flat_map(|t| t.vertices)
            .map(|p| (((p.dot(u) - origin.0) / unit).floor() as i64).max(((p.dot(v) - origin.1) / unit).floor() as i64))
            .fold(0, i64::max)
            + 1;
        let level = (extent.max(1) as u64).next_power_of_two().trailing_zeros();
        let offset = surface.normal.dot(tris[0].vertices[0]);
        // Every cell's centre lies in the root's square.
        let side = (1u64 << level) as f32 * unit;
        let corner = |a: f32, b: f32| u * (origin.0 + a) + v * (origin.1 + b) + surface.normal * offset;
        let square = [corner(0.0, 0.0), corner(side, 0.0), corner(0.0, side), corner(side, side)];
        let square = square.iter().fold((square[0], square[0]), |(lo, hi), &p| (lo.min(p), hi.max(p)));
        let sizing = sizing.within(square).in_plane(surface.normal, offset);
        Quadtree { sizing, u, v, offset, normal: surface.normal, origin, unit, root: Cell { i: 0, j: 0, level } }
    }

    /// The grid's cell (i, j) holding `p`.
    fn cell_of(&self, p: Vec3) -> (i64, i64) {
        (((p.dot(self.u) - self.origin.0) / self.unit).floor() as i64, ((p.dot(self.v) - self.origin.1) / self.unit).floor() as i64)
    }

    /// The grid's cells `lo..=hi` a triangle's box covers.
    fn cells_under(&self, triangle: &Triangle) -> CellSpan {
        let cells = triangle.vertices.map(|p| self.cell_of(p));
        cells.iter().fold((cells[0], cells[0]), |(lo, hi), &(i, j)| ((lo.0.min(i), lo.1.min(j)), (hi.0.max(i), hi.1.max(j))))
    }

    /// Whether `cell` overlaps the grid's cells `lo..=hi`.
    fn overlaps(&self, cell: Cell, (lo, hi): CellSpan) -> bool {
        let span = self.span(cell);
        cell.i <= hi.0 && cell.j <= hi.1 && cell.i + span > lo.0 && cell.j + span > lo.1
    }

    /// Adds the leaves under `cell` overlapping one of `spans` to `count`,
    /// stopping at `limit`.
    fn count_leaves(&self, cell: Cell, spans: &[CellSpan], count: &mut u64, limit: u64) {
        let spans: Vec<CellSpan> = spans.iter().copied().filter(|&span| self.overlaps(cell, span)).collect();
        if *count >= limit || spans.is_empty() {
            return;
        }
        if self.is_leaf(cell) {
            *count += 1;
            return;
        }
        for child in self.children(cell) {
            self.count_leaves(child, &spans, count, limit);
        }
    }

    fn span(&self, cell: Cell) -> i64 {
        1 << cell.level
    }

    /// The cell's bounds in the plane: (u0, v0, side).
    fn bounds(&self, cell: Cell) -> (f32, f32, f32) {
        let size = self.unit;
        (self.origin.0 + cell.i as f32 * size, self.origin.1 + cell.j as f32 * size, self.span(cell) as f32 * size)
    }

    fn is_leaf(&self, cell: Cell) -> bool {
        if cell.level == 0 {
            return true;
        }
        let (u0, v0, side) = self.bounds(cell);
        let centre = self.u * (u0 + side / 2.0) + self.v * (v0 + side / 2.0) + self.normal * self.offset;
        let square = Square { centre, u: self.u, v: self.v, half: side / 2.0 };
        side <= self.sizing.allowed_for(square, side * std::f32::consts::FRAC_1_SQRT_2)
    }

    fn children(&self, cell: Cell) -> [Cell; 4] {
        let half = self.span(cell) / 2;
        let level = cell.level - 1;
        [(0, 0), (half, 0), (0, half), (half, half)].map(|(di, dj)| Cell { i: cell.i + di, j: cell.j + dj, level })
    }

    /// The leaf holding the grid's cell (i, j).
    fn leaf_at(&self, (i, j): (i64, i64)) -> Cell {
        let mut cell = self.root;
        while !self.is_leaf(cell) {
            let half = self.span(cell) / 2;
            let (di, dj) = (i64::from(i >= cell.i + half) * half, i64::from(j >= cell.j + half) * half);
            cell = Cell { i: cell.i + di, j: cell.j + dj, level: cell.level - 1 };
        }
        cell
    }

    /// The leaves overlapping the grid's cells `cells`, into `out`.
    fn leaves_over(&self, cell: Cell, cells: CellSpan, out: &mut Vec<Cell>) {
        if !self.overlaps(cell, cells) {
            return;
        }
        if self.is_leaf(cell) {
            out.push(cell);
            return;
        }
        for child in self.children(cell) {
            self.leaves_over(child, cells, out);
        }
    }
}

/// About how many patches `subdivide` would cut, counted before cutting
/// them (every quadtree leaf under some triangle's cells, as `subdivide`
/// visits them: an upper bound), and no further than `limit`: work that
/// would not fit is refused before it is done. Leaves over a surface's
/// whole square would count a façade's 50 m sill strip, two triangles of
/// 60 patches, as the 6,000 of the square it spans (Revit's Office_A:
/// over a million for its 52,000 triangles).
pub fn estimate(triangles: &[Triangle], surfaces: &[Surface], sizing: &PatchSizing, limit: u64) -> u64 {
    let mut count = 0;
    for surface in surfaces {
        let tris = &triangles[surface.triangle_indices()];
        let tree = Quadtree::for_surface(sizing, surface, tris);
        let spans: Vec<CellSpan> = tris.iter().map(|t| tree.cells_under(t)).collect();
        tree.count_leaves(tree.root, &spans, &mut count, limit);
        if count >= limit {
            break;
        }
    }
    count
}

/// Surfaces smaller than this share of the allowed patch's area are clutter.
pub(crate) const CLUTTER: f32 = 0.25;

/// Clutter facing one way is clustered only within layers this thick (m)
/// along its main axis: parallel sheets apart (a roof's layers, one in the
/// sun, one in its shadow; a desk over a chair) are separate patches, not
/// one averaging both. (At 5 cm the Duplex's hallway under such a roof
/// reads 6.0 lx, at 10 cm 9.9, against Radiance's 3.3; but the furnished
/// floor of `benches/light.rs` gets 30,103 patches instead of 29,442.)
const CLUSTER_LAYER: f32 = 0.1;

/// What a cluster holds of a surface: all of it, or one of the patches it
/// is cut into where a window plane or a large face meeting it cuts it.
enum Member {
    Whole(u32),
    Piece(u32, Pieces),
}

impl Member {
    fn surface(&self) -> u32 {
        match self {
            Member::Whole(s) | Member::Piece(s, _) => *s,
        }
    }
}

/// A cluster's material, direction, cube, layer, the sides of the window
/// planes near it and of the large faces crossing its cube, and the sides
/// of the planes that cut its pieces.
type ClusterKey = (u32, u8, [i64; 3], i64, Vec<(u32, bool)>, Vec<bool>, Vec<([i32; 4], bool)>);

/// The clusters of clutter, gathered member by member ([`Self::add`]):
/// one patch per material, cube of the allowed size, main direction and
/// [`CLUSTER_LAYER`]. Clutter on the two sides of a window's plane (frames
/// outside and in), or of a large face crossing its cube (a door's handles
/// outside and in, [`LargeFaces::separating`]), never shares a cluster,
/// except far from the focus ([`FAR_SIDES`]); nor do the pieces of clutter
/// cut on the two sides of a plane (a frame's profile outside and inside
/// its glass, a rafter's end through a wall), nor a piece and clutter left
/// whole. (Cut clutter was patches of its own, a few square centimetres
/// each: FZK-Haus 19,274 → 17,356 patches, Duplex 39,585 → 38,772.)
struct Clusters<'a> {
    finest: f32,
    cuts: &'a [CutPlane],
    large: &'a LargeFaces<'a>,
    keys: BTreeMap<ClusterKey, u32>,
    /// Per cube (its corner and side), the large faces' planes crossing it.
    separators: HashMap<([i64; 3], u32), Vec<Plane>>,
    /// Per cluster, what it holds, the first member's surface first.
    members: Vec<Vec<Member>>,
}

impl<'a> Clusters<'a> {
    fn new(finest: f32, cuts: &'a [CutPlane], large: &'a LargeFaces<'a>) -> Self {
        Self { finest, cuts, large, keys: BTreeMap::new(), separators: HashMap::new(), members: Vec::new() }
    }

    /// Adds `member` of `surface` (its `triangles` when whole), where the
    /// side `allowed` is allowed; `planes` are those that cut the surface
    /// into pieces where it is one.
    fn add(&mut self, triangles: &[Triangle], surface: &Surface, allowed: f32, member: Member, planes: &[CutPlane]) {
        let (centroid, bounds) = match &member {
            Member::Whole(_) => centroid_and_bounds(triangles.iter().map(|t| t.vertices)),
            Member::Piece(_, pieces) => centroid_and_bounds(pieces.iter().copied()),
        };
        let far = is_far(allowed, self.finest);
        // Cubes of the allowed side, nested on the finest grid.
        let side = self.finest * (allowed / self.finest).log2().floor().exp2();
        let cube = (centroid / side).floor().as_i64vec3().to_array();
        let n = surface.normal;
        let axis = n.abs().max_position();
        let direction = (2 * axis + usize::from(n[axis] < 0.0)) as u8;
        let layer = (centroid[axis] / CLUSTER_LAYER).floor() as i64;
        let (sides, apart, cut_sides) = match far {
            true => (Vec::new(), Vec::new(), Vec::new()),
            false => {
                let sides = self
                    .cuts
                    .iter()
                    .enumerate()
                    .filter(|(_, c)| c.is_near(bounds))
                    .map(|(k, c)| (k as u32, c.height(centroid) > 0.0))
                    .collect();
                let large = self.large;
                let crossing = self.separators.entry((cube, side.to_bits())).or_insert_with(|| {
                    let corner = Vec3::new(cube[0] as f32, cube[1] as f32, cube[2] as f32) * side;
                    large.separating(corner, corner + Vec3::splat(side))
                });
                let apart = crossing.iter().map(|&(normal, offset)| normal.dot(centroid) > offset).collect();
                (sides, apart, planes.iter().map(|plane| plane_key(plane, centroid)).collect())
            }
        };
        let next = self.members.len() as u32;
        let cluster = *self.keys.entry((surface.material, direction, cube, layer, sides, apart, cut_sides)).or_insert(next);
        if cluster == next {
            self.members.push(Vec::new());
        }
        self.members[cluster as usize].push(member);
    }
}

/// Whether a place allowed patches `allowed` wide lies far from the focus
/// ([`FAR_SIDES`]).
fn is_far(allowed: f32, finest: f32) -> bool {
    allowed >= FAR_SIDES * finest
}

/// A cutting plane, the same whichever way its normal points (to 0.001 in
/// the normal, 2 mm in the offset), and the side of it `p` lies on.
fn plane_key(plane: &CutPlane, p: Vec3) -> ([i32; 4], bool) {
    let flip = if plane.normal[plane.normal.abs().max_position()] < 0.0 { -1.0 } else { 1.0 };
    let (normal, offset) = (flip * plane.normal, flip * plane.offset);
    let key = [normal.x * 1e3, normal.y * 1e3, normal.z * 1e3, offset * 500.0].map(|v| v.round() as i32);
    (key, normal.dot(p) > offset)
}

/// Cuts every surface into patches no larger than `sizing` allows, along
/// the window planes `cuts` and where the `large` faces meet it (see
/// [`super::contacts`]; not clutter far from the focus, [`FAR_SIDES`]),
/// gathers the clutter among the surfaces `clusterable` allows into
/// clusters, and sets each surface's patch range.
pub fn subdivide(
    triangles: &[Triangle],
    surfaces: &mut [Surface],
    sizing: &PatchSizing,
    clusterable: &[bool],
    cuts: &[CutPlane],
    large: &LargeFaces,
) -> PatchMesh {
    let mut mesh = PatchMesh::default();
    // Per surface `clusterable` allows: its centroid and the side allowed there.
    let placed = par_map(None, surfaces.len(), |index| {
        clusterable[index].then(|| {
            let centroid = surfaces[index].centroid(triangles);
            (centroid, sizing.allowed(centroid, 0.0))
        })
    });
    // Clutter: small where it lies. It joins a cluster whole, or, where a
    // large face meeting it or a window plane near the focus cuts it, cut
    // there piece by piece: a rafter through a wall or a frame through its
    // glass, clustered whole, lit the room inside with its sunlit end. Far
    // from the focus no face it meets cuts it.
    let clutter = |index: usize| placed[index].filter(|&(_, allowed)| surfaces[index].area < CLUTTER * allowed * allowed);
    let far_clutter = |index: usize| clutter(index).is_some_and(|(_, allowed)| is_far(allowed, sizing.finest));
    let contacts = contact_cuts(large, surfaces, |index| !far_clutter(index));
    let whole = |index: usize, allowed: f32| {
        let tris = &triangles[surfaces[index].triangle_indices()];
        let bounds = super::bounds(tris);
        contacts[index].is_empty() && (is_far(allowed, sizing.finest) || !cuts.iter().any(|c| c.cuts(tris, bounds)))
    };
    // Each surface's patches, surface by surface on every core (none for clutter left whole).
    let shared: &[Surface] = surfaces;
    let surface_patches = par_map(None, shared.len(), |index| match clutter(index) {
        Some((_, allowed)) if whole(index, allowed) => Vec::new(),
        _ => patches_of_surface(&shared[index], triangles, sizing, cuts, &contacts[index]),
    });
    let mut clusters = Clusters::new(sizing.finest, cuts, large);
    let mut own = Vec::with_capacity(shared.len());
    for (index, patches) in surface_patches.into_iter().enumerate() {
        let Some((_, allowed)) = clutter(index) else {
            own.push(patches);
            continue;
        };
        let (surface, tris) = (&shared[index], &triangles[shared[index].triangle_indices()]);
        if patches.is_empty() {
            clusters.add(tris, surface, allowed, Member::Whole(index as u32), &[]);
        }
        for pieces in patches {
            clusters.add(tris, surface, allowed, Member::Piece(index as u32, pieces), &contacts[index]);
        }
        own.push(Vec::new());
    }
    // A cluster's patch goes with its first member's surface.
    let mut first_of: Vec<Vec<Vec<Member>>> = (0..shared.len()).map(|_| Vec::new()).collect();
    for members in clusters.members {
        first_of[members[0].surface() as usize].push(members);
    }
    for (index, (patches, firsts)) in own.into_iter().zip(first_of).enumerate() {
        let first_patch = mesh.patches.len() as u32;
        for members in firsts {
            mesh.push_cluster(triangles, surfaces, members);
        }
        let surface = &mut surfaces[index];
        for pieces in patches {
            let start = mesh.triangles.len() as u32;
            let mut area = 0.0;
            let mut moment = Vec3::ZERO;
            for piece in pieces {
                let a = piece_area(&piece);
                area += a;
                moment += a * (piece[0] + piece[1] + piece[2]) / 3.0;
                mesh.triangles.push(piece);
            }
            mesh.patches.push(Patch {
                surface: index as u32,
                material: surface.material,
                area,
                normal: surface.normal,
                centroid: moment / area,
                triangles: start..mesh.triangles.len() as u32,
            });
        }
        surface.patches = first_patch..mesh.patches.len() as u32;
    }
    mesh
}

/// One surface's patches, each a list of render triangles: its quadtree's
/// leaf cells cut by the window planes `cuts` that reach it and by its
/// `contacts`, the small cells joined to a neighbour ([`merge_small_cells`]).
fn patches_of_surface(
    surface: &Surface,
    triangles: &[Triangle],
    sizing: &PatchSizing,
    cuts: &[CutPlane],
    contacts: &[CutPlane],
) -> Vec<Pieces> {
    let tris = &triangles[surface.triangle_indices()];
    let tree = Quadtree::for_surface(sizing, surface, tris);
    let (u, v) = (tree.u, tree.v);
    let cell_of = |p: Vec3| tree.cell_of(p);
    let bounds = super::bounds(tris);
    let planes: Vec<&CutPlane> = cuts.iter().filter(|c| c.cuts(tris, bounds)).chain(contacts).collect();
    // Per leaf cell and side of the cutting planes: its pieces.
    let mut cells: BTreeMap<CellKey, Pieces> = BTreeMap::new();
    let mut add = |cell: Cell, polygon: Vec<Vec3>| {
        split_by_planes(polygon, &planes, &mut |above, part| {
            let pieces = cells.entry((cell.i, cell.j, above)).or_default();
            for k in 1..part.len().saturating_sub(1) {
                let piece = [part[0], part[k], part[k + 1]];
                if piece_area(&piece) > SLIVER_AREA {
                    pieces.push(piece);
                }
            }
        })
    };
    let mut leaves = Vec::new();
    for triangle in tris {
        let [a, b, c] = triangle.vertices;
        let longest = (b - a).length().max((c - b).length()).max((a - c).length());
        let home = tree.leaf_at(cell_of(triangle.centroid()));
        if longest <= tree.bounds(home).2 {
            add(home, triangle.vertices.to_vec());
            continue;
        }
        leaves.clear();
        tree.leaves_over(tree.root, tree.cells_under(triangle), &mut leaves);
        leaves.sort_unstable();
        for &leaf in &leaves {
            let (u0, v0, side) = tree.bounds(leaf);
            let mut polygon = triangle.vertices.to_vec();
            for (axis, bound, keep_above) in [(u, u0, true), (u, u0 + side, false), (v, v0, true), (v, v0 + side, false)] {
                polygon = clip(&polygon, axis, bound, keep_above);
                if polygon.len() < 3 {
                    break;
                }
            }
            if polygon.len() >= 3 {
                add(leaf, polygon);
            }
        }
    }
    merge_small_cells(&tree, cells)
}

/// A leaf cell's pieces of a surface on one side of each cutting plane: its
/// column, row and the planes it lies above ([`split_by_planes`]).
type CellKey = (i64, i64, u64);
/// Render triangles.
type Pieces = Vec<[Vec3; 3]>;

/// A cell holding less of its surface than this share of the cell's area
/// joins a neighbour ([`merge_small_cells`]). (At a half, SampleHouse's
/// rooms read 1% darker against Radiance than with no cell joined; at a
/// quarter they read as before, FZK-Haus's closer: median 1.8 → 1.3%.)
const SMALL_CELL: f32 = 0.25;
/// A cell joins a neighbour only while together they hold no more than this
/// share of the cell's area.
const MERGED_CELLS: f32 = 1.5;

/// A surface's leaf cells' pieces (per cell and side of the cutting planes)
/// as patches: a cell holding little of the surface (its edge strip, a
/// frame's profile, the corner a cut left) joins the neighbouring cell of
/// its own size on the same sides of every cutting plane that holds the
/// most, smallest cells first, while the patch so made stays within two
/// cells each way and [`MERGED_CELLS`] of a cell's area: no patch grows past
/// what the sizing allows where it lies. Slivers then stop counting as
/// patches of their own (AC20-Institute-Var-2: 53,000 of 143,416 patches
/// held under a quarter of a cell, 5% of the area), and no patch reaches
/// far: joined without the bound, thin strips chained along a roof's
/// underside from the sunlit eaves into FZK-Haus's attic (its gallery read
/// 3× Radiance).
fn merge_small_cells(tree: &Quadtree, cells: BTreeMap<CellKey, Pieces>) -> Vec<Pieces> {
    let (keys, mut pieces): (Vec<CellKey>, Vec<Pieces>) = cells.into_iter().filter(|(_, p)| !p.is_empty()).unzip();
    let index: HashMap<CellKey, usize> = keys.iter().enumerate().map(|(k, &key)| (key, k)).collect();
    let leaves: Vec<Cell> = keys.iter().map(|&(i, j, _)| tree.leaf_at((i, j))).collect();
    let cell_area = |k: usize| tree.bounds(leaves[k]).2.powi(2);
    let mut area: Vec<f32> = pieces.iter().map(|p| p.iter().map(piece_area).sum()).collect();
    // Each group's cells' box in the grid's cells: (i0, j0, i1, j1).
    let mut extent: Vec<[i64; 4]> =
        leaves.iter().map(|&leaf| [leaf.i, leaf.j, leaf.i + tree.span(leaf), leaf.j + tree.span(leaf)]).collect();
    let mut joined: Vec<usize> = (0..keys.len()).collect();
    let root = |joined: &[usize], mut k: usize| {
        while joined[k] != k {
            k = joined[k];
        }
        k
    };
    let mut smallest_first: Vec<usize> = (0..keys.len()).filter(|&k| area[k] < SMALL_CELL * cell_area(k)).collect();
    smallest_first.sort_by(|&a, &b| area[a].total_cmp(&area[b]).then(a.cmp(&b)));
    for k in smallest_first {
        let own = root(&joined, k);
        if area[own] >= SMALL_CELL * cell_area(k) {
            continue;
        }
        let (Cell { i, j, level }, above) = (leaves[k], keys[k].2);
        let span = tree.span(leaves[k]);
        let neighbours = [(i - 1, j), (i + span, j), (i, j - 1), (i, j + span)].map(|at| {
            let leaf = tree.leaf_at(at);
            (leaf.level == level).then(|| index.get(&(leaf.i, leaf.j, above)).map(|&n| root(&joined, n))).flatten()
        });
        let fits = |group: usize| {
            let ([a0, b0, a1, b1], [c0, d0, c1, d1]) = (extent[group], extent[own]);
            group != own
                && area[group] + area[own] <= MERGED_CELLS * cell_area(k)
                && a1.max(c1) - a0.min(c0) <= 2 * span
                && b1.max(d1) - b0.min(d0) <= 2 * span
        };
        let best =
            neighbours.into_iter().flatten().filter(|&group| fits(group)).max_by(|&a, &b| area[a].total_cmp(&area[b]).then(b.cmp(&a)));
        if let Some(group) = best {
            joined[own] = group;
            area[group] += area[own];
            let ([a0, b0, a1, b1], [c0, d0, c1, d1]) = (extent[group], extent[own]);
            extent[group] = [a0.min(c0), b0.min(d0), a1.max(c1), b1.max(d1)];
            let moved = std::mem::take(&mut pieces[own]);
            pieces[group].extend(moved);
        }
    }
    pieces.into_iter().enumerate().filter(|(k, _)| root(&joined, *k) == *k).map(|(_, p)| p).collect()
}

/// Two in-plane axes: horizontal and up-slope for walls, east and north for
/// floors and ceilings.
fn plane_axes(normal: Vec3) -> (Vec3, Vec3) {
    let u = if normal.z.abs() > 0.999 { Vec3::X } else { Vec3::Z.cross(normal).normalize() };
    (u, normal.cross(u).normalize())
}

/// Sutherland–Hodgman: the part of a convex polygon on one side of the plane
/// `p·axis = bound`.
pub(crate) fn clip(polygon: &[Vec3], axis: Vec3, bound: f32, keep_above: bool) -> Vec<Vec3> {
    let side = |p: Vec3| if keep_above { p.dot(axis) - bound } else { bound - p.dot(axis) };
    let mut out = Vec::with_capacity(polygon.len() + 1);
    for (k, &current) in polygon.iter().enumerate() {
        let next = polygon[(k + 1) % polygon.len()];
        let (dc, dn) = (side(current), side(next));
        if dc >= 0.0 {
            out.push(current);
        }
        if (dc >= 0.0) != (dn >= 0.0) {
            out.push(current + (next - current) * (dc / (dc - dn)));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad(w: f32, h: f32) -> Vec<Triangle> {
        // A w × h wall in the xz plane, facing -y (south).
        let (a, b, c, d) = (Vec3::ZERO, Vec3::new(w, 0.0, 0.0), Vec3::new(w, 0.0, h), Vec3::new(0.0, 0.0, h));
        vec![
            Triangle { vertices: [a, b, c], material: 0, file_vertices: [0, 1, 2] },
            Triangle { vertices: [a, c, d], material: 0, file_vertices: [0, 2, 3] },
        ]
    }

    fn surface_of(triangles: &[Triangle]) -> Surface {
        let cross: Vec3 = triangles.iter().map(Triangle::cross).sum();
        Surface {
            material: 0,
            triangles: 0..triangles.len() as u32,
            patches: 0..0,
            normal: cross.normalize(),
            area: triangles.iter().map(Triangle::area).sum(),
        }
    }

    #[test]
    fn a_wall_becomes_a_grid_of_square_patches_that_conserve_area() {
        let tris = quad(4.0, 3.0);
        let mut surfaces = vec![surface_of(&tris)];
        let large = LargeFaces::new(&tris, &surfaces, f32::INFINITY);
        let mesh = subdivide(&tris, &mut surfaces, &PatchSizing::uniform(0.5), &[false], &[], &large);
        assert_eq!(mesh.patches.len(), 8 * 6);
        assert_eq!(surfaces[0].patches, 0..48);
        for patch in &mesh.patches {
            assert!((patch.area - 0.25).abs() < 1e-5, "patch area {}", patch.area);
            assert!((patch.normal - Vec3::NEG_Y).length() < 1e-6);
            let pieces = &mesh.triangles[patch.triangle_indices()];
            for piece in pieces {
                // Same winding as the source: the piece's normal is the surface's.
                let n = (piece[1] - piece[0]).cross(piece[2] - piece[0]).normalize();
                assert!(n.dot(patch.normal) > 0.999);
                for p in piece {
                    assert!((p - patch.centroid).abs().max_element() <= 0.5 + 1e-5);
                }
            }
        }
        let total: f32 = mesh.patches.iter().map(|p| p.area).sum();
        assert!((total - 12.0).abs() < 1e-4);
    }

    /// The estimate bounds the patches from above and follows the surface,
    /// not the square it spans: a 50 m sill strip 0.3 m deep, two
    /// triangles, is about 100 patches of 0.5 m (a hundred columns, one
    /// row), not the 10,000 of its 50 m square; the wall as before.
    #[test]
    fn the_patch_estimate_counts_the_cells_a_surface_covers() {
        let strip: Vec<Triangle> =
            quad(50.0, 0.3).into_iter().map(|t| Triangle { vertices: t.vertices.map(|v| Vec3::new(v.x, v.z, 0.8)), ..t }).collect();
        for tris in [strip, quad(4.0, 3.0)] {
            let mut surfaces = vec![surface_of(&tris)];
            let sizing = PatchSizing::uniform(0.5);
            let estimate = estimate(&tris, &surfaces, &sizing, u64::MAX);
            let large = LargeFaces::new(&tris, &surfaces, f32::INFINITY);
            let patches = subdivide(&tris, &mut surfaces, &sizing, &[false], &[], &large).patches.len() as u64;
            assert!(patches <= estimate && estimate <= 2 * patches, "{patches} patches, estimated {estimate}");
        }
    }

    /// Patches are finest around the sensors and the windows that light
    /// them; a wing with windows but no sensor is coarse, unless the scene
    /// has no sensor at all.
    #[test]
    fn patches_are_finest_where_the_sensors_are_and_coarse_in_a_wing_without_them() {
        // A 64 m façade, a window at each end, a sensor 4 m inside from the first.
        let tris = quad(64.0, 3.0);
        let window = |x: f32| (Vec3::new(x, 0.0, 1.0), Vec3::new(x + 2.0, 0.0, 2.0));
        let windows = [window(1.0), window(60.0)];
        let sensor = Vec3::new(2.0, -4.0, 0.8);
        let width_at = |sizing: &PatchSizing, x: f32| {
            let mut surfaces = vec![surface_of(&tris)];
            let large = LargeFaces::new(&tris, &surfaces, f32::INFINITY);
            let mesh = subdivide(&tris, &mut surfaces, sizing, &[false], &[], &large);
            let mut spans = mesh.patches.iter().map(|p| {
                let pieces = &mesh.triangles[p.triangle_indices()];
                pieces.iter().flatten().fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), v| (lo.min(v.x), hi.max(v.x)))
            });
            let (lo, hi) = spans.find(|&(lo, hi)| lo <= x && x <= hi).expect("a patch covers x");
            hi - lo
        };
        let point =
            |position: Vec3| Sensor { name: String::new(), position, normal: Vec3::Z, size: None, axes: [Vec3::X, Vec3::Y], grid: None };
        let with_sensor = PatchSizing::around(0.5, &[point(sensor)], &windows);
        let two_rooms = PatchSizing::around(0.5, &[point(sensor), point(sensor + 38.0 * Vec3::X)], &windows);
        // The window 4 m from the sensor lights it: finest there (the
        // sensor's own margin alone would allow 1 m).
        assert!((width_at(&with_sensor, 2.2) - 0.5).abs() < 1e-4);
        assert!(width_at(&with_sensor, 61.2) >= 4.0, "the far wing's window {}", width_at(&with_sensor, 61.2));
        // Patches far from the sensors trace fewer rays, never under the least share.
        assert_eq!(with_sensor.ray_share(Vec3::new(2.2, 0.0, 1.5)), 1.0);
        assert_eq!(with_sensor.ray_share(Vec3::new(61.2, 0.0, 1.5)), MIN_RAY_SHARE);
        let between = with_sensor.ray_share(Vec3::new(9.7, 0.0, 1.5));
        assert!(MIN_RAY_SHARE < between && between < 1.0, "{between}");
        // Without sensors every window is the focus, and what lies between.
        let without = PatchSizing::around(0.5, &[], &windows);
        for x in [2.2, 30.2, 61.2] {
            assert!((width_at(&without, x) - 0.5).abs() < 1e-4, "at x = {x}");
        }
        // The nearest focus box is found surface by surface from a few
        // candidates: the same sizing as testing them all.
        for x in [2.2, 9.7, 30.2, 61.2] {
            let region = (Vec3::new(x - 1.0, 0.0, 0.0), Vec3::new(x + 1.0, 0.0, 3.0));
            let near = two_rooms.within(region);
            assert!(near.focus.len() < two_rooms.focus.len(), "at x = {x}");
            for p in [region.0, region.1, Vec3::new(x, 0.0, 1.5)] {
                assert_eq!(near.allowed(p, 0.3), two_rooms.allowed(p, 0.3), "at {p}");
            }
        }
    }

    /// A sensor a few centimetres from a surface sees the spot in front of
    /// it: the patches there are finer, down to an eighth of `patch_size`
    /// and no wider than twice their distance from it ([`NearSensor`]). A
    /// sensor a metre from it leaves the usual grid; one lying on it facing
    /// away sees none of it, which may be as coarse as out of its view.
    #[test]
    fn patches_are_finer_in_front_of_a_sensor_close_to_a_surface() {
        let tris = quad(4.0, 3.0);
        let sensor = |y: f32, normal: Vec3| Sensor {
            name: String::new(),
            position: Vec3::new(2.1, y, 1.6),
            normal,
            size: None,
            axes: [Vec3::X, Vec3::Z],
            grid: None,
        };
        let mesh_of = |sensors: &[Sensor]| {
            let mut surfaces = vec![surface_of(&tris)];
            let large = LargeFaces::new(&tris, &surfaces, f32::INFINITY);
            subdivide(&tris, &mut surfaces, &PatchSizing::around(0.5, sensors, &[]), &[false], &[], &large)
        };
        // The width along x of the narrowest patch whose box holds (x, z).
        let width_at = |mesh: &PatchMesh, x: f32, z: f32| {
            let boxes = mesh.patches.iter().map(|p| {
                let pieces = &mesh.triangles[p.triangle_indices()];
                pieces.iter().flatten().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &v| (lo.min(v), hi.max(v)))
            });
            let holding = boxes.filter(|(lo, hi)| lo.x <= x && x <= hi.x && lo.z <= z && z <= hi.z);
            holding.map(|(lo, hi)| hi.x - lo.x).fold(f32::INFINITY, f32::min)
        };
        let close = mesh_of(&[sensor(-0.04, Vec3::Y)]);
        assert!(width_at(&close, 2.1, 1.6) <= 0.5 / FINER + 1e-4, "{}", width_at(&close, 2.1, 1.6));
        let beside = width_at(&close, 2.4, 1.6);
        assert!(beside > 0.5 / FINER + 1e-4 && beside <= NEAR_GROWTH * 0.3 + 1e-4, "30 cm along: {beside}");
        assert!((width_at(&close, 3.2, 1.7) - 0.5).abs() < 1e-4, "within a metre of it");
        assert!((width_at(&close, 3.6, 0.4) - 1.0).abs() < 1e-4, "a metre and more from it (SENSOR_SLOPE)");
        let area: f32 = close.patches.iter().map(|p| p.area).sum();
        assert!((area - 12.0).abs() < 1e-3, "area {area}");
        assert_eq!(mesh_of(&[sensor(-1.0, Vec3::Y)]).patches.len(), 4 * 3, "a metre from it");
        // Lying on it facing away, it sees none of it.
        assert_eq!(mesh_of(&[sensor(0.0, Vec3::NEG_Y)]).patches.len(), 4 * 3, "behind it");
    }

    /// Sensor `k` of a 4 × 4 grid, 2 m apart, 0.8 m over an 8 × 8 m room.
    fn desk_sensor(k: usize, normal: Vec3, grid: &str) -> Sensor {
        Sensor {
            name: String::new(),
            position: Vec3::new(1.0 + 2.0 * (k % 4) as f32, 1.0 + 2.0 * (k / 4) as f32, 0.8),
            normal,
            size: None,
            axes: [Vec3::X, Vec3::Y],
            grid: Some(grid.into()),
        }
    }

    /// The (centroid y, area) of each patch `sizing` cuts an 8 × 8 m
    /// horizontal square at `z` into, facing up or down.
    fn square_patches(z: f32, up: bool, sizing: &PatchSizing) -> Vec<(f32, f32)> {
        let corner = |x: f32, y: f32| Vec3::new(x, y, z);
        let (a, b, c, d) = (corner(0.0, 0.0), corner(8.0, 0.0), corner(8.0, 8.0), corner(0.0, 8.0));
        let tris = if up {
            vec![
                Triangle { vertices: [a, b, c], material: 0, file_vertices: [0, 1, 2] },
                Triangle { vertices: [a, c, d], material: 0, file_vertices: [0, 2, 3] },
            ]
        } else {
            vec![
                Triangle { vertices: [a, c, b], material: 0, file_vertices: [0, 2, 1] },
                Triangle { vertices: [a, d, c], material: 0, file_vertices: [0, 3, 2] },
            ]
        };
        let mut surfaces = vec![surface_of(&tris)];
        let large = LargeFaces::new(&tris, &surfaces, f32::INFINITY);
        let mesh = subdivide(&tris, &mut surfaces, sizing, &[false], &[], &large);
        mesh.patches.iter().map(|p| (p.centroid.y, p.area)).collect()
    }

    /// Away from the windows, a patch may be as wide as its distance from
    /// the sensors, at most two finest sides: a ceiling 2.2 m over its grid
    /// is 1 m patches but where the window's focus keeps it finer; 0.9 m
    /// over the grid it is the finest grid.
    #[test]
    fn a_tall_rooms_ceiling_is_coarser_away_from_its_windows() {
        let grid: Vec<Sensor> = (0..16).map(|k| desk_sensor(k, Vec3::Z, "workplane")).collect();
        let window = (Vec3::new(2.0, 0.0, 0.9), Vec3::new(6.0, 0.0, 2.4));
        let sizing = PatchSizing::around(0.5, &grid, &[window]);
        let tall = square_patches(3.0, false, &sizing);
        assert!(tall.iter().filter(|&&(y, _)| y < 1.5).all(|&(_, area)| (area - 0.25).abs() < 1e-4), "{tall:?}");
        assert!(tall.iter().filter(|&&(y, _)| y > 4.0).all(|&(_, area)| (area - 1.0).abs() < 1e-4), "{tall:?}");
        // Finest up to 4 m from the window (its margin and growth), 1 m beyond.
        assert_eq!(tall.len(), 8 * 16 + 4 * 8);
        let low = square_patches(1.7, false, &sizing);
        assert_eq!(low.len(), 256);
    }

    /// The floor under a grid of desk sensors is behind every one of them:
    /// 1 m patches but in the window's focus. Sensors facing down see it,
    /// and keep it finest.
    #[test]
    fn the_floor_under_a_grid_is_coarser_away_from_its_window() {
        let window = (Vec3::new(2.0, 0.0, 0.9), Vec3::new(6.0, 0.0, 2.4));
        let floor_of = |normal: Vec3| {
            let sensors: Vec<Sensor> = (0..16).map(|k| desk_sensor(k, normal, "desks")).collect();
            square_patches(0.0, true, &PatchSizing::around(0.5, &sensors, &[window]))
        };
        let under_desks = floor_of(Vec3::Z);
        assert!(under_desks.iter().filter(|&&(y, _)| y < 1.5).all(|&(_, area)| (area - 0.25).abs() < 1e-4), "{under_desks:?}");
        assert!(under_desks.iter().filter(|&&(y, _)| y > 5.0).all(|&(_, area)| (area - 1.0).abs() < 1e-4), "{under_desks:?}");
        // Facing down, the floor is in their view.
        let seen = floor_of(Vec3::NEG_Z);
        assert!(seen.iter().all(|&(_, area)| (area - 0.25).abs() < 1e-4), "{seen:?}");
    }

    /// Every patch's ray share, asked surface by surface of the sizing
    /// near it, is the one the whole sizing gives, on a model whose shares
    /// vary (the office: sensors in its rooms, coarse on its roof and ground).
    #[test]
    fn ray_shares_by_surface_are_the_whole_sizings() {
        let scene = crate::scene::load_scene(&crate::bundled_scene("office"), &crate::panel::PanelCatalog::new()).unwrap().scene;
        let (sizing, patches) = (&scene.patch_sizing, &scene.patches.patches);
        let one_by_one: Vec<f64> = patches.iter().map(|p| sizing.ray_share(p.centroid)).collect();
        assert_eq!(sizing.ray_shares(patches, Some(2)), one_by_one);
        let coarser = one_by_one.iter().filter(|&&s| s < 0.9).count();
        assert!(coarser > 100 && one_by_one.contains(&1.0), "{coarser} of {} shares under 0.9", one_by_one.len());
    }

    /// A cell holding a quarter of its area of the surface or more stays a
    /// patch of its own ([`SMALL_CELL`]).
    #[test]
    fn a_partial_cell_keeps_its_share() {
        let tris = quad(1.2, 0.5);
        let mut surfaces = vec![surface_of(&tris)];
        let large = LargeFaces::new(&tris, &surfaces, f32::INFINITY);
        let mesh = subdivide(&tris, &mut surfaces, &PatchSizing::uniform(0.5), &[false], &[], &large);
        let mut areas: Vec<f32> = mesh.patches.iter().map(|p| p.area).collect();
        areas.sort_by(f32::total_cmp);
        assert_eq!(areas.len(), 3);
        assert!((areas[0] - 0.1).abs() < 1e-5 && (areas[2] - 0.25).abs() < 1e-5);
    }

    /// A wall 4.1 m wide: its 10 cm edge strip joins the cell beside it
    /// rather than being a patch of its own. A window plane at x = 1.1 m
    /// leaves a 10 cm piece of a cell on its near side: that piece joins the
    /// cell beside it on the same side, never the rest of its own cell
    /// beyond the plane.
    #[test]
    fn small_cells_join_a_neighbour_on_the_same_side_of_every_cut() {
        let patches = |width: f32, cuts: &[CutPlane]| {
            let tris = quad(width, 0.5);
            let mut surfaces = vec![surface_of(&tris)];
            let large = LargeFaces::new(&tris, &surfaces, f32::INFINITY);
            let mesh = subdivide(&tris, &mut surfaces, &PatchSizing::uniform(0.5), &[false], cuts, &large);
            let mut spans: Vec<(f32, f32, f32)> = mesh
                .patches
                .iter()
                .map(|p| {
                    let xs = mesh.triangles[p.triangle_indices()].iter().flatten().map(|v| v.x);
                    (xs.clone().fold(f32::MAX, f32::min), xs.fold(f32::MIN, f32::max), p.area)
                })
                .collect();
            spans.sort_by(|a, b| a.0.total_cmp(&b.0));
            let total: f32 = spans.iter().map(|s| s.2).sum();
            assert!((total - width * 0.5).abs() < 1e-5, "area kept: {total}");
            spans
        };
        let close = |a: f32, b: f32| (a - b).abs() < 1e-4;
        let strip = patches(4.1, &[]);
        assert_eq!(strip.len(), 8, "{strip:?}");
        let last = strip[7];
        assert!(close(last.0, 3.5) && close(last.1, 4.1) && close(last.2, 0.3), "{last:?}");
        let window = CutPlane { normal: Vec3::X, offset: 1.1, near: (Vec3::splat(-10.0), Vec3::splat(10.0)) };
        let cut = patches(2.0, &[window]);
        let expected = [(0.0, 0.5, 0.25), (0.5, 1.1, 0.3), (1.1, 1.5, 0.2), (1.5, 2.0, 0.25)];
        assert_eq!(cut.len(), expected.len(), "{cut:?}");
        for (got, want) in cut.iter().zip(expected) {
            assert!(close(got.0, want.0) && close(got.1, want.1) && close(got.2, want.2), "{got:?} against {want:?}");
        }
    }

    #[test]
    fn small_triangles_are_not_split() {
        // A 0.9 × 0.3 strip of three 0.3 m squares; the middle one straddles
        // the cell edge at 0.5 but its triangles are smaller than a cell.
        let tris: Vec<Triangle> = (0..3)
            .flat_map(|k| {
                quad(0.3, 0.3).into_iter().map(move |mut t| {
                    t.vertices = t.vertices.map(|p| p + Vec3::new(0.3 * k as f32, 0.0, 0.0));
                    t
                })
            })
            .collect();
        let mut surfaces = vec![surface_of(&tris)];
        let large = LargeFaces::new(&tris, &surfaces, f32::INFINITY);
        let mesh = subdivide(&tris, &mut surfaces, &PatchSizing::uniform(0.5), &[false], &[], &large);
        assert_eq!(mesh.triangles.len(), 6);
        assert_eq!(mesh.patches.len(), 2);
        let total: f32 = mesh.patches.iter().map(|p| p.area).sum();
        assert!((total - 0.27).abs() < 1e-5);
    }

    #[test]
    fn clutter_gathers_into_one_patch_per_cube_and_direction() {
        // 40 small squares (0.1 m) in one 0.5 m cube and one layer: 20 facing
        // up (their heights within 6 cm), 20 facing south.
        let mut tris = Vec::new();
        let mut surfaces = Vec::new();
        for k in 0..40 {
            let offset = Vec3::new(0.02 + 0.01 * (k % 20) as f32, 0.12, 0.12 + 0.01 * (k % 7) as f32);
            let square: Vec<Triangle> = quad(0.1, 0.1)
                .into_iter()
                .map(|mut t| {
                    if k >= 20 {
                        // Turned to face up: (x, 0, z) -> (x, -z, 0).
                        t.vertices = t.vertices.map(|p| Vec3::new(p.x, p.z, 0.0));
                    }
                    t.vertices = t.vertices.map(|p| p + offset);
                    t
                })
                .collect();
            let start = tris.len() as u32;
            tris.extend(square.iter().copied());
            surfaces.push(Surface { triangles: start..tris.len() as u32, ..surface_of(&square) });
        }
        let clusterable = vec![true; surfaces.len()];
        let large = LargeFaces::new(&tris, &surfaces, f32::INFINITY);
        let mesh = subdivide(&tris, &mut surfaces, &PatchSizing::uniform(0.5), &clusterable, &[], &large);
        assert_eq!(mesh.patches.len(), 2, "{:?}", mesh.patches.iter().map(|p| p.normal).collect::<Vec<_>>());
        let area: f32 = mesh.patches.iter().map(|p| p.area).sum();
        assert!((area - 0.4).abs() < 1e-5, "{area}");
        assert_eq!(mesh.triangles.len(), 80);
        // Each cluster's patch is listed under its first surface; the others have none.
        let listed: Vec<usize> = surfaces.iter().map(|s| s.patches.len()).collect();
        assert_eq!(listed.iter().sum::<usize>(), 2);
        assert_eq!((listed[0], listed[20]), (1, 1));
        let directions: Vec<Vec3> = mesh.patches.iter().map(|p| p.normal).collect();
        assert!(directions.iter().any(|n| (*n - Vec3::NEG_Y).length() < 1e-5) && directions.iter().any(|n| (n.z.abs() - 1.0).abs() < 1e-5));
    }

    /// Clutter sheets facing the same way in one cube but a layer apart (a
    /// roof's two skins, one sunlit, one in its shadow) stay two patches.
    #[test]
    fn stacked_clutter_sheets_are_not_one_patch() {
        let mut tris = Vec::new();
        let mut surfaces = Vec::new();
        for (k, height) in [0.12, 0.15, 0.32].into_iter().enumerate() {
            let square: Vec<Triangle> = quad(0.1, 0.1)
                .into_iter()
                .map(|mut t| {
                    t.vertices = t.vertices.map(|p| Vec3::new(p.x + 0.05 * k as f32, p.z, height));
                    t
                })
                .collect();
            let start = tris.len() as u32;
            tris.extend(square.iter().copied());
            surfaces.push(Surface { triangles: start..tris.len() as u32, ..surface_of(&square) });
        }
        let large = LargeFaces::new(&tris, &surfaces, f32::INFINITY);
        let mesh = subdivide(&tris, &mut surfaces, &PatchSizing::uniform(0.5), &[true; 3], &[], &large);
        let heights: Vec<f32> = mesh.patches.iter().map(|p| p.centroid.z).collect();
        assert_eq!(mesh.patches.len(), 2, "{heights:?}");
        assert!(heights.iter().any(|z| (z - 0.135).abs() < 1e-4) && heights.iter().any(|z| (z - 0.32).abs() < 1e-4), "{heights:?}");
    }

    /// The y of the door handles' patches: two handles 0.1 × 0.03 m (clutter
    /// in one cube, facing the same way, in one layer) 0.16 m apart at
    /// `offset`, on either side of a door leaf when `with_door`.
    fn handle_patches(with_door: bool, offset: Vec3, sizing: &PatchSizing) -> Vec<f32> {
        let mut tris = Vec::new();
        let mut surfaces = Vec::new();
        let mut add = |tris: &mut Vec<Triangle>, material: u32, part: Vec<Triangle>| {
            let part: Vec<Triangle> =
                part.into_iter().map(|t| Triangle { material, vertices: t.vertices.map(|p| p + offset), ..t }).collect();
            let start = tris.len() as u32;
            tris.extend(part.iter().copied());
            surfaces.push(Surface { material, triangles: start..tris.len() as u32, ..surface_of(&part) });
        };
        for y in [0.19, 0.35] {
            let handle =
                quad(0.1, 0.03).into_iter().map(|t| Triangle { vertices: t.vertices.map(|p| Vec3::new(p.x + 0.6, p.z + y, 1.02)), ..t });
            add(&mut tris, 0, handle.collect());
        }
        if with_door {
            // The leaf, 4 cm thick: its outer face at y = 0.25 facing -y, its inner at 0.29 facing +y.
            let outer: Vec<Triangle> =
                quad(1.0, 2.0).into_iter().map(|t| Triangle { vertices: t.vertices.map(|p| p + Vec3::Y * 0.25), ..t }).collect();
            let inner = outer
                .iter()
                .map(|t| Triangle { vertices: [t.vertices[0], t.vertices[2], t.vertices[1]].map(|p| p + Vec3::Y * 0.04), ..*t })
                .collect();
            add(&mut tris, 1, outer);
            add(&mut tris, 1, inner);
        }
        let clusterable = vec![true; surfaces.len()];
        let large = LargeFaces::new(&tris, &surfaces, CLUTTER * 0.25);
        let mesh = subdivide(&tris, &mut surfaces, sizing, &clusterable, &[], &large);
        mesh.patches.iter().filter(|p| p.material == 0).map(|p| p.centroid.y - offset.y).collect()
    }

    /// A door's handles outside and in are two patches: the door leaf
    /// between them, a large face crossing their cube, parts them. Without
    /// it, one.
    #[test]
    fn a_doors_handles_outside_and_in_are_not_one_patch() {
        let handle_patches = |with_door| handle_patches(with_door, Vec3::ZERO, &PatchSizing::uniform(0.5));
        let without = handle_patches(false);
        assert_eq!(without.len(), 1, "{without:?}");
        let mut with = handle_patches(true);
        with.sort_by(f32::total_cmp);
        assert_eq!(with.len(), 2, "{with:?}");
        assert!((with[0] - 0.205).abs() < 1e-4 && (with[1] - 0.365).abs() < 1e-4, "{with:?}");
    }

    /// Clutter a large face runs through is cut there, and the pieces on
    /// each side gather: two sills a wall passes through are two patches,
    /// the parts on either side of it, not four, listed under the first.
    #[test]
    fn cut_clutters_pieces_gather_on_each_side_of_the_cut() {
        let mut tris = Vec::new();
        let mut surfaces = Vec::new();
        let mut add = |tris: &mut Vec<Triangle>, material: u32, part: Vec<Triangle>| {
            let start = tris.len() as u32;
            tris.extend(part.iter().map(|t| Triangle { material, ..*t }));
            surfaces.push(Surface { material, triangles: start..tris.len() as u32, ..surface_of(&part) });
        };
        for y in [0.0, 0.15] {
            let sill =
                quad(0.2, 0.1).into_iter().map(|t| Triangle { vertices: t.vertices.map(|p| Vec3::new(p.x + 0.1, p.z + y, 1.0)), ..t });
            add(&mut tris, 0, sill.collect());
        }
        let wall = quad(2.0, 2.0).into_iter().map(|t| Triangle { vertices: t.vertices.map(|p| Vec3::new(0.2, p.x - 1.0, p.z)), ..t });
        add(&mut tris, 1, wall.collect());
        let large = LargeFaces::new(&tris, &surfaces, CLUTTER * 0.25);
        let mesh = subdivide(&tris, &mut surfaces, &PatchSizing::uniform(0.5), &[true; 3], &[], &large);
        let sills: Vec<(u32, &Patch)> = (0..).zip(&mesh.patches).filter(|(_, p)| p.material == 0).collect();
        let mut xs: Vec<f32> = sills.iter().map(|(_, p)| p.centroid.x).collect();
        xs.sort_by(f32::total_cmp);
        assert_eq!(xs.len(), 2, "{xs:?}");
        assert!((xs[0] - 0.15).abs() < 1e-4 && (xs[1] - 0.25).abs() < 1e-4, "{xs:?}");
        assert!(sills.iter().all(|(k, p)| (p.area - 0.02).abs() < 1e-5 && mesh.surfaces_of(*k) == [0, 1]));
        assert_eq!((surfaces[0].patches.len(), surfaces[1].patches.len()), (2, 0));
    }

    /// Far from the sensors ([`FAR_SIDES`]) clutter clusters across the
    /// large faces that part it near them, and a strip a wall runs through
    /// is not cut there: their light reaches the sensors only after bounces
    /// that average it.
    #[test]
    fn far_from_the_sensors_clutter_clusters_across_large_faces() {
        let sensor = Sensor {
            name: String::new(),
            position: Vec3::new(0.0, 0.0, 0.8),
            normal: Vec3::Z,
            size: None,
            axes: [Vec3::X, Vec3::Y],
            grid: None,
        };
        let sizing = PatchSizing::around(0.5, &[sensor], &[]);
        let (near, far) = (Vec3::new(1.0, 0.0, 0.0), Vec3::new(40.0, 0.0, 0.0));
        assert!(sizing.allowed(near, 0.0) < FAR_SIDES * 0.5 && sizing.allowed(far, 0.0) >= FAR_SIDES * 0.5);
        assert_eq!(handle_patches(true, near, &sizing).len(), 2);
        assert_eq!(handle_patches(true, far, &sizing).len(), 1);
        // A sill 0.6 × 0.1 m (clutter) with a wall's face standing across its middle.
        let strip_patches = |offset: Vec3| {
            let sill: Vec<Triangle> = quad(0.6, 0.1)
                .into_iter()
                .map(|t| Triangle { vertices: t.vertices.map(|p| Vec3::new(p.x, p.z, 1.0) + offset), ..t })
                .collect();
            let wall: Vec<Triangle> = quad(2.0, 2.0)
                .into_iter()
                .map(|t| Triangle { material: 1, vertices: t.vertices.map(|p| Vec3::new(0.3, p.x - 1.0, p.z) + offset), ..t })
                .collect();
            let tris: Vec<Triangle> = sill.iter().chain(&wall).copied().collect();
            let mut surfaces =
                vec![Surface { triangles: 0..2, ..surface_of(&sill) }, Surface { material: 1, triangles: 2..4, ..surface_of(&wall) }];
            let large = LargeFaces::new(&tris, &surfaces, CLUTTER * 0.25);
            let mesh = subdivide(&tris, &mut surfaces, &sizing, &[true, true], &[], &large);
            mesh.patches.iter().filter(|p| p.material == 0).count()
        };
        assert_eq!(strip_patches(near), 2);
        assert_eq!(strip_patches(far), 1);
    }
}
