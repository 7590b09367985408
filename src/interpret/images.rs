//! PNG images of the pipeline's stages, so a person can see what each step changed:
//! `raw` (refined densities, dark = solid), `thresholded` (step 1.1), `skeleton` (steps 1.2–1.3:
//! the pruned skeleton in blue, thin features in red, point contacts in magenta, islands in
//! orange), and `final` (the cleaned solid). A 3D field is shown by its middle z slice.

use super::raster::{Mask, Raster};
use super::Cleaned;
use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

struct Canvas {
    w: usize,
    h: usize,
    rgb: Vec<u8>,
}

impl Canvas {
    fn new(r: &Raster) -> Canvas {
        Canvas {
            w: r.n[0],
            h: r.n[1],
            rgb: vec![255; r.n[0] * r.n[1] * 3],
        }
    }

    /// Pixel (x, y) with y up.
    fn set(&mut self, x: usize, y: usize, c: [u8; 3]) {
        let o = ((self.h - 1 - y) * self.w + x) * 3;
        self.rgb[o..o + 3].copy_from_slice(&c);
    }

    fn save(&self, path: &Path) -> Result<()> {
        crate::io::png::write_rgb(path, self.w as u32, self.h as u32, &self.rgb)
    }
}

fn slice_offset(r: &Raster) -> usize {
    (r.n[2] / 2) * r.n[0] * r.n[1]
}

fn gray(r: &Raster) -> Canvas {
    let mut c = Canvas::new(r);
    let o = slice_offset(r);
    for y in 0..r.n[1] {
        for x in 0..r.n[0] {
            let v = r.data[o + y * r.n[0] + x].clamp(0.0, 1.0);
            let g = (255.0 * (1.0 - v)).round() as u8;
            c.set(x, y, [g, g, g]);
        }
    }
    c
}

fn binary(r: &Raster, m: &Mask, solid: [u8; 3]) -> Canvas {
    let mut c = Canvas::new(r);
    let o = slice_offset(r);
    for y in 0..r.n[1] {
        for x in 0..r.n[0] {
            if m[o + y * r.n[0] + x] {
                c.set(x, y, solid);
            }
        }
    }
    c
}

/// The stages drawn, in the order of their images.
pub const STAGES: [&str; 4] = ["raw", "thresholded", "skeleton", "final"];

/// The image of `stage` for `prefix`: `PREFIX-stage.png`.
pub fn stage_path(prefix: &Path, stage: &str) -> Result<PathBuf> {
    let stem = prefix
        .file_name()
        .and_then(|f| f.to_str())
        .ok_or_else(|| Error::invalid("--images needs a file name prefix"))?;
    Ok(prefix.with_file_name(format!("{stem}-{stage}.png")))
}

/// Writes `PREFIX-raw.png`, `-thresholded`, `-skeleton`, `-final` ([`STAGES`]); returns the
/// paths.
pub fn write_stages(c: &Cleaned, prefix: &Path) -> Result<Vec<PathBuf>> {
    let name = |s: &str| stage_path(prefix, s);
    let r = &c.raw;
    let o = slice_offset(r);
    let in_slice = |i: usize| i >= o && i < o + r.n[0] * r.n[1];
    let xy = |i: usize| ((i - o) % r.n[0], (i - o) / r.n[0]);
    let mut out = Vec::new();

    let p = name("raw")?;
    gray(r).save(&p)?;
    out.push(p);

    let p = name("thresholded")?;
    binary(r, &c.thresholded, [40, 40, 40]).save(&p)?;
    out.push(p);

    let mut sk = binary(r, &c.thresholded, [190, 190, 190]);
    let a = &c.initial;
    for (i, &s) in a.skeleton.iter().enumerate() {
        if s && in_slice(i) {
            let (x, y) = xy(i);
            sk.set(x, y, [30, 80, 220]);
        }
    }
    for isl in &a.islands {
        for &i in isl.iter().filter(|&&i| in_slice(i)) {
            let (x, y) = xy(i);
            sk.set(x, y, [240, 150, 30]);
        }
    }
    let mut mark = |i: usize, col: [u8; 3], rad: isize| {
        if !in_slice(i) {
            return;
        }
        let (x, y) = xy(i);
        for dy in -rad..=rad {
            for dx in -rad..=rad {
                let (xx, yy) = (x as isize + dx, y as isize + dy);
                if xx >= 0 && yy >= 0 && (xx as usize) < r.n[0] && (yy as usize) < r.n[1] {
                    sk.set(xx as usize, yy as usize, col);
                }
            }
        }
    };
    for &i in &a.thin {
        mark(i, [220, 30, 30], 1);
    }
    for &i in &a.contacts {
        mark(i, [200, 0, 200], 3);
    }
    let p = name("skeleton")?;
    sk.save(&p)?;
    out.push(p);

    let p = name("final")?;
    binary(&c.field, &c.mask, [40, 40, 40]).save(&p)?;
    out.push(p);
    Ok(out)
}
