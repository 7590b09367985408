//! Snap: moves each mesh vertex onto the exact surface it stands for.
//!
//! OpenVDB's volumeToMesh puts one vertex per voxel cell at the mean of the cell's edge
//! crossings. That rounds every sharp edge (where the lattice meets its clipping box) and sits
//! slightly off curved surfaces, and both bias the enclosed volume. Here, as in dual contouring,
//! each vertex is moved to the exact feature its cell contains, and never out of its cell:
//!
//! * a cell crossed only by the field's surface: one Newton step onto `f = 0`;
//! * a cell where the solid meets one or two clip planes: onto those planes, then along them
//!   onto the curve or point where the surface meets them;
//! * a box corner: onto the corner.
//!
//! Where the field says its surface is not smooth within a voxel ([`Field::smooth_near`]: two
//! curved surfaces meeting at an edge), vertices keep OpenVDB's positions.
//!
//! A step that would leave the cell or the clip box is not taken (the vertex keeps the position
//! OpenVDB gave it). Where the surface meets a clip plane at a grazing angle, snapping can still
//! tip a sliver triangle through its neighbour: every triangle whose normal turned by more than
//! [`MAX_TURN_DEGREES`] is found and its vertices are returned to OpenVDB's positions, repeatedly,
//! until none is. And where a thin member meets the box, two vertices snapped onto the face can
//! swap places along it without turning a triangle over, and where two sheets of the surface
//! pass through one voxel (a neck or a wall thinner than a voxel) their snapped triangles can
//! cross: triangles there that cross one another are found exactly and their vertices restored
//! the same way.

use crate::field::{Aabb, Field, Vec3};
use crate::grid::GridSpec;
use crate::mesh::extract::{position, KeyedMesh};
use rayon::prelude::*;

/// What the snap pass did, for the report.
#[derive(Debug, Clone, Copy, Default, serde::Serialize)]
pub struct SnapStats {
    /// Vertices moved onto the surface.
    pub surface: u64,
    /// Vertices moved onto a clip-plane/surface edge or a box corner.
    pub edge: u64,
    /// Vertices left where OpenVDB put them (the step would have left their cell).
    pub kept: u64,
    /// Vertices returned to OpenVDB's position because a triangle around them turned over.
    pub restored: u64,
}

impl std::ops::AddAssign for SnapStats {
    fn add_assign(&mut self, o: SnapStats) {
        self.surface += o.surface;
        self.edge += o.edge;
        self.kept += o.kept;
        self.restored += o.restored;
    }
}

/// Restoring passes at most. Each pass reaches one ring of triangles further, so a vertex's final
/// position depends only on the mesh within this many rings of it: meshing in tiles with a margin
/// of a leaf (8 voxels) then gives every vertex the position it has in the whole part. (Across all
/// types, structures and densities the folds settle within two passes.)
pub const UNFOLD_PASSES: usize = 4;

/// A triangle whose normal turns more than this in snapping is taken as folded.
pub const MAX_TURN_DEGREES: f64 = 60.0;

enum Outcome {
    Surface,
    Edge,
    Kept,
    Untouched,
}

/// Snaps the vertices of `mesh`, extracted from `surface ∩ clip` sampled on `spec`.
pub fn snap(mesh: &mut KeyedMesh, surface: &dyn Field, clip: &Aabb, spec: &GridSpec) -> SnapStats {
    snap_within(mesh, surface, clip, spec, None)
}

/// [`snap`], leaving where OpenVDB put them the vertices outside `within` (when only part of
/// the mesh is measured).
pub fn snap_within(
    mesh: &mut KeyedMesh,
    surface: &dyn Field,
    clip: &Aabb,
    spec: &GridSpec,
    within: Option<&Aabb>,
) -> SnapStats {
    let outcomes: Vec<Outcome> = mesh
        .positions
        .par_iter_mut()
        .zip(mesh.keys.par_iter())
        .map(|(p, k)| {
            if within.is_some_and(|b| !b.contains(*p)) {
                return Outcome::Untouched;
            }
            let (out, w) = snap_vertex(*p, k.voxel, surface, clip, spec);
            if let Some(w) = w {
                *p = w;
            }
            out
        })
        .collect();
    let mut s = SnapStats::default();
    for o in outcomes {
        match o {
            Outcome::Surface => s.surface += 1,
            Outcome::Edge => s.edge += 1,
            Outcome::Kept => s.kept += 1,
            Outcome::Untouched => {}
        }
    }
    mesh.triangulate();
    s.restored = unfold(mesh, spec) + untangle(mesh, clip, spec);
    s
}

/// Returns to OpenVDB's position the vertices of triangles that snapping turned by more than
/// [`MAX_TURN_DEGREES`]; repeats until no triangle is turned, for at most [`UNFOLD_PASSES`] passes.
/// Returns how many were restored.
pub fn unfold(mesh: &mut KeyedMesh, spec: &GridSpec) -> u64 {
    use crate::geom::{cross, dot, norm, sub};
    let cos_max = MAX_TURN_DEGREES.to_radians().cos();
    let original = |m: &KeyedMesh, v: u32| {
        let v = v as usize;
        position(spec, m.keys[v].voxel, m.offsets[v])
    };
    let normal = |a: Vec3, b: Vec3, c: Vec3| cross(sub(b, a), sub(c, a));
    let mut restored = 0u64;
    for _ in 0..UNFOLD_PASSES {
        let m = &*mesh;
        let bad: Vec<u32> = (0..m.quads.len())
            .into_par_iter()
            .flat_map_iter(|q| {
                let (t, u) = m.quad_triangles(q);
                std::iter::once(t).chain(u)
            })
            .filter(|t| {
                let p = t.map(|v| m.positions[v as usize]);
                let o = t.map(|v| original(m, v));
                let (n1, n0) = (normal(p[0], p[1], p[2]), normal(o[0], o[1], o[2]));
                let (l1, l0) = (norm(n1), norm(n0));
                l0 > 0.0 && (l1 == 0.0 || dot(n1, n0) < cos_max * l1 * l0)
            })
            .flat_map_iter(|t| t.to_vec())
            .collect();
        let moved = restore(mesh, spec, &bad);
        restored += moved;
        if moved == 0 {
            break;
        }
    }
    restored
}

/// Returns to OpenVDB's positions the vertices of triangles that snapping left crossing one
/// another where they can: on the clip box's faces (two or more corners on a face: where a thin
/// member meets the box, two rim vertices snapped onto the face's curve from neighbouring cells
/// can swap places along it without turning either triangle over), and where two sheets of the
/// surface pass through one voxel (a voxel holding vertices of two edge groups: a neck or a
/// wall thinner than a voxel, whose two sides snapped onto the exact surface can cross). Each
/// such triangle is tested exactly against the others within a voxel of it; repeats for at
/// most [`UNFOLD_PASSES`] passes. Returns how many were restored.
fn untangle(mesh: &mut KeyedMesh, clip: &Aabb, spec: &GridSpec) -> u64 {
    use crate::geom::{cross, norm, sub};
    use crate::verify::self_intersect::exact::{facets_intersect, Facet};
    use std::collections::HashMap;
    let on_clip = |p: Vec3| (0..3).any(|a| p[a] == clip.min[a] || p[a] == clip.max[a]);
    // The vertices in voxels holding more than one: two sheets pass through those.
    let shared: Vec<bool> = {
        let mut order: Vec<u32> = (0..mesh.keys.len() as u32).collect();
        order.par_sort_unstable_by_key(|v| mesh.keys[*v as usize].voxel);
        let mut shared = vec![false; mesh.keys.len()];
        for w in order.windows(2) {
            let [a, b] = [w[0] as usize, w[1] as usize];
            if mesh.keys[a].voxel == mesh.keys[b].voxel {
                shared[a] = true;
                shared[b] = true;
            }
        }
        shared
    };
    let mut restored = 0u64;
    for _ in 0..UNFOLD_PASSES {
        let m = &*mesh;
        let tangled: Vec<[u32; 3]> = (0..m.quads.len())
            .into_par_iter()
            .flat_map_iter(|q| {
                let (t, u) = m.quad_triangles(q);
                std::iter::once(t).chain(u)
            })
            .filter(|t| {
                let p = t.map(|v| m.positions[v as usize]);
                (p.iter().filter(|p| on_clip(**p)).count() >= 2
                    || t.iter().any(|v| shared[*v as usize]))
                    && norm(cross(sub(p[1], p[0]), sub(p[2], p[0]))) > 0.0
            })
            .collect();
        if tangled.is_empty() {
            break;
        }
        // A triangle's corners lie in voxels next to one another (each vertex stays in its
        // voxel), so the triangle lies in the 2³ voxels from its corners' lowest: two triangles
        // that meet have lowest voxels at most one apart.
        let lowest = |t: &[u32; 3]| {
            let k = t.map(|v| m.keys[v as usize].voxel);
            [0, 1, 2].map(|a| k[0][a].min(k[1][a]).min(k[2][a]))
        };
        let mut cells: HashMap<[i32; 3], Vec<usize>> = HashMap::new();
        for (i, t) in tangled.iter().enumerate() {
            cells.entry(lowest(t)).or_default().push(i);
        }
        let facet = |t: &[u32; 3]| Facet::new(*t, t.map(|v| m.positions[v as usize]));
        let bad: Vec<u32> = (0..tangled.len())
            .into_par_iter()
            .flat_map_iter(|i| {
                let (t, k) = (tangled[i], lowest(&tangled[i]));
                let f = facet(&t);
                let mut out = Vec::new();
                for n in 0..27 {
                    let d = [n / 9, n / 3 % 3, n % 3].map(|x| x - 1);
                    let key = [k[0] + d[0], k[1] + d[1], k[2] + d[2]];
                    for &j in cells.get(&key).map_or(&[][..], Vec::as_slice) {
                        if j > i && facets_intersect(&f, &facet(&tangled[j])) {
                            out.extend(t);
                            out.extend(tangled[j]);
                        }
                    }
                }
                out
            })
            .collect();
        let moved = restore(mesh, spec, &bad);
        restored += moved;
        if moved == 0 {
            break;
        }
    }
    restored
}

/// Returns the vertices `bad` to OpenVDB's positions; how many moved.
fn restore(mesh: &mut KeyedMesh, spec: &GridSpec, bad: &[u32]) -> u64 {
    let mut moved = 0;
    for &v in bad {
        let o = position(spec, mesh.keys[v as usize].voxel, mesh.offsets[v as usize]);
        let p = &mut mesh.positions[v as usize];
        if *p != o {
            *p = o;
            moved += 1;
        }
    }
    moved
}

fn snap_vertex(
    v: Vec3,
    voxel: [i32; 3],
    surface: &dyn Field,
    clip: &Aabb,
    spec: &GridSpec,
) -> (Outcome, Option<Vec3>) {
    let h = spec.voxel;
    // The voxel holding v spans samples voxel..voxel+1 on each axis.
    let lo = [0, 1, 2].map(|a| spec.origin[a] + (voxel[a] as f64 + 0.5) * h);
    // A moved vertex must stay in its cell (no fold-over) and in the clip box (the part's bounds).
    let inside = |w: Vec3| {
        (0..3).all(|a| {
            w[a] >= lo[a] - 1e-3 * h
                && w[a] <= lo[a] + h * (1.0 + 1e-3)
                && w[a] >= clip.min[a]
                && w[a] <= clip.max[a]
        })
    };

    // Clip planes that pass through this cell.
    let mut plane: [Option<f64>; 3] = [None; 3];
    for a in 0..3 {
        for p in [clip.min[a], clip.max[a]] {
            if p > lo[a] && p < lo[a] + h {
                plane[a] = Some(p);
            }
        }
    }

    // Where the surface is not smooth (a lattice meeting a curved wall), OpenVDB's vertex stays:
    // one Newton step would land on either side of the edge, and neighbours on different
    // sides can cross.
    if !surface.smooth_near(v, h) {
        return (Outcome::Kept, None);
    }
    if plane.iter().all(Option::is_none) {
        return match newton(v, surface, [false; 3]) {
            Some(w) if inside(w) => (Outcome::Surface, Some(w)),
            _ => (Outcome::Kept, None),
        };
    }

    // Which features produce the crossings on this cell's edges?
    let corner = |i: usize| [0, 1, 2].map(|a| lo[a] + if i >> (2 - a) & 1 == 1 { h } else { 0.0 });
    let mut fs = [0.0; 8];
    let mut bs = [0.0; 8];
    for (i, (f, b)) in fs.iter_mut().zip(bs.iter_mut()).enumerate() {
        let q = corner(i);
        *f = surface.value(q);
        *b = clip.value(q);
    }
    let mut on_surface = false;
    let mut on_plane = [false; 3];
    for i in 0..8usize {
        for a in 0..3 {
            let j = i | (1 << (2 - a));
            if j == i {
                continue;
            }
            let (ci, cj) = (fs[i].max(bs[i]), fs[j].max(bs[j]));
            if (ci < 0.0) == (cj < 0.0) {
                continue;
            }
            let t = ci / (ci - cj);
            let (qi, qj) = (corner(i), corner(j));
            let q = [0, 1, 2].map(|k| qi[k] + t * (qj[k] - qi[k]));
            let (f, b) = (surface.value(q), clip.value(q));
            if f >= b {
                on_surface = true;
            } else {
                // The box face active at q: the axis of largest outward offset.
                let d = [0, 1, 2].map(|k| (clip.min[k] - q[k]).max(q[k] - clip.max[k]));
                let k = (0..3).max_by(|&x, &y| d[x].total_cmp(&d[y])).unwrap();
                on_plane[k] = true;
            }
        }
    }
    let planes: Vec<usize> = (0..3)
        .filter(|&a| on_plane[a] && plane[a].is_some())
        .collect();
    if planes.is_empty() {
        return match newton(v, surface, [false; 3]) {
            Some(w) if on_surface && inside(w) => (Outcome::Surface, Some(w)),
            _ => (Outcome::Kept, None),
        };
    }
    let mut w = v;
    let mut fixed = [false; 3];
    for &a in &planes {
        w[a] = plane[a].unwrap();
        fixed[a] = true;
    }
    if on_surface && planes.len() < 3 {
        match newton(w, surface, fixed) {
            Some(x) if inside(x) => (Outcome::Edge, Some(x)),
            _ => (Outcome::Kept, None),
        }
    } else if inside(w) {
        (
            if planes.len() == 3 {
                Outcome::Edge
            } else {
                Outcome::Untouched
            },
            Some(w),
        )
    } else {
        (Outcome::Kept, None)
    }
}

/// Newton steps onto `f = 0`, moving only along the axes not `fixed`.
fn newton(mut p: Vec3, field: &dyn Field, fixed: [bool; 3]) -> Option<Vec3> {
    for _ in 0..4 {
        let (f, mut g) = field.implicit_with_gradient(p);
        for a in 0..3 {
            if fixed[a] {
                g[a] = 0.0;
            }
        }
        let gg = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
        if gg.is_nan() || gg <= 1e-20 {
            return None;
        }
        let s = f / gg;
        let step = [s * g[0], s * g[1], s * g[2]];
        p = [p[0] - step[0], p[1] - step[1], p[2] - step[2]];
        if (step[0] * step[0] + step[1] * step[1] + step[2] * step[2]).sqrt() < 1e-7 {
            return Some(p);
        }
    }
    let (f, g) = field.implicit_with_gradient(p);
    let gn = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
    (f.abs() < 1e-5 * gn.max(1e-12)).then_some(p)
}
