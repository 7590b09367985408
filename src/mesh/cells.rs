//! The volume a closed mesh encloses in each cell of a lattice, from its triangles alone, in one
//! pass (so it can watch a mesh streamed to a file): the density of every cell of a graded part.
//!
//! The solid's volume inside a box `[x₀,x₁]×[y₀,y₁]×[z₀,z₁]` is the flux of
//! `(0, 0, clamp(z, z₀, z₁) − z₀)` through the part of the surface above the box's footprint
//! (the field's divergence is 1 inside the slab and 0 outside it; its flux through the column's
//! walls is 0). A triangle adds that flux to the cells of the columns it crosses whose slabs it
//! reaches, and its plain flux `∫ n_z dA` times their height to the cells wholly below it —
//! summed per column from the top once every triangle is in.

use crate::error::Result;
use crate::field::{Aabb, Vec3};
use crate::geom::clipped_column_integral;
use crate::io::sink::{MeshSink, Triangle};

/// Per-cell volumes of a mesh over a part's box cut into cells (partial at the far sides).
#[derive(Debug, Clone)]
pub struct CellVolumes {
    bounds: Aabb,
    cell: Vec3,
    /// Cells per axis.
    pub counts: [usize; 3],
    /// Volume within each cell, `(i·ny + j)·nz + k`, before [`CellVolumes::volumes`] adds the
    /// columns' fluxes.
    inside: Vec<f64>,
    /// Flux of the triangles whose lowest point is in slab `k` (`nz`: above the box) of each
    /// column, `(i·ny + j)·(nz + 1) + k`.
    above: Vec<f64>,
}

impl CellVolumes {
    /// Cells of size `cell` from `bounds`' lower corner; a cell the box ends inside is cut by it.
    pub fn new(bounds: Aabb, cell: Vec3) -> CellVolumes {
        let size = bounds.size();
        let counts = [0, 1, 2].map(|a| ((size[a] / cell[a] - 1e-9).ceil() as usize).max(1));
        CellVolumes {
            bounds,
            cell,
            counts,
            inside: vec![0.0; counts[0] * counts[1] * counts[2]],
            above: vec![0.0; counts[0] * counts[1] * (counts[2] + 1)],
        }
    }

    /// The box of cell `c`, cut by the part's.
    pub fn cell_box(&self, c: [usize; 3]) -> Aabb {
        let min = [0, 1, 2].map(|a| self.bounds.min[a] + c[a] as f64 * self.cell[a]);
        Aabb {
            min,
            max: [0, 1, 2].map(|a| (min[a] + self.cell[a]).min(self.bounds.max[a])),
        }
    }

    /// Whether cell `c` is whole (not cut by the box).
    pub fn is_whole(&self, c: [usize; 3]) -> bool {
        let b = self.cell_box(c);
        (0..3).all(|a| b.max[a] - b.min[a] >= self.cell[a] * (1.0 - 1e-9))
    }

    /// The index of cell `c` in [`CellVolumes::volumes`].
    pub fn index(&self, c: [usize; 3]) -> usize {
        (c[0] * self.counts[1] + c[1]) * self.counts[2] + c[2]
    }

    /// Every cell, in index order.
    pub fn cells(&self) -> impl Iterator<Item = [usize; 3]> + '_ {
        let n = self.counts;
        (0..n[0]).flat_map(move |i| (0..n[1]).flat_map(move |j| (0..n[2]).map(move |k| [i, j, k])))
    }

    /// The cell index range `[lo, hi]` along `axis` that `[a, b]` reaches (clamped to the cells;
    /// `None` when it misses them).
    fn span(&self, axis: usize, a: f64, b: f64) -> Option<(usize, usize)> {
        let n = self.counts[axis] as f64;
        let o = self.bounds.min[axis];
        let lo = ((a - o) / self.cell[axis]).floor();
        let hi = ((b - o) / self.cell[axis]).floor();
        if hi < 0.0 || lo >= n {
            return None;
        }
        Some((lo.max(0.0) as usize, hi.min(n - 1.0) as usize))
    }

    /// Adds one triangle (wound outward).
    pub fn add(&mut self, tri: [Vec3; 3]) {
        let lo = |a: usize| tri[0][a].min(tri[1][a]).min(tri[2][a]);
        let hi = |a: usize| tri[0][a].max(tri[1][a]).max(tri[2][a]);
        let (Some((i0, i1)), Some((j0, j1))) =
            (self.span(0, lo(0), hi(0)), self.span(1, lo(1), hi(1)))
        else {
            return;
        };
        let nz = self.counts[2];
        let z0 = self.bounds.min[2];
        // The slab of the triangle's lowest point (nz: above the box), and the last slab it
        // reaches.
        let k_lo = (((lo(2) - z0) / self.cell[2]).floor().max(0.0) as usize).min(nz);
        let k_hi = ((hi(2) - z0) / self.cell[2]).floor();
        if k_hi < 0.0 {
            return;
        }
        let k_hi = (k_hi as usize).min(nz - 1);
        for i in i0..=i1 {
            for j in j0..=j1 {
                for k in k_lo..=k_hi {
                    let b = self.cell_box([i, j, k]);
                    let v = clipped_column_integral(tri, &b);
                    let at = self.index([i, j, k]);
                    self.inside[at] += v;
                }
                if k_lo > 0 {
                    // The plain flux through the column, for the cells below the triangle.
                    let mut b = self.cell_box([i, j, 0]);
                    b.max[2] = lo(2) - 0.5;
                    b.min[2] = lo(2) - 1.5;
                    let flux = clipped_column_integral(tri, &b);
                    self.above[(i * self.counts[1] + j) * (nz + 1) + k_lo] += flux;
                }
            }
        }
    }

    /// Takes `volume` (a piece of the mesh dropped after it was measured) from the cells that
    /// `within`, the piece's bounds, reaches, in proportion to how much of each it covers.
    pub fn remove(&mut self, volume: f64, within: &Aabb) {
        let (Some((i0, i1)), Some((j0, j1)), Some((k0, k1))) = (
            self.span(0, within.min[0], within.max[0]),
            self.span(1, within.min[1], within.max[1]),
            self.span(2, within.min[2], within.max[2]),
        ) else {
            return;
        };
        let overlap = |c: [usize; 3]| {
            let b = self.cell_box(c);
            (0..3)
                .map(|a| (b.max[a].min(within.max[a]) - b.min[a].max(within.min[a])).max(0.0))
                .product::<f64>()
        };
        let reached: Vec<([usize; 3], f64)> = (i0..=i1)
            .flat_map(|i| (j0..=j1).flat_map(move |j| (k0..=k1).map(move |k| [i, j, k])))
            .map(|c| (c, overlap(c)))
            .collect();
        let total: f64 = reached.iter().map(|r| r.1).sum();
        for (c, o) in reached {
            let share = if total > 0.0 {
                o / total
            } else {
                1.0 / ((i1 - i0 + 1) * (j1 - j0 + 1) * (k1 - k0 + 1)) as f64
            };
            let at = self.index(c);
            self.inside[at] -= volume * share;
        }
    }

    /// Adds the cells of another pass over other triangles of the same mesh.
    pub fn merge(&mut self, o: &CellVolumes) {
        for (a, b) in self.inside.iter_mut().zip(&o.inside) {
            *a += b;
        }
        for (a, b) in self.above.iter_mut().zip(&o.above) {
            *a += b;
        }
    }

    /// The volume within each cell, mm³, in index order.
    pub fn volumes(&self) -> Vec<f64> {
        let [nx, ny, nz] = self.counts;
        let mut out = self.inside.clone();
        for i in 0..nx {
            for j in 0..ny {
                let mut flux = 0.0;
                for k in (0..nz).rev() {
                    flux += self.above[(i * ny + j) * (nz + 1) + k + 1];
                    let b = self.cell_box([i, j, k]);
                    out[self.index([i, j, k])] += flux * (b.max[2] - b.min[2]);
                }
            }
        }
        out
    }

    /// Each cell's volume fraction: its volume over its box's.
    pub fn fractions(&self) -> Vec<f64> {
        let v = self.volumes();
        self.cells()
            .map(|c| v[self.index(c)] / self.cell_box(c).volume())
            .collect()
    }

    /// The cell size, mm.
    pub fn cell(&self) -> Vec3 {
        self.cell
    }

    /// Adds the triangles of an in-memory mesh, in parallel.
    pub fn add_mesh(&mut self, mesh: &crate::geom::Mesh) {
        use rayon::prelude::*;
        let empty = CellVolumes::new(self.bounds, self.cell);
        const CHUNK: usize = 1 << 15;
        let parts: Vec<CellVolumes> = (0..mesh.triangle_count().div_ceil(CHUNK))
            .into_par_iter()
            .map(|c| {
                let mut v = empty.clone();
                for t in c * CHUNK..((c + 1) * CHUNK).min(mesh.triangle_count()) {
                    v.add(mesh.triangle(t));
                }
                v
            })
            .collect();
        for p in &parts {
            self.merge(p);
        }
    }

    /// The per-cell volumes of an in-memory mesh.
    pub fn of_mesh(mesh: &crate::geom::Mesh, bounds: Aabb, cell: Vec3) -> CellVolumes {
        let mut v = CellVolumes::new(bounds, cell);
        v.add_mesh(mesh);
        v
    }
}

/// A sink that measures each cell's volume of the triangles it passes on.
pub struct CellTee<'a> {
    /// Where the triangles go.
    pub inner: &'a mut dyn MeshSink,
    /// What they hold per cell.
    pub cells: CellVolumes,
}

impl MeshSink for CellTee<'_> {
    fn begin(&mut self, triangles: Option<u64>) -> Result<()> {
        self.inner.begin(triangles)
    }

    fn triangles(&mut self, batch: &[Triangle]) -> Result<()> {
        use rayon::prelude::*;
        // Fixed chunks merged in order: the same sums whatever the scheduling; each chunk
        // worth the cells' copy it fills.
        let empty = CellVolumes::new(self.cells.bounds, self.cells.cell);
        let chunk = (1usize << 15).max(8 * empty.inside.len());
        let parts: Vec<CellVolumes> = batch
            .par_chunks(chunk)
            .map(|chunk| {
                let mut v = empty.clone();
                for t in chunk {
                    v.add(t.map(|p| p.map(|x| x as f64)));
                }
                v
            })
            .collect();
        for p in &parts {
            self.cells.merge(p);
        }
        self.inner.triangles(batch)
    }

    fn finish(&mut self) -> Result<()> {
        self.inner.finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_box_is_shared_out_among_the_cells_it_overlaps() {
        let part = Aabb {
            min: [0.0; 3],
            max: [3.0, 2.0, 2.5],
        };
        // The second's faces lie on cell planes, its top and bottom across columns.
        for (lo, hi) in [
            ([0.5, 0.25, 0.2], [2.5, 1.5, 2.9]),
            ([0.5, 0.0, 1.0], [2.5, 2.0, 2.0]),
        ] {
            let mesh = crate::geom::Mesh::cuboid(lo, hi);
            let cells = CellVolumes::of_mesh(&mesh, part, [1.0; 3]);
            assert_eq!(cells.counts, [3, 2, 3]);
            let v = cells.volumes();
            for c in cells.cells().collect::<Vec<_>>() {
                let b = cells.cell_box(c);
                let overlap: f64 = (0..3)
                    .map(|a| (b.max[a].min(hi[a] as f64) - b.min[a].max(lo[a] as f64)).max(0.0))
                    .product();
                assert!((v[cells.index(c)] - overlap).abs() < 1e-12, "{c:?}");
            }
            assert!(cells.is_whole([2, 1, 1]) && !cells.is_whole([2, 1, 2]));
        }
    }
}
