//! Graded fills: the lattice inside a part at a density that varies through it — by position,
//! or by `d`, the depth below the part's skin (dense near the skin, open inside) — met cell by
//! cell by [`crate::mesh::graded`] on the cells that lie wholly inside the part's core.
//!
//! The part's distance grid is built exact through the whole part when the field reads `d`
//! (not only through the skin), so that `d` is the true depth everywhere. Points in the skin and
//! outside the part read the field at `d = 0`. The promised cells are those whose box lies
//! deeper than the skin, the blend and a voxel (the grid's error) and clear of the kept solids
//! and the drain holes: there the written mesh is the lattice alone.

use super::job::{closed_parts, FillJob, FillReport, Filled, Infilling};
use super::shape::{FillFamily, FillSolid, Infill, Shape};
use crate::error::Result;
use crate::field::{Aabb, Vec3};
use crate::io::sink::MeshSink;
use crate::lattice::strut::MIN_STRUT_VOXELS;
use crate::lattice::strut::{RadiusModel, StrutFamily, StrutLattice};
use crate::lattice::tpms::graded::Calibrated;
use crate::lattice::tpms::MIN_WALL_VOXELS;
use crate::lattice::tpms::{calibrate, Lattice, Structure};
use crate::mesh::cells::CellVolumes;
use crate::mesh::graded::{
    self, Cells, Feasible, Graded, GradedFamily, Grading, LevelGrid, LevelMap, Levelled, Run,
};
use crate::mesh::pipeline::Options;
use crate::mesh::report::Timings;
use crate::mesh::resolution::max_resolution;
use crate::progress::Progress;
use std::sync::Arc;
use std::time::Instant;

/// A graded lattice inside a part: the lattice and its map, the part around it.
struct FilledGraded<L> {
    lattice: L,
    map: LevelMap,
    shape: Arc<Shape>,
    skin: f64,
    blend: f64,
    base_volume: f64,
    fill_volume: f64,
}

impl<L: Levelled> Graded for FilledGraded<L> {
    type Family<'a>
        = FillFamily<GradedFamily<'a, L>>
    where
        L: 'a;

    fn level(&self, _p: Vec3, rho: f64) -> f64 {
        self.map.level(rho)
    }

    fn family<'a>(&'a self, levels: &'a LevelGrid) -> Self::Family<'a> {
        FillFamily {
            lattice: GradedFamily::new(self.lattice.clone(), levels),
            part: FillSolid {
                shape: self.shape.clone(),
                skin: self.skin,
                blend: self.blend,
                infill: Infill::Empty,
            },
            base_volume: self.base_volume,
            fill_volume: self.fill_volume,
        }
    }
}

/// The infill, as grading needs it: its feasible range, its thinnest members, its map.
enum Kind {
    Tpms(Lattice),
    Strut(StrutFamily),
}

impl FillJob {
    /// The infill's densities, at the finest resolution the job may take.
    fn feasible(&self, infill: &Kind) -> Feasible {
        let finest = if self.auto_resolution {
            max_resolution(self.resolution)
        } else {
            self.resolution
        };
        match infill {
            Kind::Tpms(l) => {
                let r = calibrate::feasible(l.surface, l.structure);
                Feasible {
                    min: r.min,
                    max: r.max,
                    what: self.lattice_name.clone(),
                    why: "the solid falls apart",
                }
            }
            Kind::Strut(f) => {
                let factor = f.part.cell.thinnest_factor();
                let voxel = self.min_cell() / finest as f64;
                let thinnest = 0.5 * MIN_STRUT_VOXELS * voxel / factor;
                Feasible {
                    min: f.model.fraction(thinnest),
                    max: f.model.fraction(f.model.closing),
                    what: format!("{} strut lattice", self.lattice_name),
                    why: "struts are under 2 voxels across at the finest resolution, or the pores close",
                }
            }
        }
    }

    /// The infill's thinnest members at density `rho`: their width in voxels at the requested
    /// resolution, the least they need, and what they are.
    fn members(&self, infill: &Kind, rho: f64) -> Option<(f64, f64, &'static str)> {
        let r = self.resolution as f64;
        match infill {
            Kind::Tpms(l) => (l.structure == Structure::Sheet).then(|| {
                let t = calibrate::analytic_level(l.surface, l.structure, rho);
                (
                    calibrate::thinnest_sheet_wall(l.surface, t) * r,
                    MIN_WALL_VOXELS,
                    "sheet walls",
                )
            }),
            Kind::Strut(f) => {
                let factor = f.part.cell.thinnest_factor();
                let across = 2.0 * f.model.radius(rho) * factor * r / self.min_cell();
                Some((across, MIN_STRUT_VOXELS, "struts"))
            }
        }
    }

    /// Runs a graded fill (see the module's notes).
    pub(super) fn run_graded(
        &self,
        grading: &Grading,
        progress: &Progress,
        sink: &mut dyn MeshSink,
    ) -> Result<FillReport> {
        let start = Instant::now();
        let (part, keep, changes) = closed_parts(self, progress)?;
        let phase = part.bounds().expect("a closed part has triangles").min;
        let infill = match &self.lattice {
            Infilling::Tpms { surface, structure } => Kind::Tpms(Lattice {
                surface: *surface,
                structure: *structure,
                level: 0.0,
                cell: self.cell,
                bounds: Aabb {
                    min: phase,
                    max: phase,
                },
                phase,
            }),
            Infilling::Strut { cell } => Kind::Strut(StrutFamily {
                part: StrutLattice {
                    cell: cell.clone(),
                    size: self.cell,
                    radius: 0.0,
                    blend: self.blend,
                    bounds: Aabb {
                        min: phase,
                        max: phase,
                    },
                    phase,
                },
                model: Arc::new(RadiusModel::new(cell, self.cell)),
            }),
        };
        let model_seconds = start.elapsed().as_secs_f64();
        let feasible = self.feasible(&infill);
        let build_shape = |resolution: u32| -> Result<Arc<Shape>> {
            let _p = progress.stage("building the part's distance field");
            self.shape(&part, &keep, self.min_cell() / resolution as f64)
        };
        let mut shape = build_shape(self.resolution)?;
        let core = |p: Vec3| {
            let d = shape.depth(p) - self.skin;
            (d >= 0.0).then_some(d)
        };
        let targets = grading.check(&shape.bounds, self.cell, &core, &feasible)?;
        let (resolution, warnings) = graded::raised(
            self.resolution,
            self.thin(self.members(&infill, targets.built[0])),
            self.auto_resolution,
            "break or perforate",
        )?;
        if resolution != self.resolution {
            shape = build_shape(resolution)?;
        }
        let voxel = self.min_cell() / resolution as f64;
        let opts = Options {
            instancing: false,
            ..self.beside(&shape, &self.options)
        };
        let (whole, base, _) = self.regions(&shape, &keep, voxel, &opts, progress)?;
        let cal_start = Instant::now();
        let (lo, hi) = (targets.built[0], targets.built[1]);
        let (bounds, cell) = (shape.bounds, self.cell);
        let skin = self.skin;
        let target = |p: Vec3| grading.target(p, (shape.depth(p) - skin).max(0.0), &feasible);
        let grid = CellVolumes::new(
            Aabb {
                min: phase,
                max: bounds.max,
            },
            cell,
        );
        let below = self.skin + self.blend + 2.0 * voxel;
        let cells = Cells::new(grid.clone(), &target, |c| {
            shape.holds(&grid.cell_box(c), below)
        });
        let run = |calibrated: bool, calibrate_seconds: f64| Run {
            grading,
            targets,
            feasible: feasible.clone(),
            voxel,
            resolution,
            options: opts,
            calibrated,
            timings: Timings {
                calibrate: model_seconds + calibrate_seconds,
                ..Timings::default()
            },
            warnings: warnings.clone(),
            start,
        };
        fn filled<L>(
            lattice: L,
            map: LevelMap,
            shape: &Arc<Shape>,
            job: &FillJob,
            base: f64,
            whole: f64,
        ) -> FilledGraded<L> {
            FilledGraded {
                lattice,
                map,
                shape: shape.clone(),
                skin: job.skin,
                blend: job.blend,
                base_volume: base,
                fill_volume: whole - base,
            }
        }
        let done = match infill {
            Kind::Tpms(l) => {
                let c = {
                    let _p = progress.stage("calibrating the density → level map");
                    let adaptivity = self.options.adaptivity;
                    Calibrated::build(l.surface, l.structure, cell, voxel, adaptivity, lo, hi)?
                };
                let kind = filled(l.with_bounds(bounds), c.map, &shape, self, base, whole);
                run(c.converged, cal_start.elapsed().as_secs_f64())
                    .over(&kind, &target, bounds, cells, progress, sink)?
            }
            Kind::Strut(f) => {
                let (map, met) = {
                    let _p = progress.stage("calibrating the density → radius map");
                    crate::lattice::strut::graded::calibrate(&f, voxel, &opts, lo, hi)?
                };
                let kind = filled(f.with_bounds(bounds), map, &shape, self, base, whole);
                run(met, cal_start.elapsed().as_secs_f64())
                    .over(&kind, &target, bounds, cells, progress, sink)?
            }
        };
        let level = done.mean_level;
        let mut part_report = done.part;
        let volume = part_report.volume.unwrap_or(f64::NAN);
        part_report.achieved_density = (volume - base) / (whole - base);
        Ok(self.report(
            changes,
            shape.drains.clone(),
            shape.memory_bytes(),
            Filled {
                level,
                level_search: done.level_search,
                part_volume: whole,
                skin_volume: base,
                resolution,
                voxel,
                grading: Some(done.grading),
                part: part_report,
            },
        ))
    }
}
