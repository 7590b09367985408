//! One TPMS job, start to finish: check the request, calibrate, mesh, verify, and report.

use super::calibrate::{self, Calibration, Connectivity, FeasibleRange};
use super::instance::{self, Template};
use super::{Domain, Lattice, MeshingStats, Structure, Surface};
use crate::error::{Error, Result};
use crate::field::Aabb;
use crate::mesh::Mesh;
use crate::progress::Progress;
use crate::sink::{Measures, MeshCollector, MeshSink, Triangle};
use crate::verify::{verify, verify_on, Verification};
use std::time::Instant;

/// Sheet walls thinner than this many voxels are not represented faithfully by a narrow band
/// (samples miss the wall and it perforates); the resolution is raised to keep them this thick.
pub const MIN_WALL_VOXELS: f64 = 1.25;

/// What to build.
#[derive(Debug, Clone)]
pub struct TpmsJob {
    pub surface: Surface,
    pub structure: Structure,
    /// Target volume fraction, in (0, 1).
    pub density: f64,
    pub domain: Domain,
    /// Voxels per cell along the cell's shortest axis.
    pub resolution: u32,
    /// OpenVDB volumeToMesh adaptivity, 0 (uniform) to 1.
    pub adaptivity: f64,
    /// Build even if the solid falls apart into islands at this density.
    pub allow_islands: bool,
    /// Raise the resolution when sheet walls would be thinner than [`MIN_WALL_VOXELS`].
    pub auto_resolution: bool,
    /// Run CGAL's self-intersection test (the costliest check).
    pub self_intersection: bool,
    /// Copy a periodic part's cells from a meshed template where possible ([`instance`]);
    /// otherwise the whole part is meshed at once.
    pub instancing: bool,
}

/// Timings per stage, seconds.
#[derive(Debug, Clone, Copy, Default, serde::Serialize)]
pub struct Timings {
    pub calibrate: f64,
    pub sample: f64,
    pub mesh: f64,
    pub snap: f64,
    pub verify: f64,
    pub write: f64,
    pub total: f64,
}

/// How the part was meshed when it was copied from a template (see [`instance`]).
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Instancing {
    /// Cells of the part per axis that the template stands for (1 along axes not copied).
    pub part_cells: [i64; 3],
    /// Cells of the template per axis.
    pub template_cells: [i64; 3],
    pub template_triangles: u64,
    /// CGAL's checks ran on the template, which holds every kind of cell the part has; the
    /// part is written as exact copies of its cells.
    pub verified: &'static str,
}

/// The JSON report of a TPMS job.
#[derive(Debug, Clone, serde::Serialize)]
pub struct TpmsReport {
    #[serde(rename = "type")]
    pub surface: Surface,
    pub structure: Structure,
    pub level: f64,
    pub target_density: f64,
    /// Volume fraction of the written mesh: its enclosed volume (divergence theorem over the
    /// triangles exactly as written) over the box volume.
    pub achieved_density: f64,
    pub density_error: f64,
    pub calibration: Calibration,
    pub feasible_range: FeasibleRange,
    pub connectivity: Connectivity,
    pub resolution_requested: u32,
    pub resolution: u32,
    pub voxel_size: f64,
    /// Thinnest sheet wall, voxels (sheets only).
    pub thinnest_wall_voxels: Option<f64>,
    pub cell_size: [f64; 3],
    pub cells: [f64; 3],
    #[serde(rename = "box")]
    pub bounds: Aabb,
    pub triangles: u64,
    pub vertices: u64,
    pub area: f64,
    pub volume: Option<f64>,
    pub bounding_box: Option<Aabb>,
    /// CGAL's checks: on the written mesh, or on the template when `instancing` is set.
    pub checks: Verification,
    pub instancing: Option<Instancing>,
    pub meshing: MeshingStats,
    pub timings: Timings,
    pub warnings: Vec<String>,
    pub output: Option<String>,
}

impl TpmsJob {
    fn validate(&self) -> Result<()> {
        if !(self.density > 0.0 && self.density < 1.0) {
            return Err(Error::invalid(format!(
                "density must be in (0, 1), got {}",
                self.density
            )));
        }
        if self.resolution < 4 {
            return Err(Error::invalid(format!(
                "resolution must be at least 4 voxels per cell, got {}",
                self.resolution
            )));
        }
        if !(0.0..=1.0).contains(&self.adaptivity) {
            return Err(Error::invalid(format!(
                "adaptivity must be in [0, 1], got {}",
                self.adaptivity
            )));
        }
        Ok(())
    }

    /// Runs the job and returns the mesh with its report.
    pub fn run(&self, progress: &Progress) -> Result<(Mesh, TpmsReport)> {
        let mut collector = MeshCollector::default();
        let report = self.run_into(progress, &mut collector)?;
        Ok((collector.mesh, report))
    }

    /// Runs the job, streaming the part's triangles into `sink`.
    pub fn run_into(&self, progress: &Progress, sink: &mut dyn MeshSink) -> Result<TpmsReport> {
        let start = Instant::now();
        self.validate()?;
        let (s, st) = (self.surface, self.structure);
        let mut warnings = Vec::new();
        let range = calibrate::feasible(s, st);
        let t0 = calibrate::analytic_level(s, st, self.density);
        let voids = calibrate::void_connected_range(s, st);
        let conn = Connectivity {
            solid: self.density >= range.min && self.density <= range.max,
            void: self.density >= voids.min && self.density <= voids.max,
        };
        if !conn.solid && !self.allow_islands {
            return Err(Error::invalid(format!(
                "density {} is outside the feasible range of a {} {} ({:.3} to {:.3}): the solid falls apart into islands (--allow-islands builds it anyway)",
                self.density,
                s.name(),
                st.name(),
                range.min,
                range.max
            )));
        }
        if !conn.solid {
            warnings.push("the solid falls apart into separate islands at this density".into());
        }
        if !conn.void {
            warnings.push(
                "the void is not one connected space: closed voids will trap powder or resin"
                    .into(),
            );
        }

        let cell = self.domain.cell;
        let min_cell = cell.iter().cloned().fold(f64::INFINITY, f64::min);
        let mut resolution = self.resolution;
        let mut wall = None;
        if st == Structure::Sheet {
            let w = calibrate::thinnest_sheet_wall(s, t0) * resolution as f64;
            if w < MIN_WALL_VOXELS {
                let needed = (resolution as f64 * MIN_WALL_VOXELS / w).ceil() as u32;
                if !self.auto_resolution {
                    return Err(Error::invalid(format!(
                        "the {} sheet's walls at density {} are {w:.2} voxels thin at resolution {resolution}; use --resolution {needed} or more",
                        s.name(),
                        self.density
                    )));
                }
                warnings.push(format!(
                    "resolution raised from {resolution} to {needed} voxels per cell: sheet walls were {w:.2} voxels thin"
                ));
                resolution = needed;
            }
            wall = Some(calibrate::thinnest_sheet_wall(s, t0) * resolution as f64);
        }
        let voxel = min_cell / resolution as f64;

        let cal = {
            let _p = progress.stage("calibrating");
            calibrate::calibrate(
                s,
                st,
                self.density,
                cell,
                voxel,
                self.domain.counts(),
                self.adaptivity,
            )?
        };
        let bounds = self.domain.bounds();
        let lattice = Lattice {
            surface: s,
            structure: st,
            level: cal.level,
            cell,
            bounds,
            phase: bounds.min,
        };
        let plan = if self.instancing && self.adaptivity == 0.0 {
            instance::plan(self.domain.size, cell, voxel)
        } else {
            None
        };
        let (checks, meshing, measures, vertices, instancing, verify_seconds, write_seconds) =
            match plan {
                Some(plan) => {
                    let (template, meshing) = {
                        let _p = progress.stage("sampling and meshing the template");
                        Template::build(&lattice, voxel, plan)?
                    };
                    // CGAL checks the template while the part is written: the two share the cores.
                    let template_mesh = template.mesh.to_mesh();
                    let (checks, verify_seconds, measures, write_seconds) = {
                        let _p = progress.stage("writing the part and verifying its template");
                        std::thread::scope(|scope| {
                            let checker = scope.spawn(|| {
                                let t = Instant::now();
                                let r = verify_on(&template_mesh, self.self_intersection, false);
                                (r, t.elapsed().as_secs_f64())
                            });
                            let t = Instant::now();
                            let measures = template.expand(sink);
                            let write_seconds = t.elapsed().as_secs_f64();
                            let (checks, verify_seconds) =
                                checker.join().expect("the CGAL check does not panic");
                            (checks, verify_seconds, measures, write_seconds)
                        })
                    };
                    let (checks, measures) = (checks?, measures?);
                    let instancing = Instancing {
                        part_cells: plan.map(|a| a.n),
                        template_cells: plan.map(|a| a.m),
                        template_triangles: template.mesh.triangle_count() as u64,
                        verified: "template",
                    };
                    (
                        checks,
                        meshing,
                        measures,
                        template.vertex_count(),
                        Some(instancing),
                        verify_seconds,
                        write_seconds,
                    )
                }
                None => {
                    let (mesh, meshing) = {
                        let _p = progress.stage("sampling and meshing");
                        lattice.mesh(voxel, self.adaptivity)?
                    };
                    let t = Instant::now();
                    let checks = {
                        let _p = progress.stage("verifying with CGAL");
                        verify(&mesh, self.self_intersection)?
                    };
                    let verify_seconds = t.elapsed().as_secs_f64();
                    let t = Instant::now();
                    let measures = {
                        let _p = progress.stage("writing the part");
                        write_mesh(&mesh, sink)?
                    };
                    (
                        checks,
                        meshing,
                        measures,
                        mesh.vertex_count() as u64,
                        None,
                        verify_seconds,
                        t.elapsed().as_secs_f64(),
                    )
                }
            };
        let volume = measures.volume;
        let achieved = volume / bounds.volume();
        if !checks.is_valid_solid() && (checks.self_intersection_checked || !checks.closed) {
            warnings.push(
                "CGAL did not find the mesh a valid closed, outward, self-intersection-free solid"
                    .into(),
            );
        }
        Ok(TpmsReport {
            surface: s,
            structure: st,
            level: cal.level,
            target_density: self.density,
            achieved_density: achieved,
            density_error: achieved - self.density,
            calibration: cal,
            feasible_range: range,
            connectivity: conn,
            resolution_requested: self.resolution,
            resolution,
            voxel_size: voxel,
            thinnest_wall_voxels: wall,
            cell_size: cell,
            cells: self.domain.counts(),
            bounds,
            triangles: measures.triangles,
            vertices,
            area: measures.area,
            volume: Some(volume),
            bounding_box: (measures.triangles > 0).then_some(measures.bounds),
            checks,
            instancing,
            timings: Timings {
                calibrate: cal.seconds,
                sample: meshing.sample_seconds,
                mesh: meshing.mesh_seconds,
                snap: meshing.snap_seconds,
                verify: verify_seconds,
                write: write_seconds,
                total: start.elapsed().as_secs_f64(),
            },
            meshing,
            warnings,
            output: None,
        })
    }
}

/// Streams an in-memory mesh into `sink` in batches, measuring it on the way.
fn write_mesh(mesh: &Mesh, sink: &mut dyn MeshSink) -> Result<Measures> {
    use rayon::prelude::*;
    sink.begin(Some(mesh.triangle_count() as u64))?;
    let mut measures = Measures::default();
    const BATCH: usize = 1 << 16;
    for start in (0..mesh.triangle_count()).step_by(BATCH) {
        let end = (start + BATCH).min(mesh.triangle_count());
        let tris: Vec<Triangle> = (start..end)
            .into_par_iter()
            .map(|t| {
                let i = &mesh.indices[3 * t..3 * t + 3];
                [i[0], i[1], i[2]].map(|v| {
                    let p = &mesh.positions[3 * v as usize..3 * v as usize + 3];
                    [p[0], p[1], p[2]]
                })
            })
            .collect();
        measures = measures.merged(&Measures::of(&tris));
        sink.triangles(&tris)?;
    }
    sink.finish()?;
    Ok(measures)
}
