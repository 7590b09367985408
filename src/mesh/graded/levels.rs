//! The level of a graded part: the type's density → level map, the level on a node grid read
//! trilinearly, and the lattice at that level for the pipeline.

use super::{MAP_MARGIN, NODES_PER_CELL};
use crate::error::Result;
use crate::field::nodes::Nodes;
use crate::field::{Aabb, Field, Vec3};
use crate::grid::GridSpec;
use crate::mesh::pipeline::{self, Family, Options, Route, Solid};

/// Knots at which a type is calibrated over `[lo, hi]`: six across it, one when it is a point.
pub fn knots(lo: f64, hi: f64) -> Vec<f64> {
    if hi - lo < 1e-6 {
        return vec![lo];
    }
    (0..6).map(|i| lo + (hi - lo) * i as f64 / 5.0).collect()
}

/// A type's density → level map over `[lo, hi]` at `voxel`, calibrated on `sample` (its unit
/// cell, or a block of the part, whose model is its own): at each knot the level at which
/// `sample`'s mesh meets the density, found by the pipeline's search, its bias against
/// `sample`'s model interpolated between the knots and read off `model_level` (the type's, the
/// whole part's, fraction → level); whether every search met its density.
pub fn calibrate_on<F: Family>(
    sample: &F,
    voxel: f64,
    opts: &Options,
    lo: f64,
    hi: f64,
    model_level: impl Fn(f64) -> f64,
) -> Result<(LevelMap, bool)> {
    let opts = Options {
        verify: crate::verify::Verify::None,
        instancing: false,
        keep_fragments: true,
        ..*opts
    };
    let knots = knots(lo, hi);
    let mut bias = Vec::with_capacity(knots.len());
    let mut met = true;
    for &rho in &knots {
        let l0 = sample.model_level(rho);
        let route = Route::choose(&sample.at(l0), voxel, &opts);
        let solved = pipeline::solve(sample, rho, l0, voxel, route, &opts)?;
        met &= solved.met;
        bias.push(sample.model_fraction(solved.best.level) - rho);
    }
    Ok((LevelMap::new(lo, hi, &knots, &bias, model_level), met))
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
        let nodes = Nodes::covering(bounds, cell.map(|c| c / NODES_PER_CELL), margin, level);
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

impl<'a, L: Levelled> GradedFamily<'a, L> {
    /// `lattice` with its level at each point read off `levels`.
    pub fn new(lattice: L, levels: &'a LevelGrid) -> Self {
        GradedFamily {
            part: GradedPart {
                lattice,
                levels,
                offset: 0.0,
            },
        }
    }
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
    /// The level of density `rho` at `p` (the same everywhere but for a blend of types).
    fn level(&self, p: Vec3, rho: f64) -> f64;
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

    fn level(&self, _p: Vec3, rho: f64) -> f64 {
        self.map.level(rho)
    }

    fn family<'a>(&'a self, levels: &'a LevelGrid) -> GradedFamily<'a, L> {
        GradedFamily::new(self.lattice.clone(), levels)
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
}
