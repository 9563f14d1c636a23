//! The false-colour legend drawn into saved pictures: a colour bar over the
//! scale's three decades with its values in lux, in a small pixel font (no
//! font files needed headless).

use super::false_colour;

/// 3 × 5 glyphs, one row per 3-bit line, top first.
fn glyph(c: char) -> Option<[u8; 5]> {
    Some(match c {
        '0' => [7, 5, 5, 5, 7],
        '1' => [2, 6, 2, 2, 7],
        '2' => [7, 1, 7, 4, 7],
        '3' => [7, 1, 3, 1, 7],
        '4' => [5, 5, 7, 1, 1],
        '5' => [7, 4, 7, 1, 7],
        '6' => [7, 4, 7, 5, 7],
        '7' => [7, 1, 1, 2, 2],
        '8' => [7, 5, 7, 5, 7],
        '9' => [7, 5, 7, 1, 7],
        'k' => [4, 5, 6, 5, 5],
        'l' => [6, 2, 2, 2, 7],
        'u' => [0, 5, 5, 5, 7],
        'x' => [0, 5, 2, 5, 5],
        '.' => [0, 0, 0, 0, 2],
        _ => return None,
    })
}

/// Short label of an illuminance: 10, 100, 1k, 10k, 1.5k.
fn label(lux: f32) -> String {
    if lux >= 1000.0 {
        let k = lux / 1000.0;
        if (k - k.round()).abs() < 1e-3 { format!("{}k", k.round()) } else { format!("{k:.1}k") }
    } else {
        format!("{}", lux.round())
    }
}

/// Draws the legend into the right edge of an RGBA picture (8-bit sRGB).
pub fn draw_legend(rgba: &mut [u8], width: u32, height: u32, top_lux: f32) {
    let scale = (height / 200).max(1) as i64;
    let (bar_w, bar_h) = (10 * scale, (height as i64 * 6 / 10).max(20));
    let (x0, y0) = (width as i64 - bar_w - 28 * scale, (height as i64 - bar_h) / 2);
    let mut put = |x: i64, y: i64, colour: [u8; 3]| {
        if x >= 0 && y >= 0 && (x as u32) < width && (y as u32) < height {
            let i = 4 * (y as usize * width as usize + x as usize);
            rgba[i..i + 3].copy_from_slice(&colour);
            rgba[i + 3] = 255;
        }
    };
    let encode = |linear: f32| {
        let c = linear.clamp(0.0, 1.0);
        let srgb = if c <= 0.003_130_8 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 };
        (srgb * 255.0).round() as u8
    };
    // A dark backing, then the bar from the top of the scale down.
    for y in y0 - 8 * scale..y0 + bar_h + 14 * scale {
        for x in x0 - 4 * scale..width as i64 - 2 * scale {
            put(x, y, [25, 25, 25]);
        }
    }
    for dy in 0..bar_h {
        let t = 1.0 - dy as f32 / (bar_h - 1) as f32;
        let lux = top_lux * 1000f32.powf(t - 1.0);
        let colour = false_colour(lux, top_lux).map(encode);
        for dx in 0..bar_w {
            put(x0 + dx, y0 + dy, colour);
        }
    }
    let mut text = |x: i64, y: i64, s: &str| {
        for (k, c) in s.chars().enumerate() {
            let Some(rows) = glyph(c) else { continue };
            for (row, bits) in rows.iter().enumerate() {
                for col in 0..3 {
                    if bits & (4 >> col) != 0 {
                        for (sx, sy) in (0..scale).flat_map(|a| (0..scale).map(move |b| (a, b))) {
                            put(x + (4 * k as i64 + col) * scale + sx, y + row as i64 * scale + sy, [235, 235, 235]);
                        }
                    }
                }
            }
        }
    };
    for decade in 0..4 {
        let lux = top_lux / 10f32.powi(decade);
        let y = y0 + bar_h * i64::from(decade) / 3;
        text(x0 + bar_w + 3 * scale, y - 2 * scale, &label(lux));
    }
    text(x0, y0 + bar_h + 5 * scale, "lux");
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_read_as_lux() {
        assert_eq!([10.0, 100.0, 1000.0, 10_000.0, 1500.0].map(label), ["10", "100", "1k", "10k", "1.5k"]);
    }

    #[test]
    fn the_bar_shows_the_scale() {
        let (w, h) = (200u32, 200u32);
        let mut rgba = vec![0u8; (w * h * 4) as usize];
        draw_legend(&mut rgba, w, h, 10_000.0);
        let pixel = |x: u32, y: u32| &rgba[4 * (y * w + x) as usize..4 * (y * w + x) as usize + 3];
        // Top of the bar: near white (top of the scale); bottom: dark blue.
        let (x0, bar_h) = (w - 10 - 28, 120u32);
        let y0 = (h - bar_h) / 2;
        assert!(pixel(x0 + 2, y0).iter().all(|&c| c > 200), "{:?}", pixel(x0 + 2, y0));
        let bottom = pixel(x0 + 2, y0 + bar_h - 1);
        assert!(bottom[2] > bottom[0] && bottom[0] < 80, "{bottom:?}");
    }
}
