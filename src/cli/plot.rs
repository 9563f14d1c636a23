//! Pictures of sweeps for reports: the curve of one key or the heat map of
//! two, with labelled axes, a colour legend in the metric's unit and the
//! best combination marked. Drawn into an RGB image with a 5 × 7 pixel
//! font (scaled), so no font file or GPU is needed.

use std::path::Path;

use image::{Rgb, RgbImage};

use super::sweep_table::{SDA_ROW, Table, best, key_value, scores};

const WIDTH: u32 = 960;
const HEIGHT: u32 = 720;
/// Text is drawn at this many pixels per font pixel.
const SCALE: u32 = 2;
const BACKGROUND: Rgb<u8> = Rgb([255, 255, 255]);
const INK: Rgb<u8> = Rgb([20, 20, 20]);
const MISSING: Rgb<u8> = Rgb([190, 190, 190]);

/// The plot area: left, top, right, bottom.
const PLOT: (u32, u32, u32, u32) = (130, 70, 790, 600);

/// Writes the picture of `table` (one key: a curve; two: a heat map).
pub fn write_sweep_picture(table: &Table, path: &Path) -> Result<(), String> {
    let scores = scores(table);
    let known: Vec<f64> = scores.iter().filter_map(|s| s.1).collect();
    if known.is_empty() {
        return Err(format!("--out {}: no combination built, nothing to draw", path.display()));
    }
    let (lo, hi) = known.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
    let year = table.rows.iter().any(|r| r.sensor == SDA_ROW);
    let metric =
        match (year, table.rows.iter().filter(|r| r.sensor != SDA_ROW).map(|r| &r.sensor).collect::<std::collections::BTreeSet<_>>().len())
        {
            (true, 1) => format!("DA300 at {} ({})", table.rows[0].sensor, table.unit),
            (true, _) => format!("sDA300/50% ({})", table.unit),
            (false, 1) => format!("illuminance at {} ({})", table.rows[0].sensor, table.unit),
            (false, _) => format!("mean illuminance at the sensors ({})", table.unit),
        };
    let best = best(table);
    let mut image = RgbImage::from_pixel(WIDTH, HEIGHT, BACKGROUND);
    let (left, top, right, bottom) = PLOT;
    match table.keys.len() {
        1 => {
            let xs: Vec<f64> = scores.iter().map(|s| s.0[0]).collect();
            let (x0, x1) = (xs[0], *xs.last().expect("a value"));
            let span = |a: f64, b: f64| if b > a { b - a } else { 1.0 };
            let (y0, y1) = if hi > lo { (lo - 0.05 * (hi - lo), hi + 0.05 * (hi - lo)) } else { (lo - 1.0, hi + 1.0) };
            let px = |x: f64| left as f64 + (x - x0) / span(x0, x1) * (right - left) as f64;
            let py = |y: f64| bottom as f64 - (y - y0) / (y1 - y0) * (bottom - top) as f64;
            frame(&mut image);
            for k in 0..=4 {
                let y = y0 + (y1 - y0) * k as f64 / 4.0;
                let at = py(y) as u32;
                line(&mut image, (left - 6) as f64, at as f64, left as f64, at as f64, INK);
                text_right(&mut image, &format!("{y:.1}"), left - 10, at - 7);
            }
            for (i, &x) in xs.iter().enumerate() {
                if i % xs.len().div_ceil(12) == 0 {
                    let at = px(x);
                    line(&mut image, at, bottom as f64, at, (bottom + 6) as f64, INK);
                    text_centred(&mut image, &key_value(x), at as u32, bottom + 12);
                }
            }
            let points: Vec<(f64, f64)> = scores.iter().filter_map(|s| s.1.map(|v| (px(s.0[0]), py(v)))).collect();
            for pair in points.windows(2) {
                line(&mut image, pair[0].0, pair[0].1, pair[1].0, pair[1].1, Rgb([40, 90, 170]));
            }
            for &(x, y) in &points {
                disc(&mut image, x, y, 3.0, Rgb([40, 90, 170]));
            }
            if let Some((values, score)) = &best {
                ring(&mut image, px(values[0]), py(*score), 9.0, Rgb([200, 30, 30]));
            }
            text_centred(&mut image, &table.keys[0], (left + right) / 2, bottom + 44);
            text_vertical(&mut image, &metric, 4, (top + bottom) / 2);
        }
        _ => {
            let xs: Vec<f64> = dedup(scores.iter().map(|s| s.0[0]));
            let ys: Vec<f64> = dedup(scores.iter().map(|s| s.0[1]));
            let (cw, ch) = ((right - left) as f64 / xs.len() as f64, (bottom - top) as f64 / ys.len() as f64);
            for (values, score) in &scores {
                let i = xs.iter().position(|&x| x == values[0]).expect("a column");
                let j = ys.iter().position(|&y| y == values[1]).expect("a row");
                let (x, y) = (left as f64 + i as f64 * cw, bottom as f64 - (j + 1) as f64 * ch);
                let colour = score.map_or(MISSING, |v| colour_map(if hi > lo { (v - lo) / (hi - lo) } else { 0.5 }));
                rect(&mut image, x, y, cw, ch, colour);
                if score.is_none() {
                    line(&mut image, x, y, x + cw, y + ch, INK);
                    line(&mut image, x, y + ch, x + cw, y, INK);
                }
            }
            if let Some((values, _)) = &best {
                let i = xs.iter().position(|&x| x == values[0]).expect("a column");
                let j = ys.iter().position(|&y| y == values[1]).expect("a row");
                let (x, y) = (left as f64 + (i as f64 + 0.5) * cw, bottom as f64 - (j as f64 + 0.5) * ch);
                let r = 0.45 * cw.min(ch);
                for (dx, dy) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)] {
                    ring(&mut image, x + dx, y + dy, r.max(5.0), Rgb([255, 255, 255]));
                }
                ring(&mut image, x, y, r.max(5.0) + 2.0, INK);
            }
            frame(&mut image);
            for (i, &x) in xs.iter().enumerate() {
                if i % xs.len().div_ceil(12) == 0 {
                    text_centred(&mut image, &key_value(x), (left as f64 + (i as f64 + 0.5) * cw) as u32, bottom + 12);
                }
            }
            for (j, &y) in ys.iter().enumerate() {
                if j % ys.len().div_ceil(12) == 0 {
                    text_right(&mut image, &key_value(y), left - 10, (bottom as f64 - (j as f64 + 0.5) * ch) as u32 - 7);
                }
            }
            text_centred(&mut image, &table.keys[0], (left + right) / 2, bottom + 44);
            text_vertical(&mut image, &table.keys[1], 4, (top + bottom) / 2);
            // The legend: the colour bar in the metric's unit.
            let (bar_left, bar_right) = (right + 40, right + 64);
            for y in top..bottom {
                let t = (bottom - y) as f64 / (bottom - top) as f64;
                rect(&mut image, bar_left as f64, y as f64, (bar_right - bar_left) as f64, 1.0, colour_map(t));
            }
            for k in 0..=4 {
                let t = k as f64 / 4.0;
                let at = bottom - ((bottom - top) as f64 * t) as u32;
                text(&mut image, &format!("{:.1}", lo + (hi - lo) * t), bar_right + 8, at.saturating_sub(7));
            }
            text_vertical(&mut image, &table.unit, bar_right + 110, (top + bottom) / 2);
        }
    }
    text(&mut image, &metric, 20, 14);
    if let Some((values, score)) = &best {
        let keys: Vec<String> = table.keys.iter().zip(values).map(|(k, v)| format!("{k} = {}", key_value(*v))).collect();
        text(&mut image, &format!("best (circled): {}: {score:.1} {}", keys.join(", "), table.unit), 20, 40);
    }
    image.save(path).map_err(|e| format!("--out {}: {e}", path.display()))
}

fn dedup(values: impl Iterator<Item = f64>) -> Vec<f64> {
    let mut out: Vec<f64> = values.collect();
    out.sort_by(f64::total_cmp);
    out.dedup();
    out
}

/// A perceptual blue-green-yellow map (viridis's control points), t in 0-1.
fn colour_map(t: f64) -> Rgb<u8> {
    const STOPS: [[f64; 3]; 5] = [[68.0, 1.0, 84.0], [59.0, 82.0, 139.0], [33.0, 145.0, 140.0], [94.0, 201.0, 98.0], [253.0, 231.0, 37.0]];
    let t = t.clamp(0.0, 1.0) * (STOPS.len() - 1) as f64;
    let i = (t.floor() as usize).min(STOPS.len() - 2);
    let f = t - i as f64;
    Rgb([0, 1, 2].map(|c| (STOPS[i][c] * (1.0 - f) + STOPS[i + 1][c] * f).round() as u8))
}

fn put(image: &mut RgbImage, x: i64, y: i64, colour: Rgb<u8>) {
    if x >= 0 && y >= 0 && (x as u32) < image.width() && (y as u32) < image.height() {
        image.put_pixel(x as u32, y as u32, colour);
    }
}

fn rect(image: &mut RgbImage, x: f64, y: f64, w: f64, h: f64, colour: Rgb<u8>) {
    for py in y.round() as i64..(y + h).round() as i64 {
        for px in x.round() as i64..(x + w).round() as i64 {
            put(image, px, py, colour);
        }
    }
}

fn line(image: &mut RgbImage, x0: f64, y0: f64, x1: f64, y1: f64, colour: Rgb<u8>) {
    let steps = (x1 - x0).abs().max((y1 - y0).abs()).ceil().max(1.0) as usize;
    for k in 0..=steps {
        let t = k as f64 / steps as f64;
        put(image, (x0 + (x1 - x0) * t).round() as i64, (y0 + (y1 - y0) * t).round() as i64, colour);
    }
}

fn disc(image: &mut RgbImage, x: f64, y: f64, r: f64, colour: Rgb<u8>) {
    for dy in -r.ceil() as i64..=r.ceil() as i64 {
        for dx in -r.ceil() as i64..=r.ceil() as i64 {
            if (dx * dx + dy * dy) as f64 <= r * r {
                put(image, x.round() as i64 + dx, y.round() as i64 + dy, colour);
            }
        }
    }
}

fn ring(image: &mut RgbImage, x: f64, y: f64, r: f64, colour: Rgb<u8>) {
    let steps = (r * 8.0).ceil() as usize;
    for k in 0..steps {
        let a = std::f64::consts::TAU * k as f64 / steps as f64;
        for w in [0.0, 1.0] {
            put(image, (x + (r + w) * a.cos()).round() as i64, (y + (r + w) * a.sin()).round() as i64, colour);
        }
    }
}

fn frame(image: &mut RgbImage) {
    let (left, top, right, bottom) = PLOT;
    let (l, t, r, b) = (left as f64, top as f64, right as f64, bottom as f64);
    for (x0, y0, x1, y1) in [(l, t, r, t), (r, t, r, b), (l, b, r, b), (l, t, l, b)] {
        line(image, x0, y0, x1, y1, INK);
    }
}

/// The 5 × 7 glyph of a character (lower case drawn as upper case), rows
/// top down, bit 4 the leftmost column.
fn glyph(c: char) -> [u8; 7] {
    match c.to_ascii_uppercase() {
        '0' => [0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E],
        '1' => [0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E],
        '2' => [0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F],
        '3' => [0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E],
        '4' => [0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02],
        '5' => [0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E],
        '6' => [0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E],
        '7' => [0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08],
        '8' => [0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E],
        '9' => [0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C],
        'A' => [0x0E, 0x11, 0x11, 0x11, 0x1F, 0x11, 0x11],
        'B' => [0x1E, 0x11, 0x11, 0x1E, 0x11, 0x11, 0x1E],
        'C' => [0x0E, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0E],
        'D' => [0x1C, 0x12, 0x11, 0x11, 0x11, 0x12, 0x1C],
        'E' => [0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x1F],
        'F' => [0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x10],
        'G' => [0x0E, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0F],
        'H' => [0x11, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11],
        'I' => [0x0E, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E],
        'J' => [0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0C],
        'K' => [0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11],
        'L' => [0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1F],
        'M' => [0x11, 0x1B, 0x15, 0x15, 0x11, 0x11, 0x11],
        'N' => [0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11],
        'O' => [0x0E, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E],
        'P' => [0x1E, 0x11, 0x11, 0x1E, 0x10, 0x10, 0x10],
        'Q' => [0x0E, 0x11, 0x11, 0x11, 0x15, 0x12, 0x0D],
        'R' => [0x1E, 0x11, 0x11, 0x1E, 0x14, 0x12, 0x11],
        'S' => [0x0F, 0x10, 0x10, 0x0E, 0x01, 0x01, 0x1E],
        'T' => [0x1F, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04],
        'U' => [0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E],
        'V' => [0x11, 0x11, 0x11, 0x11, 0x11, 0x0A, 0x04],
        'W' => [0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0A],
        'X' => [0x11, 0x11, 0x0A, 0x04, 0x0A, 0x11, 0x11],
        'Y' => [0x11, 0x11, 0x11, 0x0A, 0x04, 0x04, 0x04],
        'Z' => [0x1F, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1F],
        ' ' => [0; 7],
        '.' => [0, 0, 0, 0, 0, 0x0C, 0x0C],
        ',' => [0, 0, 0, 0, 0x0C, 0x04, 0x08],
        ';' => [0, 0x0C, 0x0C, 0, 0x0C, 0x04, 0x08],
        '-' => [0, 0, 0, 0x1F, 0, 0, 0],
        '_' => [0, 0, 0, 0, 0, 0, 0x1F],
        '[' => [0x0E, 0x08, 0x08, 0x08, 0x08, 0x08, 0x0E],
        ']' => [0x0E, 0x02, 0x02, 0x02, 0x02, 0x02, 0x0E],
        '(' => [0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02],
        ')' => [0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08],
        '%' => [0x18, 0x19, 0x02, 0x04, 0x08, 0x13, 0x03],
        '/' => [0, 0x01, 0x02, 0x04, 0x08, 0x10, 0],
        ':' => [0, 0x0C, 0x0C, 0, 0x0C, 0x0C, 0],
        '=' => [0, 0, 0x1F, 0, 0x1F, 0, 0],
        '+' => [0, 0x04, 0x04, 0x1F, 0x04, 0x04, 0],
        _ => [0x1F, 0x11, 0x11, 0x11, 0x11, 0x11, 0x1F],
    }
}

/// Width of `s` in pixels.
fn text_width(s: &str) -> u32 {
    s.chars().count() as u32 * 6 * SCALE
}

fn text(image: &mut RgbImage, s: &str, x: u32, y: u32) {
    for (k, c) in s.chars().enumerate() {
        let rows = glyph(c);
        for (row, bits) in rows.iter().enumerate() {
            for col in 0..5 {
                if bits & (0x10 >> col) != 0 {
                    let (px, py) = (x + (k as u32 * 6 + col) * SCALE, y + row as u32 * SCALE);
                    rect(image, px as f64, py as f64, SCALE as f64, SCALE as f64, INK);
                }
            }
        }
    }
}

fn text_centred(image: &mut RgbImage, s: &str, centre: u32, y: u32) {
    text(image, s, centre.saturating_sub(text_width(s) / 2), y);
}

fn text_right(image: &mut RgbImage, s: &str, right: u32, y: u32) {
    text(image, s, right.saturating_sub(text_width(s)), y);
}

/// Text turned a quarter anticlockwise, centred on (x, centre).
fn text_vertical(image: &mut RgbImage, s: &str, x: u32, centre: u32) {
    let mut strip = RgbImage::from_pixel(text_width(s), 7 * SCALE, BACKGROUND);
    text(&mut strip, s, 0, 0);
    let top = centre.saturating_sub(text_width(s) / 2);
    for (px, py, &colour) in strip.enumerate_pixels() {
        if colour != BACKGROUND {
            put(image, (x + py) as i64, (top + text_width(s) - 1 - px) as i64, colour);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_colour_map_runs_dark_to_light() {
        let luminance = |c: Rgb<u8>| 0.2126 * f64::from(c.0[0]) + 0.7152 * f64::from(c.0[1]) + 0.0722 * f64::from(c.0[2]);
        let steps: Vec<f64> = (0..=10).map(|k| luminance(colour_map(k as f64 / 10.0))).collect();
        assert!(steps.windows(2).all(|w| w[1] > w[0]), "{steps:?}");
    }
}
