//! One TPMS job, start to finish: check the request, calibrate a first level, find the level
//! that gives *this* part its density (raising the resolution when the voxels are too coarse to
//! reach it), mesh, verify, write and report — the meshing itself is [`crate::mesh::pipeline`]'s.

use super::calibrate::{self, Calibration, Connectivity, FeasibleRange};
use super::{Domain, Lattice, LatticeFamily, Structure, Surface};
use crate::error::{Error, Result};
use crate::geom::Mesh;
use crate::io::sink::{MeshCollector, MeshSink};
use crate::mesh::pipeline::{self, Family, Options, Route, Solved};
use crate::mesh::report::{LevelSearch, PartReport, Timings};
use crate::mesh::resolution;
use crate::progress::Progress;
use crate::render::{Fidelity, MODEL_MEMORY};
use crate::verify::Verdict;
use std::time::Instant;

pub use crate::mesh::pipeline::{Instancing, Tiling, DEFAULT_MEMORY};

pub use crate::lattice::tpms::MIN_WALL_VOXELS;

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
    /// Simplify the mesh within this distance of the exact surface.
    pub tolerance: Option<crate::mesh::pipeline::Tolerance>,
    /// Build even if the solid falls apart into islands at this density.
    pub allow_islands: bool,
    /// Raise the resolution when sheet walls would be thinner than [`MIN_WALL_VOXELS`].
    pub auto_resolution: bool,
    /// How the written part is verified.
    pub verify: crate::verify::Verify,
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
    /// A density that varies through the part (`density` is then not used).
    pub grading: Option<crate::mesh::graded::Grading>,
    /// A second type blended in by a weight that varies through the part.
    pub blend: Option<super::blend::Blend>,
    /// Cells wrapped around an axis (the domain's box is then not used) or growing along one.
    pub cell_map: Option<crate::field::cellmap::Mapping>,
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
    /// How a graded part met its density field, cell by cell.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub grading: Option<crate::mesh::graded::GradingReport>,
    /// The type blended to and its weight field.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub blend: Option<super::blend::BlendReport>,
    /// The tube of a cell-mapped part, and each layer's density.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cell_map: Option<super::mapped::CellMapReport>,
    /// The part as written: density, mesh, checks, timings, warnings.
    #[serde(flatten)]
    pub part: PartReport,
}

impl TpmsReport {
    /// The part's verdict: CGAL's checks (on the part, its template or its tiles), one piece
    /// (unless fragments were kept on purpose), and the density.
    pub fn verdict(&self) -> Verdict {
        self.part.verdict()
    }
}

impl TpmsJob {
    /// The part as an implicit solid: the level its mesh is written at (the same search, on the
    /// same voxels; in tiles beyond [`MODEL_MEMORY`]), for slices moved so that it encloses the
    /// mesh's volume ([`Fidelity`]), and with the fragments the mesh drops.
    pub fn model(&self, fidelity: crate::render::Fidelity) -> Result<crate::render::Model> {
        self.validate()?;
        if self.grading.is_some() || self.blend.is_some() || self.cell_map.is_some() {
            return Err(Error::invalid(
                "a graded or cell-mapped part is drawn and sliced from its mesh: make it with -o part.stl, then render, view or slice part.stl",
            ));
        }
        let bounded = TpmsJob {
            memory: Some(self.memory.unwrap_or(DEFAULT_MEMORY).min(MODEL_MEMORY)),
            ..self.clone()
        };
        let settled = bounded.settle(&Progress::hidden())?;
        let found = &settled.resolved.found;
        let (best, tried) = (&found.solved.best, &found.solved.tried);
        let cell = self.domain.cell;
        let step = pipeline::implicit_step(found.voxel, cell[0].min(cell[1]).min(cell[2]));
        let level = match fidelity {
            Fidelity::Look => best.level,
            Fidelity::Volume => {
                pipeline::implicit_level(&found.family, best, tried, found.voxel, step)
            }
        };
        Ok(crate::render::Model {
            level,
            lattice: crate::render::Lattice::Tpms(found.family.at(level)),
            voxel: found.voxel,
            cell: cell[0].min(cell[1]).min(cell[2]),
            target: Some(self.density),
            loose: pipeline::loose(&found.family, best, found.voxel)?,
        })
    }

    fn validate(&self) -> Result<()> {
        resolution::check_density(self.density)?;
        resolution::check_resolution(self.resolution)?;
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
        if let Some(map) = &self.cell_map {
            return self.run_mapped(map.clone(), progress, sink);
        }
        if let Some(g) = &self.grading {
            return self.run_graded(g, progress, sink);
        }
        if self.blend.is_some() {
            // A blend cannot be copied cell by cell: it is graded at a constant density.
            let g = crate::mesh::graded::Grading {
                field: std::sync::Arc::new(crate::field::density::DensityField::constant(
                    self.density,
                )),
                clamp: false,
            };
            return self.run_graded(&g, progress, sink);
        }
        let (s, st) = (self.surface, self.structure);
        let Settled {
            t0,
            range,
            conn,
            mut warnings,
            calibrate_seconds,
            resolved,
        } = self.settle(progress)?;
        let opts = self.options(self.instancing, !conn.solid);
        warnings.extend(resolved.raised);
        let Found {
            voxel,
            cal,
            family,
            route,
            solved,
        } = resolved.found;
        let Solved {
            best,
            tried,
            meshing: search_meshing,
            ..
        } = solved;
        let level = best.level;
        let level_search = LevelSearch::new(&best, route, &tried, resolved.coarser);
        let written = pipeline::write(&family, best, voxel, route, &opts, progress, sink)?;
        let mut part = PartReport::new(
            self.domain.bounds(),
            Some(self.density),
            route,
            written,
            search_meshing,
            Timings {
                calibrate: calibrate_seconds,
                ..Timings::default()
            },
        );
        warnings.append(&mut part.warnings);
        part.warnings = warnings;
        part.timings.total = start.elapsed().as_secs_f64();
        Ok(TpmsReport {
            surface: s,
            structure: st,
            level,
            calibration: cal,
            level_search,
            feasible_range: range,
            connectivity: conn,
            resolution_requested: self.resolution,
            resolution: resolved.resolution,
            voxel_size: voxel,
            thinnest_wall_voxels: wall_voxels(s, st, t0, resolved.resolution),
            cell_size: self.domain.cell,
            cells: self.domain.counts(),
            grading: None,
            blend: None,
            cell_map: None,
            part,
        })
    }

    /// Finds the part's resolution and level as its mesh is made at (every route that shows
    /// the part — its mesh, its slices, its pictures — takes the level from here).
    fn settle(&self, progress: &Progress) -> Result<Settled> {
        let (s, st) = (self.surface, self.structure);
        let range = calibrate::feasible(s, st);
        let (conn, warnings) = self.connectivity(range)?;
        // The first call builds the unit cell's sample table: part of calibrating.
        let table_start = Instant::now();
        let t0 = calibrate::analytic_level(s, st, self.density);
        let table_seconds = table_start.elapsed().as_secs_f64();
        // Islands asked for are kept: the solid is meant to fall apart.
        let opts = self.options(self.instancing, !conn.solid);
        let mut calibrate_seconds = table_seconds;
        let request = self.request(format!("the {} {}", s.name(), st.name()), t0);
        let resolved = resolution::search(&request, &mut |r| {
            let _p = progress.stage(if r == self.resolution {
                "calibrating and meshing"
            } else {
                "searching for a resolution that reaches the density"
            });
            let (cal_seconds, outcome) = self.attempt(r, &opts)?;
            calibrate_seconds += cal_seconds;
            Ok(outcome)
        })?;
        Ok(Settled {
            t0,
            range,
            conn,
            warnings,
            calibrate_seconds,
            resolved,
        })
    }

    /// Whether the solid and the void are each one piece at this density; outside the feasible
    /// range the job is refused unless islands are allowed. Warnings for what is allowed.
    pub(super) fn connectivity(&self, range: FeasibleRange) -> Result<(Connectivity, Vec<String>)> {
        let (s, st) = (self.surface, self.structure);
        let voids = calibrate::void_connected_range(s, st);
        let conn = Connectivity {
            solid: self.density >= range.min && self.density <= range.max,
            void: self.density >= voids.min && self.density <= voids.max,
        };
        if !conn.solid && !self.allow_islands {
            // A net's other labyrinth may hold together where this one does not.
            let other = match st {
                Structure::Net => Some((Structure::NetOther, "--side other")),
                Structure::NetOther => Some((Structure::Net, "--side first")),
                Structure::Sheet => None,
            };
            let hint = other
                .map(|(o, flag)| (calibrate::feasible(s, o), flag))
                .filter(|(r, _)| self.density >= r.min && self.density <= r.max)
                .map_or(String::new(), |(r, flag)| {
                    format!(
                        "; the other labyrinth holds together from {:.3} to {:.3} ({flag})",
                        r.min, r.max
                    )
                });
            return Err(Error::Infeasible {
                setting: "density".into(),
                value: self.density,
                min: range.min,
                max: range.max,
                message: format!(
                    "density {} is outside the feasible range of a {} {} ({:.3} to {:.3}): the solid falls apart into islands (--allow-islands builds it anyway){hint}",
                    self.density,
                    s.name(),
                    st.name(),
                    range.min,
                    range.max
                ),
            });
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

    /// The pipeline's options for this job; fragments kept when asked, or when `islands` (the
    /// solid is meant to fall apart).
    pub(super) fn options(&self, instancing: bool, islands: bool) -> Options {
        Options {
            adaptivity: self.adaptivity,
            tolerance: self.tolerance,
            verify: self.verify,
            instancing,
            tile: self.tile,
            memory: self.memory,
            keep_fragments: self.keep_fragments || islands,
        }
    }

    /// The resolution search's request for `part` ("the gyroid net") at the density, its sheet
    /// walls read at the level `t0`.
    pub(super) fn request(&self, part: String, t0: f64) -> resolution::Request {
        resolution::Request {
            part,
            setting: format!("density {}", self.density),
            requested: self.resolution,
            thin: self.thin_walls(t0),
            density: Some(self.density),
            auto: self.auto_resolution,
            per: "cell",
        }
    }

    /// The resolution sheet walls need, when the requested one leaves them thinner than
    /// [`MIN_WALL_VOXELS`] (they perforate), and why.
    pub(super) fn thin_walls(&self, t0: f64) -> Option<(u32, String)> {
        let r = self.resolution;
        let w = wall_voxels(self.surface, self.structure, t0, r)?;
        (w < MIN_WALL_VOXELS).then(|| {
            (
                (r as f64 * MIN_WALL_VOXELS / w).ceil() as u32,
                format!("sheet walls were {w:.2} voxels thin at {r} voxels per cell"),
            )
        })
    }

    /// The level calibrated for this part at `resolution` voxels per (shortest) cell, and that
    /// voxel's size.
    fn calibration(&self, resolution: u32) -> Result<(calibrate::Calibration, f64)> {
        let cell = self.domain.cell;
        let voxel = cell.iter().cloned().fold(f64::INFINITY, f64::min) / resolution as f64;
        let cal = calibrate::calibrate(
            self.surface,
            self.structure,
            self.density,
            cell,
            voxel,
            self.domain.counts(),
            self.adaptivity,
        )?;
        Ok((cal, voxel))
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
        let (cal, voxel) = self.calibration(resolution)?;
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

/// The part's resolution and level, found before anything is written.
struct Settled {
    t0: f64,
    range: FeasibleRange,
    conn: Connectivity,
    warnings: Vec<String>,
    calibrate_seconds: f64,
    resolved: resolution::Resolved<Found>,
}

/// A resolution at which the part reaches its density, with the level found.
struct Found {
    voxel: f64,
    cal: Calibration,
    family: LatticeFamily,
    route: Route,
    solved: Solved,
}

/// Sheet walls' thinnest width in voxels at `resolution` (nets: none).
fn wall_voxels(s: Surface, st: Structure, t0: f64, resolution: u32) -> Option<f64> {
    (st == Structure::Sheet).then(|| calibrate::thinnest_sheet_wall(s, t0) * resolution as f64)
}
