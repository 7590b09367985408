//! One TPMS job, start to finish: check the request, calibrate, mesh, verify, and report.

use super::calibrate::{self, Calibration, Connectivity, FeasibleRange};
use super::instance::{self, Template};
use super::{Domain, Lattice, MeshingStats, Structure, Surface};
use crate::error::{Error, Result};
use crate::field::Aabb;
use crate::grid::{GridSpec, IndexBox};
use crate::mesh::Mesh;
use crate::progress::Progress;
use crate::sink::{Measures, MeshCollector, MeshSink, Triangle};
use crate::tile;
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
    /// Mesh in tiles of this many samples a side (a multiple of 8), whatever the part's size.
    pub tile: Option<i64>,
    /// Memory budget, bytes: parts whose grid would not fit are meshed in tiles sized from it
    /// ([`DEFAULT_MEMORY`] when not given).
    pub memory: Option<u64>,
}

/// Timings per stage, seconds.
#[derive(Debug, Clone, Copy, Default, serde::Serialize)]
pub struct Timings {
    /// The unit cell's sample table and the calibration's meshings.
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

/// How the part was meshed when it was meshed in tiles (see [`crate::tile`]).
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Tiling {
    pub tiles: u64,
    /// Tile edge, samples.
    pub tile_samples: i64,
    /// Samples meshed around each tile and not kept.
    pub margin_samples: i64,
    pub verified: &'static str,
}

/// Memory a part may use while it is meshed when no budget is given: larger parts are meshed
/// in tiles.
pub const DEFAULT_MEMORY: u64 = 4 << 30;

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
    pub tiling: Option<Tiling>,
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
        // The first call builds the unit cell's sample table: part of calibrating.
        let table_start = Instant::now();
        let t0 = calibrate::analytic_level(s, st, self.density);
        let table_seconds = table_start.elapsed().as_secs_f64();
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
                // Raised to whole 8-voxel blocks, so that cells can still be copied exactly.
                let raised = needed.div_ceil(instance::BLOCK) * instance::BLOCK;
                warnings.push(format!(
                    "resolution raised from {resolution} to {raised} voxels per cell: sheet walls were {w:.2} voxels thin"
                ));
                resolution = raised;
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
        let route = self.route(&lattice, voxel);
        let written = match route {
            Route::Instanced(plan) => {
                self.write_instanced(&lattice, voxel, plan, progress, sink)?
            }
            Route::Tiled(edge) => self.write_tiled(&lattice, voxel, edge, progress, sink)?,
            Route::Whole => self.write_whole(&lattice, voxel, progress, sink)?,
        };
        let Written {
            checks,
            meshing,
            measures,
            vertices,
            instancing,
            tiling,
            verify_seconds,
            write_seconds,
        } = written;
        let volume = measures.volume;
        let achieved = volume / bounds.volume();
        if !checks.verdict().is_valid_solid() {
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
            tiling,
            timings: Timings {
                calibrate: table_seconds + cal.seconds,
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

/// How a part is meshed.
enum Route {
    /// Copied cell by cell from a meshed template.
    Instanced([instance::AxisPlan; 3]),
    /// Meshed tile by tile, tiles of this many samples a side.
    Tiled(i64),
    /// Meshed at once.
    Whole,
}

/// What writing the part gave.
struct Written {
    checks: Verification,
    meshing: MeshingStats,
    measures: Measures,
    vertices: u64,
    instancing: Option<Instancing>,
    tiling: Option<Tiling>,
    verify_seconds: f64,
    write_seconds: f64,
}

impl TpmsJob {
    fn route(&self, lattice: &Lattice, voxel: f64) -> Route {
        if self.adaptivity != 0.0 {
            return Route::Whole;
        }
        if self.instancing && self.tile.is_none() {
            if let Some(plan) = instance::plan(self.domain.size, lattice.cell, voxel) {
                return Route::Instanced(plan);
            }
        }
        if let Some(edge) = self.tile {
            return Route::Tiled(edge);
        }
        let spec = GridSpec::covering(&lattice.bounds, voxel, super::HALF_WIDTH);
        let budget = self.memory.unwrap_or(DEFAULT_MEMORY);
        if spec.padded_region().voxels() * tile::BYTES_PER_VOXEL > budget {
            Route::Tiled(tile::tile_edge_for_budget(budget))
        } else {
            Route::Whole
        }
    }

    fn write_instanced(
        &self,
        lattice: &Lattice,
        voxel: f64,
        plan: [instance::AxisPlan; 3],
        progress: &Progress,
        sink: &mut dyn MeshSink,
    ) -> Result<Written> {
        let (template, meshing) = {
            let _p = progress.stage("sampling and meshing the template");
            Template::build(lattice, voxel, plan)?
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
        Ok(Written {
            checks: checks?,
            meshing,
            measures: measures?,
            vertices: template.vertex_count(),
            instancing: Some(Instancing {
                part_cells: plan.map(|a| a.n),
                template_cells: plan.map(|a| a.m),
                template_triangles: template.mesh.triangle_count() as u64,
                verified: "template",
            }),
            tiling: None,
            verify_seconds,
            write_seconds,
        })
    }

    fn write_tiled(
        &self,
        lattice: &Lattice,
        voxel: f64,
        edge: i64,
        progress: &Progress,
        sink: &mut dyn MeshSink,
    ) -> Result<Written> {
        let spec = GridSpec::covering(&lattice.bounds, voxel, super::HALF_WIDTH);
        let stats = std::sync::Mutex::new(MeshingStats::default());
        let mesh_tile = |r: IndexBox| {
            let (m, s) = lattice.mesh_keyed_in(spec, Some(r), 0.0)?;
            let mut total = stats.lock().expect("no panic while holding the lock");
            total.add(&s);
            Ok(m)
        };
        let t = Instant::now();
        let out = {
            let _p = progress.stage("meshing and writing the part tile by tile");
            tile::mesh_tiled(
                spec.padded_region(),
                edge,
                &mesh_tile,
                self.self_intersection,
                sink,
            )?
        };
        let closed = out.bad_edges == 0;
        let m = out.measures;
        Ok(Written {
            checks: Verification {
                manifold: closed,
                closed,
                outward: closed && m.volume > 0.0,
                self_intersection_checked: out.self_intersection_checked,
                self_intersecting: out.self_intersecting,
                volume: closed.then_some(m.volume),
                area: m.area,
                faces: m.triangles,
                vertices: out.vertices,
                border_edges: out.bad_edges,
                components: 0,
            },
            meshing: stats.into_inner().expect("no panic while holding the lock"),
            measures: m,
            vertices: out.vertices,
            instancing: None,
            tiling: Some(Tiling {
                tiles: out.tiles,
                tile_samples: edge,
                margin_samples: tile::MARGIN,
                verified: "per tile: edges counted by latvox, self-intersection by CGAL",
            }),
            verify_seconds: 0.0,
            write_seconds: t.elapsed().as_secs_f64(),
        })
    }

    fn write_whole(
        &self,
        lattice: &Lattice,
        voxel: f64,
        progress: &Progress,
        sink: &mut dyn MeshSink,
    ) -> Result<Written> {
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
        Ok(Written {
            checks,
            meshing,
            measures,
            vertices: mesh.vertex_count() as u64,
            instancing: None,
            tiling: None,
            verify_seconds,
            write_seconds: t.elapsed().as_secs_f64(),
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
