//! Cells sized by a field: a box whose cells follow a cell size `s(p)` given at every point (an
//! expression or samples), each cell the smooth image of a unit cell, none torn.
//!
//! Along each axis `a` the cell coordinate is the integral of `1/s` along the line through `p`,
//! scaled so that the line holds the same whole number `N_a` of cells as every other:
//!
//! ```text
//! Φ_a(p) = ∫ dt/s(p with p_a = t)  from the box's lower face to p_a,
//! u_a(p) = N_a · Φ_a(p) / Φ_a(p at the upper face),   N_a = the mean of Φ_a at the upper face, rounded
//! ```
//!
//! so every box face is a cell face (`u_a` is 0 and `N_a` there) and the cells along a line are
//! as long as `s` asks, up to the line's scale. A field that varies only along `a` is followed
//! exactly along `a` (up to the one scale that makes the cells whole); where it varies across a
//! line, the line still holds `N_a` cells — a warp cannot add cells to one line and not to its
//! neighbour without tearing them — so the cells lean (`u_a` varies across) and their length
//! along `a` follows the field's shape along the line. [`SizedCells::fit`] reports how far the
//! cells' lengths came from the field.
//!
//! `Φ_a` is integrated (trapezoids) along the lines of a grid of nodes a tenth of the smallest
//! cell apart and read trilinearly between them; beyond the box the map goes on along its
//! Jacobian at the box's face. A field that changes so fast that a cell would fold (the
//! Jacobian's determinant not positive) is refused.

use super::cellmap::CellMap;
use super::nodes::Nodes;
use super::{Aabb, Vec3};
use crate::error::{Error, Result};
use std::sync::Arc;

/// Nodes of the tables at most (each axis at least 2).
const MAX_NODES: usize = 4_000_000;
/// Nodes per smallest cell, the most the table aims for.
const NODES_PER_CELL: f64 = 10.0;
/// Nodes per smallest cell, the fewest the table accepts.
const MIN_NODES_PER_CELL: f64 = 4.0;

/// A box of cells sized by a field.
#[derive(Debug, Clone)]
pub struct SizedCells {
    tables: Arc<Tables>,
}

/// The tabulated map and what was measured on it.
struct Tables {
    bounds: Aabb,
    /// How the field was given.
    source: String,
    /// `u_a` at the nodes, one table per axis.
    u: [Nodes; 3],
    /// Whole cells along each axis.
    counts: [u32; 3],
    /// Over the table's cells, the largest `|∇u_a·∇u_b|` (a bound on the Jacobian's Gram
    /// matrix, for the Lipschitz bound).
    gram: [[f64; 3]; 3],
    /// The thinnest cell between two faces (`1/|∇u_a|`), mm.
    shortest: f64,
    fit: Fit,
}

/// The tables' size, not their values.
impl std::fmt::Debug for Tables {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Tables")
            .field("bounds", &self.bounds)
            .field("source", &self.source)
            .field("counts", &self.counts)
            .field("fit", &self.fit)
            .finish_non_exhaustive()
    }
}

/// How the cells came from the field.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Fit {
    /// The field's smallest and largest cell size over the box, mm.
    pub asked: [f64; 2],
    /// Per axis, the smallest and largest ratio of a cell's thickness between its two faces
    /// across that axis (`1/|∇u_a|`) to the field's size there.
    pub made_over_asked: [[f64; 2]; 3],
    /// Nodes of the table along each axis.
    pub nodes: [usize; 3],
}

impl SizedCells {
    /// Cells of size `size(p)` (mm) filling `bounds`; `source` says how the field was given
    /// (for reports).
    pub fn new(
        bounds: Aabb,
        size: impl Fn(Vec3) -> f64 + Sync,
        source: String,
    ) -> Result<SizedCells> {
        use rayon::prelude::*;
        let extent = bounds.size();
        if !extent.iter().all(|e| *e > 0.0 && e.is_finite()) {
            return Err(Error::invalid(
                "the box of a cell-size field must have a size",
            ));
        }
        // A first look at the field (32 nodes a side) for its smallest size.
        let probe = Nodes::sample(bounds.min, extent.map(|e| e / 31.0), [32; 3], &size);
        check_sizes(&probe)?;
        let smallest = probe.range()[0];
        let mut step = smallest / NODES_PER_CELL;
        let count = |step: f64| extent.map(|e| ((e / step).ceil() as usize).max(1) + 1);
        let total = |n: [usize; 3]| n[0] as f64 * n[1] as f64 * n[2] as f64;
        while total(count(step)) > MAX_NODES as f64 {
            step *= 1.1;
        }
        let n = count(step);
        let node_step = [0, 1, 2].map(|a| extent[a] / (n[a] - 1) as f64);
        let inverse = Nodes::sample(bounds.min, node_step, n, &size);
        check_sizes(&inverse)?;
        let smallest = inverse.range()[0];
        let coarsest = node_step.iter().cloned().fold(0.0, f64::max);
        if smallest / coarsest < MIN_NODES_PER_CELL {
            return Err(Error::invalid(format!(
                "the cell-size field asks for cells of {smallest:.3} mm in a box of {:.0}×{:.0}×{:.0} mm: too many cells (make the smallest cell larger or the box smaller)",
                extent[0], extent[1], extent[2]
            )));
        }
        let asked = inverse.range();
        let mut inverse = inverse;
        inverse.values.par_iter_mut().for_each(|v| *v = 1.0 / *v);
        let mut counts = [0u32; 3];
        let u = [0, 1, 2].map(|a| {
            let (table, cells) = integrate(&inverse, a);
            counts[a] = cells;
            table
        });
        if counts.iter().map(|c| *c as f64).product::<f64>() > 1e9 {
            return Err(Error::invalid(format!(
                "the cell-size field makes {}×{}×{} cells: over a billion",
                counts[0], counts[1], counts[2]
            )));
        }
        let mut tables = Tables {
            bounds,
            source,
            u,
            counts,
            gram: [[0.0; 3]; 3],
            shortest: f64::INFINITY,
            fit: Fit {
                asked,
                made_over_asked: [[f64::INFINITY, 0.0]; 3],
                nodes: n,
            },
        };
        tables.measure(&inverse)?;
        Ok(SizedCells {
            tables: Arc::new(tables),
        })
    }

    /// How the cells came from the field.
    pub fn fit(&self) -> Fit {
        self.tables.fit
    }

    /// Whole cells along each axis.
    pub fn cell_counts(&self) -> [u32; 3] {
        self.tables.counts
    }

    /// How the field was given.
    pub fn source(&self) -> &str {
        &self.tables.source
    }
}

/// Refuses a field that is not a positive, finite length at some node, naming the node.
fn check_sizes(nodes: &Nodes) -> Result<()> {
    let n = nodes.n;
    if let Some(i) = nodes
        .values
        .iter()
        .position(|v| !(*v > 0.0 && v.is_finite()))
    {
        let c = [i / (n[1] * n[2]), i / n[2] % n[1], i % n[2]];
        let p = [0, 1, 2].map(|a| nodes.origin[a] + c[a] as f64 * nodes.step[a]);
        return Err(Error::invalid(format!(
            "the cell-size field is {:.4} at ({:.3}, {:.3}, {:.3}): a cell size is a positive length in mm",
            nodes.values[i], p[0], p[1], p[2]
        )));
    }
    Ok(())
}

/// `u_a` at the nodes from `1/s` at them (trapezoids along each line of nodes along `a`), and
/// the whole cells along `a`.
fn integrate(inverse: &Nodes, a: usize) -> (Nodes, u32) {
    let n = inverse.n;
    let h = inverse.step[a];
    let stride = [n[1] * n[2], n[2], 1][a];
    // The lines along a: every node whose coordinate a is 0.
    let starts: Vec<usize> = (0..n[0] * n[1] * n[2])
        .filter(|i| [i / (n[1] * n[2]), i / n[2] % n[1], i % n[2]][a] == 0)
        .collect();
    let mut phi = vec![0.0; inverse.values.len()];
    let mut ends = Vec::with_capacity(starts.len());
    for &s in &starts {
        let mut acc = 0.0;
        for k in 1..n[a] {
            let (i0, i1) = (s + (k - 1) * stride, s + k * stride);
            acc += 0.5 * h * (inverse.values[i0] + inverse.values[i1]);
            phi[i1] = acc;
        }
        ends.push(acc);
    }
    let cells = (ends.iter().sum::<f64>() / ends.len() as f64)
        .round()
        .max(1.0);
    for (&s, &end) in starts.iter().zip(&ends) {
        for k in 0..n[a] {
            let i = s + k * stride;
            phi[i] = if k + 1 == n[a] {
                cells
            } else {
                cells * phi[i] / end
            };
        }
    }
    (
        Nodes {
            origin: inverse.origin,
            step: inverse.step,
            n,
            values: phi,
        },
        cells as u32,
    )
}

impl Tables {
    /// The Jacobian at the centre of every table cell: refuses a fold, and records the Gram
    /// bound, the shortest edge and the fit.
    fn measure(&mut self, inverse: &Nodes) -> Result<()> {
        use rayon::prelude::*;
        let n = self.u[0].n;
        let cells = (n[0] - 1) * (n[1] - 1) * (n[2] - 1);
        let step = inverse.step;
        let origin = inverse.origin;
        struct Acc {
            gram: [[f64; 3]; 3],
            shortest: f64,
            ratio: [[f64; 2]; 3],
            fold: Option<Vec3>,
        }
        let empty = || Acc {
            gram: [[0.0; 3]; 3],
            shortest: f64::INFINITY,
            ratio: [[f64::INFINITY, 0.0]; 3],
            fold: None,
        };
        let acc = (0..cells)
            .into_par_iter()
            .fold(empty, |mut acc, i| {
                let m = [n[1] - 1, n[2] - 1];
                let c = [i / (m[0] * m[1]), i / m[1] % m[0], i % m[1]];
                let p = [0, 1, 2].map(|a| origin[a] + (c[a] as f64 + 0.5) * step[a]);
                let j = [0, 1, 2].map(|a| self.u[a].with_gradient(p).1);
                let det = j[0][0] * (j[1][1] * j[2][2] - j[1][2] * j[2][1])
                    - j[0][1] * (j[1][0] * j[2][2] - j[1][2] * j[2][0])
                    + j[0][2] * (j[1][0] * j[2][1] - j[1][1] * j[2][0]);
                if (det <= 0.0 || det.is_nan()) && acc.fold.is_none() {
                    acc.fold = Some(p);
                }
                let asked = 1.0 / inverse.at(p);
                for a in 0..3 {
                    for b in 0..3 {
                        let d = (j[a][0] * j[b][0] + j[a][1] * j[b][1] + j[a][2] * j[b][2]).abs();
                        acc.gram[a][b] = acc.gram[a][b].max(d);
                    }
                    let edge = 1.0 / (j[a][0].powi(2) + j[a][1].powi(2) + j[a][2].powi(2)).sqrt();
                    acc.shortest = acc.shortest.min(edge);
                    let r = edge / asked;
                    acc.ratio[a] = [acc.ratio[a][0].min(r), acc.ratio[a][1].max(r)];
                }
                acc
            })
            .reduce(empty, |mut x, y| {
                for a in 0..3 {
                    for b in 0..3 {
                        x.gram[a][b] = x.gram[a][b].max(y.gram[a][b]);
                    }
                    x.ratio[a] = [
                        x.ratio[a][0].min(y.ratio[a][0]),
                        x.ratio[a][1].max(y.ratio[a][1]),
                    ];
                }
                x.shortest = x.shortest.min(y.shortest);
                x.fold = x.fold.or(y.fold);
                x
            });
        if let Some(p) = acc.fold {
            return Err(Error::invalid(format!(
                "the cell-size field changes too fast across the box near ({:.2}, {:.2}, {:.2}): the cells would fold there (make it vary more slowly)",
                p[0], p[1], p[2]
            )));
        }
        self.gram = acc.gram;
        self.shortest = acc.shortest;
        self.fit.made_over_asked = acc.ratio;
        Ok(())
    }
}

impl CellMap for SizedCells {
    fn coords(&self, p: Vec3) -> (Vec3, [Vec3; 3]) {
        let t = &*self.tables;
        let c = [0, 1, 2].map(|a| p[a].clamp(t.bounds.min[a], t.bounds.max[a]));
        let mut u = [0.0; 3];
        let mut j = [[0.0; 3]; 3];
        for a in 0..3 {
            let (v, g) = t.u[a].with_gradient(c);
            u[a] = v + g[0] * (p[0] - c[0]) + g[1] * (p[1] - c[1]) + g[2] * (p[2] - c[2]);
            j[a] = g;
        }
        (u, j)
    }

    /// `|Σ_a ∂F/∂u_a ∇u_a|² ≤ Σ_ab l_a l_b |∇u_a·∇u_b|`, with each product at its largest over
    /// the table (a trilinear reading's slopes are blends of those at the cells' centres'
    /// neighbours: 10 % of room).
    fn lipschitz(&self, l: Vec3) -> f64 {
        let g = &self.tables.gram;
        let mut s = 0.0;
        for a in 0..3 {
            for b in 0..3 {
                s += l[a] * l[b] * g[a][b];
            }
        }
        1.1 * s.sqrt()
    }

    fn room(&self, _p: Vec3) -> f64 {
        f64::INFINITY
    }

    fn cut(&self, _p: Vec3) -> Option<(f64, Vec3)> {
        None
    }

    fn bounds(&self) -> Aabb {
        self.tables.bounds
    }

    fn volume(&self) -> f64 {
        self.tables.bounds.volume()
    }

    fn shortest_edge(&self) -> f64 {
        self.tables.shortest
    }

    fn mid_cell(&self) -> Vec3 {
        let size = self.tables.bounds.size();
        [0, 1, 2].map(|a| size[a] / self.tables.counts[a] as f64)
    }

    fn counts(&self) -> [f64; 3] {
        self.tables.counts.map(f64::from)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn block() -> Aabb {
        Aabb {
            min: [1.0, -2.0, 0.5],
            max: [21.0, 18.0, 40.5],
        }
    }

    /// A field along z alone is the linear grade's map: faces where `∫dz/s` is whole, cells of
    /// the box's width across.
    #[test]
    fn a_field_along_one_axis_grades_that_axis() {
        let b = block();
        let m = SizedCells::new(b, |p| 3.0 + 5.0 * (p[2] - 0.5) / 40.0, String::new()).unwrap();
        // ∫dz/(3 + z/8) over 40 mm = 8 ln(8/3) = 7.85 → 8 cells; across, 20/s̄ averaged → 4.
        assert_eq!(m.cell_counts()[2], 8);
        let held = 8.0 * (8.0f64 / 3.0).ln();
        for z in [0.5, 7.0, 19.0, 33.3, 40.5] {
            let (u, j) = m.coords([5.0, 3.0, z]);
            let want = 8.0 / held * 8.0 * ((3.0 + (z - 0.5) / 8.0) / 3.0).ln();
            assert!((u[2] - want).abs() < 2e-4, "{z}: {} vs {want}", u[2]);
            assert!(j[2][0].abs() < 1e-9 && j[2][1].abs() < 1e-9);
            assert!(j[0][2].abs() < 1e-9, "x does not lean: {:?}", j[0]);
        }
        let (u, _) = m.coords([21.0, 18.0, 40.5]);
        assert_eq!(u, m.counts());
        let f = m.fit();
        assert!((f.made_over_asked[2][0] - 1.0).abs() < 0.05, "{f:?}");
        assert!((f.made_over_asked[2][1] - 1.0).abs() < 0.05, "{f:?}");
    }

    /// Beyond the box the map goes on along its Jacobian; at every face the cell coordinate is
    /// whole; the map is one-to-one along each axis.
    #[test]
    fn faces_are_whole_and_the_map_continues_beyond_them() {
        let b = block();
        let r = |p: Vec3| ((p[0] - 11.0).powi(2) + (p[1] - 8.0).powi(2)).sqrt();
        let m = SizedCells::new(b, |p| 2.5 + 0.2 * r(p) + 0.02 * p[2], String::new()).unwrap();
        let n = m.counts();
        let mut rng = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            (rng >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..200 {
            let p = [0, 1, 2].map(|a| b.min[a] + next() * (b.max[a] - b.min[a]));
            for a in 0..3 {
                let (mut lo, mut hi) = (p, p);
                lo[a] = b.min[a];
                hi[a] = b.max[a];
                assert!(m.coords(lo).0[a].abs() < 1e-9);
                assert!((m.coords(hi).0[a] - n[a]).abs() < 1e-9);
                let mut q = p;
                q[a] += 1e-3;
                assert!(m.coords(q).0[a] > m.coords(p).0[a]);
                // Just beyond the face, the coordinate goes on at the face's slope.
                let mut out = hi;
                out[a] += 0.5;
                let (u, j) = m.coords(hi);
                assert!((m.coords(out).0[a] - (u[a] + 0.5 * j[a][a])).abs() < 1e-9);
            }
        }
    }

    #[test]
    fn bad_fields_are_refused_with_the_place() {
        let e = SizedCells::new(block(), |p| 3.0 - p[0] / 5.0, String::new())
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("positive length") && e.contains('('), "{e}");
        let e = SizedCells::new(block(), |_| f64::NAN, String::new())
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("NaN"), "{e}");
        let e = SizedCells::new(block(), |_| 0.001, String::new())
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("too many cells"), "{e}");
    }
}
