//! Two TPMS types blended by a weight that varies through the part (`--blend-to TYPE
//! --blend-field EXPR|AXIS:A:B`): the solid is where `(1 − w)·F_a/s_a + w·F_b/s_b` is below the
//! level (or its magnitude, for sheets), `w` the weight held to [0, 1] and `s` each surface's RMS
//! over its cell (so that both speak the same units). A smooth weight gives a smooth surface: no
//! seam, and no islands where the two fields meet, since neither is cut off.
//!
//! The density is met as every graded part's is ([`crate::mesh::graded`]), with no empirical
//! thinning factor: the level of a density at a point comes from the blend's own density →
//! level model at the point's weight — the quantiles of the blended function over the unit cell,
//! tabulated at five weights and interpolated between them — less the meshing's bias calibrated
//! on each type at the part's voxels; each whole cell is then measured on the mesh and corrected.

use super::{Lattice, Structure, Surface, TpmsField};
use crate::field::density::DensityField;
use crate::field::nodes::Nodes;
use crate::field::{Aabb, Field, Vec3};
use crate::grid::GridSpec;
use crate::lattice::tpms::graded::Calibrated;
use crate::mesh::graded::{self, Graded, GradedFamily, LevelGrid, LevelMap, Levelled};
use std::sync::Arc;

/// Weights at which the blend's model is tabulated.
const WEIGHTS: [f64; 5] = [0.0, 0.25, 0.5, 0.75, 1.0];
/// Samples per cell edge for the blend's model (cell midpoints).
const MODEL_SAMPLES: usize = 40;

/// A blend asked for: the second type and the weight field (0: the part's type, 1: `to`).
#[derive(Clone)]
pub struct Blend {
    /// The type blended to.
    pub to: Surface,
    /// The weight of `to` at each point (held to [0, 1]).
    pub weight: Arc<DensityField>,
}

impl std::fmt::Debug for Blend {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Blend(to {}, {})", self.to.name(), self.weight.source)
    }
}

/// A blend as reported: the type blended to and how its weight was given.
#[derive(Debug, Clone, serde::Serialize)]
pub struct BlendReport {
    /// The type blended to.
    #[serde(rename = "type")]
    pub to: Surface,
    /// The weight field.
    pub weight: String,
}

/// The blended function's quantiles over the unit cell at each of [`WEIGHTS`]: its density →
/// level model.
struct Model {
    /// Per weight, the solid measure (`F`, `|F|` or `−F`) at the cell's sample points, sorted.
    sorted: Vec<Vec<f64>>,
}

impl Model {
    fn new(a: Surface, b: Surface, structure: Structure, scale: [f64; 2]) -> Model {
        let n = MODEL_SAMPLES;
        let values: Vec<(f64, f64)> = (0..n * n * n)
            .map(|i| {
                let u = [i / (n * n), i / n % n, i % n].map(|c| (c as f64 + 0.5) / n as f64);
                (a.eval(u).0 / scale[0], b.eval(u).0 / scale[1])
            })
            .collect();
        let sorted = WEIGHTS
            .iter()
            .map(|&w| {
                let mut s: Vec<f64> = values
                    .iter()
                    .map(|&(fa, fb)| solid_measure(structure, (1.0 - w) * fa + w * fb))
                    .collect();
                s.sort_by(f64::total_cmp);
                s
            })
            .collect();
        Model { sorted }
    }

    /// The level at which the blend at weight knot `k` holds `fraction`.
    fn level(&self, k: usize, fraction: f64) -> f64 {
        let s = &self.sorted[k];
        let x = (fraction.clamp(0.0, 1.0) * s.len() as f64 - 0.5).clamp(0.0, (s.len() - 1) as f64);
        let i = (x.floor() as usize).min(s.len() - 2);
        s[i] + (s[i + 1] - s[i]) * (x - i as f64)
    }

    /// The fraction the blend at weight knot `k` holds at `level`.
    fn fraction(&self, k: usize, level: f64) -> f64 {
        let s = &self.sorted[k];
        s.partition_point(|&v| v <= level) as f64 / s.len() as f64
    }
}

/// What is solid where the blended function is `f`: `F ≤ t`, `|F| ≤ t` or `−F ≤ t`.
fn solid_measure(structure: Structure, f: f64) -> f64 {
    match structure {
        Structure::Net => f,
        Structure::Sheet => f.abs(),
        Structure::NetOther => -f,
    }
}

/// The knot below `w` and the weight of the knot above it.
fn bracket(w: f64) -> (usize, f64) {
    let x = w.clamp(0.0, 1.0) * (WEIGHTS.len() - 1) as f64;
    let k = (x.floor() as usize).min(WEIGHTS.len() - 2);
    (k, x - k as f64)
}

/// `F`'s RMS over the unit cell.
fn rms(s: Surface) -> f64 {
    let n = 24;
    let sum: f64 = (0..n * n * n)
        .map(|i| {
            let u = [i / (n * n), i / n % n, i % n].map(|c| (c as f64 + 0.5) / n as f64);
            s.eval(u).0.powi(2)
        })
        .sum();
    (sum / (n * n * n) as f64).sqrt()
}

/// The largest `|F|` can be: the sum of its terms' coefficients.
fn amplitude(s: Surface) -> f64 {
    s.factors().iter().map(|(c, _)| c.abs()).sum()
}

/// The blended lattice in its box: the part's lattice (type `a`), the type blended to, the
/// weight at nodes, and the blend's model.
#[derive(Clone)]
pub struct BlendedLattice {
    lattice: Lattice,
    to: Surface,
    scale: [f64; 2],
    weight: Arc<Nodes>,
    model: Arc<Model>,
}

impl BlendedLattice {
    /// The weight at `p`, held to [0, 1], and its gradient (zero where held).
    #[inline(always)]
    fn weight_at(&self, p: Vec3) -> (f64, Vec3) {
        let (w, g) = self.weight.with_gradient(p);
        if (0.0..=1.0).contains(&w) {
            (w, g)
        } else {
            (w.clamp(0.0, 1.0), [0.0; 3])
        }
    }
}

struct BlendField<'a> {
    part: &'a BlendedLattice,
    a: TpmsField,
    b: TpmsField,
    levels: &'a LevelGrid,
    offset: f64,
    lipschitz: f64,
}

impl BlendField<'_> {
    /// The implicit value, the blended function's gradient (mm⁻¹) and the level's gradient.
    #[inline(always)]
    fn eval(&self, p: Vec3) -> (f64, Vec3, Vec3) {
        let [sa, sb] = self.part.scale;
        let (fa, ga) = self.a.eval_at(p);
        let (fb, gb) = self.b.eval_at(p);
        let (w, gw) = self.part.weight_at(p);
        let (ua, ub) = (fa / sa, fb / sb);
        let f = (1.0 - w) * ua + w * ub;
        let cell = self.a.cell;
        let g = [0, 1, 2]
            .map(|i| ((1.0 - w) * ga[i] / sa + w * gb[i] / sb) / cell[i] + gw[i] * (ub - ua));
        let (t, gt) = self.levels.at(p);
        let sign = match self.a.structure {
            Structure::Net => 1.0,
            Structure::Sheet => f.signum(),
            Structure::NetOther => -1.0,
        };
        let g = g.map(|x| sign * x);
        (self.a.implicit_at(f, t + self.offset), g, gt)
    }
}

impl Field for BlendField<'_> {
    fn value(&self, p: Vec3) -> f64 {
        let (v, g, _) = self.eval(p);
        let norm = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
        let clamp = self.a.clamp;
        if norm > 1e-12 {
            (v / norm).clamp(-clamp, clamp)
        } else {
            v.signum() * clamp
        }
    }

    fn clearance(&self, p: Vec3) -> f64 {
        self.eval(p).0.abs() / self.lipschitz
    }

    fn implicit_with_gradient(&self, p: Vec3) -> (f64, Vec3) {
        let (v, g, gt) = self.eval(p);
        (v, [0, 1, 2].map(|i| g[i] - gt[i]))
    }
}

impl Levelled for BlendedLattice {
    fn graded_field<'a>(
        &'a self,
        levels: &'a LevelGrid,
        offset: f64,
        spec: &GridSpec,
    ) -> Box<dyn Field + 'a> {
        let clamp = spec.half_width * spec.voxel;
        let a = self.lattice.field(clamp);
        let b = Lattice {
            surface: self.to,
            ..self.lattice
        }
        .field(clamp);
        let [sa, sb] = self.scale;
        // |∇f| ≤ max(|∇F_a|/s_a, |∇F_b|/s_b) + |∇w|·max|F_b/s_b − F_a/s_a|.
        let lipschitz = (a.lipschitz() / sa).max(b.lipschitz() / sb)
            + self.weight.lipschitz()
                * (amplitude(self.lattice.surface) / sa + amplitude(self.to) / sb)
            + levels.lipschitz;
        Box::new(BlendField {
            part: self,
            a,
            b,
            levels,
            offset,
            lipschitz,
        })
    }

    fn bounds(&self) -> Aabb {
        self.lattice.bounds
    }

    fn with_bounds(&self, bounds: Aabb) -> Self {
        BlendedLattice {
            lattice: Lattice {
                bounds,
                ..self.lattice
            },
            ..self.clone()
        }
    }

    fn model_fraction(&self, level: f64) -> f64 {
        let (k, _) = bracket(self.weight.mean());
        self.model.fraction(k, level)
    }

    fn model_level(&self, fraction: f64) -> f64 {
        let (k, _) = bracket(self.weight.mean());
        self.model.level(k, fraction)
    }
}

/// The blended lattice and its maps at [`WEIGHTS`]: the graded blend in its box.
pub struct BlendMapped {
    lattice: BlendedLattice,
    maps: Vec<LevelMap>,
}

impl BlendMapped {
    /// The blend of `lattice` (the part's type, its box and phase) to `blend.to`, its weight
    /// sampled over `bounds` grown by `margin`, mapping densities over `[lo, hi]`; `a` and `b`
    /// are the two types calibrated over the same knots at the part's voxels (their bias is
    /// blended with the weight).
    pub fn new(
        lattice: Lattice,
        blend: &Blend,
        margin: f64,
        (lo, hi): (f64, f64),
        a: &Calibrated,
        b: &Calibrated,
    ) -> BlendMapped {
        let scale = [rms(lattice.surface), rms(blend.to)];
        let step = lattice.cell.map(|c| c / 4.0);
        let weight = Nodes::covering(&lattice.bounds, step, margin, |p| {
            blend.weight.at(p, 0.0).clamp(0.0, 1.0)
        });
        let model = Model::new(lattice.surface, blend.to, lattice.structure, scale);
        let knots = graded::knots(lo, hi);
        let maps = WEIGHTS
            .iter()
            .enumerate()
            .map(|(k, &w)| {
                let bias: Vec<f64> = a
                    .bias
                    .iter()
                    .zip(&b.bias)
                    .map(|(x, y)| (1.0 - w) * x + w * y)
                    .collect();
                LevelMap::new(lo, hi, &knots, &bias, |f| model.level(k, f))
            })
            .collect();
        BlendMapped {
            lattice: BlendedLattice {
                lattice,
                to: blend.to,
                scale,
                weight: Arc::new(weight),
                model: Arc::new(model),
            },
            maps,
        }
    }
}

impl Graded for BlendMapped {
    type Family<'a> = GradedFamily<'a, BlendedLattice>;

    fn level(&self, p: Vec3, rho: f64) -> f64 {
        let (k, u) = bracket(self.lattice.weight.at(p));
        self.maps[k].level(rho) * (1.0 - u) + self.maps[k + 1].level(rho) * u
    }

    fn family<'a>(&'a self, levels: &'a LevelGrid) -> GradedFamily<'a, BlendedLattice> {
        GradedFamily::new(self.lattice.clone(), levels)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// At the ends the blend's model is each type's own: the fraction at the type's analytic
    /// level (scaled by its RMS) is the type's.
    #[test]
    fn the_blends_model_at_its_ends_is_each_types() {
        let (a, b) = (Surface::Gyroid, Surface::D);
        let scale = [rms(a), rms(b)];
        let m = Model::new(a, b, Structure::Net, scale);
        for rho in [0.15, 0.3, 0.5] {
            let ta = super::super::calibrate::analytic_level(a, Structure::Net, rho);
            let tb = super::super::calibrate::analytic_level(b, Structure::Net, rho);
            assert!((m.fraction(0, ta / scale[0]) - rho).abs() < 3e-3, "{rho}");
            assert!((m.fraction(4, tb / scale[1]) - rho).abs() < 3e-3, "{rho}");
            assert!((m.fraction(2, m.level(2, rho)) - rho).abs() < 1e-3, "{rho}");
        }
    }
}
