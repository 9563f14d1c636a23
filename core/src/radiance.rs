//! `export-radiance`: the scene, sky and sensors as a Radiance model, with a
//! `run.sh` that renders the sensors' illuminance with oconv and rtrace, so
//! any heliodon number can be checked against Radiance. The sky is written
//! with heliodon's own arguments and sun (SPA angles), not regenerated.

use std::fmt::Write as _;
use std::path::Path;

use crate::light::sensor_points;
use crate::report::csv_field;
use crate::scene::{MaterialKind, Scene};
use crate::sky::{Sky, radiance_sky};

/// rtrace settings of the reference runs in ../shared/validation: pure Monte
/// Carlo, 16 bounces, converged well under 1%.
pub const RTRACE_OPTIONS: &str = "-ab 16 -lr -32 -aa 0 -as 0 -dt 0 -dc 1 -dj 0 -st 0.15 -ss 1 -ad 131072 -lw 3.81e-06";

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
            MaterialKind::Panel { panel, .. } => {
                // Panels pass light straight through in heliodon until their models land.
                let _ = writeln!(rad, "# panel '{panel}': exported as clear pass-through\nvoid trans {id}\n0\n0\n7 1 1 1 0 0 1 1\n");
            }
        }
    }
    for (i, t) in scene.triangles.iter().enumerate() {
        let id = &ids[t.material as usize];
        let _ = writeln!(rad, "{id} polygon t{i}\n0\n0\n9");
        for v in t.vertices {
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
