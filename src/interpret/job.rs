//! The whole `topo` job on one density field: clean (Liu et al. 2018, steps 1–2), mesh (2D:
//! extrude the boundary loops; 3D: OpenVDB), verify with CGAL, and fit the CAD curves (2D,
//! step 3). The CLI and the benchmarks call this; writing files is left to the caller.

use super::clean::{clean, CleanOptions, Cleaned, Pass};
use super::contour::{self, Loop};
use super::{extrude, volume, Density};
use crate::cad::bspline::Periodic;
use crate::cad::fit;
use crate::check::cgal::{verify, Verification};
use crate::error::Result;
use crate::mesh::Mesh;
use crate::progress::Progress;
use rayon::prelude::*;
use std::time::Instant;

/// What to do besides cleaning.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct TopoJob {
    /// The cleanup loop's options.
    pub clean: CleanOptions,
    /// Extrusion of a 2D field, mm.
    pub thickness: f64,
    /// Max deviation of the CAD curves from the boundary points, mm.
    pub tolerance: f64,
    /// Fit the CAD curves (2D only).
    pub fit_curves: bool,
    /// Run CGAL's self-intersection test (the costliest check).
    pub self_intersection: bool,
    /// 3D: OpenVDB level-set smoothing passes (0: none) and the flow.
    pub smooth_iterations: u32,
    /// The level-set flow used for smoothing.
    pub smoothing: volume::Smoothing,
}

/// One boundary loop's fits.
#[derive(Debug, Clone, serde::Serialize)]
pub struct LoopFit {
    /// Boundary points of the loop.
    pub points: usize,
    /// Counter-clockwise outer boundary (false: a hole).
    pub outer: bool,
    /// Control points of the uniform fit.
    pub uniform_control_points: usize,
    /// Its largest distance from a boundary point, mm.
    pub uniform_max_deviation: f64,
    /// Control points of the adaptive fit.
    pub adaptive_control_points: usize,
    /// Its largest distance from a boundary point, mm.
    pub adaptive_max_deviation: f64,
}

/// Wall time of each stage, seconds.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct Timings {
    /// The cleanup loop.
    pub clean: f64,
    /// Meshing (extrusion in 2D, OpenVDB in 3D).
    pub mesh: f64,
    /// CGAL's checks.
    pub verify: f64,
    /// Curve fitting.
    pub fit: f64,
    /// The whole job.
    pub total: f64,
}

/// Defect counts of one analysed mask.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Defects {
    /// Thin-feature pixels (voxels in 3D).
    pub thin_pixels: usize,
    /// Islands: solid parts not face-connected to the main body.
    pub islands: usize,
    /// Point contacts: solids touching only at a corner (or an edge, in 3D).
    pub point_contacts: usize,
    /// Smallest inscribed radius on the 2D skeleton, mm (`null` in 3D).
    pub min_radius: Option<f64>,
}

/// Everything `latvox topo` reports.
#[derive(Debug, Clone, serde::Serialize)]
pub struct TopoReport {
    /// Elements along x, y, z (z = 0 for a 2D field).
    pub dims: [usize; 3],
    /// Whether the field is 3D.
    pub is_3d: bool,
    /// Element edge length, mm.
    pub element_size: f64,
    /// The options the job ran with.
    pub job: TopoJob,
    /// Pixel (voxel) edge length of the refined grid, mm.
    pub pixel_size: f64,
    /// Pixels (voxels) of the refined grid along x, y, z.
    pub refined_dims: [usize; 3],
    /// Defects of the thresholded field (before the loop).
    pub initial: Defects,
    /// Defects left after the loop: all zero when `clean`.
    pub remaining: Defects,
    /// No defect left after the loop.
    pub clean: bool,
    /// Passes the loop took.
    pub iterations: usize,
    /// Counts after each pass.
    pub passes: Vec<Pass>,
    /// Level of the final solid (3D: the level meshed, moved to keep the volume).
    pub level: f64,
    /// Solid volume (3D, mm³) or area (2D, mm²) of the thresholded field: what the loop keeps.
    pub thresholded_measure: f64,
    /// The same measure of the final pixels.
    pub final_pixel_measure: f64,
    /// The same measure of the final outline (2D: the loops' area; 3D: the mesh's volume as
    /// CGAL measures it).
    pub final_measure: f64,
    /// `final_measure / thresholded_measure − 1`.
    pub measure_change: f64,
    /// Triangles of the mesh.
    pub triangles: usize,
    /// Vertices of the mesh.
    pub vertices: usize,
    /// CGAL's checks of the mesh.
    pub checks: Verification,
    /// The mesh's volume as CGAL measures it, mm³ (`null` when it is not closed).
    pub mesh_volume: Option<f64>,
    /// Each boundary loop's fits (2D with curve fitting).
    pub loops: Vec<LoopFit>,
    /// Control points of the uniform fits, all loops.
    pub uniform_control_points: usize,
    /// Control points of the adaptive fits, all loops.
    pub adaptive_control_points: usize,
    /// `adaptive / uniform` control points over all loops.
    pub control_point_ratio: Option<f64>,
    /// Wall time of each stage.
    pub timings: Timings,
}

/// Results of [`run`].
pub struct TopoResult {
    /// The cleanup loop's results.
    pub cleaned: Cleaned,
    /// The closed mesh (extruded in 2D, OpenVDB's in 3D).
    pub mesh: Mesh,
    /// Boundary loops of the final solid, mm (2D; empty in 3D).
    pub loops: Vec<Loop>,
    /// Uniform fit of each loop.
    pub uniform: Vec<Periodic>,
    /// Adaptive fit of each loop (written to IGES and DXF).
    pub adaptive: Vec<Periodic>,
    /// The report.
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
