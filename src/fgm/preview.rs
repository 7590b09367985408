//! A picture of an FGM part to look at before printing it: a horizontal section at height `z`
//! (the middle of the part by default), every pixel of the part coloured by its composition —
//! the palette's colours mixed by the fractions there, read from the grids as the PNG stack
//! reads them — and a legend: each material's colour and name, and a bar of the composition
//! against the distance to the features, from 0 to d_max.

use super::job::{mix, Fgm};
use super::material::Composition;
use crate::error::{Error, Result};
use crate::io::canvas::Canvas;
use std::path::Path;

/// The section's longer side, pixels.
pub(crate) const SIDE: f64 = 560.0;
pub(crate) const MARGIN: usize = 20;

/// The section's height: `z`, or the part's mid-height; refused outside the part.
pub fn section_height(fgm: &Fgm, z: Option<f64>) -> Result<f64> {
    let b = fgm
        .mesh
        .bounds()
        .ok_or_else(|| Error::invalid("the part is empty"))?;
    let z = z.unwrap_or(0.5 * (b.min[2] + b.max[2]));
    if !(b.min[2]..=b.max[2]).contains(&z) {
        return Err(Error::invalid(format!(
            "--preview-z {z} is outside the part ({:.3} to {:.3} mm)",
            b.min[2], b.max[2]
        )));
    }
    Ok(z)
}

/// Writes the preview of `fgm`, its section at `z` (mm; the part's mid-height when `None`).
pub fn write(fgm: &Fgm, path: &Path, palette: &[[u8; 3]], z: Option<f64>) -> Result<()> {
    let z = section_height(fgm, z)?;
    let b = fgm
        .mesh
        .bounds()
        .ok_or_else(|| Error::invalid("the part is empty"))?;
    let size = b.size();
    let scale = SIDE / size[0].max(size[1]).max(1e-9);
    let (pw, ph) = (
        (size[0] * scale).ceil() as usize,
        (size[1] * scale).ceil() as usize,
    );
    let n = fgm.composition.materials.len();
    let mut c = canvas(pw, ph, n);
    let mut pts = vec![0.0; 3 * pw];
    let (mut s, mut d) = (vec![0f32; pw], vec![0f32; pw]);
    let mut f = vec![0.0; n];
    for r in 0..ph {
        let y = b.max[1] - (r as f64 + 0.5) / scale;
        for col in 0..pw {
            pts[3 * col] = b.min[0] + (col as f64 + 0.5) / scale;
            pts[3 * col + 1] = y;
            pts[3 * col + 2] = z;
        }
        fgm.sdf.probe(&pts, &mut s);
        fgm.distance_grid.probe(&pts, &mut d);
        for col in 0..pw {
            if s[col] <= 0.0 {
                fgm.fractions_at(d[col] as f64, &mut f);
                c.put((MARGIN + col) as i64, (MARGIN + r) as i64, mix(&f, palette));
            }
        }
    }
    let title = format!("section z = {}", short(z));
    legend(&mut c, ph, &title, &fgm.composition, fgm.dmax, palette);
    c.write_png(path)
}

/// A white canvas for a picture `pw × ph` pixels of `n` materials, with room for the legend.
pub(crate) fn canvas(pw: usize, ph: usize, n: usize) -> Canvas {
    let width = (pw + 2 * MARGIN).max(460);
    Canvas::new(width, ph + 2 * MARGIN + 70 + 22 * n, [255; 3])
}

/// The legend under a picture `ph` pixels high: its title, each material's colour and name, and
/// a bar of the composition against the distance to the features, from 0 to `dmax`.
pub(crate) fn legend(
    c: &mut Canvas,
    ph: usize,
    title: &str,
    composition: &Composition,
    dmax: f64,
    palette: &[[u8; 3]],
) {
    let top = (ph + 2 * MARGIN) as i64;
    c.text(MARGIN as i64, top, title, 2);
    for (k, name) in composition.materials.iter().enumerate() {
        let y = top + 24 + 22 * k as i64;
        c.rect(MARGIN as i64, y, 16, 16, palette[k]);
        c.text(MARGIN as i64 + 24, y + 1, name, 2);
    }
    let mut f = vec![0.0; composition.materials.len()];
    let bar_x = (MARGIN + 200) as i64;
    let bar_w = c.width as i64 - bar_x - MARGIN as i64;
    let bar_y = top + 24;
    for i in 0..bar_w {
        let dist = dmax * i as f64 / (bar_w - 1).max(1) as f64;
        composition.fractions(dist, dmax, &mut f);
        c.rect(bar_x + i, bar_y, 1, 24, mix(&f, palette));
    }
    c.text(bar_x, bar_y + 30, "0", 2);
    let right = format!("{} mm", short(dmax));
    c.text(
        bar_x + bar_w - 12 * right.chars().count() as i64,
        bar_y + 30,
        &right,
        2,
    );
    c.text(bar_x, bar_y + 52, "distance to features", 2);
}

/// A number with at most three decimals, trailing zeros dropped.
pub(crate) fn short(x: f64) -> String {
    let s = format!("{x:.3}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}
