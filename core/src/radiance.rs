//! `export-radiance`: the scene, sky and sensors as a Radiance model, with a
//! `run.sh` that renders the sensors' illuminance with oconv and rtrace, so
//! any heliodon number can be checked against Radiance. The sky is written
//! with heliodon's own arguments and sun (SPA angles), not regenerated.
//! A panel fitted to measured data ([`PanelModel::bsdf_file`]) becomes
//! Radiance's `BSDF` material on that data, one per window group: its up
//! the panel frame's, its windows' polygons facing into the room (Radiance
//! puts a BSDF's front, +z, on the normal's side; WINDOW's exterior "front"
//! is its back). Other panels pass light straight through.
//!
//! [`PanelModel::bsdf_file`]: crate::panel::PanelModel::bsdf_file

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::light::{LightModel, PanelFrame, sensor_points};
use crate::report::csv_field;
use crate::scene::{MaterialKind, Scene};
use crate::sky::{Sky, radiance_sky};

/// rtrace settings of the reference: pure Monte Carlo, as the reference runs
/// in ../shared/validation, but with 64 ambient bounces where those have 16.
/// In a bright room 16 bounces leave light out: deep in a café whose
/// ceiling reflects 0.9 and walls 0.87 (web-ifc-viewer's `test.ifc`), -ab
/// 16 reads 7-8% under -ab 64, and -ab 128 agrees with -ab 64 within
/// noise; in the validation's side room all three agree within 0.3%.
/// Russian roulette (-lr -32, -lw) ends the deep bounces of darker rooms,
/// so they cost little there; the café's cost 40% more time.
pub const RTRACE_OPTIONS: &str = "-ab 64 -lr -32 -aa 0 -as 0 -dt 0 -dc 1 -dj 0 -st 0.15 -ss 1 -ad 131072 -lw 3.81e-06";

/// A name as a Radiance word: letters, digits, `_-.` kept, the rest `_`.
fn word(name: &str) -> String {
    name.chars().map(|c| if c.is_ascii_alphanumeric() || "_-.".contains(c) { c } else { '_' }).collect()
}

/// Radiance identifiers of the materials: their names as words, numbered
/// where two names become the same word.
fn identifiers(scene: &Scene) -> Vec<String> {
    let mut taken = std::collections::HashSet::new();
    scene
        .materials
        .iter()
        .map(|m| {
            let base = format!("m_{}", word(&m.name));
            let id =
                (1..).map(|k| if k == 1 { base.clone() } else { format!("{base}_{k}") }).find(|id| !taken.contains(id)).expect("a free id");
            taken.insert(id.clone());
            id
        })
        .collect()
}

/// Text on one line: control characters (line breaks included) as spaces.
fn one_line(text: &str) -> String {
    text.chars().map(|c| if c.is_control() { ' ' } else { c }).collect()
}

/// Radiance's glass transmissivity for a normal-incidence transmittance.
fn transmissivity(t: f64) -> f64 {
    crate::light::Glass::from_transmittance(t).transmissivity
}

/// The window groups of panels fitted to a BSDF file, and the group of
/// every triangle in one.
struct BsdfWindows {
    groups: Vec<BsdfGroup>,
    /// Per triangle of the scene: its index in `groups`.
    of_triangle: Vec<Option<u32>>,
}

/// Windows of one BSDF panel material facing one way.
struct BsdfGroup {
    material: u32,
    frame: PanelFrame,
    /// The data file, absolute.
    file: PathBuf,
}

impl BsdfWindows {
    fn new(scene: &Scene) -> Self {
        let mut out = Self { groups: Vec::new(), of_triangle: vec![None; scene.triangles.len()] };
        let data = |material: u32| match &scene.materials[material as usize].kind {
            MaterialKind::Panel { model, up, .. } => model.0.bsdf_file().map(|f| (f.to_path_buf(), *up)),
            _ => None,
        };
        if (0..scene.materials.len() as u32).all(|m| data(m).is_none()) {
            return out;
        }
        // The windows' outward sides are ray-tested, as the engine groups them.
        let windows = LightModel::unlit(Arc::new(scene.clone())).windows;
        for group in &windows.groups {
            let Some((file, up)) = data(group.material) else { continue };
            for &window in &group.windows {
                let surface = &scene.surfaces[scene.windows[window as usize].surface as usize];
                for t in surface.triangles.clone() {
                    out.of_triangle[t as usize] = Some(out.groups.len() as u32);
                }
            }
            let frame = PanelFrame::new(-group.outward, up.map(|u| u.as_dvec3()));
            out.groups.push(BsdfGroup { material: group.material, frame, file: std::fs::canonicalize(&file).unwrap_or(file) });
        }
        out
    }
}

/// Writes `scene.rad`, `sky.rad`, `sensors.pts`, `sensors.txt` (each
/// sensor's name as a Radiance word and its number of points), `names.csv`
/// (the names as they are, CSV fields) and `run.sh` into `dir`.
pub fn export(scene: &Scene, sky: &Sky, case: &str, dir: &Path) -> Result<(), String> {
    let write = |name: &str, text: &str| {
        std::fs::write(dir.join(name), text).map_err(|e| format!("{}: cannot write: {e}", dir.join(name).display()))
    };
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: cannot create: {e}", dir.display()))?;

    let mut rad = String::new();
    let _ = writeln!(rad, "# {} — exported by heliodon (metres, x east, y north, z up)\n", one_line(&scene.name));
    let ids = identifiers(scene);
    let bsdf_windows = BsdfWindows::new(scene);
    for (k, group) in bsdf_windows.groups.iter().enumerate() {
        let (id, up) = (&ids[group.material as usize], group.frame.y);
        let _ = writeln!(rad, "void BSDF {id}_g{k}\n6 0 {} {:.9} {:.9} {:.9} .\n0\n0\n", group.file.display(), up.x, up.y, up.z);
    }
    for (material, id) in scene.materials.iter().zip(&ids) {
        match &material.kind {
            MaterialKind::Diffuse { reflectance } => {
                let [r, g, b] = reflectance.0;
                let _ = writeln!(rad, "void plastic {id}\n0\n0\n5 {r} {g} {b} 0 0\n");
            }
            MaterialKind::Glass { transmittance } => {
                let tn = transmissivity(f64::from(*transmittance));
                let _ = writeln!(rad, "void glass {id}\n0\n0\n3 {tn:.9} {tn:.9} {tn:.9}\n");
            }
            MaterialKind::Panel { panel, model, .. } if model.0.bsdf_file().is_some() => {
                let _ = writeln!(rad, "# panel '{panel}' ({id}): Radiance's BSDF on its data, one per window group (above)\n");
            }
            MaterialKind::Panel { panel, .. } => {
                // Radiance cannot run heliodon's panel models.
                let _ = writeln!(rad, "# panel '{panel}': exported as clear pass-through\nvoid trans {id}\n0\n0\n7 1 1 1 0 0 1 1\n");
            }
        }
    }
    for (i, t) in scene.triangles.iter().enumerate() {
        let mut vertices = t.vertices;
        let id = match bsdf_windows.of_triangle[i] {
            Some(group) => {
                let inward = bsdf_windows.groups[group as usize].frame.z;
                if t.cross().as_dvec3().dot(inward) < 0.0 {
                    vertices.swap(1, 2);
                }
                format!("{}_g{group}", ids[t.material as usize])
            }
            None => ids[t.material as usize].clone(),
        };
        let _ = writeln!(rad, "{id} polygon t{i}\n0\n0\n9");
        for v in vertices {
            let _ = writeln!(rad, "  {:.6} {:.6} {:.6}", v.x, v.y, v.z);
        }
    }
    write("scene.rad", &rad)?;

    let (sky_rad, cal) = radiance_sky(sky);
    write("sky.rad", &format!("# {case}\n{sky_rad}"))?;
    if let Some((name, text)) = cal {
        write(&name, &text)?;
    }

    let mut points = String::new();
    let mut index = String::new();
    // The names as they are, for radiance.csv (sensors.txt has them as words).
    let mut names = String::new();
    for (sensor, at) in scene.sensors.iter().zip(sensor_points(scene)) {
        let n = sensor.normal;
        for p in &at {
            let _ = writeln!(points, "{:.6} {:.6} {:.6} {:.6} {:.6} {:.6}", p.x, p.y, p.z, n.x, n.y, n.z);
        }
        let _ = writeln!(index, "{} {}", word(&sensor.name), at.len());
        let _ = writeln!(names, "{}", csv_field(&one_line(&sensor.name)));
    }
    write("sensors.pts", &points)?;
    write("sensors.txt", &index)?;
    write("names.csv", &names)?;
    write(
        "run.sh",
        &format!(
            r#"#!/bin/sh
# Radiance's illuminance at heliodon's sensors for {case}.
# Needs Radiance on PATH (oconv, rtrace, rcalc) with its lib on RAYPATH.
# Writes radiance.csv: name,illuminance_lux (area sensors: the mean of their points).
set -e
cd "$(dirname "$0")"
oconv sky.rad scene.rad > scene.oct
rtrace -h -I {RTRACE_OPTIONS} scene.oct < sensors.pts \
  | rcalc -e '$1=179*(0.265*$1+0.670*$2+0.065*$3)' > points.lux
awk 'FILENAME == "sensors.txt" {{ count[FNR] = $2; sensors = FNR; next }}
     FILENAME == "names.csv" {{ name[FNR] = $0; next }}
     {{ lux[FNR] = $1 }}
     END {{ print "name,illuminance_lux"; k = 0
           for (s = 1; s <= sensors; s++) {{ sum = 0
             for (j = 0; j < count[s]; j++) {{ k++; sum += lux[k] }}
             printf "%s,%.1f\n", name[s], sum / count[s] }} }}' sensors.txt names.csv points.lux > radiance.csv
cat radiance.csv
"#
        ),
    )?;
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let _ = std::fs::set_permissions(dir.join("run.sh"), std::fs::Permissions::from_mode(0o755));
    }
    Ok(())
}
