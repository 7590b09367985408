//! Instancing: a periodic lattice is meshed once, at template size, and copied cell by cell.
//!
//! Away from the box, every cell of a TPMS lattice is the same cell. A cell's mesh depends only
//! on whether it touches the box's lower face, its upper face, or neither, along each axis — so
//! a part of n cells per axis contains only the kinds of cell that a part of three cells per axis
//! contains (four when the last cell is cut short: the full cell before it is a kind of its own).
//! That small part, the *template*, is sampled, meshed by OpenVDB, snapped, and verified by CGAL
//! as a part in its own right. The big part is then written cell by cell, each cell a translated
//! copy of the template cell of its kind, straight to the output: memory and meshing time do not
//! grow with the part, only the copying and writing do.
//!
//! Exactness. The template is sampled with index-periodic phases ([`TpmsField`]'s
//! `samples_per_cell`), so sample values one cell apart are bit-identical, and OpenVDB meshes
//! identical samples identically: cell kinds agree wherever they meet. Vertices are named by
//! [`VertexKey`] (voxel and edge group); a quad belongs to the cell holding its edge's lower
//! sample, a vertex to the cell holding its voxel. Each vertex of the big part is taken from one
//! template vertex (of the kind of the cell that owns it) and translated by whole cells, so every
//! triangle that shares it writes bit-identical coordinates: seams are welded exactly, and the
//! big part has the template's topology cell by cell. Where a copied quad reaches into a
//! neighbouring cell whose kind differs from the template neighbour's, its corner is taken from
//! the *twin* of the template vertex — the same key one cell over, inside the interior cell.
//!
//! Requirements: adaptivity 0 (OpenVDB's adaptive merging is not local), a whole number of
//! OpenVDB leaves (8 voxels) per cell along each copied axis, and cells of at least [`MIN_SAMPLES_PER_CELL`] voxels, so the
//! box's influence (narrow band, clipping, snapping) dies out well inside the first cell.
//!
//! [`TpmsField`]: super::TpmsField

use super::{Lattice, MeshingStats};
use crate::error::{Error, Result};
use crate::extract::{KeyedMesh, VertexKey};
use crate::field::{Aabb, Vec3};
use crate::grid::GridSpec;
use crate::sink::{Measures, MeshSink, Triangle};
use rayon::prelude::*;
use std::collections::HashMap;

/// Fewest voxels per cell for instancing.
pub const MIN_SAMPLES_PER_CELL: i64 = 16;
/// OpenVDB's leaf edge, voxels: a copied cell spans a whole number of leaves.
pub const BLOCK: u32 = 8;

/// How one axis of the part maps onto the template.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AxisPlan {
    /// Cells of the part along the axis (1 when the axis is not copied).
    pub n: i64,
    /// Cells of the template along the axis.
    pub m: i64,
    /// Samples per cell.
    pub p: i64,
}

impl AxisPlan {
    const WHOLE: AxisPlan = AxisPlan {
        n: 1,
        m: 1,
        p: i64::MAX / 8,
    };

    /// The template cell standing for the part's cell `i`: the first cell, the interior cell 1,
    /// or one of the `m − 2` cells at the far end.
    pub fn kind(&self, i: i64) -> i64 {
        if self.m == self.n || i == 0 {
            i
        } else if i >= self.n - (self.m - 2) {
            i - (self.n - self.m)
        } else {
            1
        }
    }

    /// The template cell holding sample (or voxel) index `s`.
    fn cell_of(&self, s: i64) -> i64 {
        s.div_euclid(self.p).clamp(0, self.m - 1)
    }
}

/// Plans instancing for a lattice box of `size` with cells of `cell`, sampled at voxel `h`;
/// `None` when no axis can be copied.
pub fn plan(size: Vec3, cell: Vec3, h: f64) -> Option<[AxisPlan; 3]> {
    let axes = [0, 1, 2].map(|a| {
        let n = ((size[a] / cell[a]) * (1.0 - 1e-12)).ceil().max(1.0) as i64;
        let last = size[a] - (n - 1) as f64 * cell[a];
        let partial = last < cell[a] * (1.0 - 1e-9);
        let p = (cell[a] / h).round();
        let whole = (cell[a] / h - p).abs() < 1e-9 * p;
        let m = if partial { 4 } else { 3 };
        // OpenVDB meshes leaf by leaf (8³ voxels) and settles ambiguous voxels at leaf borders
        // its own way: a cell meshes alike wherever it is only if it spans whole leaves.
        let aligned = p as i64 % BLOCK as i64 == 0;
        if whole && aligned && p as i64 >= MIN_SAMPLES_PER_CELL && n > m {
            AxisPlan { n, m, p: p as i64 }
        } else {
            AxisPlan::WHOLE
        }
    });
    axes.iter().any(|a| a.n > a.m).then_some(axes)
}

/// The template's box: the part's box cut down to the template's cells along copied axes.
pub fn template_bounds(part: &Aabb, cell: Vec3, plan: &[AxisPlan; 3]) -> Aabb {
    let mut b = *part;
    for a in 0..3 {
        let ax = plan[a];
        if ax.n > ax.m {
            // The far-end cells keep their own widths: shift the box's far face by whole cells.
            b.max[a] = part.max[a] - (ax.n - ax.m) as f64 * cell[a];
        }
    }
    b
}

/// A meshed template and what is needed to copy it.
pub struct Template {
    pub plan: [AxisPlan; 3],
    pub cell: Vec3,
    pub mesh: KeyedMesh,
    /// Template cell of each vertex.
    point_cell: Vec<[i8; 3]>,
    /// Quads of each template cell (cells in x-major order).
    quads_by_cell: Vec<Vec<u32>>,
    /// Per vertex and axis: the vertex with the same key shifted along that axis into template
    /// cell 1, or `u32::MAX`.
    twin: Vec<[u32; 3]>,
}

impl Template {
    /// Meshes the template of `lattice` (the part) on voxels of size `h`.
    pub fn build(
        lattice: &Lattice,
        h: f64,
        plan: [AxisPlan; 3],
    ) -> Result<(Template, MeshingStats)> {
        let tb = template_bounds(&lattice.bounds, lattice.cell, &plan);
        let small = Lattice {
            bounds: tb,
            ..*lattice
        };
        let spec = GridSpec::covering(&tb, h, super::HALF_WIDTH);
        let (mesh, stats) = small.mesh_keyed(spec, 0.0)?;
        Ok((Template::from_mesh(mesh, lattice.cell, plan)?, stats))
    }

    fn from_mesh(mesh: KeyedMesh, cell: Vec3, plan: [AxisPlan; 3]) -> Result<Template> {
        let m = plan.map(|a| a.m as usize);
        let cell_index =
            |c: [i64; 3]| (c[0] as usize * m[1] + c[1] as usize) * m[2] + c[2] as usize;
        let point_cell: Vec<[i8; 3]> = mesh
            .keys
            .iter()
            .map(|k| [0, 1, 2].map(|a| plan[a].cell_of(k.voxel[a] as i64) as i8))
            .collect();
        let mut quads_by_cell = vec![Vec::new(); m[0] * m[1] * m[2]];
        for (q, e) in mesh.edges.iter().enumerate() {
            let c = [0, 1, 2].map(|a| plan[a].cell_of(e[a] as i64));
            quads_by_cell[cell_index(c)].push(q as u32);
        }
        let index: HashMap<VertexKey, u32> = mesh
            .keys
            .iter()
            .enumerate()
            .map(|(i, k)| (*k, i as u32))
            .collect();
        let twin: Vec<[u32; 3]> = mesh
            .keys
            .par_iter()
            .zip(point_cell.par_iter())
            .map(|(k, c)| {
                [0, 1, 2].map(|a| {
                    let shift = 1 - c[a] as i64;
                    if plan[a].n <= plan[a].m || shift == 0 {
                        return u32::MAX;
                    }
                    let mut key = *k;
                    key.voxel[a] += (shift * plan[a].p) as i32;
                    index.get(&key).copied().unwrap_or(u32::MAX)
                })
            })
            .collect();
        Ok(Template {
            plan,
            cell,
            mesh,
            point_cell,
            quads_by_cell,
            twin,
        })
    }

    fn cells(&self) -> [i64; 3] {
        self.plan.map(|a| a.n)
    }

    fn kind_index(&self, k: [i64; 3]) -> usize {
        let m = self.plan.map(|a| a.m as usize);
        (k[0] as usize * m[1] + k[1] as usize) * m[2] + k[2] as usize
    }

    /// Triangles of the whole part.
    pub fn triangle_count(&self) -> u64 {
        let per_kind: Vec<u64> = self
            .quads_by_cell
            .iter()
            .map(|qs| {
                qs.iter()
                    .map(|&q| {
                        let quad = self.mesh.quads[q as usize];
                        if quad[2] == quad[3] {
                            1
                        } else {
                            2
                        }
                    })
                    .sum()
            })
            .collect();
        self.count_over_cells(|k| per_kind[k])
    }

    /// Vertices of the whole part.
    pub fn vertex_count(&self) -> u64 {
        let mut per_kind = vec![0u64; self.quads_by_cell.len()];
        for c in &self.point_cell {
            per_kind[self.kind_index(c.map(|x| x as i64))] += 1;
        }
        self.count_over_cells(|k| per_kind[k])
    }

    /// Σ over the part's cells of `f(kind)`, counting cells per kind instead of visiting them.
    fn count_over_cells(&self, f: impl Fn(usize) -> u64) -> u64 {
        let per_axis = self.plan.map(|ax| {
            let mut counts = vec![0u64; ax.m as usize];
            for t in 0..ax.m {
                counts[t as usize] = if ax.m == ax.n || t != 1 {
                    1
                } else {
                    (ax.n - ax.m + 1) as u64
                };
            }
            counts
        });
        let mut total = 0;
        for (i, &cx) in per_axis[0].iter().enumerate() {
            for (j, &cy) in per_axis[1].iter().enumerate() {
                for (k, &cz) in per_axis[2].iter().enumerate() {
                    total += cx * cy * cz * f(self.kind_index([i as i64, j as i64, k as i64]));
                }
            }
        }
        total
    }

    /// Writes the whole part to `sink`, a batch of cells at a time, and measures what it wrote.
    pub fn expand(&self, sink: &mut dyn MeshSink) -> Result<Measures> {
        let n = self.cells();
        let total = (n[0] * n[1] * n[2]) as usize;
        let per_kind: Vec<usize> = self
            .quads_by_cell
            .iter()
            .map(|qs| qs.iter().map(|&q| self.quad_triangle_count(q)).sum())
            .collect();
        let cell_at = |i: usize| {
            [
                (i / (n[1] * n[2]) as usize) as i64,
                ((i / n[2] as usize) % n[1] as usize) as i64,
                (i % n[2] as usize) as i64,
            ]
        };
        let kind_of = |c: [i64; 3]| self.kind_index([0, 1, 2].map(|a| self.plan[a].kind(c[a])));
        sink.begin(Some(self.triangle_count()))?;
        let mut measures = Measures::default();
        // Batches of about a million triangles: both cores stay busy, memory stays bounded, and
        // the one buffer is reused.
        let mut buf: Vec<Triangle> = Vec::new();
        let mut start = 0;
        while start < total {
            let mut end = start;
            let mut count = 0;
            while end < total && (end == start || count < 1 << 20) {
                count += per_kind[kind_of(cell_at(end))];
                end += 1;
            }
            buf.clear();
            buf.resize(count, [[0.0; 3]; 3]);
            let mut slices = Vec::with_capacity(end - start);
            let mut rest = &mut buf[..];
            for i in start..end {
                let (head, tail) = rest.split_at_mut(per_kind[kind_of(cell_at(i))]);
                slices.push((i, head));
                rest = tail;
            }
            let parts: Vec<Result<Measures>> = slices
                .into_par_iter()
                .map(|(i, out)| self.cell_triangles(cell_at(i), out))
                .collect();
            for m in parts {
                measures = measures.merged(&m?);
            }
            sink.triangles(&buf)?;
            start = end;
        }
        sink.finish()?;
        Ok(measures)
    }

    fn quad_triangle_count(&self, q: u32) -> usize {
        let quad = self.mesh.quads[q as usize];
        if quad[2] == quad[3] {
            1
        } else {
            2
        }
    }

    /// Writes the triangles of the part's cell `c` into `out` (sized for them) and measures them.
    fn cell_triangles(&self, c: [i64; 3], out: &mut [Triangle]) -> Result<Measures> {
        let kind = [0, 1, 2].map(|a| self.plan[a].kind(c[a]));
        // For each neighbour offset d ∈ {−1, 0, 1}³ of a corner's template cell from this cell's
        // kind: per axis, whether the twin is needed, and the translation in cells.
        let mut twin_to = [[-1i8; 3]; 27];
        let mut shift = [[0.0f64; 3]; 27];
        for (di, (tw, sh)) in twin_to.iter_mut().zip(shift.iter_mut()).enumerate() {
            let d = [
                di as i64 / 9 - 1,
                (di as i64 / 3) % 3 - 1,
                di as i64 % 3 - 1,
            ];
            for a in 0..3 {
                let owner = c[a] + d[a];
                let owner_kind = self.plan[a].kind(owner);
                if owner_kind != kind[a] + d[a] {
                    tw[a] = owner_kind as i8;
                }
                sh[a] = (owner - owner_kind) as f64 * self.cell[a];
            }
        }
        let tpos = &self.mesh.positions;
        let corner = |v: u32| -> Result<[f32; 3]> {
            let vc = self.point_cell[v as usize];
            let d = [0, 1, 2].map(|a| vc[a] as i64 - kind[a]);
            if d.iter().any(|x| x.abs() > 1) {
                return Err(Error::invalid(
                    "a lattice template quad spans more than one cell",
                ));
            }
            let di = ((d[0] + 1) * 9 + (d[1] + 1) * 3 + (d[2] + 1)) as usize;
            let mut j = v;
            for (a, &to) in twin_to[di].iter().enumerate() {
                if to >= 0 {
                    j = self.twin[j as usize][a];
                    if j == u32::MAX || self.point_cell[j as usize][a] != to {
                        return Err(Error::invalid(
                            "the lattice template is not periodic where it should be",
                        ));
                    }
                }
            }
            let p = tpos[j as usize];
            Ok([0, 1, 2].map(|a| (p[a] + shift[di][a]) as f32))
        };
        let quads = &self.quads_by_cell[self.kind_index(kind)];
        let mut k = 0;
        for &q in quads {
            let (t, u) = self.mesh.quad_triangles(q as usize);
            out[k] = [corner(t[0])?, corner(t[1])?, corner(t[2])?];
            k += 1;
            if let Some(u) = u {
                out[k] = [corner(u[0])?, corner(u[1])?, corner(u[2])?];
                k += 1;
            }
        }
        Ok(Measures::of_serial(out))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kinds_cover_first_interior_and_far_end() {
        let full = AxisPlan { n: 7, m: 3, p: 32 };
        let kinds: Vec<i64> = (0..7).map(|i| full.kind(i)).collect();
        assert_eq!(kinds, [0, 1, 1, 1, 1, 1, 2]);
        let cut = AxisPlan { n: 7, m: 4, p: 32 };
        let kinds: Vec<i64> = (0..7).map(|i| cut.kind(i)).collect();
        assert_eq!(kinds, [0, 1, 1, 1, 1, 2, 3]);
    }

    #[test]
    fn plan_copies_only_axes_with_whole_voxels_per_cell() {
        let p = plan([50.0, 50.0, 10.0], [5.0; 3], 5.0 / 32.0).unwrap();
        assert_eq!(p[0], AxisPlan { n: 10, m: 3, p: 32 });
        assert_eq!(p[2], AxisPlan::WHOLE);
        // Partial last cell: four template cells.
        let p = plan([52.0, 5.0, 5.0], [5.0; 3], 5.0 / 32.0).unwrap();
        assert_eq!(p[0], AxisPlan { n: 11, m: 4, p: 32 });
        // Too coarse to copy.
        assert!(plan([50.0; 3], [5.0; 3], 5.0 / 8.0).is_none());
        let b = template_bounds(
            &Aabb {
                min: [1.0; 3],
                max: [53.0, 6.0, 6.0],
            },
            [5.0; 3],
            &plan([52.0, 5.0, 5.0], [5.0; 3], 5.0 / 32.0).unwrap(),
        );
        assert!((b.max[0] - 18.0).abs() < 1e-12);
    }
}
