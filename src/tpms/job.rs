//! One TPMS job, start to finish: check the request, calibrate a first level, find the level
//! that gives *this* part its density (raising the resolution when the voxels are too coarse to
//! reach it), mesh, verify, write and report — the meshing itself is [`crate::mesh::pipeline`]'s.

use super::calibrate::{self, Calibration, Connectivity, FeasibleRange};
use super::{Domain, Lattice, LatticeFamily, MeshingStats, Structure, Surface};
use crate::check::cgal::Verification;
use crate::check::Verdict;
use crate::error::{Error, Result};
use crate::field::Aabb;
use crate::io::sink::{MeshCollector, MeshSink};
use crate::mesh::instance;
use crate::mesh::pieces::Fragments;
use crate::mesh::pipeline::{self, Options, Route, Solved, PROMISE};
use crate::mesh::Mesh;
use crate::progress::Progress;
use std::time::Instant;

pub use crate::mesh::pipeline::{Instancing, Tiling, DEFAULT_MEMORY};

/// Sheet walls thinner than this many voxels are not represented faithfully by a narrow band
/// (samples miss the wall and it perforates); the resolution is raised to keep them this thick.
pub const MIN_WALL_VOXELS: f64 = 1.25;

/// What to build.
#[derive(Debug, Clone)]
pub struct TpmsJob {
    /// Which minimal surface.
    pub surface: Surface,
    /// Net or sheet.
    pub structure: Structure,
    /// Target volume fraction, in (0, 1).
    pub density: f64,
    /// The box: cell size, overall size and lower corner, mm.
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
    /// Keep the fragments the box cuts loose from the lattice (removed by default).
    pub keep_fragments: bool,
}

/// Timings per stage, seconds.
#[derive(Debug, Clone, Copy, Default, serde::Serialize)]
pub struct Timings {
    /// The unit cell's sample table and the calibration's meshings.
    pub calibrate: f64,
    /// Sampling the field into OpenVDB grids.
    pub sample: f64,
    /// OpenVDB's meshing.
    pub mesh: f64,
    /// Snapping the vertices onto the surface and box.
    pub snap: f64,
    /// CGAL's checks.
    pub verify: f64,
    /// Writing the part.
    pub write: f64,
    /// The whole job.
    pub total: f64,
}

/// How the level of the part was found: the part (or a template of its cells) meshed at each
/// level tried, and the volume fraction measured.
#[derive(Debug, Clone, serde::Serialize)]
pub struct LevelSearch {
    /// What was measured: `part` (the whole part), `template` (a template of its cells, which
    /// gives the part's volume) or `tiles` (the part meshed tile by tile, not kept).
    pub measured_on: &'static str,
    /// `[level, volume fraction]` of each meshing, in order.
    pub tried: Vec<[f64; 2]>,
    /// Resolutions tried before the one used, with the closest fraction each could give.
    pub coarser: Vec<ResolutionMiss>,
}

/// A resolution at which no level gave the target density.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct ResolutionMiss {
    /// Voxels per cell.
    pub resolution: u32,
    /// The closest volume fraction found.
    pub closest: f64,
}

/// The JSON report of a TPMS job.
#[derive(Debug, Clone, serde::Serialize)]
pub struct TpmsReport {
    /// Which minimal surface.
    #[serde(rename = "type")]
    pub surface: Surface,
    /// Net or sheet.
    pub structure: Structure,
    /// The level `t` the part was written at.
    pub level: f64,
    /// The volume fraction asked for.
    pub target_density: f64,
    /// Volume fraction of the written mesh: its enclosed volume (divergence theorem over the
    /// triangles exactly as written) over the box volume.
    pub achieved_density: f64,
    /// `achieved_density − target_density`.
    pub density_error: f64,
    /// Whether the written mesh is within 0.002 of the target density.
    pub density_met: bool,
    /// The first guess of the level, from the unit cell.
    pub calibration: Calibration,
    /// How the part's level was found.
    pub level_search: LevelSearch,
    /// Volume fractions at which solid and void both stay connected.
    pub feasible_range: FeasibleRange,
    /// Whether solid and void percolate at the level written.
    pub connectivity: Connectivity,
    /// Voxels per cell asked for.
    pub resolution_requested: u32,
    /// Voxels per cell used (raised for thin sheet walls or an unmet density).
    pub resolution: u32,
    /// Voxel edge, mm.
    pub voxel_size: f64,
    /// Thinnest sheet wall, voxels (sheets only).
    pub thinnest_wall_voxels: Option<f64>,
    /// Cell size per axis, mm.
    pub cell_size: [f64; 3],
    /// Cells per axis (fractional where the box ends inside a cell).
    pub cells: [f64; 3],
    /// The part's box, mm.
    #[serde(rename = "box")]
    pub bounds: Aabb,
    /// Triangles written.
    pub triangles: u64,
    /// Vertices of the part.
    pub vertices: u64,
    /// Surface area of the written mesh, mm².
    pub area: f64,
    /// Volume enclosed by the written mesh, mm³.
    pub volume: Option<f64>,
    /// Bounding box of the written mesh, mm (`null` when empty).
    pub bounding_box: Option<Aabb>,
    /// CGAL's checks: on the written mesh, or on the template when `instancing` is set.
    pub checks: Verification,
    /// Pieces of the lattice the box cut loose: removed (unless kept with `keep_fragments`).
    pub fragments: Fragments,
    /// Whether what was written is one piece (`null` where it was not checked: a part meshed in
    /// tiles without a template of its cells).
    pub one_piece: Option<bool>,
    /// Set when the part was copied from a template.
    pub instancing: Option<Instancing>,
    /// Set when the part was meshed in tiles.
    pub tiling: Option<Tiling>,
    /// Meshing statistics over every meshing of the job.
    pub meshing: MeshingStats,
    /// Wall time of each stage.
    pub timings: Timings,
    /// Warnings, one sentence each (islands, raised resolution, …).
    pub warnings: Vec<String>,
    /// The output file, when the command line wrote one.
    pub output: Option<String>,
}

impl TpmsReport {
    /// The part's verdict: CGAL's checks (on the part, its template or its tiles), one piece
    /// (unless fragments were kept on purpose), and the density.
    pub fn verdict(&self) -> Verdict {
        let kept_on_purpose = !self.fragments.removed && self.fragments.count > 0;
        Verdict {
            one_piece: self.one_piece.filter(|_| !kept_on_purpose),
            density_met: Some(self.density_met),
            ..self.checks.verdict()
        }
    }
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
        let range = calibrate::feasible(s, st);
        let (conn, mut warnings) = self.connectivity(range)?;
        // The first call builds the unit cell's sample table: part of calibrating.
        let table_start = Instant::now();
        let t0 = calibrate::analytic_level(s, st, self.density);
        let table_seconds = table_start.elapsed().as_secs_f64();
        let opts = Options {
            adaptivity: self.adaptivity,
            self_intersection: self.self_intersection,
            instancing: self.instancing,
            tile: self.tile,
            memory: self.memory,
            // Islands asked for are kept: the solid is meant to fall apart.
            keep_fragments: self.keep_fragments || !conn.solid,
        };
        let search = self.search_resolution(t0, &opts, progress)?;
        warnings.extend(search.raised);
        let Found {
            voxel,
            cal,
            family,
            route,
            solved,
        } = search.found;
        let Solved {
            best,
            tried,
            meshing: search_meshing,
            ..
        } = solved;
        let level = best.level;
        let measured_on = match (&best.made, route) {
            (pipeline::Made::Whole(_), _) => "part",
            (_, Route::Tiled(_, None)) => "tiles",
            _ => "template",
        };
        let written = pipeline::write(&family, best, voxel, route, &opts, progress, sink)?;
        // The meshings of the search are part of the work (the whole route's last one is the
        // part's own mesh).
        let mut all_meshing = search_meshing;
        if !matches!(route, Route::Whole(None)) {
            all_meshing.add(&written.meshing);
        }
        let bounds = self.domain.bounds();
        let measures = written.measures;
        let achieved = measures.volume / bounds.volume();
        let density_met = (achieved - self.density).abs() <= PROMISE;
        let one_piece = match route {
            Route::Tiled(_, None) => None,
            _ => Some(written.fragments.count == 0 || written.fragments.removed),
        };
        warnings.extend(self.written_warnings(achieved, &written));
        Ok(TpmsReport {
            surface: s,
            structure: st,
            level,
            target_density: self.density,
            achieved_density: achieved,
            density_error: achieved - self.density,
            density_met,
            calibration: cal,
            level_search: LevelSearch {
                measured_on,
                tried: tried.iter().map(|&(t, f)| [t, f]).collect(),
                coarser: search.coarser,
            },
            feasible_range: range,
            connectivity: conn,
            resolution_requested: self.resolution,
            resolution: search.resolution,
            voxel_size: voxel,
            thinnest_wall_voxels: wall_voxels(s, st, t0, search.resolution),
            cell_size: self.domain.cell,
            cells: self.domain.counts(),
            bounds,
            triangles: measures.triangles,
            vertices: written.vertices,
            area: measures.area,
            volume: Some(measures.volume),
            bounding_box: (measures.triangles > 0).then_some(measures.bounds),
            checks: written.checks,
            fragments: written.fragments,
            one_piece,
            instancing: written.instancing,
            tiling: written.tiling,
            timings: Timings {
                calibrate: table_seconds + search.calibrate_seconds,
                sample: all_meshing.sample_seconds,
                mesh: all_meshing.mesh_seconds,
                snap: all_meshing.snap_seconds,
                verify: written.verify_seconds,
                write: written.write_seconds,
                total: start.elapsed().as_secs_f64(),
            },
            meshing: all_meshing,
            warnings,
            output: None,
        })
    }

    /// Whether the solid and the void are each one piece at this density; outside the feasible
    /// range the job is refused unless islands are allowed. Warnings for what is allowed.
    fn connectivity(&self, range: FeasibleRange) -> Result<(Connectivity, Vec<String>)> {
        let (s, st) = (self.surface, self.structure);
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
        let mut warnings = Vec::new();
        if !conn.solid {
            warnings.push("the solid falls apart into separate islands at this density".into());
        }
        if !conn.void {
            warnings.push(
                "the void is not one connected space: closed voids will trap powder or resin"
                    .into(),
            );
        }
        Ok((conn, warnings))
    }

    /// The level is found on the part at the requested resolution; where sheet walls are too
    /// thin or no level reaches the target on these voxels, finer ones are searched (steps that
    /// double, then bisection), and the smallest that works is used (or, with a fixed
    /// resolution, named in the refusal).
    fn search_resolution(
        &self,
        t0: f64,
        opts: &Options,
        progress: &Progress,
    ) -> Result<ResolutionSearch> {
        let (s, st) = (self.surface, self.structure);
        let mut passed_over: Vec<String> = Vec::new();
        let mut start_at = self.resolution;
        // Sheet walls thinner than MIN_WALL_VOXELS perforate; a resolution that leaves them so
        // is passed over without meshing.
        if let Some(w) = wall_voxels(s, st, t0, start_at).filter(|&w| w < MIN_WALL_VOXELS) {
            let needed = (start_at as f64 * MIN_WALL_VOXELS / w).ceil() as u32;
            passed_over.push(format!(
                "sheet walls were {w:.2} voxels thin at {start_at} voxels per cell"
            ));
            // Raised to whole 8-voxel blocks, so that cells can still be copied exactly; a
            // refusal names the smallest that works.
            start_at = if self.auto_resolution {
                needed.div_ceil(instance::BLOCK) * instance::BLOCK
            } else {
                needed
            };
        }
        let limit = max_resolution(self.resolution).max(start_at);
        let mut coarser = Vec::new();
        let mut calibrate_seconds = 0.0;
        let mut attempt = |r: u32| -> Result<Option<Found>> {
            let _p = progress.stage(if r == self.resolution {
                "calibrating and meshing"
            } else {
                "searching for a resolution that reaches the density"
            });
            let (cal_seconds, outcome) = self.attempt(r, opts)?;
            calibrate_seconds += cal_seconds;
            Ok(match outcome {
                Ok(found) => Some(found),
                Err(closest) => {
                    coarser.push(ResolutionMiss {
                        resolution: r,
                        closest,
                    });
                    None
                }
            })
        };
        let Some((resolution, found)) =
            pipeline::smallest_resolution(start_at, limit, &mut attempt)?
        else {
            let closest = coarser.last().map_or(f64::NAN, |m| m.closest);
            return Err(Error::invalid(format!(
                "no level gives the {} {} a density of {} within {PROMISE} at {} to {limit} voxels per cell (closest {closest:.4}); the box may cut the lattice into pieces",
                s.name(),
                st.name(),
                self.density,
                self.resolution,
            )));
        };
        coarser.sort_by_key(|m| m.resolution);
        if let Some(miss) = coarser.first().filter(|m| m.resolution == start_at) {
            passed_over.push(format!(
                "at {} voxels per cell no level gives density {} (closest {:.4}): the voxels are too coarse for the lattice's members",
                miss.resolution, self.density, miss.closest
            ));
        }
        let mut raised = Vec::new();
        if let Some(why) = passed_over.first() {
            if !self.auto_resolution {
                return Err(Error::invalid(format!(
                    "the {} {} at density {}: {why}; use --resolution {resolution}, the smallest that works",
                    s.name(),
                    st.name(),
                    self.density
                )));
            }
            raised.push(format!(
                "resolution raised from {} to {resolution} voxels per cell: {why}",
                self.resolution
            ));
        }
        Ok(ResolutionSearch {
            resolution,
            found,
            coarser,
            calibrate_seconds,
            raised,
        })
    }

    /// What the written mesh says that the user should hear: a missed density (a bug), a
    /// failed CGAL check, fragments cut loose by the box.
    fn written_warnings(&self, achieved: f64, written: &pipeline::Written) -> Vec<String> {
        let mut warnings = Vec::new();
        if (achieved - self.density).abs() > PROMISE {
            warnings.push(format!(
                "the written mesh's density {achieved:.4} misses the target {} by more than {PROMISE}: please report this",
                self.density
            ));
        }
        if !written.checks.verdict().is_valid_solid() {
            warnings.push(
                "CGAL did not find the mesh a valid closed, outward, self-intersection-free solid"
                    .into(),
            );
        }
        let fragments = &written.fragments;
        if fragments.count > 0 {
            warnings.push(format!(
                "{} fragment{} cut loose by the box ({:.3} mm³) {}",
                fragments.count,
                if fragments.count == 1 { "" } else { "s" },
                fragments.volume,
                if fragments.removed {
                    "removed"
                } else {
                    "kept: they are not joined to the part"
                }
            ));
        }
        warnings
    }

    /// Calibrates a first level at `resolution` and searches the level for the part from it:
    /// the part found, or the closest fraction when no level on these voxels gives the target
    /// (the unit cell's calibration not converging is enough to tell, without meshing the
    /// part). Returns the calibration's time too.
    fn attempt(
        &self,
        resolution: u32,
        opts: &Options,
    ) -> Result<(f64, std::result::Result<Found, f64>)> {
        let cell = self.domain.cell;
        let min_cell = cell.iter().cloned().fold(f64::INFINITY, f64::min);
        let voxel = min_cell / resolution as f64;
        let cal = calibrate::calibrate(
            self.surface,
            self.structure,
            self.density,
            cell,
            voxel,
            self.domain.counts(),
            self.adaptivity,
        )?;
        if !cal.converged {
            return Ok((cal.seconds, Err(cal.predicted_fraction)));
        }
        let bounds = self.domain.bounds();
        let family = LatticeFamily {
            part: Lattice {
                surface: self.surface,
                structure: self.structure,
                level: cal.level,
                cell,
                bounds,
                phase: bounds.min,
            },
        };
        let route = Route::choose(&family.part, voxel, opts);
        let solved = pipeline::solve(&family, self.density, cal.level, voxel, route, opts)?;
        if !solved.met {
            return Ok((cal.seconds, Err(solved.best.fraction)));
        }
        Ok((
            cal.seconds,
            Ok(Found {
                voxel,
                cal,
                family,
                route,
                solved,
            }),
        ))
    }
}

/// A resolution at which the part reaches its density, with the level found.
struct Found {
    voxel: f64,
    cal: Calibration,
    family: LatticeFamily,
    route: Route,
    solved: Solved,
}

/// The outcome of the resolution search: the resolution used and the part found there, the
/// coarser resolutions that missed, the seconds spent calibrating, and the warning when the
/// resolution was raised.
struct ResolutionSearch {
    resolution: u32,
    found: Found,
    coarser: Vec<ResolutionMiss>,
    calibrate_seconds: f64,
    raised: Vec<String>,
}

/// Sheet walls' thinnest width in voxels at `resolution` (nets: none).
fn wall_voxels(s: Surface, st: Structure, t0: f64, resolution: u32) -> Option<f64> {
    (st == Structure::Sheet).then(|| calibrate::thinnest_sheet_wall(s, t0) * resolution as f64)
}

/// The finest resolution tried before a part is refused.
fn max_resolution(requested: u32) -> u32 {
    (4 * requested).max(64)
}
