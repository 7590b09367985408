//! Pieces: the separate solids a mesh encloses, and the removal of loose fragments.
//!
//! A box cuts a lattice where it likes, and near its faces it can cut a piece of the lattice
//! loose: a fragment that is not joined to the part. It falls out of a powder bed or floats in
//! a resin vat, so a part is written as one piece: the shells of the mesh (triangles joined
//! through shared vertices) are grouped into pieces — a shell enclosing positive volume is the
//! outside of a piece, one enclosing negative volume a cavity inside some piece — the piece of
//! the largest volume is the part, and every other outer shell, with the cavities lying within
//! its bounds, is a fragment.

use crate::field::{Aabb, Vec3};
use crate::geom::bvh::Bvh;
use crate::geom::signed_volume;
use crate::geom::topology::UnionFind;
use crate::mesh::extract::KeyedMesh;

/// Fragments found (and removed, unless kept) in a mesh.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct Fragments {
    /// Fragments: pieces not joined to the largest one.
    pub count: u64,
    /// Their volume, mm³.
    pub volume: f64,
    /// Whether they were removed from what was written.
    pub removed: bool,
    /// Voids the part encloses (cavities of the piece kept): powder or resin left in them
    /// cannot get out.
    pub cavities: u64,
    /// Their volume, mm³ (positive).
    pub cavity_volume: f64,
}

impl Fragments {
    /// Adds another mesh's fragments (tiles or cells of one part).
    pub fn add(&mut self, o: &Fragments) {
        self.count += o.count;
        self.volume += o.volume;
        self.removed |= o.removed;
        self.cavities += o.cavities;
        self.cavity_volume += o.cavity_volume;
    }
}

/// The shells of a keyed mesh and the pieces they form.
pub struct Shells {
    /// Shell of each vertex (dense ids, `0..count`).
    pub of_vertex: Vec<u32>,
    /// Per shell: signed enclosed volume (positive for an outer shell), mm³.
    pub volume: Vec<f64>,
    /// Per shell: bounds of its vertices.
    pub bounds: Vec<Aabb>,
    /// Per shell: whether it belongs to the largest piece.
    pub kept: Vec<bool>,
}

impl Shells {
    /// Finds the shells of `mesh` and which belong to its largest piece.
    pub fn of(mesh: &KeyedMesh) -> Shells {
        Shells::of_quads(mesh, |_| true)
    }

    /// Finds the shells that the quads of `mesh` marked by `quad` form, and which belong to
    /// their largest piece; a vertex on no such quad is in no shell (`u32::MAX`).
    pub fn of_quads(mesh: &KeyedMesh, quad: impl Fn(usize) -> bool) -> Shells {
        let n = mesh.positions.len();
        let mut uf = UnionFind::new(n);
        let mut on = vec![false; n];
        for (i, q) in mesh.quads.iter().enumerate() {
            if quad(i) {
                uf.union(q[0], q[1]);
                uf.union(q[0], q[2]);
                uf.union(q[0], q[3]);
                q.iter().for_each(|&v| on[v as usize] = true);
            }
        }
        let mut id = vec![u32::MAX; n];
        let mut count = 0u32;
        let of_vertex: Vec<u32> = (0..n as u32)
            .map(|v| {
                if !on[v as usize] {
                    return u32::MAX;
                }
                let r = uf.find(v) as usize;
                if id[r] == u32::MAX {
                    id[r] = count;
                    count += 1;
                }
                id[r]
            })
            .collect();
        let empty = Aabb {
            min: [f64::INFINITY; 3],
            max: [f64::NEG_INFINITY; 3],
        };
        let mut volume = vec![0.0; count as usize];
        let mut bounds = vec![empty; count as usize];
        for (i, q) in mesh.quads.iter().enumerate() {
            if quad(i) {
                let (t, u) = mesh.quad_triangles(i);
                for t in std::iter::once(t).chain(u) {
                    let [a, b, c] = t.map(|v| mesh.positions[v as usize]);
                    volume[of_vertex[q[0] as usize] as usize] += signed_volume(a, b, c);
                }
            }
        }
        for (v, p) in mesh.positions.iter().enumerate() {
            if of_vertex[v] == u32::MAX {
                continue;
            }
            let b = &mut bounds[of_vertex[v] as usize];
            for (a, &x) in p.iter().enumerate() {
                b.min[a] = b.min[a].min(x);
                b.max[a] = b.max[a].max(x);
            }
        }
        let kept = kept_shells(&volume, &bounds);
        Shells {
            of_vertex,
            volume,
            bounds,
            kept,
        }
    }

    /// The fragments: outer shells not kept, with the cavities they hold.
    pub fn fragments(&self, removed: bool) -> Fragments {
        fragments_of(&self.volume, &self.kept, removed)
    }
}

/// Which shells (by signed volume and bounds) belong to the largest piece: the outer shell of
/// largest volume, and every cavity that no other outer shell's bounds hold.
pub fn kept_shells(volume: &[f64], bounds: &[Aabb]) -> Vec<bool> {
    let count = volume.len();
    let main = (0..count).max_by(|&a, &b| volume[a].total_cmp(&volume[b]));
    let inside = |inner: &Aabb, outer: &Aabb| {
        (0..3).all(|a| inner.min[a] >= outer.min[a] && inner.max[a] <= outer.max[a])
    };
    // An outer shell other than the main one is a fragment; a cavity goes with the fragment
    // whose bounds hold it, and otherwise with the part.
    (0..count)
        .map(|s| match main {
            Some(m) if s == m => true,
            _ if volume[s] > 0.0 => false,
            _ => !(0..count)
                .any(|o| Some(o) != main && volume[o] > 0.0 && inside(&bounds[s], &bounds[o])),
        })
        .collect()
}

/// The fragments among shells of signed `volume`, `kept` as [`kept_shells`] says.
pub fn fragments_of(volume: &[f64], kept: &[bool], removed: bool) -> Fragments {
    let mut f = Fragments {
        removed,
        ..Default::default()
    };
    for (s, &k) in kept.iter().enumerate() {
        if !k {
            f.count += (volume[s] > 0.0) as u64;
            f.volume += volume[s];
        } else if volume[s] < 0.0 {
            f.cavities += 1;
            f.cavity_volume -= volume[s];
        }
    }
    f
}

/// Removes the fragments of `mesh` (every shell not in its largest piece), keeping the order of
/// the vertices and quads that stay; returns what was removed, and its triangles.
pub fn remove_fragments(mesh: &mut KeyedMesh) -> (Fragments, Vec<[Vec3; 3]>) {
    let shells = Shells::of(mesh);
    let f = shells.fragments(true);
    if f.count == 0 && shells.kept.iter().all(|&k| k) {
        return (f, Vec::new());
    }
    let loose = loose_triangles(mesh, &shells);
    let keep_vertex: Vec<bool> = shells
        .of_vertex
        .iter()
        .map(|&s| s != u32::MAX && shells.kept[s as usize])
        .collect();
    retain(mesh, &keep_vertex);
    (f, loose)
}

/// The triangles of the shells of `mesh` that are not kept (its fragments, their cavities).
pub fn loose_triangles(mesh: &KeyedMesh, shells: &Shells) -> Vec<[Vec3; 3]> {
    let mut out = Vec::new();
    for (i, q) in mesh.quads.iter().enumerate() {
        let s = shells.of_vertex[q[0] as usize];
        if s == u32::MAX || shells.kept[s as usize] {
            continue;
        }
        let (t, u) = mesh.quad_triangles(i);
        for t in std::iter::once(t).chain(u) {
            out.push(t.map(|v| mesh.positions[v as usize]));
        }
    }
    out
}

/// The fragments a meshing removed, as closed shells: whether a point of the solid lies in one
/// (what the implicit routes — slices straight from a part file — need to drop the same
/// fragments as the mesh). The shells are the whole part's, or a template's, whose cells stand
/// for the part's as [`crate::mesh::instance::AxisPlan::kind`] says.
#[derive(Debug, Clone, Default)]
pub struct Loose {
    shells: Option<Bvh>,
    copies: Option<Copies>,
}

/// How the part's cells map onto a template's: the plan, the cells' lower corner and size.
#[derive(Debug, Clone, Copy)]
struct Copies {
    plan: [crate::mesh::instance::AxisPlan; 3],
    corner: Vec3,
    cell: Vec3,
}

impl Loose {
    /// The fragments bounded by `triangles` (closed shells, in the part's coordinates).
    pub fn of(triangles: Vec<[Vec3; 3]>) -> Loose {
        Loose {
            shells: (!triangles.is_empty()).then(|| Bvh::over(triangles)),
            copies: None,
        }
    }

    /// The fragments of a template bounded by `triangles`: the part's cell `c` along an axis
    /// holds what the template's cell `plan[a].kind(c)` holds; cells of size `cell` from
    /// `corner`.
    pub fn of_template(
        triangles: Vec<[Vec3; 3]>,
        plan: [crate::mesh::instance::AxisPlan; 3],
        corner: Vec3,
        cell: Vec3,
    ) -> Loose {
        Loose {
            copies: Some(Copies { plan, corner, cell }),
            ..Loose::of(triangles)
        }
    }

    /// Whether no fragment was removed.
    pub fn is_empty(&self) -> bool {
        self.shells.is_none()
    }

    /// Whether `p` lies inside a removed fragment's shell, or within `reach` of one.
    pub fn holds(&self, p: Vec3, reach: f64) -> bool {
        let Some(shells) = &self.shells else {
            return false;
        };
        let q = self.in_shells(p);
        shells.contains(q) || (reach > 0.0 && shells.distance(q, reach) < reach)
    }

    /// Whether `p` lies inside a removed fragment's shell.
    pub fn contains(&self, p: Vec3) -> bool {
        self.holds(p, 0.0)
    }

    /// `p` where the shells are: in the template cell that stands for its cell.
    fn in_shells(&self, p: Vec3) -> Vec3 {
        let mut q = p;
        if let Some(c) = &self.copies {
            for a in 0..3 {
                let ax = c.plan[a];
                if ax.n > ax.m {
                    let i = ((p[a] - c.corner[a]) / c.cell[a]).floor() as i64;
                    let i = i.clamp(0, ax.n - 1);
                    q[a] = p[a] - (i - ax.kind(i)) as f64 * c.cell[a];
                }
            }
        }
        q
    }
}

/// Keeps the vertices marked in `keep` and the quads whose corners are all kept, renumbering.
pub fn retain(mesh: &mut KeyedMesh, keep: &[bool]) {
    let mut new_index = vec![u32::MAX; keep.len()];
    let mut next = 0u32;
    for (v, &k) in keep.iter().enumerate() {
        if k {
            new_index[v] = next;
            next += 1;
        }
    }
    let mut w = 0;
    for (v, &k) in keep.iter().enumerate() {
        if k {
            mesh.keys[w] = mesh.keys[v];
            mesh.positions[w] = mesh.positions[v];
            mesh.offsets[w] = mesh.offsets[v];
            w += 1;
        }
    }
    mesh.keys.truncate(w);
    mesh.positions.truncate(w);
    mesh.offsets.truncate(w);
    let mut w = 0;
    for q in 0..mesh.quads.len() {
        let quad = mesh.quads[q];
        if quad.iter().all(|&v| keep[v as usize]) {
            mesh.quads[w] = quad.map(|v| new_index[v as usize]);
            if !mesh.edges.is_empty() {
                mesh.edges[w] = mesh.edges[q];
            }
            mesh.diagonal_bd[w] = mesh.diagonal_bd[q];
            w += 1;
        }
    }
    mesh.quads.truncate(w);
    if !mesh.edges.is_empty() {
        mesh.edges.truncate(w);
    }
    mesh.diagonal_bd.truncate(w);
}
