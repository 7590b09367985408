//! FGM in the plane: a measured contour (a cam's profile from a CMM, a section's points) → a
//! signed distance image → material fractions graded by the distance to features in the plane →
//! the part's outline (the zero iso-line).
//!
//! The field is the scan's own ([`super::geometry::ScanSdf`]) with the cloud in the plane
//! ([`Cloud::in_plane`]): the moving-least-squares distance near the points, the winding number
//! (angles summed over 2π) or the line scans away from them. It is sampled at the nodes
//! `(x₀ + i·h, y₀ + j·h)` of a square grid, as the implicit FGM literature computes the signed
//! distance at the vertices of a uniformly subdivided box (its example: a cam's profile in a
//! 20 × 20 grid). The outline is the zero iso-line by marching squares
//! ([`crate::geom::contour::iso_loops`]).

use super::cloud::Cloud;
use super::geometry::ScanSdf;
use super::job::{choose_dmax, mix, FgmJob, Geometry, GeometryReport};
use super::material::Composition;
use crate::error::{Error, Result};
use crate::field::{Aabb, Field};
use crate::geom::contour::{iso_loops, signed_area, Loop};
use crate::grid::GridSpec;
use crate::mesh::pipeline::HALF_WIDTH;
use crate::progress::Progress;
use rayon::prelude::*;
use std::io::Write;
use std::path::Path;
use std::time::Instant;

/// Refused above this many nodes (a micrometre grid over a metre part).
const MAX_NODES: f64 = 4e8;

/// A plane FGM part: its signed distance image, the distance to the features, its outline.
pub struct PlaneFgm {
    /// The node `(0, 0)`, mm.
    pub origin: [f64; 2],
    /// Node spacing, mm.
    pub voxel: f64,
    /// Nodes along x and y.
    pub size: [usize; 2],
    /// Signed distance at every node (negative inside), row by row from `j = 0`, mm.
    pub sdf: Vec<f64>,
    /// Distance to the features at every node inside the part; NaN outside.
    pub distance: Vec<f64>,
    /// The distance at which a power law reaches 1, mm.
    pub dmax: f64,
    /// The materials.
    pub composition: Composition,
    /// The outline: closed loops, mm, the part on their left.
    pub loops: Vec<Loop>,
    /// The contour's points (to draw over the preview).
    pub points: Vec<[f64; 2]>,
    /// The geometry stage's report.
    pub geometry: GeometryReport,
    /// Seconds per stage.
    pub timings: Vec<(&'static str, f64)>,
}

impl FgmJob {
    /// Runs a job whose geometry is a plane contour.
    pub fn run_plane(&self, progress: &Progress) -> Result<PlaneFgm> {
        let Geometry::Contour(pc) = &self.geometry else {
            return Err(Error::invalid(
                "a plane job needs a contour (--2d --points)",
            ));
        };
        let h = self.voxel;
        if !(h > 0.0 && h.is_finite()) {
            return Err(Error::invalid("--voxel must be a positive length in mm"));
        }
        let mut timings = Vec::new();
        let t = Instant::now();
        let stage = progress.stage("signed distance image");
        let cloud = Cloud::in_plane(pc.clone())?;
        let b = cloud.bounds();
        let pad = 2.0 * h + 3.0 * cloud.median_spacing;
        let origin = [b.min[0] - pad, b.min[1] - pad];
        let size = [0, 1].map(|a| ((b.max[a] + pad - origin[a]) / h).ceil() as usize + 1);
        let nodes = size[0] as f64 * size[1] as f64;
        if nodes > MAX_NODES {
            return Err(Error::invalid(format!(
                "--voxel {h} mm on a contour of {:.1} × {:.1} mm makes {nodes:.1e} nodes; choose a coarser voxel",
                b.max[0] - b.min[0],
                b.max[1] - b.min[1]
            )));
        }
        let bounds = Aabb {
            min: [origin[0], origin[1], -h],
            max: [
                origin[0] + size[0] as f64 * h,
                origin[1] + size[1] as f64 * h,
                h,
            ],
        };
        let field = ScanSdf::new(
            &cloud,
            GridSpec::covering(&bounds, h, HALF_WIDTH),
            self.sign,
        );
        let at = |k: usize| {
            let (i, j) = (k % size[0], k / size[0]);
            [origin[0] + i as f64 * h, origin[1] + j as f64 * h, 0.0]
        };
        let sdf: Vec<f64> = (0..size[0] * size[1])
            .into_par_iter()
            .map(|k| field.value(at(k)))
            .collect();
        let loops: Vec<Loop> = iso_loops(size, |i, j| -sdf[j * size[0] + i], 0.0, -1.0)
            .into_iter()
            .map(|l| {
                l.iter()
                    .map(|p| [origin[0] + p[0] * h, origin[1] + p[1] * h])
                    .collect()
            })
            .collect();
        if !sdf.iter().any(|s| *s <= 0.0) || loops.is_empty() {
            return Err(Error::invalid(
                "the contour encloses nothing at this voxel size (a finer --voxel, or a closed contour)",
            ));
        }
        let geometry = GeometryReport {
            source: "contour",
            points: Some(cloud.points.len()),
            point_spacing: Some(cloud.median_spacing),
            normals_estimated: Some(cloud.normals_estimated),
            normals_flipped: Some(cloud.normals_flipped),
            sign: Some(self.sign),
            voxel: h,
            band_voxels: sdf.len() as u64,
            grid_bytes: 8 * sdf.len() as u64,
        };
        drop(stage);
        timings.push(("signed distance", t.elapsed().as_secs_f64()));

        let t = Instant::now();
        let stage = progress.stage("material distance");
        // The distance to the part's own outline is the field's magnitude inside it.
        let distance: Vec<f64> = (0..sdf.len())
            .into_par_iter()
            .map(|k| match sdf[k] <= 0.0 {
                true => self.features.distance(at(k), -sdf[k]),
                false => f64::NAN,
            })
            .collect();
        let largest = distance
            .iter()
            .filter(|d| !d.is_nan())
            .fold(0.0, |a, b| b.max(a));
        let dmax = choose_dmax(self.dmax, largest)?;
        self.composition.check(dmax)?;
        drop(stage);
        timings.push(("material distance", t.elapsed().as_secs_f64()));
        Ok(PlaneFgm {
            origin,
            voxel: h,
            size,
            sdf,
            distance,
            dmax,
            composition: self.composition.clone(),
            loops,
            points: cloud.points.iter().map(|p| [p[0], p[1]]).collect(),
            geometry,
            timings,
        })
    }
}

impl PlaneFgm {
    /// The part's area: the outline's, mm².
    pub fn area(&self) -> f64 {
        self.loops.iter().map(|l| signed_area(l)).sum()
    }

    /// The area share of each material in the part (nodes inside, equally weighted).
    pub fn shares(&self) -> Vec<f64> {
        let n = self.composition.materials.len();
        let (mut sum, mut f, mut count) = (vec![0.0; n], vec![0.0; n], 0usize);
        for d in self.distance.iter().filter(|d| !d.is_nan()) {
            self.composition.fractions(*d, self.dmax, &mut f);
            for k in 0..n {
                sum[k] += f[k];
            }
            count += 1;
        }
        sum.iter().map(|s| s / count.max(1) as f64).collect()
    }

    /// Bilinear interpolation of node values at `(x, y)` (NaN beyond the grid or where a
    /// corner is NaN).
    pub fn interpolate(&self, values: &[f64], x: f64, y: f64) -> f64 {
        let u = (x - self.origin[0]) / self.voxel;
        let v = (y - self.origin[1]) / self.voxel;
        let (nx, ny) = (self.size[0], self.size[1]);
        if !(u >= 0.0 && v >= 0.0 && u <= (nx - 1) as f64 && v <= (ny - 1) as f64) {
            return f64::NAN;
        }
        let i = (u.floor() as usize).min(nx.saturating_sub(2));
        let j = (v.floor() as usize).min(ny.saturating_sub(2));
        let (fu, fv) = (u - i as f64, v - j as f64);
        let at = |a: usize, b: usize| values[(j + b).min(ny - 1) * nx + (i + a).min(nx - 1)];
        (1.0 - fv) * ((1.0 - fu) * at(0, 0) + fu * at(1, 0))
            + fv * ((1.0 - fu) * at(0, 1) + fu * at(1, 1))
    }

    /// The signed distance image as CSV: one line per row of nodes from `j = 0` (the lowest y),
    /// comma-separated, after `#` lines giving the grid (NumPy's `loadtxt(delimiter=',')` reads
    /// it as it is).
    pub fn write_csv(&self, w: &mut dyn Write) -> std::io::Result<()> {
        writeln!(
            w,
            "# signed distance, mm (negative inside), at x = x0 + i*h, y = y0 + j*h"
        )?;
        writeln!(w, "# row j, column i; j = 0 first (lowest y)")?;
        writeln!(
            w,
            "# x0 = {}, y0 = {}, h = {}, columns = {}, rows = {}",
            self.origin[0], self.origin[1], self.voxel, self.size[0], self.size[1]
        )?;
        for row in self.sdf.chunks(self.size[0]) {
            let line: Vec<String> = row.iter().map(|v| format!("{v:.6}")).collect();
            writeln!(w, "{}", line.join(","))?;
        }
        Ok(())
    }

    /// The outline as SVG: one closed path per loop (y up, as in the plane; millimetres).
    pub fn write_svg(&self, w: &mut dyn Write) -> std::io::Result<()> {
        let (x0, y0) = (self.origin[0], self.origin[1]);
        let (wmm, hmm) = (
            (self.size[0] - 1) as f64 * self.voxel,
            (self.size[1] - 1) as f64 * self.voxel,
        );
        writeln!(
            w,
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{wmm}mm\" height=\"{hmm}mm\" viewBox=\"{x0} {} {wmm} {hmm}\">",
            -(y0 + hmm)
        )?;
        let mut d = String::new();
        for l in &self.loops {
            for (k, p) in l.iter().enumerate() {
                let c = if k == 0 { 'M' } else { 'L' };
                d.push_str(&format!("{c}{:.5} {:.5} ", p[0], -p[1]));
            }
            d.push_str("Z ");
        }
        writeln!(
            w,
            "<path d=\"{}\" fill=\"#c8c8c8\" fill-rule=\"evenodd\" stroke=\"black\" stroke-width=\"{}\"/>",
            d.trim_end(),
            0.5 * self.voxel
        )?;
        writeln!(w, "</svg>")
    }

    /// A picture: every pixel of the part coloured by its composition, the outline in black,
    /// the contour's points in red, and the legend.
    pub fn write_preview(&self, path: &Path, palette: &[[u8; 3]]) -> Result<()> {
        let span = [0, 1].map(|a| (self.size[a] - 1) as f64 * self.voxel);
        let scale = super::preview::SIDE / span[0].max(span[1]).max(1e-9);
        let (pw, ph) = (
            (span[0] * scale).ceil() as usize,
            (span[1] * scale).ceil() as usize,
        );
        let m = super::preview::MARGIN;
        let mut c = super::preview::canvas(pw, ph, self.composition.materials.len());
        let n = self.composition.materials.len();
        let mut f = vec![0.0; n];
        let to_mm = |col: usize, r: usize| {
            (
                self.origin[0] + (col as f64 + 0.5) / scale,
                self.origin[1] + span[1] - (r as f64 + 0.5) / scale,
            )
        };
        for r in 0..ph {
            for col in 0..pw {
                let (x, y) = to_mm(col, r);
                if self.interpolate(&self.sdf, x, y) <= 0.0 {
                    let d = self.interpolate(&self.distance, x, y);
                    let d = if d.is_nan() { 0.0 } else { d };
                    self.composition.fractions(d, self.dmax, &mut f);
                    c.put((m + col) as i64, (m + r) as i64, mix(&f, palette));
                }
            }
        }
        let px = |p: [f64; 2]| {
            (
                m as f64 + (p[0] - self.origin[0]) * scale,
                m as f64 + (self.origin[1] + span[1] - p[1]) * scale,
            )
        };
        for l in &self.loops {
            for k in 0..l.len() {
                c.line(px(l[k]), px(l[(k + 1) % l.len()]), [0; 3]);
            }
        }
        for p in &self.points {
            let (x, y) = px(*p);
            c.rect(x as i64 - 1, y as i64 - 1, 3, 3, [200, 30, 30]);
        }
        let title = format!("contour, h = {} mm", super::preview::short(self.voxel));
        super::preview::legend(&mut c, ph, &title, &self.composition, self.dmax, palette);
        c.write_png(path)
    }
}
