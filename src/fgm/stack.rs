//! Voxel-print PNG stacks: one picture per layer, one material per pixel, for material-jetting
//! printers driven by bitmaps (PolyJet through GrabCAD Voxel Print and its like).
//!
//! Every picture covers the part's box at the same pixel size (`25.4 / dpi` mm per axis, 600 ×
//! 300 dpi by default: PolyJet's native grid) and each is one layer (27 µm by default) sampled at
//! its mid-height. A pixel is in the part where the signed distance grid, read trilinearly, is
//! ≤ 0; its composition comes from the distance grid through the laws. A pixel takes one material
//! by error diffusion — Floyd and Steinberg's weights ("An adaptive algorithm for spatial
//! greyscale", 1976) on a serpentine path, carried for every material at once (the material with
//! the largest wanted fraction plus carried error wins, and the difference is passed on) — and
//! only to neighbours inside the part, so the error is not lost at the part's edge and each
//! layer's material counts match its continuous fractions. Outside the part a pixel is
//! transparent. The report gives, per layer, the largest difference between a material's share
//! of the layer's pixels and its mean fraction over them.

use super::job::Fgm;
use crate::error::{Error, Result};
use crate::io::atomic::AtomicDir;
use crate::progress::Progress;
use rayon::prelude::*;
use std::path::Path;

/// How the stack is cut.
#[derive(Debug, Clone)]
pub struct StackSpec {
    /// Dots per inch along x and y.
    pub dpi: [f64; 2],
    /// Layer thickness, mm.
    pub layer: f64,
    /// One colour per material.
    pub palette: Vec<[u8; 3]>,
}

/// What was written.
#[derive(Debug, Clone, serde::Serialize)]
pub struct StackReport {
    /// The folder.
    pub folder: String,
    /// Pictures (layers).
    pub layers: usize,
    /// Pixels per picture, x and y.
    pub width: usize,
    /// Pixels per picture along y.
    pub height: usize,
    /// Pixel size, mm (x, y).
    pub pixel_mm: [f64; 2],
    /// Layer thickness, mm.
    pub layer_mm: f64,
    /// Lower corner of the first picture's first pixel (x, y) and the first layer's bottom, mm.
    pub origin: [f64; 3],
    /// Pixels in the part, over all layers.
    pub part_pixels: u64,
    /// Per material, its share of the part's pixels.
    pub shares: Vec<f64>,
    /// The largest difference, over layers and materials, between a material's share of a
    /// layer's part pixels and its mean fraction over them (layers of at least 100 pixels).
    pub worst_layer_error: f64,
}

/// A layer's material pixel counts, fraction sums, part pixels and worst share error.
type LayerCounts = (Vec<u64>, Vec<f64>, u64, f64);

/// The stack's geometry: the part's box, the pixel size, pictures' size and their count.
pub struct Plan {
    corner: [f64; 3],
    px: [f64; 2],
    width: usize,
    height: usize,
    layers: usize,
    top: f64,
}

/// Checks `spec` against `fgm` (a colour per material, a stack of sane size) and lays the
/// stack out; nothing is written.
pub fn plan(fgm: &Fgm, spec: &StackSpec) -> Result<Plan> {
    let n = fgm.composition.materials.len();
    if spec.palette.len() != n {
        return Err(Error::invalid(format!(
            "{} palette colours for {n} materials",
            spec.palette.len()
        )));
    }
    let b = fgm
        .mesh
        .bounds()
        .ok_or_else(|| Error::invalid("the part is empty"))?;
    let px = [25.4 / spec.dpi[0], 25.4 / spec.dpi[1]];
    let size = b.size();
    let width = (size[0] / px[0]).ceil().max(1.0) as usize;
    let height = (size[1] / px[1]).ceil().max(1.0) as usize;
    let layers = (size[2] / spec.layer).ceil().max(1.0) as usize;
    let pixels = width as f64 * height as f64;
    if pixels > 4e8 || pixels * layers as f64 > 1e12 {
        return Err(Error::invalid(format!(
            "the stack would be {layers} pictures of {width} × {height} pixels; lower --dpi or thicken --layer"
        )));
    }
    Ok(Plan {
        corner: b.min,
        px,
        width,
        height,
        layers,
        top: b.max[1],
    })
}

/// Writes the stack of `fgm` into the folder `dir` (replaced whole when done).
pub fn write(fgm: &Fgm, dir: &Path, spec: &StackSpec, progress: &Progress) -> Result<StackReport> {
    let n = fgm.composition.materials.len();
    let Plan {
        corner,
        px,
        width,
        height,
        layers,
        top,
    } = plan(fgm, spec)?;
    let out = AtomicDir::create(dir, "stack.json")?;
    let counter = progress.counter(layers as u64, "layers");
    let results: Vec<Result<LayerCounts>> = (0..layers)
        .into_par_iter()
        .map(|l| {
            let z = corner[2] + (l as f64 + 0.5) * spec.layer;
            let r = layer(fgm, spec, [corner[0], top], px, width, height, z);
            let (rgba, counts, sums, inside) = r;
            let path = out.file(&format!("layer_{l:05}.png"));
            crate::io::png::write_rgba(&path, width as u32, height as u32, &rgba)?;
            counter.inc();
            let worst = if inside >= 100 {
                (0..n)
                    .map(|k| (counts[k] as f64 - sums[k]).abs() / inside as f64)
                    .fold(0.0, f64::max)
            } else {
                0.0
            };
            Ok((counts, sums, inside, worst))
        })
        .collect();
    let mut counts = vec![0u64; n];
    let mut part_pixels = 0;
    let mut worst = 0.0f64;
    for r in results {
        let (c, _, inside, w) = r?;
        for k in 0..n {
            counts[k] += c[k];
        }
        part_pixels += inside;
        worst = worst.max(w);
    }
    let report = StackReport {
        folder: dir.display().to_string(),
        layers,
        width,
        height,
        pixel_mm: px,
        layer_mm: spec.layer,
        origin: corner,
        part_pixels,
        shares: counts
            .iter()
            .map(|c| *c as f64 / part_pixels.max(1) as f64)
            .collect(),
        worst_layer_error: worst,
    };
    let manifest = serde_json::json!({
        "materials": fgm.composition.materials,
        "palette": spec.palette.iter().map(|c| format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2])).collect::<Vec<_>>(),
        "stack": &report,
        "note": "layer_00000.png is the bottom layer; image rows run from the part's largest y down; transparent pixels are outside the part",
    });
    crate::io::atomic::write_json(&out.file("stack.json"), &manifest)?;
    out.commit()?;
    Ok(report)
}

/// One layer at height `z`: its RGBA picture, per-material pixel counts and fraction sums, and
/// its part pixels. `corner` is the picture's top-left corner (x min, y max), mm.
fn layer(
    fgm: &Fgm,
    spec: &StackSpec,
    corner: [f64; 2],
    px: [f64; 2],
    width: usize,
    height: usize,
    z: f64,
) -> (Vec<u8>, Vec<u64>, Vec<f64>, u64) {
    let n = fgm.composition.materials.len();
    // Fractions of every part pixel (NaN in the first slot outside the part).
    let mut want = vec![f64::NAN; width * height * n];
    let mut pts = vec![0.0; 3 * width];
    let mut s = vec![0f32; width];
    let mut d = vec![0f32; width];
    let mut f = vec![0.0; n];
    let mut sums = vec![0.0; n];
    let mut inside = 0u64;
    for r in 0..height {
        let y = corner[1] - (r as f64 + 0.5) * px[1];
        for c in 0..width {
            pts[3 * c] = corner[0] + (c as f64 + 0.5) * px[0];
            pts[3 * c + 1] = y;
            pts[3 * c + 2] = z;
        }
        fgm.sdf.probe(&pts, &mut s);
        fgm.distance_grid.probe(&pts, &mut d);
        for c in 0..width {
            if s[c] > 0.0 {
                continue;
            }
            fgm.fractions_at(d[c] as f64, &mut f);
            let at = (r * width + c) * n;
            want[at..at + n].copy_from_slice(&f);
            for k in 0..n {
                sums[k] += f[k];
            }
            inside += 1;
        }
    }
    let is_in = |r: usize, c: usize| !want[(r * width + c) * n].is_nan();
    let mut rgba = vec![0u8; 4 * width * height];
    for p in rgba.chunks_exact_mut(4) {
        p.copy_from_slice(&[255, 255, 255, 0]);
    }
    let mut counts = vec![0u64; n];
    let mut err = want.clone();
    let mut e = vec![0.0; n];
    for r in 0..height {
        let forward = r % 2 == 0;
        for i in 0..width {
            let c = if forward { i } else { width - 1 - i };
            if !is_in(r, c) {
                continue;
            }
            let at = (r * width + c) * n;
            let k = (0..n)
                .max_by(|&a, &b| err[at + a].total_cmp(&err[at + b]))
                .unwrap_or(0);
            counts[k] += 1;
            let col = spec.palette[k];
            rgba[4 * (r * width + c)..4 * (r * width + c) + 4]
                .copy_from_slice(&[col[0], col[1], col[2], 255]);
            for m in 0..n {
                e[m] = err[at + m] - if m == k { 1.0 } else { 0.0 };
            }
            // Floyd–Steinberg neighbours, mirrored on the way back, renormalised over those in
            // the part.
            let dir: i64 = if forward { 1 } else { -1 };
            let targets = [(0i64, dir, 7.0), (1, -dir, 3.0), (1, 0, 5.0), (1, dir, 1.0)];
            let mut total = 0.0;
            let mut ok = [false; 4];
            for (t, &(dr, dc, w)) in targets.iter().enumerate() {
                let (rr, cc) = (r as i64 + dr, c as i64 + dc);
                if rr < height as i64
                    && cc >= 0
                    && cc < width as i64
                    && is_in(rr as usize, cc as usize)
                {
                    ok[t] = true;
                    total += w;
                }
            }
            if total == 0.0 {
                continue;
            }
            for (t, &(dr, dc, w)) in targets.iter().enumerate() {
                if ok[t] {
                    let to = ((r as i64 + dr) as usize * width + (c as i64 + dc) as usize) * n;
                    for m in 0..n {
                        err[to + m] += e[m] * w / total;
                    }
                }
            }
        }
    }
    (rgba, counts, sums, inside)
}
