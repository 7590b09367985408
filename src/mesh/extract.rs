//! Extraction: a level set to a mesh whose every vertex knows what it stands for.
//!
//! OpenVDB's volumeToMesh (at adaptivity 0) puts one point in each voxel per *edge group* — per
//! separate piece of surface crossing the voxel — and one quad across every sign-changing edge
//! between samples, joining the points of the four voxels around it. `Grid::extract` recovers
//! for each point its voxel and edge group, so a vertex is named by a [`VertexKey`] that does not
//! depend on which grid it was meshed in, and each quad by the primal edge it crosses. Vertex
//! positions are computed here from the key alone (voxel corner + OpenVDB's in-voxel average of
//! the crossings), in double precision and in the part's own coordinates.
//!
//! That is what lets a part be meshed in pieces: tiles, or copies of a periodic cell, meshed
//! separately give bit-identical vertices where they meet, so seams weld exactly, and a quad
//! belongs to exactly one piece (the one holding its edge's lower sample).

use crate::error::Result;
use crate::geom::Mesh;
use crate::grid::{Grid, GridSpec};
use rayon::prelude::*;

/// A vertex of an extracted mesh: the voxel it lies in (by its lower-corner sample index) and
/// which of the voxel's surface pieces it stands for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct VertexKey {
    /// Sample index of the voxel's lower corner, in the spec's global indices.
    pub voxel: [i32; 3],
    /// Which of the voxel's edge groups (surface pieces): OpenVDB's numbering.
    pub group: u8,
}

/// A mesh as extracted: vertices by key, with positions in millimetres (double precision), and
/// OpenVDB's quads, wound outward, each with the primal edge it crosses. Each quad is cut into two
/// triangles along the diagonal [`KeyedMesh::triangulate`] picks once the vertices have settled.
#[derive(Debug, Clone, Default)]
pub struct KeyedMesh {
    /// Each vertex's key.
    pub keys: Vec<VertexKey>,
    /// Where each vertex is; [`KeyedMesh::extract`] fills in OpenVDB's point, `snap` moves it.
    pub positions: Vec<[f64; 3]>,
    /// OpenVDB's point within the voxel, in [0, 1]³ (kept to restore a vertex snapping folded).
    pub offsets: Vec<[f64; 3]>,
    /// Outward quads `[a, b, c, d]`; a triangle is stored as `[a, b, c, c]`.
    pub quads: Vec<[u32; 4]>,
    /// Lower sample of the edge (between two samples) that each quad crosses.
    pub edges: Vec<[i32; 3]>,
    /// Per quad: cut along `b–d` (true) or `a–c` (false).
    pub diagonal_bd: Vec<bool>,
}

impl KeyedMesh {
    /// Meshes the zero level set of `grid`.
    pub fn extract(grid: &Grid) -> Result<KeyedMesh> {
        let ex = grid.extract()?;
        let spec = grid.spec;
        let np = ex.groups.len();
        let keys: Vec<VertexKey> = (0..np)
            .into_par_iter()
            .map(|i| VertexKey {
                voxel: [ex.voxels[3 * i], ex.voxels[3 * i + 1], ex.voxels[3 * i + 2]],
                group: ex.groups[i],
            })
            .collect();
        let offsets: Vec<[f64; 3]> = ex
            .offsets
            .par_chunks_exact(3)
            .map(|o| [o[0], o[1], o[2]])
            .collect();
        let positions: Vec<[f64; 3]> = keys
            .par_iter()
            .zip(offsets.par_iter())
            .map(|(k, o)| position(&spec, k.voxel, *o))
            .collect();
        // OpenVDB winds quads inward: reverse them.
        let quads: Vec<[u32; 4]> = ex
            .quads
            .par_chunks_exact(4)
            .map(|q| [q[3], q[2], q[1], q[0]])
            .collect();
        let edges = quads
            .par_iter()
            .map(|q| quad_edge(q.map(|v| keys[v as usize].voxel)))
            .collect();
        let mut m = KeyedMesh {
            keys,
            positions,
            offsets,
            diagonal_bd: vec![false; quads.len()],
            quads,
            edges,
        };
        m.triangulate();
        Ok(m)
    }

    /// A mesh OpenVDB made with adaptivity above 0, where merged points stand for several voxels:
    /// each vertex is keyed by the voxel it lies in. (Such meshes cannot be meshed in pieces.)
    pub fn from_adaptive(mesh: &Mesh, spec: &GridSpec) -> KeyedMesh {
        let n = mesh.vertex_count();
        let quads: Vec<[u32; 4]> = mesh
            .indices
            .chunks_exact(3)
            .map(|t| [t[0], t[1], t[2], t[2]])
            .collect();
        let mut out = KeyedMesh {
            keys: Vec::with_capacity(n),
            positions: Vec::with_capacity(n),
            offsets: Vec::with_capacity(n),
            edges: Vec::new(),
            diagonal_bd: vec![false; quads.len()],
            quads,
        };
        for i in 0..n as u32 {
            let p = mesh.vertex(i);
            let u = [0, 1, 2].map(|a| (p[a] - spec.origin[a]) / spec.voxel - 0.5);
            let voxel = u.map(|x| x.floor() as i32);
            out.keys.push(VertexKey { voxel, group: 0 });
            out.offsets.push([0, 1, 2].map(|a| u[a] - voxel[a] as f64));
            out.positions.push(p);
        }
        out
    }

    /// Picks each quad's diagonal for the current positions: the cut whose worse triangle is the
    /// better shaped (so a quad with three vertices snapped onto one straight line is not cut
    /// into a zero-area sliver).
    pub fn triangulate(&mut self) {
        let pos = &self.positions;
        self.quads
            .par_iter()
            .zip(self.diagonal_bd.par_iter_mut())
            .for_each(|(q, bd)| {
                if q[2] == q[3] {
                    *bd = false;
                    return;
                }
                let p = q.map(|v| pos[v as usize]);
                let ac = quality(p[0], p[1], p[2]).min(quality(p[0], p[2], p[3]));
                let bd_q = quality(p[0], p[1], p[3]).min(quality(p[1], p[2], p[3]));
                // A tie (a symmetric quad, often on a flat cut face) keeps the first diagonal:
                // the copies of a cell, whose coordinates differ in their last bits, then
                // choose alike.
                *bd = bd_q > ac * (1.0 + 1e-9);
            });
    }

    /// The two triangles of quad `q` (one for a stored triangle).
    #[inline]
    pub fn quad_triangles(&self, q: usize) -> ([u32; 3], Option<[u32; 3]>) {
        let [a, b, c, d] = self.quads[q];
        if c == d {
            ([a, b, c], None)
        } else if self.diagonal_bd[q] {
            ([a, b, d], Some([b, c, d]))
        } else {
            ([a, b, c], Some([a, c, d]))
        }
    }

    /// Every triangle, in quad order.
    pub fn triangles(&self) -> impl Iterator<Item = [u32; 3]> + '_ {
        (0..self.quads.len()).flat_map(move |q| {
            let (t, u) = self.quad_triangles(q);
            std::iter::once(t).chain(u)
        })
    }

    /// Edges of one triangle only: where the mesh has a hole. OpenVDB's meshes of a level set are
    /// closed; on voxels too coarse for a lattice's members (a void thinner than a voxel where
    /// it meets the box) they can come out open.
    pub fn open_edges(&self) -> u64 {
        let mut edges: Vec<u64> = self
            .triangles()
            .flat_map(|[a, b, c]| [(a, b), (b, c), (c, a)])
            .map(|(a, b)| (a.min(b) as u64) << 32 | a.max(b) as u64)
            .collect();
        edges.sort_unstable();
        let mut open = 0;
        let mut i = 0;
        while i < edges.len() {
            let mut j = i + 1;
            while j < edges.len() && edges[j] == edges[i] {
                j += 1;
            }
            open += (j - i == 1) as u64;
            i = j;
        }
        open
    }

    /// Number of triangles the quads make (a stored triangle counts once).
    pub fn triangle_count(&self) -> usize {
        self.quads
            .iter()
            .map(|q| if q[2] == q[3] { 1 } else { 2 })
            .sum()
    }

    /// The mesh in single precision, as it is written; the keyed mesh (keys, offsets, quads:
    /// as large again as the mesh) is freed before the caller goes on.
    pub fn into_mesh(self) -> Mesh {
        self.to_mesh()
    }

    /// The mesh in single precision, as it is written.
    pub fn to_mesh(&self) -> Mesh {
        Mesh {
            positions: self
                .positions
                .iter()
                .flat_map(|p| p.map(|x| x as f32))
                .collect(),
            indices: self.triangles().flatten().collect(),
        }
    }
}

/// Shape quality of a triangle: twice its area over the sum of its squared edge lengths (0 for a
/// sliver, largest for an equilateral triangle).
pub(crate) fn quality(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    use crate::geom::{cross, dot, norm, sub};
    let (ab, bc, ca) = (sub(b, a), sub(c, b), sub(a, c));
    let s = dot(ab, ab) + dot(bc, bc) + dot(ca, ca);
    if s > 0.0 {
        norm(cross(ab, sub(c, a))) / s
    } else {
        0.0
    }
}

/// World position of the point at `offset` (in [0, 1]³) inside voxel `voxel`.
pub fn position(spec: &GridSpec, voxel: [i32; 3], offset: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|a| spec.origin[a] + spec.voxel * (voxel[a] as f64 + 0.5 + offset[a]))
}

/// The primal edge a quad crosses, from the voxels of its four points: the axis along which the
/// four agree, and along the other two axes the larger of the two voxel indices (the voxels
/// around the edge from sample `s` along axis `a` start at `s`, `s − e_b`, `s − e_c`,
/// `s − e_b − e_c`).
fn quad_edge(v: [[i32; 3]; 4]) -> [i32; 3] {
    [0, 1, 2].map(|a| v.iter().map(|p| p[a]).max().expect("four voxels"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quad_edge_is_the_shared_edge() {
        // Edge along y from sample (4, 7, 2): voxels (3|4, 7, 1|2).
        let v = [[3, 7, 1], [4, 7, 1], [4, 7, 2], [3, 7, 2]];
        assert_eq!(quad_edge(v), [4, 7, 2]);
    }
}
