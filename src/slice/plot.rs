//! The layer plot (`--plot FILE.png`): layer thickness (top) and cross-section area (bottom)
//! against height, as an 8-bit RGB PNG — a look at where adaptive layers thinned and why.
//! Drawn directly (lines, ticks and a 5 × 7 pixel font), no plotting library.

use super::Layer;
use crate::error::Result;
use std::path::Path;

const W: usize = 960;
const H: usize = 640;
const LEFT: usize = 110;
const RIGHT: usize = 30;

struct Canvas {
    rgb: Vec<u8>,
}

impl Canvas {
    fn put(&mut self, x: i64, y: i64, c: [u8; 3]) {
        if x >= 0 && y >= 0 && (x as usize) < W && (y as usize) < H {
            let i = 3 * (y as usize * W + x as usize);
            self.rgb[i..i + 3].copy_from_slice(&c);
        }
    }

    fn line(&mut self, a: (f64, f64), b: (f64, f64), c: [u8; 3]) {
        let n = ((b.0 - a.0).abs().max((b.1 - a.1).abs()).ceil() as usize).max(1);
        for k in 0..=n {
            let t = k as f64 / n as f64;
            let (x, y) = (a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1));
            self.put(x.round() as i64, y.round() as i64, c);
            self.put(x.round() as i64, y.round() as i64 + 1, c);
        }
    }

    /// Text in the 5 × 7 font, `scale` pixels a dot, left edge at `x`, top at `y`.
    fn text(&mut self, x: i64, y: i64, s: &str, scale: i64) {
        let mut cx = x;
        for ch in s.chars() {
            if let Some(rows) = glyph(ch) {
                for (r, bits) in rows.iter().enumerate() {
                    for col in 0..5 {
                        if bits >> (4 - col) & 1 == 1 {
                            for dy in 0..scale {
                                for dx in 0..scale {
                                    self.put(
                                        cx + col * scale + dx,
                                        y + r as i64 * scale + dy,
                                        [40, 40, 40],
                                    );
                                }
                            }
                        }
                    }
                }
            }
            cx += 6 * scale;
        }
    }
}

/// The 5 × 7 dots of the characters the plot writes (rows top down, 5 bits each).
fn glyph(c: char) -> Option<[u8; 7]> {
    Some(match c {
        '0' => [14, 17, 19, 21, 25, 17, 14],
        '1' => [4, 12, 4, 4, 4, 4, 14],
        '2' => [14, 17, 1, 2, 4, 8, 31],
        '3' => [31, 2, 4, 2, 1, 17, 14],
        '4' => [2, 6, 10, 18, 31, 2, 2],
        '5' => [31, 16, 30, 1, 1, 17, 14],
        '6' => [6, 8, 16, 30, 17, 17, 14],
        '7' => [31, 1, 2, 4, 8, 8, 8],
        '8' => [14, 17, 17, 14, 17, 17, 14],
        '9' => [14, 17, 17, 15, 1, 2, 12],
        '.' => [0, 0, 0, 0, 0, 12, 12],
        '-' => [0, 0, 0, 31, 0, 0, 0],
        '(' => [2, 4, 8, 8, 8, 4, 2],
        ')' => [8, 4, 2, 2, 2, 4, 8],
        '²' => [12, 2, 4, 8, 14, 0, 0],
        'a' => [0, 0, 14, 1, 15, 17, 15],
        'c' => [0, 0, 14, 16, 16, 17, 14],
        'e' => [0, 0, 14, 17, 31, 16, 14],
        'g' => [0, 15, 17, 17, 15, 1, 14],
        'h' => [16, 16, 22, 25, 17, 17, 17],
        'i' => [4, 0, 12, 4, 4, 4, 14],
        'k' => [16, 16, 18, 20, 24, 20, 18],
        'l' => [12, 4, 4, 4, 4, 4, 14],
        'm' => [0, 0, 26, 21, 21, 17, 17],
        'n' => [0, 0, 22, 25, 17, 17, 17],
        'r' => [0, 0, 22, 25, 16, 16, 16],
        's' => [0, 0, 14, 16, 14, 1, 30],
        't' => [8, 8, 28, 8, 8, 9, 6],
        'y' => [0, 0, 17, 17, 15, 1, 14],
        'z' => [0, 0, 31, 2, 4, 8, 31],
        ' ' => [0; 7],
        _ => return None,
    })
}

/// About five round tick values covering `lo..hi`.
fn ticks(lo: f64, hi: f64) -> Vec<f64> {
    let span = (hi - lo).max(1e-12);
    let raw = span / 5.0;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * mag);
    let mut v = Vec::new();
    let mut t = (lo / step).ceil() * step;
    while t <= hi + 1e-9 * span {
        v.push(if t.abs() < 1e-12 * span { 0.0 } else { t });
        t += step;
    }
    v
}

fn label(v: f64) -> String {
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.to_string()
    }
}

/// Writes the plot of `layers` and their `areas` (mm²) to `path`.
pub fn write_plot(path: &Path, layers: &[Layer], areas: &[f64]) -> Result<()> {
    let mut c = Canvas {
        rgb: vec![255; 3 * W * H],
    };
    if layers.is_empty() {
        return crate::io::png::write_rgb(path, W as u32, H as u32, &c.rgb);
    }
    let z0 = layers[0].bottom();
    let z1 = layers.last().map_or(z0 + 1.0, |l| l.top()).max(z0 + 1e-9);
    let xs = |z: f64| LEFT as f64 + (z - z0) / (z1 - z0) * (W - LEFT - RIGHT) as f64;
    let t_max = layers.iter().map(|l| l.thickness).fold(0.0, f64::max) * 1.1;
    let a_max = areas.iter().copied().fold(0.0, f64::max).max(1e-12) * 1.1;
    // Two panels: (top, bottom) pixel rows, value range, title.
    let panels = [
        (30usize, 290usize, t_max, "layer (mm)"),
        (350, 590, a_max, "area (mm²)"),
    ];
    for (k, &(top, bottom, vmax, title)) in panels.iter().enumerate() {
        let ys = |v: f64| bottom as f64 - v / vmax * (bottom - top) as f64;
        let axis = [90, 90, 90];
        c.line(
            (LEFT as f64, top as f64),
            (LEFT as f64, bottom as f64),
            axis,
        );
        c.line(
            (LEFT as f64, bottom as f64),
            ((W - RIGHT) as f64, bottom as f64),
            axis,
        );
        for t in ticks(0.0, vmax / 1.1) {
            let y = ys(t);
            c.line((LEFT as f64 - 6.0, y), (LEFT as f64, y), axis);
            for x in (LEFT..W - RIGHT).step_by(6) {
                c.put(x as i64, y.round() as i64, [220, 220, 220]);
            }
            let s = label(t);
            c.text(
                LEFT as i64 - 10 - 12 * s.chars().count() as i64,
                y as i64 - 7,
                &s,
                2,
            );
        }
        for t in ticks(z0, z1) {
            let x = xs(t);
            c.line((x, bottom as f64), (x, bottom as f64 + 6.0), axis);
            let s = label(t);
            c.text(
                x as i64 - 6 * s.chars().count() as i64,
                bottom as i64 + 10,
                &s,
                2,
            );
        }
        c.text(LEFT as i64 + 10, top as i64 - 22, title, 2);
        let colour = if k == 0 { [30, 90, 200] } else { [200, 80, 30] };
        for (i, l) in layers.iter().enumerate() {
            if k == 0 {
                // A step per layer: its thickness across its own height range.
                let y = ys(l.thickness);
                c.line((xs(l.bottom()), y), (xs(l.top()), y), colour);
                if let Some(n) = layers.get(i + 1) {
                    c.line((xs(l.top()), y), (xs(n.bottom()), ys(n.thickness)), colour);
                }
            } else if let (Some(n), Some(&a)) = (layers.get(i + 1), areas.get(i)) {
                c.line((xs(l.z), ys(a)), (xs(n.z), ys(areas[i + 1])), colour);
            }
        }
    }
    c.text((W / 2) as i64 - 36, (H - 22) as i64, "z (mm)", 2);
    crate::io::png::write_rgb(path, W as u32, H as u32, &c.rgb)
}
