//! A strut lattice clipped by its box, for the meshing pipeline: the [`Solid`] at one radius and
//! the [`Family`] of radii the pipeline searches for the part's density.

use super::cell::UnitCell;
use super::field::StrutField;
use crate::field::{Aabb, Field, Vec3};
use crate::grid::GridSpec;
use crate::mesh::pipeline::{Family, Solid};
use rayon::prelude::*;
use std::sync::Arc;

/// A strut lattice clipped by a box, at one radius.
#[derive(Debug, Clone)]
pub struct StrutLattice {
    /// The unit cell.
    pub cell: Arc<UnitCell>,
    /// Cell size per axis, mm.
    pub size: Vec3,
    /// Strut radius, mm (times each node's factor).
    pub radius: f64,
    /// Radius of the smooth minimum at the joints, mm (0: a sharp union).
    pub blend: f64,
    /// The clipping box.
    pub bounds: Aabb,
    /// A cell's lower corner (the phase), mm: the box's lower corner for a part.
    pub phase: Vec3,
}

impl StrutLattice {
    /// The lattice's field, unclipped, exact up to `reach` mm.
    pub fn field(&self, reach: f64) -> StrutField {
        StrutField::new(
            &self.cell,
            self.size,
            self.phase,
            self.radius,
            self.blend,
            reach,
        )
    }
}

impl Solid for StrutLattice {
    fn field(&self, spec: &GridSpec) -> Box<dyn Field + '_> {
        Box::new(
            StrutLattice::field(self, spec.half_width * spec.voxel)
                .with_periodic_samples(spec.voxel),
        )
    }

    fn bounds(&self) -> Aabb {
        self.bounds
    }

    fn with_bounds(&self, bounds: Aabb) -> Self {
        StrutLattice {
            bounds,
            ..self.clone()
        }
    }

    fn period(&self) -> Option<Vec3> {
        (self.phase == self.bounds.min).then_some(self.size)
    }
}

/// The volume fraction of the lattice against the strut radius, measured once per cell: for
/// each of a stratified set of points in the cell, the smallest radius at which a strut holds
/// it (its distance to the strut's axis over the strut's mean radius factor: exact for
/// capsules in a sharp union, a model for cones and blended joints); the fraction at a radius is
/// then the share of points held, interpolated between the sorted radii so that it increases
/// strictly. The pipeline steps the radius through it and corrects it on the meshed part.
#[derive(Debug, Clone)]
pub struct RadiusModel {
    /// The radius at which each point is held, sorted.
    radii: Vec<f64>,
    /// A radius at which every point is held.
    max_radius: f64,
}

/// Points per axis of the model's stratified set.
const MODEL_POINTS: usize = 40;

impl RadiusModel {
    /// The model of `cell` with cells of `size` mm.
    pub fn new(cell: &UnitCell, size: Vec3) -> RadiusModel {
        // No point of the cell is farther than half its diagonal from a node.
        let reach = 0.5 * size.iter().map(|s| s * s).sum::<f64>().sqrt();
        let field = StrutField::new(cell, size, [0.0; 3], 0.0, 0.0, reach);
        let n = MODEL_POINTS;
        let mut radii: Vec<f64> = (0..n * n * n)
            .into_par_iter()
            .map(|i| {
                // One point in each of n³ strata, offset inside it by an additive recurrence
                // (so points do not line up with the cell's symmetry planes).
                let idx = [i / (n * n), (i / n) % n, i % n];
                let alpha = [0.754_877_666, 0.569_840_291, 0.438_028_374];
                let p = [0, 1, 2].map(|a| {
                    let g = ((i as f64 + 1.0) * alpha[a]).fract();
                    (idx[a] as f64 + g) / n as f64 * size[a]
                });
                field.axis_distance(p)
            })
            .collect();
        radii.sort_by(f64::total_cmp);
        let max_radius = radii.last().copied().unwrap_or(reach) * (1.0 + 1e-9) + 1e-12;
        RadiusModel { radii, max_radius }
    }

    /// The fraction of the cell the lattice fills at radius `r`.
    pub fn fraction(&self, r: f64) -> f64 {
        let n = self.radii.len();
        if r <= 0.0 {
            return 0.0;
        }
        if r >= self.max_radius {
            return 1.0;
        }
        // Points held at r: radii[k] ≤ r for k < count; interpolate to the next.
        let count = self.radii.partition_point(|&x| x <= r);
        let below = if count == 0 {
            0.0
        } else {
            self.radii[count - 1]
        };
        let above = self.radii.get(count).copied().unwrap_or(self.max_radius);
        let t = if above > below {
            (r - below) / (above - below)
        } else {
            0.0
        };
        ((count as f64 + t) / (n as f64 + 1.0)).clamp(0.0, 1.0)
    }

    /// The radius at which the lattice fills `fraction` of the cell (the inverse of
    /// [`RadiusModel::fraction`]).
    pub fn radius(&self, fraction: f64) -> f64 {
        let (mut lo, mut hi) = (0.0, self.max_radius);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if self.fraction(mid) < fraction {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    }
}

/// A strut part at every radius: the family the pipeline searches for the part's density.
#[derive(Debug, Clone)]
pub struct StrutFamily {
    /// The part at some radius (the radius is replaced).
    pub part: StrutLattice,
    /// Its cell's fraction against the radius.
    pub model: Arc<RadiusModel>,
}

impl StrutFamily {
    /// The family of `part`, its model measured.
    pub fn new(part: StrutLattice) -> StrutFamily {
        let model = Arc::new(RadiusModel::new(&part.cell, part.size));
        StrutFamily { part, model }
    }
}

impl Family for StrutFamily {
    type Solid = StrutLattice;

    fn at(&self, level: f64) -> StrutLattice {
        StrutLattice {
            radius: level,
            ..self.part.clone()
        }
    }

    fn model_fraction(&self, level: f64) -> f64 {
        self.model.fraction(level)
    }

    fn model_level(&self, fraction: f64) -> f64 {
        self.model.radius(fraction)
    }
}
