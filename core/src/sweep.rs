//! Parameter sweeps of a window material (the thesis's fig. 1.4g): one or
//! two keys of a panel (a list item as `facet_angles[1]`) or a glass's
//! `transmittance`, varied over a grid; for every combination the
//! illuminance at the sensors at one instant, or their DA300 and the
//! scene's sDA over a year of weather.
//!
//! How it works:
//! 1. **The grid** ([`Axis`], [`Grid`]): each axis `KEY=LO..HI:STEP`; the
//!    combinations in row-major order (the first key slowest). A shard is a
//!    contiguous range of them ([`Grid::shard`]), so parts computed on many
//!    machines join back in order.
//! 2. **Each combination's material** ([`Variation::material`]): the panel's
//!    keys with the combination's values set, rebuilt by its panel type, or
//!    the glass with its transmittance. A value the type refuses is that
//!    combination's error, reported in its row, not the run's.
//! 3. **The light** ([`sweep`]): panel keys change what crosses their windows
//!    (the sun's beams and the sky's transfer), not how rays cross them (a
//!    panel passes gather rays unweighted), so one precomputation and one
//!    set of sensor coefficients serve every combination: only the panel
//!    model is swapped ([`LightModel::set_panel_model`]; the coefficients
//!    are solved again only where a combination changes how much light the
//!    panel reflects back into the room). At an instant a
//!    combination is one coefficient reading. A glass's transmittance
//!    changes every ray that crosses it: each combination is precomputed
//!    anew.
//! 4. **A year** ([`SweptYear`]): what does not pass the panel (the sun
//!    through glass, other panels' lobes) is traced once for every hour,
//!    on the room with the panel dark to the sun, and the sky light that
//!    does not pass it is read once per hour ([`YearSkies::beside_panels`]);
//!    the panel's lobes' bounces are read from lobe coefficients
//!    ([`LobeTable`]: traced once per direction node the combinations'
//!    lobes fall among, not once per hour and combination); a combination
//!    then traces only its beams' direct light at the sensors, hour by hour
//!    (sharp, and cheap), and reads what its panel passes.

use std::ops::Range;
use std::sync::Arc;

use glam::DVec3;

use crate::annual::{AnnualOptions, AnnualResult, MAX_TABLE_BYTES, Occupancy, YearSkies, annual, sun_directions};
use crate::light::{LightModel, LobeTable, SensorCoefficients, SunBeam, SunPath, Sunlit};
use crate::panel::{KeyKind, PanelCatalog, PanelModel, PanelResponse, Parameters, base_dir};
use crate::scene::{Material, MaterialKind, Scene};
use crate::site::Site;
use crate::sky::{Sky, SunSource};
use crate::weather::HOURS;
use crate::weather::Weather;

/// The most keys varied together.
pub const MAX_AXES: usize = 2;

/// One varied key and its values.
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    /// The key as written: `name` or `name[index]`.
    pub key: String,
    /// Its values, from `LO` up to `HI` (included, within rounding) by `STEP`.
    pub values: Vec<f64>,
}

impl Axis {
    /// Parses `KEY=LO..HI:STEP`.
    pub fn parse(spec: &str) -> Result<Self, String> {
        let (key, range) = spec.split_once('=').ok_or_else(|| format!("'{spec}' is not KEY=LO..HI:STEP"))?;
        let (bounds, step) = range.split_once(':').ok_or_else(|| format!("'{spec}': no :STEP"))?;
        let (lo, hi) = bounds.split_once("..").ok_or_else(|| format!("'{spec}': no LO..HI"))?;
        let number = |text: &str, what: &str| -> Result<f64, String> {
            text.trim().parse::<f64>().ok().filter(|v| v.is_finite()).ok_or_else(|| format!("'{spec}': {what} '{text}' is not a number"))
        };
        let (lo, hi, step) = (number(lo, "LO")?, number(hi, "HI")?, number(step, "STEP")?);
        let key = key.trim();
        if key.is_empty() {
            return Err(format!("'{spec}': no key"));
        }
        if step <= 0.0 {
            return Err(format!("'{spec}': the step must be positive"));
        }
        if hi < lo {
            return Err(format!("'{spec}': the range is empty (HI below LO)"));
        }
        let count = ((hi - lo) / step + 1e-9).floor() as usize + 1;
        if count > 10_000 {
            return Err(format!("'{spec}': {count} values; at most 10,000 per key"));
        }
        // Rounded so that 0.1 steps print as 0.3, not 0.30000000000000004.
        let values = (0..count).map(|i| ((lo + i as f64 * step) * 1e9).round() / 1e9).collect();
        Ok(Self { key: key.to_string(), values })
    }

    /// The key's name and list index.
    pub fn name_and_index(&self) -> (&str, Option<usize>) {
        key_path(&self.key)
    }
}

fn key_path(key: &str) -> (&str, Option<usize>) {
    match key.strip_suffix(']').and_then(|k| k.split_once('[')) {
        Some((name, index)) => (name, index.parse().ok().or(Some(usize::MAX))),
        None => (key, None),
    }
}

/// The combinations of one or two axes, row-major.
#[derive(Debug, Clone, PartialEq)]
pub struct Grid {
    /// The varied keys.
    pub axes: Vec<Axis>,
}

impl Grid {
    /// Combinations in all.
    pub fn len(&self) -> usize {
        self.axes.iter().map(|a| a.values.len()).product()
    }

    /// Whether there are none (never: every axis has a value).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The values of combination `index`, one per axis.
    pub fn combination(&self, index: usize) -> Vec<f64> {
        let mut rest = index;
        let mut values: Vec<f64> = self
            .axes
            .iter()
            .rev()
            .map(|axis| {
                let value = axis.values[rest % axis.values.len()];
                rest /= axis.values.len();
                value
            })
            .collect();
        values.reverse();
        values
    }

    /// Part `k` (from 1) of `n` equal parts, as combination indices.
    pub fn shard(&self, k: usize, n: usize) -> Range<usize> {
        (k - 1) * self.len() / n..k * self.len() / n
    }
}

/// Parses `K/N` (1 ≤ K ≤ N).
pub fn parse_shard(text: &str) -> Result<(usize, usize), String> {
    let (k, n) = text.split_once('/').ok_or_else(|| format!("'{text}' is not K/N"))?;
    let (k, n) = (k.trim().parse::<usize>(), n.trim().parse::<usize>());
    match (k, n) {
        (Ok(k), Ok(n)) if n >= 1 && (1..=n).contains(&k) => Ok((k, n)),
        (Ok(_), Ok(0)) => Err(format!("'{text}': N must be at least 1")),
        (Ok(k), Ok(n)) => Err(format!("'{text}': K must be from 1 to {n}, not {k}")),
        _ => Err(format!("'{text}' is not K/N with whole numbers")),
    }
}

/// A material whose keys a sweep varies.
#[derive(Debug, Clone)]
pub struct Variation {
    /// The material's index in [`Scene::materials`].
    pub material: u32,
    base: Material,
    base_dir: std::path::PathBuf,
    /// The panel types, to rebuild the panel with each combination's keys.
    catalog: PanelCatalog,
}

impl Variation {
    /// Checks that `material` exists, is a glass or a panel, and has every
    /// key of `grid` (a list index within the list): one line naming what
    /// is wrong otherwise.
    pub fn new(scene: &Scene, material: &str, grid: &Grid, catalog: &PanelCatalog) -> Result<Self, String> {
        let index = scene.materials.iter().position(|m| m.name == material).ok_or_else(|| {
            let windows: Vec<&str> = scene.materials.iter().filter(|m| m.kind.transmits()).map(|m| m.name.as_str()).collect();
            format!("--material {material}: no face of the model uses it (window materials: {})", windows.join(", "))
        })?;
        let base = scene.materials[index].clone();
        for axis in &grid.axes {
            let (name, list_index) = axis.name_and_index();
            let flag = format!("--vary {}", axis.key);
            match &base.kind {
                MaterialKind::Diffuse { .. } => {
                    return Err(format!("--material {material}: a diffuse material; sweeps vary glass and panels"));
                }
                MaterialKind::Glass { .. } if name == "transmittance" && list_index.is_none() => {}
                MaterialKind::Glass { .. } => return Err(format!("{flag}: glass '{material}' has one key, transmittance")),
                MaterialKind::Panel { panel, .. } => {
                    let kind = catalog.get(panel).and_then(|t| t.keys().iter().find(|k| k.name == name)).map(|k| k.kind);
                    let keys =
                        || catalog.get(panel).map(|t| t.keys().iter().map(|k| k.name).collect::<Vec<_>>().join(", ")).unwrap_or_default();
                    match (kind, list_index) {
                        (None, _) => return Err(format!("{flag}: '{name}' is not a key of panel '{panel}' (its keys: {})", keys())),
                        (Some(KeyKind::Number { .. } | KeyKind::Count { .. }), None) => {}
                        (Some(KeyKind::Numbers { default, .. }), Some(i)) if i < default.len() => {}
                        (Some(KeyKind::Numbers { default, .. }), Some(_)) => {
                            return Err(format!(
                                "{flag}: '{name}' is a list of {} numbers ({name}[0] to {name}[{}])",
                                default.len(),
                                default.len() - 1
                            ));
                        }
                        (Some(KeyKind::Numbers { .. }), None) => {
                            return Err(format!("{flag}: '{name}' is a list; vary one item, as {name}[0]"));
                        }
                        (Some(KeyKind::File { .. }), _) => return Err(format!("{flag}: '{name}' is a file, not a number")),
                        (Some(_), Some(_)) => return Err(format!("{flag}: '{name}' is a single number, not a list")),
                    }
                }
            }
        }
        Ok(Self { material: index as u32, base, base_dir: base_dir(&scene.files.scene), catalog: catalog.clone() })
    }

    /// Whether the material is a panel (one precomputation serves every combination).
    pub fn is_panel(&self) -> bool {
        matches!(self.base.kind, MaterialKind::Panel { .. })
    }

    /// The material with `keys` set to `values`; the panel type's or the
    /// glass's refusal otherwise (that combination's error).
    pub fn material(&self, grid: &Grid, values: &[f64]) -> Result<Material, String> {
        let catalog = &self.catalog;
        let mut material = self.base.clone();
        match &mut material.kind {
            MaterialKind::Glass { transmittance } => {
                let t = values[0];
                if !(0.0..=1.0).contains(&t) {
                    return Err(format!("transmittance {t} is out of range [0, 1]"));
                }
                *transmittance = t as f32;
            }
            MaterialKind::Panel { panel, parameters, model, .. } => {
                let keys = catalog.get(panel).map(|t| t.keys()).unwrap_or_default();
                for (axis, &value) in grid.axes.iter().zip(values) {
                    let (name, index) = axis.name_and_index();
                    let key = keys.iter().find(|k| k.name == name).expect("checked by Variation::new");
                    let entry = parameters.entry(name.to_string()).or_insert_with(|| key.default_value().expect("a number key"));
                    let number = match key.kind {
                        KeyKind::Count { .. } if value.fract() != 0.0 => return Err(format!("{name} must be a whole number, not {value}")),
                        KeyKind::Count { .. } => toml::Value::Integer(value as i64),
                        _ => toml::Value::Float(value),
                    };
                    match (index, entry) {
                        (Some(i), toml::Value::Array(items)) if i < items.len() => items[i] = number,
                        (Some(_), _) => return Err(format!("{} is not a list item of the material", axis.key)),
                        (None, entry) => *entry = number,
                    }
                }
                let built = catalog
                    .build(panel, &Parameters::new(parameters.clone(), &self.base_dir))
                    .map_err(|e| format!("{}: {}", e.key, e.message))?;
                model.0 = built;
            }
            MaterialKind::Diffuse { .. } => unreachable!("refused by Variation::new"),
        }
        Ok(material)
    }
}

/// What each combination is judged by.
#[derive(Clone, Copy)]
pub enum Target<'a> {
    /// The sensors' illuminance (lux) under one sky.
    Instant(&'a Sky),
    /// The sensors' DA300 (%) and the scene's sDA300/50% over a year.
    Year(&'a Weather, Occupancy),
}

/// One combination's outcome: per chosen sensor its value, and over a year
/// the scene's sDA; or why the combination does not build.
#[derive(Debug, Clone, PartialEq)]
pub struct Outcome {
    /// The combination's key values, one per axis.
    pub values: Vec<f64>,
    /// Per chosen sensor (in the order asked) its value, and the scene's
    /// sDA300/50% for a year; the combination's error otherwise.
    pub result: Result<(Vec<f64>, Option<f64>), String>,
}

/// Runs combinations `range` of `grid` on `model` (precomputed for the
/// scene as its file says), reading `sensors` (indices). `each` hears every
/// combination's outcome as it comes, with the share done (a viewer fills
/// its heat map in).
pub fn sweep(
    model: &mut LightModel,
    variation: &Variation,
    grid: &Grid,
    range: Range<usize>,
    sensors: &[usize],
    target: Target,
    each: &dyn Fn(&Outcome, f64),
) -> Vec<Outcome> {
    let coefficients = variation.is_panel().then(|| model.sensor_coefficients());
    let back_reflectance = model.panel_back_reflectance(variation.material);
    // The year's skies and their sphere bins, made once: every combination's model has the same sky bins.
    let skies = match target {
        Target::Year(weather, _) => Some(YearSkies::binned(&{ model.scene.site }, weather, model)),
        Target::Instant(_) => None,
    };
    let mut year = match (target, &coefficients, &skies) {
        (Target::Year(weather, occupancy), Some(coefficients), Some(skies)) => {
            SweptYear::new(model, coefficients, variation, weather, occupancy, skies)
        }
        _ => None,
    };
    let skies = skies.as_ref();
    let total = range.len().max(1);
    range
        .enumerate()
        .map(|(done, index)| {
            let values = grid.combination(index);
            let result = variation.material(grid, &values).and_then(|material| match (&material.kind, &coefficients) {
                (MaterialKind::Panel { model: panel, .. }, Some(coefficients)) => {
                    model.set_panel_model(variation.material, panel.0.clone());
                    if model.panel_back_reflectance(variation.material) != back_reflectance {
                        // The room's interreflection changed with the panel's back.
                        evaluate(model, &model.sensor_coefficients(), sensors, target, skies)
                    } else if let (Some(year), Target::Year(weather, occupancy)) = (&mut year, target) {
                        year.evaluate(model, coefficients, weather, occupancy, sensors)
                    } else {
                        evaluate(model, coefficients, sensors, target, skies)
                    }
                }
                _ => {
                    let mut scene = (*model.scene).clone();
                    scene.materials[variation.material as usize] = material;
                    let varied = LightModel::precompute(Arc::new(scene), model.settings)?;
                    evaluate(&varied, &varied.sensor_coefficients(), sensors, target, skies)
                }
            });
            let outcome = Outcome { values, result };
            each(&outcome, (done + 1) as f64 / total as f64);
            outcome
        })
        .collect()
}

/// One combination's values, from scratch but for the coefficients given
/// and the year's `skies` (made once per sweep).
fn evaluate(
    model: &LightModel,
    coefficients: &SensorCoefficients,
    sensors: &[usize],
    target: Target,
    skies: Option<&YearSkies>,
) -> Result<(Vec<f64>, Option<f64>), String> {
    match target {
        Target::Instant(sky) => {
            let readings = coefficients.readings(model, sky, None);
            Ok((sensors.iter().map(|&s| readings[s].total).collect(), None))
        }
        Target::Year(weather, occupancy) => {
            let options = AnnualOptions { occupancy, coefficients: Some(coefficients), skies, ..Default::default() };
            Ok(year_values(&annual(model, &model.scene.site, weather, &options, &|_| {})?, sensors))
        }
    }
}

/// A year's values for a sweep: DA300 at `sensors`, and the scene's sDA.
fn year_values(year: &AnnualResult, sensors: &[usize]) -> (Vec<f64>, Option<f64>) {
    (sensors.iter().map(|&s| year.sensors[s].da300).collect(), Some(year.sda()))
}

/// A year of sun prepared once for a sweep of a panel's keys ([`sweep`]'s
/// step 4): every hour's sun but the panel's lobes, how the sun lights the
/// panel's windows, and the lobe coefficients, which grow as
/// combinations' lobes ask for nodes.
struct SweptYear {
    skies: YearSkies,
    /// Per hour of the year whose sun the study reads: its direction, how
    /// it lights the panel's windows, and the interreflected light (lux per
    /// W/m²) of its every beam but the panel's lobes.
    hours: Vec<Option<(DVec3, Sunlit, Vec<f32>)>>,
    table: LobeTable,
}

/// The swept panel with its lobes taken away: the room with it dark to
/// the sun is where the rest of the year's sun is traced.
#[derive(Debug)]
struct WithoutLobes(Arc<dyn PanelModel>);

impl PanelModel for WithoutLobes {
    fn response(&self, incoming: DVec3) -> PanelResponse {
        let mut response = self.0.response(incoming);
        response.lobes.retain(|lobe| lobe.direction.z <= 0.0);
        response
    }

    fn back_reflectance(&self) -> f64 {
        self.0.back_reflectance()
    }
}

impl SweptYear {
    /// The year's sun on `model` (its panel as the scene file has it) but
    /// for `variation`'s lobes; `None` when the rest of the sun would take
    /// more than [`MAX_TABLE_BYTES`] in memory (combinations then trace
    /// their years whole).
    fn new(
        model: &mut LightModel,
        coefficients: &SensorCoefficients,
        variation: &Variation,
        weather: &Weather,
        occupancy: Occupancy,
        skies: &YearSkies,
    ) -> Option<Self> {
        let MaterialKind::Panel { model: panel, .. } = &variation.base.kind else { return None };
        let site: Site = model.scene.site;
        let with_sun = AnnualOptions { occupancy, ..Default::default() }.hours_with_sun(weather);
        let suns: Vec<Option<DVec3>> = sun_directions(&site, &with_sun).into_iter().map(Option::flatten).collect();
        let up: Vec<DVec3> = suns.iter().flatten().copied().collect();
        if up.len() * model.scene.sensors.len() * size_of::<f32>() > MAX_TABLE_BYTES {
            return None;
        }
        model.set_panel_model(variation.material, Arc::new(WithoutLobes(panel.0.clone())));
        let path = SunPath::new(model, coefficients, &site, &up, None);
        let table = LobeTable::new(model, variation.material);
        let hours = crate::parallel::par_map(None, HOURS, |k| {
            let sun = suns[k]?;
            let rest = coefficients.sun_response(model, sun, &path, Some(1)).interreflected;
            Some((sun, table.sunlit(model, sun), rest))
        });
        model.set_panel_model(variation.material, panel.0.clone());
        let skies = skies.clone().beside_panels(model, &coefficients.totals(model), table.groups());
        Some(Self { skies, hours, table })
    }

    /// The year of `model` (a combination's panel in the windows): DA300
    /// at `sensors` and the scene's sDA.
    fn evaluate(
        &mut self,
        model: &LightModel,
        coefficients: &SensorCoefficients,
        weather: &Weather,
        occupancy: Occupancy,
        sensors: &[usize],
    ) -> Result<(Vec<f64>, Option<f64>), String> {
        let beams: Vec<Option<Vec<SunBeam>>> =
            crate::parallel::par_map(None, HOURS, |k| self.hours[k].as_ref().map(|(sun, ..)| model.sun_beams(&SunSource::unit(*sun))));
        self.table.trace(model, coefficients, beams.iter().flatten().flatten(), None);
        let (hours, table) = (&self.hours, &self.table);
        let sun = |k: usize| {
            let (_, sunlit, rest) = hours[k].as_ref()?;
            Some(coefficients.sun_response_with_lobes(model, beams[k].as_deref()?, table, sunlit, rest, Some(1)))
        };
        let options =
            AnnualOptions { occupancy, coefficients: Some(coefficients), sun: Some(&sun), skies: Some(&self.skies), ..Default::default() };
        Ok(year_values(&annual(model, &model.scene.site, weather, &options, &|_| {})?, sensors))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axes_parse_and_refuse_in_one_line() {
        let axis = Axis::parse("facet_angles[1]=0..30:7.5").unwrap();
        assert_eq!(axis.values, vec![0.0, 7.5, 15.0, 22.5, 30.0]);
        assert_eq!(axis.name_and_index(), ("facet_angles", Some(1)));
        assert_eq!(Axis::parse("transmittance=0.1..0.3:0.1").unwrap().values, vec![0.1, 0.2, 0.3]);
        assert_eq!(Axis::parse("t=0..1:0.4").unwrap().values, vec![0.0, 0.4, 0.8]);
        for (spec, message) in [
            ("t=0..1:0", "the step must be positive"),
            ("t=1..0:0.1", "the range is empty"),
            ("t=a..1:0.1", "LO 'a' is not a number"),
            ("t=0..1", "no :STEP"),
            ("t", "is not KEY=LO..HI:STEP"),
        ] {
            let error = Axis::parse(spec).unwrap_err();
            assert!(error.contains(message), "{spec}: {error}");
        }
    }

    #[test]
    fn grids_are_row_major_and_shards_cover_them_once() {
        let grid = Grid { axes: vec![Axis::parse("a=0..2:1").unwrap(), Axis::parse("b=10..30:10").unwrap()] };
        assert_eq!(grid.len(), 9);
        assert_eq!(grid.combination(0), vec![0.0, 10.0]);
        assert_eq!(grid.combination(1), vec![0.0, 20.0]);
        assert_eq!(grid.combination(3), vec![1.0, 10.0]);
        for n in 1..=9 {
            let covered: Vec<usize> = (1..=n).flat_map(|k| grid.shard(k, n)).collect();
            assert_eq!(covered, (0..9).collect::<Vec<_>>(), "{n} shards");
        }
        assert_eq!(parse_shard("2/4"), Ok((2, 4)));
        assert!(parse_shard("0/4").unwrap_err().contains("K must be from 1 to 4"));
        assert!(parse_shard("5/4").unwrap_err().contains("K must be from 1 to 4"));
        assert!(parse_shard("1/0").is_err() && parse_shard("x").is_err());
    }
}
