//! Graded parts: a density that varies through the part, met cell by cell — for any lattice
//! whose solid grows with one parameter (the TPMS level, the strut radius).
//!
//! The parameter varies from point to point through the type's calibrated density → level map
//! ([`LevelMap`]: the unit cell meshed at the part's own voxel at a handful of densities
//! spanning the field's range, the meshing's bias between them interpolated, and the level read
//! off the type's exact model at the density less that bias — no polynomial fit and no
//! empirical factor). The level is sampled on a grid of four nodes per cell edge and read
//! trilinearly between them ([`LevelGrid`]), so its Lipschitz bound (and the field's clearance,
//! which lets sampling skip blocks the surface cannot reach) is exact.
//!
//! A cell whose density varies across it does not hold exactly the fraction of the level at its
//! centre (the level's slope meets the cell's own asymmetry), and cells at the box's faces are
//! cut. So the part is meshed, each promised cell's density measured on the mesh
//! ([`super::cells`]), and each cell's density shifted by its error (the shift read
//! trilinearly between cell centres, so the correction has no seam) until every promised cell
//! is within [`AIM`] of the field at its centre, or [`MAX_MESHINGS`] meshings ([`mesh`]). Parts
//! meshed in tiles are corrected the same way: each meshing's cells are measured as its tiles
//! pass (nothing held), the fragments it drops taken from the cells their bounds cover, and the
//! best meshing's levels are meshed again as they are written.
//!
//! [`levels`] holds the level (the map, the grid, the graded part), [`correct`] the meshing and
//! the per-cell correction; this module the grading's setting, checks and reports.

use super::cells::CellVolumes;
use super::pipeline::Options;
use super::report::{LevelSearch, PartReport, Timings};
use crate::error::{Error, Result};
use crate::field::density::DensityField;
use crate::field::{Aabb, Vec3};
use crate::io::sink::MeshSink;
use crate::progress::Progress;
use std::sync::Arc;

pub mod correct;
pub mod levels;

pub use correct::{mesh, Cells, Outcome};
pub use levels::{
    calibrate_on, knots, Graded, GradedFamily, GradedPart, LevelGrid, LevelMap, Levelled, Mapped,
};

/// A promised cell's measured density must be within this of the field at its centre.
pub const CELL_PROMISE: f64 = 0.01;
/// … and within this where the field is constant over the cell.
pub const FLAT_CELL_PROMISE: f64 = 0.005;
/// Cells are corrected until every promised cell is within this.
pub const AIM: f64 = 0.003;
/// Meshings of the part the per-cell correction may take.
pub const MAX_MESHINGS: u32 = 6;
/// `--clamp` holds the field this far inside the feasible range's ends, where the lattice's
/// thinnest members are too thin to survive the box's cut.
pub const CLAMP_MARGIN: f64 = 0.01;
/// How far the density → level table reaches beyond the field's range (the corrections' room).
pub const MAP_MARGIN: f64 = 0.05;
/// Level nodes per cell edge.
const NODES_PER_CELL: f64 = 4.0;

/// A density field and what to do where it leaves the type's feasible range.
#[derive(Clone)]
pub struct Grading {
    /// The field.
    pub field: Arc<DensityField>,
    /// Hold the field to the feasible range instead of refusing it.
    pub clamp: bool,
}

impl std::fmt::Debug for Grading {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Grading({}, clamp {})", self.field.source, self.clamp)
    }
}

/// The densities a type can be built at, and its name for messages ("gyroid net").
#[derive(Debug, Clone)]
pub struct Feasible {
    /// The lowest density.
    pub min: f64,
    /// The highest density.
    pub max: f64,
    /// The type, as messages name it.
    pub what: String,
    /// Why the solid fails beyond the range, as messages say it.
    pub why: &'static str,
}

/// The field's range over the part.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Targets {
    /// Smallest and largest value over the box, before clamping.
    pub asked: [f64; 2],
    /// The range built.
    pub built: [f64; 2],
}

impl Grading {
    /// Refuses a field that reads `d`, the distance to a skin, for a part that has none.
    pub fn without_skin(&self) -> Result<()> {
        if self.field.uses_distance() {
            return Err(Error::invalid(
                "the density field reads d, the distance to a part's skin, which only latvox fill knows",
            ));
        }
        Ok(())
    }

    /// The density the part is built to at `p`, `d` mm inside its skin: the field's, held to
    /// the feasible range when clamped.
    pub fn target(&self, p: Vec3, d: f64, feasible: &Feasible) -> f64 {
        let v = self.field.at(p, d);
        if self.clamp {
            v.clamp(feasible.min + CLAMP_MARGIN, feasible.max - CLAMP_MARGIN)
        } else {
            v
        }
    }

    /// The field's range over the part, on the level grid's nodes over `bounds` (`distance`:
    /// how far inside the skin a point is; points where it is `None` are not part of the
    /// lattice): refused where it is not a volume fraction, or leaves `feasible` (unless
    /// clamped).
    pub fn check(
        &self,
        bounds: &Aabb,
        cell: Vec3,
        distance: &dyn Fn(Vec3) -> Option<f64>,
        feasible: &Feasible,
    ) -> Result<Targets> {
        let size = bounds.size();
        let n = [0, 1, 2].map(|a| ((size[a] / cell[a]) * NODES_PER_CELL).ceil() as usize + 1);
        let (mut lo, mut hi) = ((f64::INFINITY, [0.0; 3]), (f64::NEG_INFINITY, [0.0; 3]));
        for i in 0..n[0] * n[1] * n[2] {
            let c = [i / (n[1] * n[2]), i / n[2] % n[1], i % n[2]];
            let p = [0, 1, 2].map(|a| bounds.min[a] + size[a] * c[a] as f64 / (n[a] - 1) as f64);
            let Some(d) = distance(p) else { continue };
            let v = self.field.at(p, d);
            if !(v > 0.0 && v < 1.0) {
                return Err(Error::invalid(format!(
                    "the density field ({}) is {v} at ({}): densities are volume fractions in (0, 1)",
                    self.field.source,
                    point(p)
                )));
            }
            if v < lo.0 {
                lo = (v, p);
            }
            if v > hi.0 {
                hi = (v, p);
            }
        }
        if lo.0 > hi.0 {
            return Err(Error::invalid(
                "no point of the part holds lattice: the skin leaves no room for one",
            ));
        }
        for (v, p) in [lo, hi] {
            if !self.clamp && (v < feasible.min || v > feasible.max) {
                return Err(Error::Infeasible {
                    setting: "density".into(),
                    value: v,
                    min: feasible.min,
                    max: feasible.max,
                    message: format!(
                        "the density field reaches {v:.4} at ({}), outside the feasible range of a {} ({:.3} to {:.3}), where {} (--clamp holds the field to the range)",
                        point(p),
                        feasible.what,
                        feasible.min,
                        feasible.max,
                        feasible.why
                    ),
                });
            }
        }
        let built = if self.clamp {
            let (a, b) = (feasible.min + CLAMP_MARGIN, feasible.max - CLAMP_MARGIN);
            [lo.0.clamp(a, b), hi.0.clamp(a, b)]
        } else {
            [lo.0, hi.0]
        };
        Ok(Targets {
            asked: [lo.0, hi.0],
            built,
        })
    }
}

/// What grading did, in the report.
#[derive(Debug, Clone, serde::Serialize)]
pub struct GradingReport {
    /// The field, as given.
    pub field: String,
    /// The field's smallest and largest value over the box, as built (after clamping).
    pub range: [f64; 2],
    /// The field's range before clamping, when `--clamp` held it to the feasible range.
    pub clamped_from: Option<[f64; 2]>,
    /// Meshings of the part: the first, and one per correction of the cells.
    pub meshings: u32,
    /// Cells promised: whole cells (of a filled part: whole cells wholly inside its core).
    pub whole_cells: usize,
    /// Largest `|density − field at centre|` over the promised cells.
    pub max_cell_error: f64,
    /// Every promised cell within its promise ([`CELL_PROMISE`], or [`FLAT_CELL_PROMISE`]
    /// where the field is constant over the cell).
    pub cells_met: bool,
    /// Each cell: index, the field at its centre, the density measured on the written mesh,
    /// whether it is promised, and its promise.
    pub cells: Vec<CellDensity>,
}

/// One cell of a graded part.
#[derive(Debug, Clone, serde::Serialize)]
pub struct CellDensity {
    /// Index along x, y, z.
    pub cell: [usize; 3],
    /// The field at the cell's centre.
    pub target: f64,
    /// The volume fraction of the written mesh inside the cell's box.
    pub density: f64,
    /// Whether the cell's density is promised (partial cells are measured, not promised).
    pub whole: bool,
    /// The promise on this cell's density.
    pub tolerance: f64,
}

impl GradingReport {
    /// The report of `grading`, built over `targets`, meshed to `outcome`.
    pub fn new(grading: &Grading, targets: &Targets, outcome: &Outcome) -> GradingReport {
        let clamped = grading.clamp && targets.asked != targets.built;
        GradingReport {
            field: grading.field.source.clone(),
            range: targets.built,
            clamped_from: clamped.then_some(targets.asked),
            meshings: outcome.meshings,
            whole_cells: outcome.cells.iter().filter(|c| c.whole).count(),
            max_cell_error: outcome.max_cell_error,
            cells_met: outcome.cells_met,
            cells: outcome.cells.clone(),
        }
    }

    /// What the report should warn of: the worst cell when a promise is missed, the clamp.
    pub fn warnings(&self, feasible: &Feasible) -> Vec<String> {
        let mut out = Vec::new();
        let worst = self.cells.iter().filter(|c| c.whole).max_by(|a, b| {
            (a.density - a.target)
                .abs()
                .total_cmp(&(b.density - b.target).abs())
        });
        if let Some(w) = worst.filter(|_| !self.cells_met) {
            out.push(format!(
                "cell {:?} has density {:.4} where the field asks {:.4} (promise ±{})",
                w.cell, w.density, w.target, w.tolerance
            ));
        }
        if let Some([a, b]) = self.clamped_from {
            out.push(format!(
                "the density field ({a:.3} to {b:.3}) was held to the feasible range of a {} ({:.3} to {:.3}, {CLAMP_MARGIN} inside its ends)",
                feasible.what, feasible.min, feasible.max
            ));
        }
        out
    }
}

/// The resolution a graded part is built at: `requested`, or the one its thinnest members
/// need at the field's lowest density (`thin`: that resolution and why), with the warning that
/// says so; refused at a fixed resolution (`fails`: what the members would do).
pub fn raised(
    requested: u32,
    thin: Option<(u32, String)>,
    auto: bool,
    fails: &str,
) -> Result<(u32, Vec<String>)> {
    match thin {
        None => Ok((requested, Vec::new())),
        Some((r, why)) if !auto => Err(Error::invalid(format!(
            "{why}: they would {fails} (--resolution {r} or more, or drop --fixed-resolution)"
        ))),
        Some((r, why)) => Ok((
            r,
            vec![format!(
                "{why} at the field's lowest density: the resolution was raised to {r}"
            )],
        )),
    }
}

/// A graded part's reports.
pub struct Finished {
    /// The part's.
    pub part: PartReport,
    /// The grading's.
    pub grading: GradingReport,
    /// The meshings, as a level search.
    pub level_search: LevelSearch,
    /// The mean level written.
    pub mean_level: f64,
}

impl Outcome {
    /// The reports of the part in `bounds` graded by `grading` over `targets` (`timings`: the
    /// type's own; `warnings`: the job's, before the grading's and the mesh's), its verdict on
    /// density that every promised cell met its promise.
    #[allow(clippy::too_many_arguments)]
    pub fn finish(
        self,
        grading: &Grading,
        targets: &Targets,
        feasible: &Feasible,
        bounds: Aabb,
        timings: Timings,
        mut warnings: Vec<String>,
        start: std::time::Instant,
    ) -> Finished {
        let report = GradingReport::new(grading, targets, &self);
        let mut part = PartReport::new(
            bounds,
            None,
            self.route,
            self.written,
            self.meshing,
            timings,
        );
        part.density_met = Some(report.cells_met);
        warnings.extend(report.warnings(feasible));
        warnings.append(&mut part.warnings);
        part.warnings = warnings;
        part.timings.total = start.elapsed().as_secs_f64();
        Finished {
            part,
            grading: report,
            level_search: self.level_search,
            mean_level: self.mean_level,
        }
    }
}

/// A graded job's setting, once its type is calibrated: what [`Run::in_box`] and
/// [`Run::over`] need to mesh, correct and report the part.
pub struct Run<'a> {
    /// The grading.
    pub grading: &'a Grading,
    /// The field's range over the part.
    pub targets: Targets,
    /// The type's feasible range.
    pub feasible: Feasible,
    /// Voxel edge, mm.
    pub voxel: f64,
    /// Voxels per cell (for messages).
    pub resolution: u32,
    /// The pipeline's options.
    pub options: Options,
    /// Whether every calibration of the map converged.
    pub calibrated: bool,
    /// The type's own timings (its calibration).
    pub timings: Timings,
    /// The job's warnings so far.
    pub warnings: Vec<String>,
    /// When the job started.
    pub start: std::time::Instant,
}

impl Run<'_> {
    /// A lattice in the box `bounds` of cells `cell` from its lower corner, each whole cell
    /// promised its density.
    pub fn in_box<G: Graded>(
        self,
        kind: &G,
        bounds: Aabb,
        cell: Vec3,
        progress: &Progress,
        sink: &mut dyn MeshSink,
    ) -> Result<Finished> {
        self.try_in_box(kind, bounds, cell, false, progress, sink)
            .map(|f| f.expect("written when not held back"))
    }

    /// [`Run::in_box`]; with `hold_back`, nothing is written and `None` returned when even the
    /// best meshing misses a promised cell (finer voxels may meet it).
    pub fn try_in_box<G: Graded>(
        self,
        kind: &G,
        bounds: Aabb,
        cell: Vec3,
        hold_back: bool,
        progress: &Progress,
        sink: &mut dyn MeshSink,
    ) -> Result<Option<Finished>> {
        let grid = CellVolumes::new(bounds, cell);
        let (grading, feasible) = (self.grading, self.feasible.clone());
        let target = move |p: Vec3| grading.target(p, 0.0, &feasible);
        let cells = Cells::new(grid.clone(), &target, |c| grid.is_whole(c));
        self.try_over(kind, &target, bounds, cells, hold_back, progress, sink)
    }

    /// A part in `bounds` at density `target`, `cells` promised theirs.
    pub fn over<G: Graded>(
        self,
        kind: &G,
        target: &(dyn Fn(Vec3) -> f64 + Sync),
        bounds: Aabb,
        cells: Cells,
        progress: &Progress,
        sink: &mut dyn MeshSink,
    ) -> Result<Finished> {
        self.try_over(kind, target, bounds, cells, false, progress, sink)
            .map(|f| f.expect("written when not held back"))
    }

    /// [`Run::over`], holding back a part that misses a promised cell when `hold_back`.
    #[allow(clippy::too_many_arguments)]
    fn try_over<G: Graded>(
        mut self,
        kind: &G,
        target: &(dyn Fn(Vec3) -> f64 + Sync),
        bounds: Aabb,
        cells: Cells,
        hold_back: bool,
        progress: &Progress,
        sink: &mut dyn MeshSink,
    ) -> Result<Option<Finished>> {
        if !self.calibrated {
            self.warnings.push(format!(
                "the unit cell could not be calibrated at every density on {} voxels per cell: finer voxels (--resolution) meet the field more closely",
                self.resolution
            ));
        }
        let Some(outcome) = mesh(
            kind,
            target,
            &bounds,
            cells,
            self.voxel,
            &self.options,
            hold_back,
            progress,
            sink,
        )?
        else {
            return Ok(None);
        };
        Ok(Some(outcome.finish(
            self.grading,
            &self.targets,
            &self.feasible,
            bounds,
            self.timings,
            self.warnings,
            self.start,
        )))
    }
}

fn point(p: Vec3) -> String {
    p.map(|x| format!("{:.3}", x)).join(", ")
}
