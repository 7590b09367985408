//! A strut lattice clipped by its box, for the meshing pipeline: the [`Solid`] at one radius and
//! the [`Family`] of radii the pipeline searches for the part's density.

use super::cell::UnitCell;
use super::field::StrutField;
use crate::field::{Aabb, Field, Vec3};
use crate::grid::GridSpec;
use crate::lattice::model::LevelModel;
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
    /// The fraction held against the radius (points held at their distance to a strut axis).
    radii: LevelModel,
    /// The radius at which the pores close: the void stops running through the lattice from
    /// cell to cell (at and above it, powder or resin is trapped).
    pub closing: f64,
}

/// The distance to the nearest strut axis (over the strut's mean radius factor) anywhere in a
/// cell: looked up in a field whose bins list only the struts within a short reach (a few per
/// bin), and, for the rare point farther than that from every axis, in one that lists all.
struct AxisDistance {
    near: StrutField,
    reach: f64,
    all: std::sync::OnceLock<StrutField>,
    cell: UnitCell,
    size: Vec3,
}

impl AxisDistance {
    fn new(cell: &UnitCell, size: Vec3) -> AxisDistance {
        let reach = 0.3 * size.iter().cloned().fold(f64::INFINITY, f64::min);
        AxisDistance {
            near: StrutField::new(cell, size, [0.0; 3], 0.0, 0.0, reach),
            reach,
            all: std::sync::OnceLock::new(),
            cell: cell.clone(),
            size,
        }
    }

    fn axis_distance(&self, p: Vec3) -> f64 {
        let d = self.near.axis_distance(p);
        if d < self.reach {
            return d;
        }
        // No point of the cell is farther than half its diagonal from a node.
        let all = self.all.get_or_init(|| {
            let reach = 0.5 * self.size.iter().map(|s| s * s).sum::<f64>().sqrt();
            StrutField::new(&self.cell, self.size, [0.0; 3], 0.0, 0.0, reach)
        });
        all.axis_distance(p)
    }
}

/// Points per axis of the model's stratified set.
const MODEL_POINTS: usize = 40;

/// Points per axis of the grid on which the void's connection through the cell is followed.
const CLOSING_POINTS: usize = 48;

/// The largest radius at which the void still runs through the periodic lattice, on a grid of
/// `n³` points of one cell: the points are added to the void from the one farthest from any
/// strut axis down, joined to their six neighbours (across the cell's faces too, counting how
/// many periods each join crosses), and the first join that closes a loop around a period —
/// two copies of one point in one cluster — is the moment the void percolates. Its radius is
/// the point's axis distance. (Union–find with a period offset per point, as in Newman and
/// Ziff's percolation algorithm, Phys. Rev. E 64, 016706, 2001.)
fn closing_radius(field: &AxisDistance, size: Vec3, n: usize) -> f64 {
    let idx = |i: usize| [i / (n * n), (i / n) % n, i % n];
    let at = |c: [usize; 3]| (c[0] * n + c[1]) * n + c[2];
    let distances: Vec<f64> = (0..n * n * n)
        .into_par_iter()
        .map(|i| {
            let c = idx(i);
            field.axis_distance([0, 1, 2].map(|a| (c[a] as f64 + 0.5) / n as f64 * size[a]))
        })
        .collect();
    let mut order: Vec<usize> = (0..distances.len()).collect();
    order.sort_by(|&a, &b| distances[b].total_cmp(&distances[a]));
    // parent and, per point, the periods between it and its parent's copy in its cluster.
    let mut parent: Vec<usize> = (0..distances.len()).collect();
    let mut shift = vec![[0i32; 3]; distances.len()];
    let mut open = vec![false; distances.len()];
    let mut size_of = vec![1u32; distances.len()];
    let mut path = Vec::new();
    // The root of i and i's offset from it, compressing the path.
    let mut root = |parent: &mut [usize], shift: &mut [[i32; 3]], i: usize| {
        path.clear();
        let mut k = i;
        while parent[k] != k {
            path.push(k);
            k = parent[k];
        }
        let mut total = [0i32; 3];
        for &node in path.iter().rev() {
            total = [0, 1, 2].map(|a| shift[node][a] + total[a]);
            shift[node] = total;
            parent[node] = k;
        }
        (k, total)
    };
    for &i in &order {
        open[i] = true;
        let c = idx(i);
        for a in 0..3 {
            for step in [-1i64, 1] {
                let mut d = c;
                let x = c[a] as i64 + step;
                // Crossing a face of the cell moves one period along the axis.
                let wrap = if x < 0 { -1 } else { (x >= n as i64) as i32 };
                d[a] = x.rem_euclid(n as i64) as usize;
                let j = at(d);
                if !open[j] {
                    continue;
                }
                let (ri, si) = root(&mut parent, &mut shift, i);
                let (rj, sj) = root(&mut parent, &mut shift, j);
                // j's copy next to i's is `wrap` periods on; in the cluster's frame i sits at
                // si and j at sj.
                let mut w = [0i32; 3];
                w[a] = wrap;
                let want = [0, 1, 2].map(|k| si[k] + w[k]);
                if ri == rj {
                    if want != sj {
                        return distances[i];
                    }
                } else if size_of[ri] >= size_of[rj] {
                    // Hang j's root under i's so that j's copy lands next to i's.
                    parent[rj] = ri;
                    shift[rj] = [0, 1, 2].map(|k| want[k] - sj[k]);
                    size_of[ri] += size_of[rj];
                } else {
                    parent[ri] = rj;
                    shift[ri] = [0, 1, 2].map(|k| sj[k] - want[k]);
                    size_of[rj] += size_of[ri];
                }
            }
        }
    }
    0.0
}

impl RadiusModel {
    /// The model of `cell` with cells of `size` mm.
    pub fn new(cell: &UnitCell, size: Vec3) -> RadiusModel {
        // No point of the cell is farther than half its diagonal from a node.
        let field = AxisDistance::new(cell, size);
        let n = MODEL_POINTS;
        let radii: Vec<f64> = (0..n * n * n)
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
        let diagonal = size.iter().map(|s| s * s).sum::<f64>().sqrt();
        let closing = closing_radius(&field, size, CLOSING_POINTS);
        RadiusModel {
            radii: LevelModel::new(radii, diagonal),
            closing,
        }
    }

    /// The fraction of the cell the lattice fills at radius `r`.
    pub fn fraction(&self, r: f64) -> f64 {
        self.radii.fraction(r)
    }

    /// The radius at which the lattice fills `fraction` of the cell (the inverse of
    /// [`RadiusModel::fraction`]).
    pub fn radius(&self, fraction: f64) -> f64 {
        self.radii.level(fraction)
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Simple cubic struts run along the cube's edges: the void passes through the cells'
    /// faces, whose centres are half the face's shorter side from its struts, so the pores
    /// close at half a cube cell; in cells of 2 by 3 by 4 mm the void still runs along x
    /// (through the 3 × 4 faces) up to 1.5 mm.
    #[test]
    fn simple_cubic_pores_close_at_half_the_face() {
        let cell = UnitCell::built_in("sc").unwrap();
        let m = RadiusModel::new(&cell, [2.0, 3.0, 4.0]);
        // The grid's points lie half a spacing off the face (0.03 mm here): no closer.
        assert!(
            (m.closing - 1.5).abs() < 0.06,
            "closes at {} mm, not 1.5 mm",
            m.closing
        );
        let cubic = RadiusModel::new(&cell, [1.0; 3]);
        assert!((cubic.closing - 0.5).abs() < 0.02, "{}", cubic.closing);
    }
}
