//! Instancing: a periodic solid is meshed once, at template size, and copied cell by cell.
//!
//! Away from the box, every cell of a periodic lattice (TPMS, struts) is the same cell. A cell's mesh depends only
//! on whether it touches the box's lower face, its upper face, or neither, along each axis — so
//! a part of n cells per axis contains only the kinds of cell that a part of three cells per axis
//! contains (four when the last cell is cut short: the full cell before it is a kind of its own).
//! That small part, the *template*, is sampled, meshed by OpenVDB, snapped, and verified by CGAL
//! as a part in its own right. The big part is then written cell by cell, each cell a translated
//! copy of the template cell of its kind, straight to the output: memory and meshing time do not
//! grow with the part, only the copying and writing do.
//!
//! Exactness. The template is sampled with index-periodic phases (a [`Solid`]'s field is
//! sampled by index modulo the cell), so sample values one cell apart are bit-identical, and OpenVDB meshes
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
//! OpenVDB leaves (8 voxels) per cell along each copied axis, and cells of at least
//! [`MIN_SAMPLES_PER_CELL`] voxels, so the box's influence (narrow band, clipping, snapping)
//! dies out well inside the first cell.
//!
//! Measuring. The part's volume is the template's, cell kind by cell kind, times how often each
//! kind occurs, corrected for where the copies sit ([`Template::part_volume`]): the level that
//! gives a part its density can be found on the template alone. Without the leaf alignment the
//! copies would not be bit-exact, but a template still measures the part (a *measuring
//! template*, [`measuring_plan`]); fragments the box cuts loose are found on the template too.

use crate::error::{Error, Result};
use crate::field::{Aabb, Vec3};
use crate::grid::GridSpec;
use crate::io::sink::{Measures, MeshSink, Triangle};
use crate::mesh::extract::{KeyedMesh, VertexKey};
use crate::mesh::pieces::{Fragments, Shells};
use crate::mesh::pipeline::{MeshingStats, Solid};
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
    plan_with(size, cell, h, true)
}

/// Plans a measuring template: like [`plan`], but a cell need not span whole OpenVDB leaves
/// (the copies' volumes agree with the part's to rounding, their vertices not bit for bit).
pub fn measuring_plan(size: Vec3, cell: Vec3, h: f64) -> Option<[AxisPlan; 3]> {
    plan_with(size, cell, h, false)
}

fn plan_with(size: Vec3, cell: Vec3, h: f64, leaf_aligned: bool) -> Option<[AxisPlan; 3]> {
    let axes = [0, 1, 2].map(|a| {
        let n = ((size[a] / cell[a]) * (1.0 - 1e-12)).ceil().max(1.0) as i64;
        let last = size[a] - (n - 1) as f64 * cell[a];
        let partial = last < cell[a] * (1.0 - 1e-9);
        let p = (cell[a] / h).round();
        let whole = (cell[a] / h - p).abs() < 1e-9 * p;
        let m = if partial { 4 } else { 3 };
        // OpenVDB meshes leaf by leaf (8³ voxels) and settles ambiguous voxels at leaf borders
        // its own way: a cell meshes alike wherever it is only if it spans whole leaves.
        let aligned = !leaf_aligned || p as i64 % BLOCK as i64 == 0;
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

/// A template cell's triangles by local vertex (see [`Template::kind_tables`]).
#[derive(Default)]
struct KindTable {
    vertices: Vec<u32>,
    triangles: Vec<[u32; 3]>,
}

/// A meshed template and what is needed to copy it.
pub struct Template {
    /// How each axis of the part maps onto the template.
    pub plan: [AxisPlan; 3],
    /// The cell's edge lengths, mm.
    pub cell: Vec3,
    /// The template's mesh, every vertex keyed by voxel and edge group.
    pub mesh: KeyedMesh,
    /// Template cell of each vertex.
    point_cell: Vec<[i8; 3]>,
    /// Quads of each template cell (cells in x-major order).
    quads_by_cell: Vec<Vec<u32>>,
    /// Per vertex and axis: the vertex with the same key shifted along that axis into template
    /// cell 1, or `u32::MAX`.
    twin: Vec<[u32; 3]>,
    /// Fragments removed from the template, per template cell (by the cell of each fragment's
    /// least vertex key): how many, and their volume.
    fragments_by_cell: Vec<(u64, f64)>,
    /// Keys of the vertices of removed fragments.
    fragment_keys: std::collections::HashSet<VertexKey>,
    /// The removed fragments' shells, standing for their copies in the part.
    loose: crate::mesh::pieces::Loose,
}

impl Template {
    /// Meshes the template of `solid` (the part, periodic with cells starting at its box's
    /// lower corner) on voxels of size `h`; removes the fragments the box cuts loose unless
    /// `keep_fragments`.
    pub fn build<S: Solid>(
        solid: &S,
        h: f64,
        plan: [AxisPlan; 3],
        keep_fragments: bool,
    ) -> Result<(Template, MeshingStats)> {
        let cell = solid
            .period()
            .ok_or_else(|| Error::invalid("a template needs a periodic solid"))?;
        let tb = template_bounds(&solid.bounds(), cell, &plan);
        let small = solid.with_bounds(tb);
        let spec = GridSpec::covering(&tb, h, crate::mesh::pipeline::HALF_WIDTH);
        let (mut mesh, stats) = crate::mesh::pipeline::mesh_keyed(&small, spec, None, 0.0, None)?;
        let m = plan.map(|a| a.m as usize);
        let mut fragments_by_cell = vec![(0u64, 0.0f64); m[0] * m[1] * m[2]];
        let mut fragment_keys = std::collections::HashSet::new();
        let mut loose = crate::mesh::pieces::Loose::default();
        if !keep_fragments {
            let shells = Shells::of(&mesh);
            if shells.kept.iter().any(|&k| !k) {
                // Each removed shell is counted in the cell of its least vertex key, so that
                // every copy of it in the part is counted once.
                let mut least = vec![None::<VertexKey>; shells.volume.len()];
                for (v, k) in mesh.keys.iter().enumerate() {
                    let s = shells.of_vertex[v] as usize;
                    if !shells.kept[s] {
                        fragment_keys.insert(*k);
                        if least[s].is_none_or(|l| *k < l) {
                            least[s] = Some(*k);
                        }
                    }
                }
                for (s, key) in least.iter().enumerate() {
                    if let Some(key) = key {
                        let c = [0, 1, 2].map(|a| plan[a].cell_of(key.voxel[a] as i64) as usize);
                        let e = &mut fragments_by_cell[(c[0] * m[1] + c[1]) * m[2] + c[2]];
                        e.0 += (shells.volume[s] > 0.0) as u64;
                        e.1 += shells.volume[s];
                    }
                }
                loose = crate::mesh::pieces::Loose::of_template(
                    crate::mesh::pieces::loose_triangles(&mesh, &shells),
                    plan,
                    tb.min,
                    cell,
                );
                let keep: Vec<bool> = shells
                    .of_vertex
                    .iter()
                    .map(|&s| shells.kept[s as usize])
                    .collect();
                crate::mesh::pieces::retain(&mut mesh, &keep);
            }
        }
        let mut t = Template::from_mesh(mesh, cell, plan)?;
        t.fragments_by_cell = fragments_by_cell;
        t.fragment_keys = fragment_keys;
        t.loose = loose;
        Ok((t, stats))
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
            fragments_by_cell: Vec::new(),
            fragment_keys: Default::default(),
            loose: Default::default(),
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
        let mut total = 0;
        self.for_each_kind(|k, count, _| total += count * f(k));
        total
    }

    /// Calls `f(kind, cells, shift)` for every template cell: how many cells of the part are of
    /// its kind, and the sum over them of their offset from the template cell, mm.
    fn for_each_kind(&self, mut f: impl FnMut(usize, u64, Vec3)) {
        // Per axis and template cell: (cells of the part, Σ of their offsets in cells).
        let per_axis = self.plan.map(|ax| {
            (0..ax.m)
                .map(|t| {
                    let extra = ax.n - ax.m;
                    if ax.m == ax.n || t == 0 {
                        (1u64, 0.0)
                    } else if t == 1 {
                        ((extra + 1) as u64, (extra * (extra + 1)) as f64 / 2.0)
                    } else {
                        (1, extra as f64)
                    }
                })
                .collect::<Vec<_>>()
        });
        for (i, &(cx, sx)) in per_axis[0].iter().enumerate() {
            for (j, &(cy, sy)) in per_axis[1].iter().enumerate() {
                for (k, &(cz, sz)) in per_axis[2].iter().enumerate() {
                    let shift = [
                        sx * (cy * cz) as f64 * self.cell[0],
                        sy * (cx * cz) as f64 * self.cell[1],
                        sz * (cx * cy) as f64 * self.cell[2],
                    ];
                    f(
                        self.kind_index([i as i64, j as i64, k as i64]),
                        cx * cy * cz,
                        shift,
                    );
                }
            }
        }
    }

    /// Enclosed volume of the whole part, mm³, without writing it: each triangle of a template
    /// cell stands for one in every cell of its kind, and a triangle moved by `d` adds
    /// `d · n / 3` to the divergence-theorem volume (`n` its area vector), so per kind the sum of
    /// the triangles' volumes and of their area vectors is enough.
    pub fn part_volume(&self) -> f64 {
        use crate::geom::{cross, dot, signed_volume, sub};
        let pos = |v: u32| self.mesh.positions[v as usize].map(|x| x as f32 as f64);
        let per_kind: Vec<(f64, Vec3)> = self
            .quads_by_cell
            .par_iter()
            .map(|qs| {
                let (mut vol, mut area) = (0.0, [0.0; 3]);
                for &q in qs {
                    let (t, u) = self.mesh.quad_triangles(q as usize);
                    for tri in std::iter::once(t).chain(u) {
                        let [a, b, c] = tri.map(pos);
                        vol += signed_volume(a, b, c);
                        let n = cross(sub(b, a), sub(c, a));
                        for x in 0..3 {
                            area[x] += 0.5 * n[x];
                        }
                    }
                }
                (vol, area)
            })
            .collect();
        let mut total = 0.0;
        self.for_each_kind(|k, count, shift| {
            total += count as f64 * per_kind[k].0 + dot(shift, per_kind[k].1) / 3.0;
        });
        total
    }

    /// The sum over the whole part of a quantity each of the template's quads has (one that a
    /// translation leaves alone): the template's cells stand for every cell of their kind.
    pub fn part_sum(&self, per_quad: impl Fn(usize) -> f64 + Sync) -> f64 {
        let per_kind: Vec<f64> = self
            .quads_by_cell
            .par_iter()
            .map(|qs| qs.iter().map(|&q| per_quad(q as usize)).sum())
            .collect();
        let mut total = 0.0;
        self.for_each_kind(|k, count, _| total += count as f64 * per_kind[k]);
        total
    }

    /// The template's cells, each with the number of the part's cells it stands for: boxes
    /// within the template's box (that of the part `part` cut down).
    pub fn cells_with_counts(&self, part: &Aabb) -> Vec<(Aabb, u64)> {
        let tb = template_bounds(part, self.cell, &self.plan);
        let m = self.plan.map(|a| a.m);
        let mut boxes = vec![tb; (m[0] * m[1] * m[2]) as usize];
        for i in 0..m[0] {
            for j in 0..m[1] {
                for k in 0..m[2] {
                    let c = [i, j, k];
                    let b = &mut boxes[self.kind_index(c)];
                    for a in 0..3 {
                        if self.plan[a].n > self.plan[a].m {
                            let lo = tb.min[a] + c[a] as f64 * self.cell[a];
                            b.min[a] = lo;
                            b.max[a] = if c[a] == m[a] - 1 {
                                tb.max[a]
                            } else {
                                lo + self.cell[a]
                            };
                        }
                    }
                }
            }
        }
        let mut out = Vec::with_capacity(boxes.len());
        self.for_each_kind(|k, count, _| out.push((boxes[k], count)));
        out
    }

    /// The fragments the box cuts loose in the whole part (removed from the template, so from
    /// every copy).
    pub fn part_fragments(&self) -> Fragments {
        let mut f = Fragments {
            removed: true,
            ..Default::default()
        };
        if self.fragments_by_cell.is_empty() {
            f.removed = false;
            return f;
        }
        self.for_each_kind(|k, count, _| {
            f.count += count * self.fragments_by_cell[k].0;
            f.volume += count as f64 * self.fragments_by_cell[k].1;
        });
        f
    }

    /// The fragments removed from the part (their shells in the template, standing for every
    /// copy).
    pub fn loose(&self) -> &crate::mesh::pieces::Loose {
        &self.loose
    }

    /// Whether the vertex of the part with key `key` is a copy of a removed fragment's vertex.
    pub fn is_fragment(&self, key: &VertexKey) -> bool {
        if self.fragment_keys.is_empty() {
            return false;
        }
        let mut k = *key;
        for a in 0..3 {
            let ax = self.plan[a];
            if ax.n > ax.m {
                let v = key.voxel[a] as i64;
                let c = v.div_euclid(ax.p).clamp(0, ax.n - 1);
                k.voxel[a] = (v - (c - ax.kind(c)) * ax.p) as i32;
            }
        }
        self.fragment_keys.contains(&k)
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
        let kinds = self.kind_tables();
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
                .map(|(i, out)| self.cell_triangles(cell_at(i), &kinds, out))
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

    /// Per template cell: the vertices its triangles use, each once, and its triangles (in quad
    /// order) as indices into that list — so a copied cell places each vertex once, not once
    /// per triangle around it.
    fn kind_tables(&self) -> Vec<KindTable> {
        self.quads_by_cell
            .par_iter()
            .map(|qs| {
                let mut local: HashMap<u32, u32> = HashMap::new();
                let mut table = KindTable::default();
                for &q in qs {
                    let (t, u) = self.mesh.quad_triangles(q as usize);
                    for tri in std::iter::once(t).chain(u) {
                        table.triangles.push(tri.map(|v| {
                            *local.entry(v).or_insert_with(|| {
                                table.vertices.push(v);
                                table.vertices.len() as u32 - 1
                            })
                        }));
                    }
                }
                table
            })
            .collect()
    }

    /// Writes the triangles of the part's cell `c` into `out` (sized for them) and measures them.
    fn cell_triangles(
        &self,
        c: [i64; 3],
        kinds: &[KindTable],
        out: &mut [Triangle],
    ) -> Result<Measures> {
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
        let table = &kinds[self.kind_index(kind)];
        let placed: Vec<[f32; 3]> = table
            .vertices
            .iter()
            .map(|&v| corner(v))
            .collect::<Result<_>>()?;
        for (o, t) in out.iter_mut().zip(&table.triangles) {
            *o = t.map(|i| placed[i as usize]);
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
