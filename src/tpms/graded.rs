//! Graded TPMS lattices: a density that varies through the part, met cell by cell.
//!
//! The level varies from point to point through the type's calibrated density → level map: the
//! unit cell is meshed at the part's own voxel size at a handful of densities spanning the
//! field's range (as a uniform part's first guess is), the meshing's bias between them
//! interpolated, and the analytic level read off the exact fraction at the density less that
//! bias — no polynomial fit of the level and no empirical factor. The level is sampled on a grid
//! of four nodes per cell edge and read trilinearly between them, so its Lipschitz bound (and
//! the field's clearance, which lets sampling skip blocks the surface cannot reach) is exact.
//!
//! A cell whose density varies across it does not hold exactly the fraction of the level at its
//! centre (the level's slope meets the cell's own asymmetry), and cells at the box's faces are
//! cut. So the part is meshed, each whole cell's density measured on the mesh
//! ([`crate::mesh::cells`]), and each cell's density shifted by its error (the shift read
//! trilinearly between cell centres, so the correction has no seam) until every whole cell is
//! within [`AIM`] of the field at its centre, or [`MAX_MESHINGS`] meshings. Parts meshed in
//! tiles are written from the first meshing; their cells are measured as they are written.

use super::calibrate::{self, Calibration};
use super::job::TpmsJob;
use super::{Lattice, Structure, Surface, TpmsField, TpmsReport};
use crate::error::{Error, Result};
use crate::field::density::DensityField;
use crate::field::{Aabb, Field, Vec3};
use crate::grid::GridSpec;
use crate::io::sink::MeshSink;
use crate::mesh::cells::{CellTee, CellVolumes};
use crate::mesh::pipeline::{self, Family, Made, Options, Route, Solid};
use crate::mesh::report::{LevelSearch, PartReport, Timings};
use crate::progress::Progress;
use std::time::Instant;

/// A whole cell's measured density must be within this of the field at its centre.
pub const CELL_PROMISE: f64 = 0.01;
/// … and within this where the field is constant over the cell.
pub const FLAT_CELL_PROMISE: f64 = 0.005;
/// Cells are corrected until every whole cell is within this.
pub const AIM: f64 = 0.003;
/// Meshings of the part the per-cell correction may take.
pub const MAX_MESHINGS: u32 = 6;
/// `--clamp` holds the field this far inside the feasible range's ends, where the lattice's
/// necks are too thin to survive the box's cut.
pub const CLAMP_MARGIN: f64 = 0.01;
/// Level nodes per cell edge.
const NODES_PER_CELL: f64 = 4.0;

/// A density field and what to do where it leaves the type's feasible range.
#[derive(Clone)]
pub struct Grading {
    /// The field.
    pub field: std::sync::Arc<DensityField>,
    /// Hold the field to the feasible range instead of refusing it.
    pub clamp: bool,
}

impl std::fmt::Debug for Grading {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Grading({}, clamp {})", self.field.source, self.clamp)
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
    /// Whole cells checked.
    pub whole_cells: usize,
    /// Largest `|density − field at centre|` over the whole cells.
    pub max_cell_error: f64,
    /// Every whole cell within its promise ([`CELL_PROMISE`], or [`FLAT_CELL_PROMISE`] where
    /// the field is constant over the cell).
    pub cells_met: bool,
    /// Each cell: index, the field at its centre, the density measured on the written mesh,
    /// whether it is whole, and its promise.
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
    /// Whether the cell is whole (partial cells are measured, not promised).
    pub whole: bool,
    /// The promise on this cell's density.
    pub tolerance: f64,
}

/// The calibrated density → level map of a type at one voxel size, tabulated over a range.
pub struct LevelMap {
    lo: f64,
    step: f64,
    levels: Vec<f64>,
    /// The calibration at the middle of the range (for the report).
    pub middle: Calibration,
    /// Whether every calibration converged.
    pub converged: bool,
}

impl LevelMap {
    /// Calibrates the unit cell at densities spanning `[lo, hi]` on voxels of `voxel`.
    pub fn build(
        surface: Surface,
        structure: Structure,
        cell: Vec3,
        voxel: f64,
        adaptivity: f64,
        lo: f64,
        hi: f64,
    ) -> Result<LevelMap> {
        let k = if hi - lo < 1e-6 { 1 } else { 6 };
        let knots: Vec<f64> = (0..k)
            .map(|i| {
                if k == 1 {
                    lo
                } else {
                    lo + (hi - lo) * i as f64 / (k - 1) as f64
                }
            })
            .collect();
        let mut bias = Vec::with_capacity(k);
        let mut middle = None;
        let mut converged = true;
        for (i, &rho) in knots.iter().enumerate() {
            // An interior cell: the part's faces are met by the per-cell correction.
            let cal =
                calibrate::calibrate(surface, structure, rho, cell, voxel, [1e6; 3], adaptivity)?;
            converged &= cal.converged;
            bias.push(calibrate::analytic_fraction(surface, structure, cal.level) - rho);
            if i == k / 2 {
                middle = Some(cal);
            }
        }
        let n = if k == 1 { 1 } else { 257 };
        let step = if n == 1 {
            1.0
        } else {
            (hi - lo) / (n - 1) as f64
        };
        let levels = (0..n)
            .map(|i| {
                let rho = lo + step * i as f64;
                let b = interpolate(&knots, &bias, rho);
                calibrate::analytic_level(surface, structure, (rho + b).clamp(1e-6, 1.0 - 1e-6))
            })
            .collect();
        Ok(LevelMap {
            lo,
            step,
            levels,
            middle: middle.expect("at least one knot"),
            converged,
        })
    }

    /// The level of density `rho` (held to the tabulated range).
    pub fn level(&self, rho: f64) -> f64 {
        let n = self.levels.len();
        if n == 1 {
            return self.levels[0];
        }
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
    origin: Vec3,
    step: Vec3,
    n: [usize; 3],
    t: Vec<f64>,
    /// A bound on `|∇t|` (exact for the trilinear reading).
    lipschitz: f64,
    /// The mean level, for the family's model.
    mean: f64,
}

impl LevelGrid {
    /// Nodes `NODES_PER_CELL` per cell edge over `bounds` grown by `margin`, at level
    /// `level(p)`.
    fn build(
        bounds: &Aabb,
        cell: Vec3,
        margin: f64,
        level: impl Fn(Vec3) -> f64 + Sync,
    ) -> LevelGrid {
        use rayon::prelude::*;
        let step = cell.map(|c| c / NODES_PER_CELL);
        let origin = [0, 1, 2].map(|a| bounds.min[a] - (margin / step[a]).ceil() * step[a]);
        let n =
            [0, 1, 2].map(|a| ((bounds.max[a] + margin - origin[a]) / step[a]).ceil() as usize + 1);
        let t: Vec<f64> = (0..n[0] * n[1] * n[2])
            .into_par_iter()
            .map(|i| {
                let (x, y, z) = (i / (n[1] * n[2]), i / n[2] % n[1], i % n[2]);
                level([
                    origin[0] + x as f64 * step[0],
                    origin[1] + y as f64 * step[1],
                    origin[2] + z as f64 * step[2],
                ])
            })
            .collect();
        let mut slope = [0.0f64; 3];
        for x in 0..n[0] {
            for y in 0..n[1] {
                for z in 0..n[2] {
                    let at = |x: usize, y: usize, z: usize| t[(x * n[1] + y) * n[2] + z];
                    let v = at(x, y, z);
                    if x + 1 < n[0] {
                        slope[0] = slope[0].max((at(x + 1, y, z) - v).abs() / step[0]);
                    }
                    if y + 1 < n[1] {
                        slope[1] = slope[1].max((at(x, y + 1, z) - v).abs() / step[1]);
                    }
                    if z + 1 < n[2] {
                        slope[2] = slope[2].max((at(x, y, z + 1) - v).abs() / step[2]);
                    }
                }
            }
        }
        let mean = t.iter().sum::<f64>() / t.len() as f64;
        LevelGrid {
            origin,
            step,
            n,
            t,
            lipschitz: (slope[0].powi(2) + slope[1].powi(2) + slope[2].powi(2)).sqrt(),
            mean,
        }
    }

    /// The level at `p` and its gradient.
    #[inline(always)]
    fn at(&self, p: Vec3) -> (f64, Vec3) {
        let mut i0 = [0usize; 3];
        let mut w = [0.0; 3];
        for a in 0..3 {
            let u = ((p[a] - self.origin[a]) / self.step[a]).clamp(0.0, (self.n[a] - 1) as f64);
            i0[a] = (u as usize).min(self.n[a] - 2);
            w[a] = u - i0[a] as f64;
        }
        let n = self.n;
        let base = (i0[0] * n[1] + i0[1]) * n[2] + i0[2];
        let c = |dx: usize, dy: usize, dz: usize| self.t[base + (dx * n[1] + dy) * n[2] + dz];
        let lerp = |a: f64, b: f64, w: f64| a + (b - a) * w;
        let (c00, c01) = (
            lerp(c(0, 0, 0), c(0, 0, 1), w[2]),
            lerp(c(0, 1, 0), c(0, 1, 1), w[2]),
        );
        let (c10, c11) = (
            lerp(c(1, 0, 0), c(1, 0, 1), w[2]),
            lerp(c(1, 1, 0), c(1, 1, 1), w[2]),
        );
        let (c0, c1) = (lerp(c00, c01, w[1]), lerp(c10, c11, w[1]));
        let v = lerp(c0, c1, w[0]);
        let gx = (c1 - c0) / self.step[0];
        let gy = lerp(c01 - c00, c11 - c10, w[0]) / self.step[1];
        let dz = |y: usize| lerp(c(0, y, 1) - c(0, y, 0), c(1, y, 1) - c(1, y, 0), w[0]);
        let gz = lerp(dz(0), dz(1), w[1]) / self.step[2];
        (v, [gx, gy, gz])
    }
}

/// A TPMS lattice whose level varies through its box, clipped by it.
#[derive(Clone, Copy)]
pub struct GradedLattice<'a> {
    /// The lattice (its level is not used).
    pub lattice: Lattice,
    /// The level at each point.
    pub levels: &'a LevelGrid,
    /// Added to every level (the family's parameter; 0 as built).
    pub offset: f64,
}

struct GradedField<'a> {
    tpms: TpmsField,
    levels: &'a LevelGrid,
    offset: f64,
    lipschitz: f64,
}

impl GradedField<'_> {
    #[inline(always)]
    fn level(&self, p: Vec3) -> (f64, Vec3) {
        let (t, g) = self.levels.at(p);
        (t + self.offset, g)
    }
}

impl Field for GradedField<'_> {
    fn value(&self, p: Vec3) -> f64 {
        let (f, g) = self.tpms.eval_at(p);
        self.tpms.distance_at(f, g, self.level(p).0)
    }

    fn clearance(&self, p: Vec3) -> f64 {
        self.value_and_clearance(p).1
    }

    fn value_and_clearance(&self, p: Vec3) -> (f64, f64) {
        let (f, g) = self.tpms.eval_at(p);
        let t = self.level(p).0;
        (
            self.tpms.distance_at(f, g, t),
            self.tpms.implicit_at(f, t).abs() / self.lipschitz,
        )
    }

    fn implicit_with_gradient(&self, p: Vec3) -> (f64, Vec3) {
        let (f, g) = self.tpms.eval_at(p);
        let (t, gt) = self.level(p);
        let sign = match self.tpms.structure {
            Structure::Net => 1.0,
            Structure::Sheet => f.signum(),
            Structure::NetOther => -1.0,
        };
        (
            self.tpms.implicit_at(f, t),
            [0, 1, 2].map(|a| sign * g[a] / self.tpms.cell[a] - gt[a]),
        )
    }

    fn sample_block(&self, origin: Vec3, h: f64, out: &mut [f32; 512]) {
        self.tpms.sample_block_at(origin, h, out, |i, j, k| {
            self.level([
                origin[0] + h * i as f64,
                origin[1] + h * j as f64,
                origin[2] + h * k as f64,
            ])
            .0
        })
    }
}

impl Solid for GradedLattice<'_> {
    fn field(&self, spec: &GridSpec) -> Box<dyn Field + '_> {
        let tpms = self
            .lattice
            .field(spec.half_width * spec.voxel)
            .with_periodic_samples(spec.voxel);
        Box::new(GradedField {
            lipschitz: tpms.lipschitz() + self.levels.lipschitz,
            tpms,
            levels: self.levels,
            offset: self.offset,
        })
    }

    fn bounds(&self) -> Aabb {
        self.lattice.bounds
    }

    fn with_bounds(&self, bounds: Aabb) -> Self {
        GradedLattice {
            lattice: Lattice {
                bounds,
                ..self.lattice
            },
            ..*self
        }
    }

    fn period(&self) -> Option<Vec3> {
        None
    }
}

/// The graded part at every offset of its levels.
struct GradedFamily<'a> {
    part: GradedLattice<'a>,
}

impl<'a> Family for GradedFamily<'a> {
    type Solid = GradedLattice<'a>;

    fn at(&self, level: f64) -> GradedLattice<'a> {
        GradedLattice {
            offset: level,
            ..self.part
        }
    }

    fn model_fraction(&self, level: f64) -> f64 {
        let l = &self.part.lattice;
        calibrate::analytic_fraction(l.surface, l.structure, self.part.levels.mean + level)
    }

    fn model_level(&self, fraction: f64) -> f64 {
        let l = &self.part.lattice;
        calibrate::analytic_level(l.surface, l.structure, fraction) - self.part.levels.mean
    }
}

/// The field's targets over the part: at the level nodes' places and the cells' centres.
struct Targets {
    /// Smallest and largest value over the box, before clamping.
    asked: [f64; 2],
    /// The range built.
    built: [f64; 2],
}

impl TpmsJob {
    /// Runs a graded job (see the module's notes).
    pub(super) fn run_graded(
        &self,
        grading: &Grading,
        progress: &Progress,
        sink: &mut dyn MeshSink,
    ) -> Result<TpmsReport> {
        let start = Instant::now();
        let (s, st) = (self.surface, self.structure);
        let field = &*grading.field;
        if field.uses_distance() {
            return Err(Error::invalid(
                "the density field reads d, the distance to a part's skin, which only latvox fill knows",
            ));
        }
        let bounds = self.domain.bounds();
        let cell = self.domain.cell;
        let range = calibrate::feasible(s, st);
        let targets = self.check_field(grading, range)?;
        // Sheet walls are thinnest at the lowest density.
        let mut warnings = Vec::new();
        let mut resolution = self.resolution;
        if let Some((r, why)) = self.thin_walls(calibrate::analytic_level(s, st, targets.built[0]))
        {
            if !self.auto_resolution {
                return Err(Error::invalid(format!(
                    "{why}: they would perforate (--resolution {r} or more, or drop --fixed-resolution)"
                )));
            }
            warnings.push(format!(
                "{why} at the field's lowest density: the resolution was raised to {r}"
            ));
            resolution = r;
        }
        let voxel = cell.iter().cloned().fold(f64::INFINITY, f64::min) / resolution as f64;
        let target = |p: Vec3| {
            let v = field.at(p, 0.0);
            if grading.clamp {
                v.clamp(range.min + CLAMP_MARGIN, range.max - CLAMP_MARGIN)
            } else {
                v
            }
        };
        let cal_start = Instant::now();
        let map = {
            let _p = progress.stage("calibrating the density → level map");
            LevelMap::build(
                s,
                st,
                cell,
                voxel,
                self.adaptivity,
                targets.built[0],
                targets.built[1],
            )?
        };
        let calibrate_seconds = cal_start.elapsed().as_secs_f64();
        let lattice = Lattice {
            surface: s,
            structure: st,
            level: map.middle.level,
            cell,
            bounds,
            phase: bounds.min,
        };
        let opts = Options {
            adaptivity: self.adaptivity,
            verify: self.verify,
            instancing: false,
            tile: self.tile,
            memory: self.memory,
            keep_fragments: self.keep_fragments,
        };
        let cells = CellVolumes::new(bounds, cell);
        let whole: Vec<bool> = cells.cells().map(|c| cells.is_whole(c)).collect();
        let centre_targets: Vec<f64> = cells
            .cells()
            .map(|c| {
                let b = cells.cell_box(c);
                target([0, 1, 2].map(|a| 0.5 * (b.min[a] + b.max[a])))
            })
            .collect();
        let tolerances: Vec<f64> = cells
            .cells()
            .map(|c| {
                if flat_over(&target, &cells.cell_box(c)) {
                    FLAT_CELL_PROMISE
                } else {
                    CELL_PROMISE
                }
            })
            .collect();
        // Density shift per cell, read trilinearly between cell centres.
        let mut shift = vec![0.0; whole.len()];
        let margin = (pipeline::HALF_WIDTH + 2.0) * voxel;
        let build = |shift: &[f64]| {
            LevelGrid::build(&bounds, cell, margin, |p| {
                map.level(target(p) + interpolate_cells(&cells, shift, p))
            })
        };
        let mut levels = build(&shift);
        let mut brackets = vec![Bracket::default(); whole.len()];
        let mut best: Option<(f64, pipeline::Measured)> = None;
        let mut meshings = 0u32;
        let mut tried = Vec::new();
        let mut search_meshing = pipeline::MeshingStats::default();
        let route = Route::choose(
            &GradedLattice {
                lattice,
                levels: &levels,
                offset: 0.0,
            },
            voxel,
            &opts,
        );
        let measured = loop {
            let family = GradedFamily {
                part: GradedLattice {
                    lattice,
                    levels: &levels,
                    offset: 0.0,
                },
            };
            let m = {
                let _p = progress.stage(if meshings == 0 {
                    "sampling and meshing the graded part"
                } else {
                    "meshing the part again with its cells corrected"
                });
                pipeline::measure(&family, 0.0, voxel, route, &opts)?
            };
            meshings += 1;
            search_meshing.add(&m.meshing);
            tried.push((0.0, m.fraction));
            let Made::Whole(mesh) = &m.made else {
                break m;
            };
            let measured = CellVolumes::of_mesh(&mesh.to_mesh(), bounds, cell).fractions();
            let worst = (0..whole.len())
                .filter(|&i| whole[i])
                .map(|i| (measured[i] - centre_targets[i]).abs())
                .fold(0.0, f64::max);
            let done = worst <= AIM || meshings >= MAX_MESHINGS;
            // The meshing whose worst cell is closest is written.
            if best.as_ref().is_none_or(|b| worst < b.0) {
                best = Some((worst, m));
            }
            if done {
                break best.take().expect("a meshing was kept").1;
            }
            for i in 0..whole.len() {
                if whole[i] {
                    shift[i] = brackets[i].next(shift[i], measured[i], centre_targets[i]);
                }
            }
            extend_to_partial_cells(&cells, &whole, &mut shift);
            levels = build(&shift);
        };
        let family = GradedFamily {
            part: GradedLattice {
                lattice,
                levels: &levels,
                offset: 0.0,
            },
        };
        let level_search = LevelSearch::new(&measured, route, &tried, Vec::new());
        let mut tee = CellTee { inner: sink, cells };
        let written = pipeline::write(&family, measured, voxel, route, &opts, progress, &mut tee)?;
        let densities = tee.cells.fractions();
        let cell_reports: Vec<CellDensity> = tee
            .cells
            .cells()
            .enumerate()
            .map(|(i, c)| CellDensity {
                cell: c,
                target: centre_targets[i],
                density: densities[i],
                whole: whole[i],
                tolerance: tolerances[i],
            })
            .collect();
        let checked: Vec<&CellDensity> = cell_reports.iter().filter(|c| c.whole).collect();
        let max_cell_error = checked
            .iter()
            .map(|c| (c.density - c.target).abs())
            .fold(0.0, f64::max);
        let cells_met = checked
            .iter()
            .all(|c| (c.density - c.target).abs() <= c.tolerance);
        let mut part = PartReport::new(
            bounds,
            None,
            route,
            written,
            search_meshing,
            Timings {
                calibrate: calibrate_seconds,
                ..Timings::default()
            },
        );
        part.density_met = Some(cells_met);
        if !map.converged {
            warnings.push(format!(
                "the unit cell could not be calibrated at every density on {resolution} voxels per cell: finer voxels (--resolution) meet the field more closely"
            ));
        }
        if let Some(worst) = checked.iter().max_by(|a, b| {
            (a.density - a.target)
                .abs()
                .total_cmp(&(b.density - b.target).abs())
        }) {
            if !cells_met {
                warnings.push(format!(
                    "cell {:?} has density {:.4} where the field asks {:.4} (promise ±{})",
                    worst.cell, worst.density, worst.target, worst.tolerance
                ));
            }
        }
        if grading.clamp && targets.asked != targets.built {
            warnings.push(format!(
                "the density field ({:.3} to {:.3}) was held to the feasible range of a {} {} ({:.3} to {:.3}, {CLAMP_MARGIN} inside its ends)",
                targets.asked[0],
                targets.asked[1],
                s.name(),
                st.name(),
                range.min,
                range.max
            ));
        }
        warnings.append(&mut part.warnings);
        part.warnings = warnings;
        part.timings.total = start.elapsed().as_secs_f64();
        let grading_report = GradingReport {
            field: field.source.clone(),
            range: targets.built,
            clamped_from: (grading.clamp && targets.asked != targets.built)
                .then_some(targets.asked),
            meshings,
            whole_cells: checked.len(),
            max_cell_error,
            cells_met,
            cells: cell_reports,
        };
        let conn = calibrate::Connectivity {
            solid: true,
            void: true,
        };
        Ok(TpmsReport {
            surface: s,
            structure: st,
            level: levels.mean,
            calibration: map.middle,
            level_search,
            feasible_range: range,
            connectivity: conn,
            resolution_requested: self.resolution,
            resolution,
            voxel_size: voxel,
            thinnest_wall_voxels: None,
            cell_size: cell,
            cells: self.domain.counts(),
            grading: Some(grading_report),
            part,
        })
    }

    /// The field's range over the box, refused where it is not a volume fraction, or leaves
    /// the type's feasible range (unless clamped).
    fn check_field(&self, grading: &Grading, range: calibrate::FeasibleRange) -> Result<Targets> {
        let bounds = self.domain.bounds();
        let cell = self.domain.cell;
        let size = bounds.size();
        let n = [0, 1, 2].map(|a| ((size[a] / cell[a]) * NODES_PER_CELL).ceil() as usize + 1);
        let (mut lo, mut hi) = ((f64::INFINITY, [0.0; 3]), (f64::NEG_INFINITY, [0.0; 3]));
        for i in 0..n[0] {
            for j in 0..n[1] {
                for k in 0..n[2] {
                    let p = [0, 1, 2]
                        .map(|a| bounds.min[a] + size[a] * [i, j, k][a] as f64 / (n[a] - 1) as f64);
                    let v = grading.field.at(p, 0.0);
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
            }
        }
        let (s, st) = (self.surface, self.structure);
        for (v, p) in [lo, hi] {
            if !grading.clamp && (v < range.min || v > range.max) {
                return Err(Error::invalid(format!(
                    "the density field reaches {v:.4} at ({}), outside the feasible range of a {} {} ({:.3} to {:.3}), where the solid falls apart (--clamp holds the field to the range)",
                    point(p),
                    s.name(),
                    st.name(),
                    range.min,
                    range.max
                )));
            }
        }
        let built = if grading.clamp {
            let (a, b) = (range.min + CLAMP_MARGIN, range.max - CLAMP_MARGIN);
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

fn point(p: Vec3) -> String {
    p.map(|x| format!("{:.3}", x)).join(", ")
}

/// Whether `f` is constant over the box (on a 3×3×3 set of points).
fn flat_over(f: &impl Fn(Vec3) -> f64, b: &Aabb) -> bool {
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

/// The per-cell `values` read trilinearly between the cells' centres at `p` (held at the outer
/// centres beyond them).
fn interpolate_cells(cells: &CellVolumes, values: &[f64], p: Vec3) -> f64 {
    let n = cells.counts;
    let b0 = cells.cell_box([0, 0, 0]);
    let mut i0 = [0usize; 3];
    let mut w = [0.0; 3];
    for a in 0..3 {
        let size = b0.max[a] - b0.min[a];
        let u = ((p[a] - b0.min[a]) / size - 0.5).clamp(0.0, (n[a] - 1) as f64);
        i0[a] = (u as usize).min(n[a].saturating_sub(2));
        w[a] = if n[a] == 1 { 0.0 } else { u - i0[a] as f64 };
    }
    let mut v = 0.0;
    for c in 0..8 {
        let d = [c >> 2 & 1, c >> 1 & 1, c & 1];
        if (0..3).any(|a| d[a] == 1 && n[a] == 1) {
            continue;
        }
        let weight: f64 = (0..3)
            .map(|a| if d[a] == 1 { w[a] } else { 1.0 - w[a] })
            .product();
        v += weight * values[cells.index([0, 1, 2].map(|a| i0[a] + d[a]))];
    }
    v
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

/// Gives each partial cell the shift of the nearest whole cell.
fn extend_to_partial_cells(cells: &CellVolumes, whole: &[bool], shift: &mut [f64]) {
    let all: Vec<[usize; 3]> = cells.cells().collect();
    let last_whole = [0, 1, 2].map(|a| {
        all.iter()
            .filter(|c| whole[cells.index(**c)])
            .map(|c| c[a])
            .max()
    });
    for c in &all {
        if whole[cells.index(*c)] {
            continue;
        }
        let Some(near) = (0..3)
            .map(|a| last_whole[a].map(|m| c[a].min(m)))
            .collect::<Option<Vec<usize>>>()
        else {
            continue;
        };
        shift[cells.index(*c)] = shift[cells.index([near[0], near[1], near[2]])];
    }
}
