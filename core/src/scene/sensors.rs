//! Sensors (points, squares and grids of points) and named viewpoints, from
//! the scene file, in the canonical frame.

use std::collections::BTreeSet;

use glam::{DVec3, Vec3};
use toml::Spanned;

use super::error::SceneError;
use super::file::ParsedScene;

/// A virtual illuminance meter: it occludes nothing.
#[derive(Debug, Clone, PartialEq)]
pub struct Sensor {
    /// Unique in the scene; a grid's points are `<grid>/<k>`.
    pub name: String,
    /// The measuring point (the square's centre for an area sensor), canonical
    /// frame.
    pub position: Vec3,
    /// Unit normal of the measured plane.
    pub normal: Vec3,
    /// Side of the square (metres) for an area sensor; `None` for a point.
    pub size: Option<f32>,
    /// The square's edge directions: the model's horizontal axes when the
    /// normal is vertical, otherwise a horizontal edge and the one across it.
    pub axes: [Vec3; 2],
    /// The grid it belongs to, for grid sensors.
    pub grid: Option<String>,
}

/// A named camera position (`[[cameras]]`).
#[derive(Debug, Clone, PartialEq)]
pub struct Viewpoint {
    /// The name the scene file gives it.
    pub name: String,
    /// Camera position, canonical frame.
    pub eye: Vec3,
    /// The point the camera looks at, canonical frame.
    pub target: Vec3,
    /// Vertical field of view in degrees.
    pub fov: f32,
}

/// Default vertical field of view, degrees.
pub const DEFAULT_FOV: f32 = 60.0;

/// Grids larger than this are surely a typo in `spacing`.
const MAX_GRID_SENSORS: usize = 1_000_000;

pub fn sensors(parsed: &ParsedScene) -> Result<Vec<Sensor>, SceneError> {
    let frame = &parsed.frame;
    let up = frame.direction(frame.up.vector());
    let [first_axis, second_axis] = frame.horizontal_axes();
    let axes_for = |normal: Vec3| {
        if normal.dot(up).abs() > 0.9999 {
            [first_axis, normal.cross(first_axis).normalize()]
        } else {
            let horizontal = up.cross(normal).normalize();
            [horizontal, normal.cross(horizontal).normalize()]
        }
    };
    let mut names = BTreeSet::new();
    let mut unique = |name: &Spanned<String>, key: &str| {
        if name.get_ref().is_empty() {
            return parsed.error(name.span(), key, "a sensor needs a name");
        }
        if !names.insert(name.get_ref().clone()) {
            return parsed.error(name.span(), key, format!("duplicate sensor name '{}'", name.get_ref()));
        }
        Ok(())
    };
    let mut out = Vec::new();
    for (i, entry) in parsed.sensors.iter().enumerate() {
        let sensor = entry.get_ref();
        let key = |k: &str| format!("sensors[{i}].{k}");
        unique(&sensor.name, &key("name"))?;
        let position = parsed.position(&sensor.position, &key("position"))?;
        let normal = parsed.finite(&sensor.normal, &key("normal"))?;
        let normal_vec = DVec3::from_array(normal);
        if normal_vec.abs().max_element() < 1e-9 {
            return parsed.error(sensor.normal.span(), key("normal"), "the normal must not be the zero vector");
        }
        let size = match &sensor.size {
            Some(size) => {
                let s = *size.get_ref();
                if !s.is_finite() || s <= 0.0 {
                    return parsed.error(size.span(), key("size"), format!("{s} is not a positive length"));
                }
                Some(frame.length(s as f32))
            }
            None => None,
        };
        // Normalised in f64, scaled first: a normal of enormous length must
        // overflow neither its squared length nor f32.
        let normal = frame.direction((normal_vec / normal_vec.abs().max_element()).normalize().as_vec3());
        out.push(Sensor {
            name: sensor.name.get_ref().clone(),
            position: frame.point(DVec3::from_array(position)),
            normal,
            size,
            axes: axes_for(normal),
            grid: None,
        });
    }
    for (g, entry) in parsed.sensor_grids.iter().enumerate() {
        let grid = entry.get_ref();
        let key = |k: &str| format!("sensor_grids[{g}].{k}");
        if grid.name.get_ref().is_empty() {
            return parsed.error(grid.name.span(), key("name"), "a grid needs a name");
        }
        let min = parsed.position(&grid.min, &key("min"))?;
        let max = parsed.position(&grid.max, &key("max"))?;
        let height = parsed.number(&grid.height, &key("height"), (f64::MIN, f64::MAX))?;
        let spacing = parsed.number(&grid.spacing, &key("spacing"), (f64::MIN_POSITIVE, f64::MAX))?;
        let cells = |axis: usize| ((max[axis] - min[axis]) / spacing + 1e-9).floor();
        let (nx, ny) = (cells(0), cells(1));
        if nx < 1.0 || ny < 1.0 {
            return parsed.error(
                grid.max.span(),
                key("max"),
                "the grid must span at least one spacing in each direction (max > min + spacing)",
            );
        }
        if nx * ny > MAX_GRID_SENSORS as f64 {
            return parsed.error(grid.spacing.span(), key("spacing"), format!("{nx} × {ny} sensors is more than {MAX_GRID_SENSORS}"));
        }
        let [ax, ay] = frame.up.horizontal_axes();
        let model_up = frame.up.vector();
        for j in 0..ny as usize {
            for i in 0..nx as usize {
                let x = min[0] + (i as f64 + 0.5) * spacing;
                let y = min[1] + (j as f64 + 0.5) * spacing;
                let model_point = ax.as_dvec3() * x + ay.as_dvec3() * y + model_up.as_dvec3() * height;
                let name = format!("{}/{}", grid.name.get_ref(), j * nx as usize + i);
                unique(&Spanned::new(grid.name.span(), name.clone()), &key("name"))?;
                out.push(Sensor {
                    name,
                    position: frame.point(model_point),
                    normal: up,
                    size: None,
                    axes: [first_axis, second_axis],
                    grid: Some(grid.name.get_ref().clone()),
                });
            }
        }
    }
    Ok(out)
}

pub fn viewpoints(parsed: &ParsedScene) -> Result<Vec<Viewpoint>, SceneError> {
    let mut out = Vec::new();
    for (i, entry) in parsed.cameras.iter().enumerate() {
        let camera = entry.get_ref();
        let key = |k: &str| format!("cameras[{i}].{k}");
        let eye = parsed.frame.point(DVec3::from_array(parsed.position(&camera.eye, &key("eye"))?));
        let target = parsed.frame.point(DVec3::from_array(parsed.position(&camera.target, &key("target"))?));
        if (target - eye).length() < 1e-6 {
            return parsed.error(camera.target.span(), key("target"), "the target must differ from the eye");
        }
        let fov = match &camera.fov {
            Some(fov) => parsed.number(fov, &key("fov"), (1.0, 170.0))? as f32,
            None => DEFAULT_FOV,
        };
        out.push(Viewpoint { name: camera.name.get_ref().clone(), eye, target, fov });
    }
    Ok(out)
}
