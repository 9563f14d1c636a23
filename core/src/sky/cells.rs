//! A quadrature's directions kept as columns, and a sky's radiance toward
//! all of them in one call ([`Sky::radiances_into`]). An annual study
//! integrates every lit hour's sky over some 15,000 cells of the sphere
//! bins; for the Perez sky this runs as wide as the CPU allows
//! ([`crate::lanes`]: its `acos` and `exp` are branch-free, [`super::elementary`]) and gives
//! the numbers [`Sky::radiance_toward`] gives each cell, bit for bit.

use glam::DVec3;

use super::perez::Perez;
use super::{Distribution, NEGLIGIBLE_SKY_WEIGHT, Sky, SkyDirection};

/// Fixed directions a sky is evaluated toward many times.
#[derive(Debug, Clone)]
pub(super) struct SkyCells {
    directions: Vec<SkyDirection>,
    /// The directions' components and blend weights, as columns.
    x: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
    blend: Vec<f64>,
    /// The directions' heights (z), each once: a quadrature's cells lie in
    /// rows of one height, whose Perez gradation is computed once.
    heights: Vec<f64>,
    /// Each direction's height in `heights`.
    height_of: Vec<u32>,
    /// Past this index every direction sees the ground glow alone (its sky
    /// weight under [`NEGLIGIBLE_SKY_WEIGHT`]): the sky is not evaluated there.
    sky_end: usize,
}

impl SkyCells {
    /// The cells of unit directions `directions`.
    pub(super) fn new(directions: impl IntoIterator<Item = DVec3>) -> Self {
        let directions: Vec<SkyDirection> = directions.into_iter().map(SkyDirection::new).collect();
        let column = |f: fn(&SkyDirection) -> f64| directions.iter().map(f).collect::<Vec<f64>>();
        let mut heights: Vec<f64> = Vec::new();
        let height_of = directions
            .iter()
            .map(|d| {
                // Cells of a row come together: the last height is the likely one.
                let index = heights.iter().rposition(|&z| z.to_bits() == d.d.z.to_bits()).unwrap_or_else(|| {
                    heights.push(d.d.z);
                    heights.len() - 1
                });
                index as u32
            })
            .collect();
        let sky_end = directions.iter().rposition(|d| d.blend >= NEGLIGIBLE_SKY_WEIGHT).map_or(0, |i| i + 1);
        Self {
            x: column(|d| d.d.x),
            y: column(|d| d.d.y),
            z: column(|d| d.d.z),
            blend: column(|d| d.blend),
            directions,
            heights,
            height_of,
            sky_end,
        }
    }

    /// How many distinct heights the directions have.
    #[cfg(test)]
    pub(super) fn height_count(&self) -> usize {
        self.heights.len()
    }

    /// The unit directions.
    #[cfg(test)]
    pub(super) fn directions(&self) -> impl Iterator<Item = DVec3> + '_ {
        self.directions.iter().map(|d| d.d)
    }
}

impl Sky {
    /// [`Self::radiance_toward`] each of `cells`, into `out` (cleared first).
    pub(super) fn radiances_into(&self, cells: &SkyCells, out: &mut Vec<f64>) {
        out.clear();
        match &self.distribution {
            Distribution::Perez(perez) => {
                let by_height = self.height_terms(&cells.heights);
                let gradations: Vec<f64> = cells.height_of[..cells.sky_end].iter().map(|&h| by_height[h as usize]).collect();
                out.resize(cells.directions.len(), self.ground_radiance);
                perez_radiances(perez, cells, &gradations, self.ground_radiance, &mut out[..cells.sky_end]);
            }
            _ => out.extend(cells.directions.iter().map(|d| self.radiance_toward(d, None))),
        }
    }
}

/// The Perez sky blended into the ground glow toward the first `out.len()`
/// cells (their gradations given), as [`Sky::radiance_toward`] computes it,
/// as many lanes wide as the CPU allows ([`crate::lanes`]).
fn perez_radiances(perez: &Perez, cells: &SkyCells, gradations: &[f64], ground: f64, out: &mut [f64]) {
    crate::lanes::widest(
        #[inline(always)]
        || {
            let columns = cells.x.iter().zip(&cells.y).zip(&cells.z).zip(&cells.blend).zip(gradations);
            for (radiance, ((((&x, &y), &z), &blend), &gradation)) in out.iter_mut().zip(columns) {
                let sky = perez.sky_with_gradation(DVec3::new(x, y, z), gradation);
                *radiance = if blend < NEGLIGIBLE_SKY_WEIGHT { ground } else { blend * sky + (1.0 - blend) * ground };
            }
        },
    )
}
