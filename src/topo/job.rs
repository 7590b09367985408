//! The whole `topo` job on one density field: clean (seed 003 steps 1–2), mesh (2D: extrude the
//! boundary loops; 3D: OpenVDB), verify with CGAL, and fit the CAD curves (2D, step 3). The CLI
//! and the benchmarks call this; writing files is left to the caller.

use super::clean::{clean, CleanOptions, Cleaned, Pass};
use super::contour::{self, Loop};
use super::{extrude, volume, Density};
use crate::cad::bspline::Periodic;
use crate::cad::fit;
use crate::error::Result;
use crate::grid::Smoothing;
use crate::mesh::Mesh;
use crate::progress::Progress;
use crate::verify::{verify, Verification};
use rayon::prelude::*;
use std::time::Instant;

/// What to do besides cleaning.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct TopoJob {
    pub clean: CleanOptions,
    /// Extrusion of a 2D field, mm.
    pub thickness: f64,
    /// Max deviation of the CAD curves from the boundary points, mm.
    pub tolerance: f64,
    /// Fit the CAD curves (2D only).
    pub fit_curves: bool,
    pub self_intersection: bool,
    /// 3D: OpenVDB level-set smoothing passes (0: none) and the flow.
    pub smooth_iterations: u32,
    pub smoothing: Smoothing,
}

/// One boundary loop's fits.
#[derive(Debug, Clone, serde::Serialize)]
pub struct LoopFit {
    pub points: usize,
    /// Counter-clockwise outer boundary (false: a hole).
    pub outer: bool,
    pub uniform_control_points: usize,
    pub uniform_max_deviation: f64,
    pub adaptive_control_points: usize,
    pub adaptive_max_deviation: f64,
}

#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct Timings {
    pub clean: f64,
    pub mesh: f64,
    pub verify: f64,
    pub fit: f64,
    pub total: f64,
}

/// Defect counts of one analysed mask.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Defects {
    pub thin_pixels: usize,
    pub islands: usize,
    pub point_contacts: usize,
    /// Smallest inscribed radius on the 2D skeleton, mm (`null` in 3D).
    pub min_radius: Option<f64>,
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct TopoReport {
    pub dims: [usize; 3],
    pub is_3d: bool,
    pub element_size: f64,
    pub job: TopoJob,
    pub pixel_size: f64,
    pub refined_dims: [usize; 3],
    /// Defects of the thresholded field (before the loop).
    pub initial: Defects,
    /// Defects left after the loop: all zero when `clean`.
    pub remaining: Defects,
    pub clean: bool,
    pub iterations: usize,
    pub passes: Vec<Pass>,
    pub level: f64,
    /// Solid volume (3D, mm³) or area (2D, mm²) of the thresholded field, the final pixels and
    /// the final outline (2D: the loops' area; 3D: the mesh's volume as CGAL measures it).
    pub thresholded_measure: f64,
    pub final_pixel_measure: f64,
    pub final_measure: f64,
    /// `final_measure / thresholded_measure − 1`.
    pub measure_change: f64,
    pub triangles: usize,
    pub vertices: usize,
    pub checks: Verification,
    pub mesh_volume: Option<f64>,
    pub loops: Vec<LoopFit>,
    pub uniform_control_points: usize,
    pub adaptive_control_points: usize,
    /// `adaptive / uniform` control points over all loops.
    pub control_point_ratio: Option<f64>,
    pub timings: Timings,
}

/// Results of [`run`].
pub struct TopoResult {
    pub cleaned: Cleaned,
    pub mesh: Mesh,
    pub loops: Vec<Loop>,
    pub uniform: Vec<Periodic>,
    pub adaptive: Vec<Periodic>,
    pub report: TopoReport,
}

fn defects(a: &super::features::Analysis, is_3d: bool) -> Defects {
    Defects {
        thin_pixels: a.thin.len(),
        islands: a.islands.len(),
        point_contacts: a.contacts.len(),
        min_radius: (!is_3d && a.min_radius_mm.is_finite()).then_some(a.min_radius_mm),
    }
}

/// Runs the job on `d`.
pub fn run(d: &Density, job: &TopoJob, progress: &Progress) -> Result<TopoResult> {
    let t0 = Instant::now();
    let mut timings = Timings::default();
    let mut cleaned = {
        let _s = progress.stage("cleaning the density field");
        clean(d, &job.clean)?
    };
    timings.clean = t0.elapsed().as_secs_f64();
    let h = cleaned.field.h;
    let cell = if d.is_3d { h * h * h } else { h * h };
    let thresholded_measure = cleaned.target_pixels as f64 * cell;
    let final_pixel_measure = cleaned.last.solid as f64 * cell;

    let t = Instant::now();
    let (mesh, loops) = {
        let _s = progress.stage("meshing");
        if d.is_3d && job.smooth_iterations > 0 {
            // Smooth once, then offset the smoothed surface until it keeps the volume.
            let s = volume::Smoothed::new(
                &cleaned.field,
                cleaned.level,
                job.smoothing,
                job.smooth_iterations,
            )?;
            let mut meshed = Vec::new();
            let offset = super::clean::secant_in(
                |t| match s.mesh(t) {
                    Ok(m) => {
                        let v = m.volume();
                        meshed.push((t, m));
                        v
                    }
                    Err(_) => f64::NAN,
                },
                0.0,
                thresholded_measure,
                [-3.0 * h, 3.0 * h],
                0.1 * h,
            );
            let mesh = match meshed.into_iter().find(|(t, _)| *t == offset) {
                Some((_, m)) => m,
                None => s.mesh(offset)?,
            };
            (mesh, Vec::new())
        } else if d.is_3d {
            // The iso-surface encloses less than the voxels it was thresholded from (thin
            // members most): move the level until the mesh keeps the thresholded volume.
            let mut meshed = Vec::new();
            let level = super::clean::secant(
                |t| match volume::mesh(&cleaned.field, t) {
                    Ok(m) => {
                        let v = m.volume();
                        meshed.push((t, m));
                        v
                    }
                    Err(_) => f64::NAN,
                },
                cleaned.level,
                thresholded_measure,
            );
            let mesh = match meshed.into_iter().find(|(t, _)| *t == level) {
                Some((_, m)) => m,
                None => volume::mesh(&cleaned.field, level)?,
            };
            cleaned.level = level;
            (mesh, Vec::new())
        } else {
            let loops = contour::loops(&cleaned.field, cleaned.level);
            (extrude::extrude(&loops, job.thickness)?, loops)
        }
    };
    timings.mesh = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let checks = {
        let _s = progress.stage("verifying with CGAL");
        verify(&mesh, job.self_intersection)?
    };
    timings.verify = t.elapsed().as_secs_f64();
    let final_measure = if d.is_3d {
        checks.volume.unwrap_or(f64::NAN)
    } else {
        loops.iter().map(contour::signed_area).sum()
    };

    let t = Instant::now();
    let (mut uniform, mut adaptive, mut fits) = (Vec::new(), Vec::new(), Vec::new());
    if job.fit_curves && !d.is_3d {
        let _s = progress.stage("fitting B-spline curves");
        let results: Vec<(fit::Fitted, fit::Fitted)> = loops
            .par_iter()
            .map(|l| {
                let u = fit::uniform(l, job.tolerance);
                let a = fit::adaptive(l, job.tolerance, &u);
                (u, a)
            })
            .collect();
        for (l, (u, a)) in loops.iter().zip(results) {
            fits.push(LoopFit {
                points: l.len(),
                outer: contour::signed_area(l) > 0.0,
                uniform_control_points: u.curve.len(),
                uniform_max_deviation: u.max_deviation,
                adaptive_control_points: a.curve.len(),
                adaptive_max_deviation: a.max_deviation,
            });
            uniform.push(u.curve);
            adaptive.push(a.curve);
        }
    }
    timings.fit = t.elapsed().as_secs_f64();
    timings.total = t0.elapsed().as_secs_f64();
    let (uc, ac): (usize, usize) = (
        fits.iter().map(|f| f.uniform_control_points).sum(),
        fits.iter().map(|f| f.adaptive_control_points).sum(),
    );
    let report = TopoReport {
        dims: [d.nx, d.ny, if d.is_3d { d.nz } else { 0 }],
        is_3d: d.is_3d,
        element_size: d.element_size,
        job: *job,
        pixel_size: h,
        refined_dims: cleaned.field.n,
        initial: defects(&cleaned.initial, d.is_3d),
        remaining: defects(&cleaned.last, d.is_3d),
        clean: cleaned.is_clean(),
        iterations: cleaned.passes.len(),
        passes: cleaned.passes.clone(),
        level: cleaned.level,
        thresholded_measure,
        final_pixel_measure,
        final_measure,
        measure_change: final_measure / thresholded_measure - 1.0,
        triangles: mesh.triangle_count(),
        vertices: mesh.vertex_count(),
        mesh_volume: checks.volume,
        checks,
        loops: fits,
        uniform_control_points: uc,
        adaptive_control_points: ac,
        control_point_ratio: (uc > 0).then(|| ac as f64 / uc as f64),
        timings,
    };
    Ok(TopoResult {
        cleaned,
        mesh,
        loops,
        uniform,
        adaptive,
        report,
    })
}
