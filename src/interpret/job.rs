//! The whole `topo` job on one density field: clean (Liu et al. 2018, steps 1–2), mesh (2D:
//! extrude the boundary loops; 3D: OpenVDB), verify with CGAL, and fit the CAD curves (2D,
//! step 3). The CLI and the benchmarks call this; writing files is left to the caller.

use super::clean::{clean, CleanOptions, Cleaned, Pass};
use super::contour::{self, Loop};
use super::{extrude, volume, Density};
use crate::cad::bspline::Periodic;
use crate::cad::fit;
use crate::error::Result;
use crate::geom::Mesh;
use crate::grid::Smoothing;
use crate::mesh::simplify::Simplified;
use crate::progress::Progress;
use crate::verify::cgal::Verification;
use crate::verify::Verdict;
use rayon::prelude::*;
use std::time::Instant;

/// What to do besides cleaning.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct InterpretJob {
    /// The cleanup loop's options.
    pub clean: CleanOptions,
    /// Extrusion of a 2D field, mm.
    pub thickness: f64,
    /// Max deviation of the CAD curves from the boundary points, mm.
    pub tolerance: f64,
    /// 3D: simplify the mesh within this distance of the surface it stands for, mm (`None`:
    /// the uniform mesh, two triangles per voxel the surface crosses).
    pub mesh_tolerance: Option<f64>,
    /// Fit the CAD curves (2D only).
    pub fit_curves: bool,
    /// How the 3D part is verified.
    pub verify: crate::verify::Verify,
    /// 3D: OpenVDB level-set smoothing passes (0: none) and the flow.
    pub smooth_iterations: u32,
    /// The level-set flow used for smoothing.
    pub smoothing: Smoothing,
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

/// Everything `latvox interpret` reports.
#[derive(Debug, Clone, serde::Serialize)]
pub struct InterpretReport {
    /// Elements along x, y, z (z = 0 for a 2D field).
    pub dims: [usize; 3],
    /// Whether the field is 3D.
    pub is_3d: bool,
    /// Element edge length, mm.
    pub element_size: f64,
    /// The options the job ran with.
    pub job: InterpretJob,
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
    /// Set when the 3D mesh was simplified within `--tolerance`.
    pub simplified: Option<Simplified>,
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
pub struct InterpretResult {
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
    pub report: InterpretReport,
}

fn defects(a: &super::features::Analysis, is_3d: bool) -> Defects {
    Defects {
        thin_pixels: a.thin.len(),
        islands: a.islands.len(),
        point_contacts: a.contacts.len(),
        min_radius: (!is_3d && a.min_radius_mm.is_finite()).then_some(a.min_radius_mm),
    }
}

impl InterpretReport {
    /// The part's verdict: CGAL's checks of the mesh, and whether every feature is one the
    /// printer can make (no thin feature, island or point contact left after the last pass).
    pub fn verdict(&self) -> Verdict {
        Verdict {
            features_printable: Some(self.clean),
            ..self.checks.verdict()
        }
    }

    /// Warnings, one sentence each: a part whose volume strays from the thresholded volume.
    pub fn warnings(&self) -> Vec<String> {
        let mut w = Vec::new();
        if self.measure_change.abs() > 0.01 {
            w.push(format!(
                "the part's volume differs from the thresholded volume by {:+.1} % \
                 (heavy smoothing erases thin members; try fewer --smooth passes)",
                100.0 * self.measure_change
            ));
        }
        w
    }
}

/// Runs the job on `d`.
pub fn run(d: &Density, job: &InterpretJob, progress: &Progress) -> Result<InterpretResult> {
    let t0 = Instant::now();
    let mut timings = Timings::default();
    let mut cleaned = {
        let _s = progress.stage("cleaning the density field");
        clean(d, &job.clean)?
    };
    timings.clean = t0.elapsed().as_secs_f64();

    let t = Instant::now();
    let (mesh, loops) = {
        let _s = progress.stage("meshing");
        mesh_solid(d, job, &mut cleaned)?
    };
    let (mesh, simplified) = match job.mesh_tolerance {
        // Set for 3D fields only.
        Some(tolerance) => {
            let _s = progress.stage("simplifying");
            let (m, s) = if job.smooth_iterations > 0 {
                // The smoothed surface exists only as its grid: held to its uniform mesh.
                crate::repair::simplify_to_mesh(&mesh, &mesh, cleaned.field.h, tolerance)
            } else {
                volume::simplified(&cleaned.field, cleaned.level, &mesh, tolerance)
            };
            (m, Some(s))
        }
        None => (mesh, None),
    };
    timings.mesh = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let checks = {
        let _s = progress.stage("verifying");
        crate::verify::verify(&mesh, job.verify, progress)?
    };
    timings.verify = t.elapsed().as_secs_f64();

    let t = Instant::now();
    let fits = if job.fit_curves && !d.is_3d {
        let _s = progress.stage("fitting B-spline curves");
        fit_loops(&loops, job.tolerance)
    } else {
        Fits::default()
    };
    timings.fit = t.elapsed().as_secs_f64();
    timings.total = t0.elapsed().as_secs_f64();
    let report = InterpretReport {
        timings,
        simplified,
        ..report(d, job, &cleaned, &mesh, &loops, checks, fits.loops)
    };
    Ok(InterpretResult {
        cleaned,
        mesh,
        loops,
        uniform: fits.uniform,
        adaptive: fits.adaptive,
        report,
    })
}

/// Solid volume (3D, mm³) or area (2D, mm²) of `pixels` pixels of the cleaned grid.
fn pixel_measure(d: &Density, cleaned: &Cleaned, pixels: usize) -> f64 {
    let h = cleaned.field.h;
    pixels as f64 * if d.is_3d { h * h * h } else { h * h }
}

/// The cleaned solid as a closed mesh, with its boundary loops in 2D: in 2D the outline
/// extruded; in 3D OpenVDB's surface, moved to keep the thresholded volume (by its level, or
/// after smoothing by an offset).
fn mesh_solid(d: &Density, job: &InterpretJob, cleaned: &mut Cleaned) -> Result<(Mesh, Vec<Loop>)> {
    let goal = pixel_measure(d, cleaned, cleaned.target_pixels);
    let h = cleaned.field.h;
    if d.is_3d && job.smooth_iterations > 0 {
        // Smooth once, then offset the smoothed surface until it keeps the volume.
        let s = volume::Smoothed::new(
            &cleaned.field,
            cleaned.level,
            job.smoothing,
            job.smooth_iterations,
        )?;
        let (_, mesh) = mesh_at_volume(
            |t| s.mesh(t),
            |volume| super::clean::secant_in(volume, 0.0, goal, [-3.0 * h, 3.0 * h], 0.1 * h),
        )?;
        Ok((mesh, Vec::new()))
    } else if d.is_3d {
        // The iso-surface encloses less than the voxels it was thresholded from (thin
        // members most): move the level until the mesh keeps the thresholded volume.
        let (level, mesh) = mesh_at_volume(
            |t| volume::mesh(&cleaned.field, t),
            |volume| super::clean::secant(volume, cleaned.level, goal),
        )?;
        cleaned.level = level;
        Ok((mesh, Vec::new()))
    } else {
        let loops = contour::loops(&cleaned.field, cleaned.level);
        Ok((extrude::extrude(&loops, job.thickness)?, loops))
    }
}

/// The mesh at the parameter `search` settles on, given the volume of the mesh at a parameter
/// (NaN where meshing fails); the meshes tried are kept, so the one found is not made twice.
fn mesh_at_volume(
    mesh_at: impl Fn(f64) -> Result<Mesh>,
    search: impl FnOnce(&mut dyn FnMut(f64) -> f64) -> f64,
) -> Result<(f64, Mesh)> {
    let mut meshed = Vec::new();
    let found = search(&mut |t| match mesh_at(t) {
        Ok(m) => {
            let v = m.volume();
            meshed.push((t, m));
            v
        }
        Err(_) => f64::NAN,
    });
    let mesh = match meshed.into_iter().find(|(t, _)| *t == found) {
        Some((_, m)) => m,
        None => mesh_at(found)?,
    };
    Ok((found, mesh))
}

/// The B-spline fits of the boundary loops.
#[derive(Default)]
struct Fits {
    uniform: Vec<Periodic>,
    adaptive: Vec<Periodic>,
    loops: Vec<LoopFit>,
}

/// Uniform and adaptive closed B-spline fits of every loop within `tolerance` mm (step 3).
fn fit_loops(loops: &[Loop], tolerance: f64) -> Fits {
    let results: Vec<(fit::Fitted, fit::Fitted)> = loops
        .par_iter()
        .map(|l| {
            let u = fit::uniform(l, tolerance);
            let a = fit::adaptive(l, tolerance, &u);
            (u, a)
        })
        .collect();
    let mut fits = Fits::default();
    for (l, (u, a)) in loops.iter().zip(results) {
        fits.loops.push(LoopFit {
            points: l.len(),
            outer: contour::signed_area(l) > 0.0,
            uniform_control_points: u.curve.len(),
            uniform_max_deviation: u.max_deviation,
            adaptive_control_points: a.curve.len(),
            adaptive_max_deviation: a.max_deviation,
        });
        fits.uniform.push(u.curve);
        fits.adaptive.push(a.curve);
    }
    fits
}

/// The job's report (timings left at zero, for the caller to fill in).
fn report(
    d: &Density,
    job: &InterpretJob,
    cleaned: &Cleaned,
    mesh: &Mesh,
    loops: &[Loop],
    checks: Verification,
    fits: Vec<LoopFit>,
) -> InterpretReport {
    let thresholded_measure = pixel_measure(d, cleaned, cleaned.target_pixels);
    let final_measure = if d.is_3d {
        checks.volume.unwrap_or(f64::NAN)
    } else {
        loops.iter().map(|l| contour::signed_area(l)).sum()
    };
    let (uc, ac): (usize, usize) = (
        fits.iter().map(|f| f.uniform_control_points).sum(),
        fits.iter().map(|f| f.adaptive_control_points).sum(),
    );
    InterpretReport {
        dims: [d.nx, d.ny, if d.is_3d { d.nz } else { 0 }],
        is_3d: d.is_3d,
        element_size: d.element_size,
        job: *job,
        pixel_size: cleaned.field.h,
        refined_dims: cleaned.field.n,
        initial: defects(&cleaned.initial, d.is_3d),
        remaining: defects(&cleaned.last, d.is_3d),
        clean: cleaned.is_clean(),
        iterations: cleaned.passes.len(),
        passes: cleaned.passes.clone(),
        level: cleaned.level,
        thresholded_measure,
        final_pixel_measure: pixel_measure(d, cleaned, cleaned.last.solid),
        final_measure,
        measure_change: final_measure / thresholded_measure - 1.0,
        triangles: mesh.triangle_count(),
        vertices: mesh.vertex_count(),
        mesh_volume: checks.volume,
        simplified: None,
        checks,
        loops: fits,
        uniform_control_points: uc,
        adaptive_control_points: ac,
        control_point_ratio: (uc > 0).then(|| ac as f64 / uc as f64),
        timings: Timings::default(),
    }
}
