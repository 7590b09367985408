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
//! meshed in tiles are written from the first meshing; their cells are measured as they are
//! written.

use super::cells::{CellTee, CellVolumes};
use super::pipeline::{self, Family, Made, MeshingStats, Options, Route, Solid, Written};
use super::report::{LevelSearch, PartReport, Timings};
use crate::error::{Error, Result};
use crate::field::density::DensityField;
use crate::field::nodes::Nodes;
use crate::field::{Aabb, Field, Vec3};
use crate::grid::GridSpec;
use crate::io::sink::MeshSink;
use crate::progress::Progress;
use std::sync::Arc;

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
                    "the density field is {v} at ({}): densities are volume fractions in (0, 1)",
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
            return Err(Error::invalid("the part holds no lattice to grade"));
        }
        for (v, p) in [lo, hi] {
            if !self.clamp && (v < feasible.min || v > feasible.max) {
                return Err(Error::invalid(format!(
                    "the density field reaches {v:.4} at ({}), outside the feasible range of a {} ({:.3} to {:.3}), where {} (--clamp holds the field to the range)",
                    point(p),
                    feasible.what,
                    feasible.min,
                    feasible.max,
                    feasible.why
                )));
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

/// Knots at which a type is calibrated over `[lo, hi]`: six across it, one when it is a point.
pub fn knots(lo: f64, hi: f64) -> Vec<f64> {
    if hi - lo < 1e-6 {
        return vec![lo];
    }
    (0..6).map(|i| lo + (hi - lo) * i as f64 / 5.0).collect()
}

/// A type's calibrated density → level map at one voxel size, tabulated over a range.
#[derive(Debug, Clone)]
pub struct LevelMap {
    lo: f64,
    step: f64,
    levels: Vec<f64>,
}

impl LevelMap {
    /// The map over `[lo, hi]` from the meshing's bias at `knots` (the model's fraction at the
    /// level calibrated there, less the knot's density; interpolated between knots, held beyond
    /// them) and the type's exact model `model_level` (fraction → level). The table reaches
    /// [`MAP_MARGIN`] beyond the range, so that cells at its ends can be corrected past it.
    pub fn new(
        lo: f64,
        hi: f64,
        knots: &[f64],
        bias: &[f64],
        model_level: impl Fn(f64) -> f64,
    ) -> LevelMap {
        let lo = (lo - MAP_MARGIN).max(1e-3);
        let hi = (hi + MAP_MARGIN).min(1.0 - 1e-3);
        let n = 257;
        let step = (hi - lo) / (n - 1) as f64;
        let levels = (0..n)
            .map(|i| {
                let rho = lo + step * i as f64;
                let b = interpolate(knots, bias, rho);
                model_level((rho + b).clamp(1e-6, 1.0 - 1e-6))
            })
            .collect();
        LevelMap { lo, step, levels }
    }

    /// The level of density `rho` (held to the tabulated range).
    pub fn level(&self, rho: f64) -> f64 {
        let n = self.levels.len();
        let u = ((rho - self.lo) / self.step).clamp(0.0, (n - 1) as f64);
        let i = (u.floor() as usize).min(n - 2);
        let w = u - i as f64;
        self.levels[i] * (1.0 - w) + self.levels[i + 1] * w
    }
}

/// Piecewise-linear interpolation through `(xs, ys)`, held at the ends.
fn interpolate(xs: &[f64], ys: &[f64], x: f64) -> f64 {
    if xs.len() == 1 || x <= xs[0] {
        return ys[0];
    }
    for i in 1..xs.len() {
        if x <= xs[i] {
            let w = (x - xs[i - 1]) / (xs[i] - xs[i - 1]);
            return ys[i - 1] * (1.0 - w) + ys[i] * w;
        }
    }
    ys[ys.len() - 1]
}

/// The level at the nodes of a regular grid over the part's box and a margin, read trilinearly.
pub struct LevelGrid {
    nodes: Nodes,
    /// A bound on `|∇t|` (exact for the trilinear reading).
    pub lipschitz: f64,
    /// The mean level, for the family's model.
    pub mean: f64,
    /// The largest level.
    pub max: f64,
}

impl LevelGrid {
    /// Nodes `NODES_PER_CELL` per cell edge over `bounds` grown by `margin`, at level
    /// `level(p)`.
    pub fn build(
        bounds: &Aabb,
        cell: Vec3,
        margin: f64,
        level: impl Fn(Vec3) -> f64 + Sync,
    ) -> LevelGrid {
        let step = cell.map(|c| c / NODES_PER_CELL);
        let origin = [0, 1, 2].map(|a| bounds.min[a] - (margin / step[a]).ceil() * step[a]);
        let n =
            [0, 1, 2].map(|a| ((bounds.max[a] + margin - origin[a]) / step[a]).ceil() as usize + 1);
        let nodes = Nodes::sample(origin, step, n, level);
        LevelGrid {
            lipschitz: nodes.lipschitz(),
            mean: nodes.mean(),
            max: nodes.range()[1],
            nodes,
        }
    }

    /// The level at `p` and its gradient.
    #[inline(always)]
    pub fn at(&self, p: Vec3) -> (f64, Vec3) {
        self.nodes.with_gradient(p)
    }

    /// The level at the sample `(i, j, k)` of the 8³ block at `origin`, spacing `h`, plus
    /// `offset`.
    #[inline(always)]
    pub fn in_block(&self, origin: Vec3, h: f64, [i, j, k]: [usize; 3], offset: f64) -> f64 {
        let p = [
            origin[0] + h * i as f64,
            origin[1] + h * j as f64,
            origin[2] + h * k as f64,
        ];
        self.at(p).0 + offset
    }
}

/// A lattice clipped by a box whose level can vary from point to point.
pub trait Levelled: Clone + Sync {
    /// The lattice's field, its level at each point read off `levels` plus `offset`, set up for
    /// sampling on `spec`'s voxels.
    fn graded_field<'a>(
        &'a self,
        levels: &'a LevelGrid,
        offset: f64,
        spec: &GridSpec,
    ) -> Box<dyn Field + 'a>;
    /// The clipping box.
    fn bounds(&self) -> Aabb;
    /// The lattice clipped by another box.
    fn with_bounds(&self, bounds: Aabb) -> Self;
    /// The type's model: the fraction at a uniform level.
    fn model_fraction(&self, level: f64) -> f64;
    /// The model's inverse.
    fn model_level(&self, fraction: f64) -> f64;
}

/// A lattice whose level varies through its box, clipped by it.
#[derive(Clone)]
pub struct GradedPart<'a, L> {
    /// The lattice (its own level is not used).
    pub lattice: L,
    /// The level at each point.
    pub levels: &'a LevelGrid,
    /// Added to every level (the family's parameter; 0 as built).
    pub offset: f64,
}

impl<L: Levelled> Solid for GradedPart<'_, L> {
    fn field(&self, spec: &GridSpec) -> Box<dyn Field + '_> {
        self.lattice.graded_field(self.levels, self.offset, spec)
    }

    fn bounds(&self) -> Aabb {
        self.lattice.bounds()
    }

    fn with_bounds(&self, bounds: Aabb) -> Self {
        GradedPart {
            lattice: self.lattice.with_bounds(bounds),
            ..self.clone()
        }
    }

    fn period(&self) -> Option<Vec3> {
        None
    }
}

/// A graded part at every offset of its levels.
pub struct GradedFamily<'a, L> {
    /// The part at offset 0.
    pub part: GradedPart<'a, L>,
}

impl<'a, L: Levelled> Family for GradedFamily<'a, L> {
    type Solid = GradedPart<'a, L>;

    fn at(&self, level: f64) -> GradedPart<'a, L> {
        GradedPart {
            offset: level,
            ..self.part.clone()
        }
    }

    fn model_fraction(&self, level: f64) -> f64 {
        self.part
            .lattice
            .model_fraction(self.part.levels.mean + level)
    }

    fn model_level(&self, fraction: f64) -> f64 {
        self.part.lattice.model_level(fraction) - self.part.levels.mean
    }
}

/// A lattice type graded: its calibrated map and its part at a graded level.
pub trait Graded: Sync {
    /// The part at every offset of its levels (the family's level is added to every point's).
    type Family<'a>: Family
    where
        Self: 'a;
    /// The level of density `rho`.
    fn level(&self, rho: f64) -> f64;
    /// The part whose level at each point is read off `levels`.
    fn family<'a>(&'a self, levels: &'a LevelGrid) -> Self::Family<'a>;
}

/// A lattice and its calibrated map: the graded lattice in its box.
pub struct Mapped<L> {
    /// The lattice.
    pub lattice: L,
    /// Its density → level map.
    pub map: LevelMap,
}

impl<L: Levelled> Graded for Mapped<L> {
    type Family<'a>
        = GradedFamily<'a, L>
    where
        L: 'a;

    fn level(&self, rho: f64) -> f64 {
        self.map.level(rho)
    }

    fn family<'a>(&'a self, levels: &'a LevelGrid) -> GradedFamily<'a, L> {
        GradedFamily {
            part: GradedPart {
                lattice: self.lattice.clone(),
                levels,
                offset: 0.0,
            },
        }
    }
}

/// The cells of a graded part: which are promised, and what each is promised.
pub struct Cells {
    /// The cells, nothing measured.
    pub grid: CellVolumes,
    /// Whether each cell's density is promised.
    pub promised: Vec<bool>,
    /// The field at each cell's centre.
    pub targets: Vec<f64>,
    /// Each cell's promise.
    pub tolerances: Vec<f64>,
}

impl Cells {
    /// The cells of `grid` at density `target`; `promised` says which are.
    pub fn new(
        grid: CellVolumes,
        target: &dyn Fn(Vec3) -> f64,
        promised: impl Fn([usize; 3]) -> bool,
    ) -> Cells {
        let all: Vec<[usize; 3]> = grid.cells().collect();
        Cells {
            promised: all.iter().map(|c| promised(*c)).collect(),
            targets: all
                .iter()
                .map(|c| target(grid.cell_box(*c).centre()))
                .collect(),
            tolerances: all
                .iter()
                .map(|c| {
                    if flat_over(target, &grid.cell_box(*c)) {
                        FLAT_CELL_PROMISE
                    } else {
                        CELL_PROMISE
                    }
                })
                .collect(),
            grid,
        }
    }
}

/// A graded part meshed and written.
pub struct Outcome {
    /// What was written.
    pub written: Written,
    /// The route it took.
    pub route: Route,
    /// The meshings, as a level search.
    pub level_search: LevelSearch,
    /// Statistics of the meshings before the written one.
    pub meshing: MeshingStats,
    /// Meshings of the part.
    pub meshings: u32,
    /// Every cell, measured on what was written.
    pub cells: Vec<CellDensity>,
    /// The largest error over the promised cells.
    pub max_cell_error: f64,
    /// Every promised cell within its promise.
    pub cells_met: bool,
    /// The mean level written.
    pub mean_level: f64,
}

/// Meshes the graded part of `kind` over `bounds` to density `target`, corrects its cells (see
/// the module's notes) and writes the best meshing to `sink`.
#[allow(clippy::too_many_arguments)]
pub fn mesh<G: Graded>(
    kind: &G,
    target: &(dyn Fn(Vec3) -> f64 + Sync),
    bounds: &Aabb,
    cells: Cells,
    voxel: f64,
    opts: &Options,
    progress: &Progress,
    sink: &mut dyn MeshSink,
) -> Result<Outcome> {
    let Cells {
        grid,
        promised,
        targets,
        tolerances,
    } = cells;
    let margin = (pipeline::HALF_WIDTH + 2.0) * voxel;
    // Density shift per cell, read trilinearly between cell centres.
    let mut shift = vec![0.0; promised.len()];
    let build = |shift: &[f64]| {
        let shifts = between_centres(&grid, shift);
        LevelGrid::build(bounds, grid.cell(), margin, |p| {
            kind.level(target(p) + shifts.at(p))
        })
    };
    let mut levels = build(&shift);
    let mut brackets = vec![Bracket::default(); promised.len()];
    let mut best: Option<(f64, pipeline::Measured)> = None;
    let mut meshings = 0u32;
    let mut tried = Vec::new();
    let mut search_meshing = MeshingStats::default();
    let route = Route::choose(&kind.family(&levels).at(0.0), voxel, opts);
    let measured = loop {
        let m = {
            let _p = progress.stage(if meshings == 0 {
                "sampling and meshing the graded part"
            } else {
                "meshing the part again with its cells corrected"
            });
            pipeline::measure(&kind.family(&levels), 0.0, voxel, route, opts)?
        };
        meshings += 1;
        search_meshing.add(&m.meshing);
        tried.push((0.0, m.fraction));
        let Made::Whole(mesh) = &m.made else {
            break m;
        };
        let mut measured = grid.clone();
        measured.add_mesh(&mesh.to_mesh());
        let measured = measured.fractions();
        let worst = (0..promised.len())
            .filter(|&i| promised[i])
            .map(|i| (measured[i] - targets[i]).abs())
            .fold(0.0, f64::max);
        let done = worst <= AIM || meshings >= MAX_MESHINGS;
        // The meshing whose worst cell is closest is written.
        if best.as_ref().is_none_or(|b| worst < b.0) {
            best = Some((worst, m));
        }
        if done {
            break best.take().expect("a meshing was kept").1;
        }
        for i in 0..promised.len() {
            if promised[i] {
                shift[i] = brackets[i].next(shift[i], measured[i], targets[i]);
            }
        }
        extend_to_unpromised(&grid, &promised, &mut shift);
        levels = build(&shift);
    };
    let level_search = LevelSearch::new(&measured, route, &tried, Vec::new());
    let mut tee = CellTee {
        inner: sink,
        cells: grid,
    };
    let family = kind.family(&levels);
    let written = pipeline::write(&family, measured, voxel, route, opts, progress, &mut tee)?;
    let densities = tee.cells.fractions();
    let cells: Vec<CellDensity> = tee
        .cells
        .cells()
        .enumerate()
        .map(|(i, c)| CellDensity {
            cell: c,
            target: targets[i],
            density: densities[i],
            whole: promised[i],
            tolerance: tolerances[i],
        })
        .collect();
    let checked = cells.iter().filter(|c| c.whole);
    let max_cell_error = checked
        .clone()
        .map(|c| (c.density - c.target).abs())
        .fold(0.0, f64::max);
    let cells_met = checked
        .into_iter()
        .all(|c| (c.density - c.target).abs() <= c.tolerance);
    Ok(Outcome {
        written,
        route,
        level_search,
        meshing: search_meshing,
        meshings,
        cells,
        max_cell_error,
        cells_met,
        mean_level: levels.mean,
    })
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
        let grid = CellVolumes::new(bounds, cell);
        let (grading, feasible) = (self.grading, self.feasible.clone());
        let target = move |p: Vec3| grading.target(p, 0.0, &feasible);
        let cells = Cells::new(grid.clone(), &target, |c| grid.is_whole(c));
        self.over(kind, &target, bounds, cells, progress, sink)
    }

    /// A part in `bounds` at density `target`, `cells` promised theirs.
    pub fn over<G: Graded>(
        mut self,
        kind: &G,
        target: &(dyn Fn(Vec3) -> f64 + Sync),
        bounds: Aabb,
        cells: Cells,
        progress: &Progress,
        sink: &mut dyn MeshSink,
    ) -> Result<Finished> {
        if !self.calibrated {
            self.warnings.push(format!(
                "the unit cell could not be calibrated at every density on {} voxels per cell: finer voxels (--resolution) meet the field more closely",
                self.resolution
            ));
        }
        let outcome = mesh(
            kind,
            target,
            &bounds,
            cells,
            self.voxel,
            &self.options,
            progress,
            sink,
        )?;
        Ok(outcome.finish(
            self.grading,
            &self.targets,
            &self.feasible,
            bounds,
            self.timings,
            self.warnings,
            self.start,
        ))
    }
}

fn point(p: Vec3) -> String {
    p.map(|x| format!("{:.3}", x)).join(", ")
}

/// Whether `f` is constant over the box (on a 3×3×3 set of points).
fn flat_over(f: &dyn Fn(Vec3) -> f64, b: &Aabb) -> bool {
    let mut values = Vec::with_capacity(27);
    for i in 0..27 {
        let w = [i / 9, i / 3 % 3, i % 3];
        values.push(f(
            [0, 1, 2].map(|a| b.min[a] + (b.max[a] - b.min[a]) * w[a] as f64 / 2.0)
        ));
    }
    let (lo, hi) = values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(*v), b.max(*v))
        });
    hi - lo < 1e-9
}

/// Nodes at the cells' centres (read trilinearly between them, held at the outer centres
/// beyond them) whose mean over each cell is the cell's `means`: the reading's cell means are
/// a blur of the node values (along an axis, ⅛ of each neighbour and ¾ of the cell's own; ⅞ at
/// the ends, where the reading is held), so the node values are the means un-blurred — one
/// tridiagonal solve per line of cells along each axis. A cell is then shifted by what it asked,
/// not by a mixture of its neighbours' asks, and the correction converges in a few meshings
/// where the field bends sharply.
fn between_centres(cells: &CellVolumes, means: &[f64]) -> Nodes {
    let n = cells.counts;
    let mut values = means.to_vec();
    for axis in 0..3 {
        if n[axis] < 2 {
            continue;
        }
        let stride = [n[1] * n[2], n[2], 1][axis];
        let lines = (0..n[0] * n[1] * n[2]).filter(|i| (i / stride).is_multiple_of(n[axis]));
        for start in lines.collect::<Vec<_>>() {
            let idx: Vec<usize> = (0..n[axis]).map(|k| start + k * stride).collect();
            let line: Vec<f64> = idx.iter().map(|&i| values[i]).collect();
            for (k, v) in unblur(&line).into_iter().enumerate() {
                values[idx[k]] = v;
            }
        }
    }
    let b0 = cells.cell_box([0, 0, 0]);
    Nodes {
        origin: [0, 1, 2].map(|a| b0.min[a] + 0.5 * cells.cell()[a]),
        step: cells.cell(),
        n,
        values,
    }
}

/// Solves `⅛ s[k−1] + ¾ s[k] + ⅛ s[k+1] = m[k]` (`⅞ s[0] + ⅛ s[1]` and `⅛ s[n−2] + ⅞ s[n−1]`
/// at the ends) for `s` (Thomas' algorithm; the system is diagonally dominant). At least two
/// values.
fn unblur(m: &[f64]) -> Vec<f64> {
    let n = m.len();
    let (off, diag) = (
        0.125,
        |k: usize| if k == 0 || k == n - 1 { 0.875 } else { 0.75 },
    );
    let mut c = vec![0.0; n];
    let mut d = vec![0.0; n];
    c[0] = off / diag(0);
    d[0] = m[0] / diag(0);
    for k in 1..n {
        let w = diag(k) - off * c[k - 1];
        c[k] = off / w;
        d[k] = (m[k] - off * d[k - 1]) / w;
    }
    let mut s = d;
    for k in (0..n - 1).rev() {
        s[k] -= c[k] * s[k + 1];
    }
    s
}

/// One cell's correction: the shifts tried on either side of its target.
#[derive(Clone, Copy, Default)]
struct Bracket {
    /// `(shift, density)` of the last meshing below the target, and above it.
    below: Option<(f64, f64)>,
    above: Option<(f64, f64)>,
}

impl Bracket {
    /// The next shift of a cell that measured `density` at `shift`: its error added, until the
    /// target is bracketed; then the secant between the two sides, or their midpoint where the
    /// density jumps between them (a piece the box cuts loose, and that is removed, joins the
    /// lattice again between them: the level is pinned just above the jump).
    fn next(&mut self, shift: f64, density: f64, target: f64) -> f64 {
        if density < target {
            self.below = Some((shift, density));
        } else {
            self.above = Some((shift, density));
        }
        match (self.below, self.above) {
            (Some((s0, d0)), Some((s1, d1))) => {
                // The shift is in density's units: a jump moves the density far more.
                if (d1 - d0) > 2.0 * (s1 - s0).abs() + 0.002 {
                    0.5 * (s0 + s1)
                } else {
                    s0 + (target - d0) * (s1 - s0) / (d1 - d0).max(1e-9)
                }
            }
            _ => shift + target - density,
        }
    }
}

/// Gives each unpromised cell the shift of the nearest promised cell (along each axis, the
/// nearest promised index; unchanged where none is).
fn extend_to_unpromised(cells: &CellVolumes, promised: &[bool], shift: &mut [f64]) {
    let all: Vec<[usize; 3]> = cells.cells().collect();
    let on = |c: &[usize; 3]| promised[cells.index(*c)];
    let range = [0, 1, 2].map(|a| {
        let idx = all.iter().filter(|c| on(c)).map(|c| c[a]);
        idx.clone().min().zip(idx.max())
    });
    for c in &all {
        if on(c) {
            continue;
        }
        let Some(near) = (0..3)
            .map(|a| range[a].map(|(lo, hi)| c[a].clamp(lo, hi)))
            .collect::<Option<Vec<usize>>>()
        else {
            continue;
        };
        let near = [near[0], near[1], near[2]];
        if on(&near) {
            shift[cells.index(*c)] = shift[cells.index(near)];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The map reads the model at the density less the bias, interpolated between knots.
    #[test]
    fn level_map_removes_the_bias() {
        let model = |f: f64| 2.0 * f;
        let m = LevelMap::new(0.1, 0.5, &[0.1, 0.5], &[0.01, 0.03], model);
        for rho in [0.06f64, 0.1, 0.2, 0.35, 0.5, 0.54] {
            let b = 0.01 + 0.02 * ((rho - 0.1) / 0.4).clamp(0.0, 1.0);
            // Exact but where the bias bends between two of the table's rows.
            assert!((m.level(rho) - model(rho + b)).abs() < 1e-4, "{rho}");
        }
        // One knot (a flat field): the bias held, the table still spans the margin.
        let flat = LevelMap::new(0.3, 0.3, &[0.3], &[0.02], model);
        assert!((flat.level(0.28) - model(0.30)).abs() < 1e-9);
        assert_eq!(knots(0.3, 0.3), vec![0.3]);
        assert_eq!(knots(0.1, 0.6).len(), 6);
    }

    /// The nodes' trilinear reading has each cell's asked mean over the cell (by a fine
    /// midpoint rule), partial-free grids of 1 to 4 cells per axis.
    #[test]
    fn shifts_are_met_on_average_over_each_cell() {
        let grid = CellVolumes::new(
            Aabb {
                min: [1.0, -2.0, 0.5],
                max: [4.0, 2.0, 1.5],
            },
            [1.0; 3],
        );
        let means: Vec<f64> = (0..grid.counts.iter().product::<usize>())
            .map(|i| ((i * 7919) % 13) as f64 / 13.0 - 0.5)
            .collect();
        let nodes = between_centres(&grid, &means);
        let m = 24;
        for c in grid.cells().collect::<Vec<_>>() {
            let b = grid.cell_box(c);
            let mut sum = 0.0;
            for q in 0..m * m * m {
                let w = [q / (m * m), q / m % m, q % m];
                let p = [0, 1, 2].map(|a| b.min[a] + (w[a] as f64 + 0.5) / m as f64);
                sum += nodes.at(p);
            }
            let mean = sum / (m * m * m) as f64;
            assert!((mean - means[grid.index(c)]).abs() < 1e-3, "{c:?}");
        }
    }

    /// A bracketed cell takes the secant; a jump across the target takes the midpoint.
    #[test]
    fn brackets_close_on_the_target() {
        let mut b = Bracket::default();
        let s = b.next(0.0, 0.29, 0.30);
        assert!((s - 0.01).abs() < 1e-12);
        let s2 = b.next(s, 0.302, 0.30);
        assert!((s2 - (0.0 + 0.01 * 0.01 / 0.012)).abs() < 1e-12);
        let mut j = Bracket::default();
        j.next(0.0, 0.20, 0.30);
        assert!((j.next(0.02, 0.40, 0.30) - 0.01).abs() < 1e-12);
    }
}
