//! A sky as Radiance scene text: the same sky function with the same
//! arguments (skybright.cal, perezlum.cal, or a CIE .cal written alongside),
//! the same sun, and the usual sky and ground glows, so that Radiance sees
//! exactly the sky heliodon lit the scene with.

use std::fmt::Write as _;

use super::{Distribution, Sky, SkySpec};

/// `sky.rad`, and a .cal file it needs (name, text), if any.
pub fn radiance_sky(sky: &Sky) -> (String, Option<(String, String)>) {
    let mut out = String::new();
    let mut cal = None;
    let _ = writeln!(
        out,
        "# heliodon sky: {} (sun altitude {:.4}°, direction {:.6} {:.6} {:.6})",
        sky.spec.name(),
        sky.sun_direction.z.asin().to_degrees(),
        sky.sun_direction.x,
        sky.sun_direction.y,
        sky.sun_direction.z
    );
    if let Some(sun) = sky.sun {
        let diameter = 2.0 * (1.0 - sun.solid_angle / (2.0 * std::f64::consts::PI)).acos().to_degrees();
        let _ = writeln!(out, "\nvoid light solar\n0\n0\n3 {r:.6e} {r:.6e} {r:.6e}", r = sun.radiance);
        let d = sun.direction;
        let _ = writeln!(out, "\nsolar source sun\n0\n0\n4 {:.9} {:.9} {:.9} {diameter:.6}", d.x, d.y, d.z);
    }
    let ground = sky.ground_radiance;
    match &sky.distribution {
        Distribution::Dark => {
            let _ = writeln!(out, "\nvoid brightfunc skyfunc\n2 skybr skybright.cal\n0\n3 3 0 0");
        }
        Distribution::Gensky(g) => {
            let (zenith, f2) = g.arguments();
            let kind = match sky.spec {
                SkySpec::Clear { .. } => 1,
                SkySpec::Overcast => 2,
                SkySpec::Uniform => 3,
                _ => 4,
            };
            let s = g.sun_for_sky();
            if kind == 2 || kind == 3 {
                let _ = writeln!(out, "\nvoid brightfunc skyfunc\n2 skybr skybright.cal\n0\n3 {kind} {zenith:.9e} {ground:.9e}");
            } else {
                let _ = writeln!(
                    out,
                    "\nvoid brightfunc skyfunc\n2 skybr skybright.cal\n0\n7 {kind} {zenith:.9e} {ground:.9e} {f2:.9e} {:.9} {:.9} {:.9}",
                    s.x, s.y, s.z
                );
            }
        }
        Distribution::Perez(p) => {
            let (norm, c) = p.arguments();
            let s = p.sun_for_sky();
            let _ = writeln!(
                out,
                "\nvoid brightfunc skyfunc\n2 skybright perezlum.cal\n0\n10 {norm:.9e} {ground:.9e} {:.9} {:.9} {:.9} {:.9} {:.9} {:.9} {:.9} {:.9}",
                c[0], c[1], c[2], c[3], c[4], s.x, s.y, s.z
            );
        }
        Distribution::Cie(c) => {
            let (scale, [a, b, cc, d, e], s) = c.arguments();
            let _ = writeln!(
                out,
                "\nvoid brightfunc skyfunc\n2 skybright heliodon_cie.cal\n0\n10 {scale:.9e} {ground:.9e} {a} {b} {cc} {d} {e} {:.9} {:.9} {:.9}",
                s.x, s.y, s.z
            );
            cal = Some(("heliodon_cie.cal".to_string(), CIE_CAL.to_string()));
        }
    }
    out.push_str(GLOWS);
    (out, cal)
}

const GLOWS: &str = "
skyfunc glow sky_glow
0
0
4 1 1 1 0

sky_glow source sky
0
0
4 0 0 1 180

skyfunc glow ground_glow
0
0
4 1 1 1 0

ground_glow source ground
0
0
4 0 0 -1 180
";

const CIE_CAL: &str = "{ CIE S 011 standard general sky, as heliodon computes it.
  A1: zenith luminance / (f(Zs) phi(0)), A2: ground radiance,
  A3..A7: a b c d e, A8..A10: sun direction }
wmean(a, x, b, y) : (a*x + b*y) / (a + b);
cosgamma = Dx*A8 + Dy*A9 + Dz*A10;
chi = Acos(cosgamma);
gradation = if(Dz, 1 + A3*exp(A4/Dz), 1);
indicatrix = 1 + A5*(exp(A6*chi) - exp(A6*PI/2)) + A7*cosgamma*cosgamma;
skybright = wmean((Dz+1.01)^10, A1*indicatrix*gradation, (Dz+1.01)^-10, A2);
";
