//! The layer plot (`--plot FILE.png`): layer thickness (top) and cross-section area (bottom)
//! against height, as an 8-bit RGB PNG — a look at where adaptive layers thinned and why.
//! Drawn directly on latvox's canvas (lines, ticks and a 5 × 7 pixel font), no plotting library.

use super::Layer;
use crate::error::Result;
use crate::io::canvas::Canvas;
use std::path::Path;

const W: usize = 960;
const H: usize = 640;
const LEFT: usize = 110;
const RIGHT: usize = 30;

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
    let mut c = Canvas::new(W, H, [255; 3]);
    if layers.is_empty() {
        return c.write_png(path);
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
    c.write_png(path)
}
