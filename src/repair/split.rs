//! Splitting steps of repair: edges cut at T-junction vertices (so neighbours share whole
//! edges), and vertices duplicated where shells or sheets touch only at a vertex or along a
//! non-manifold edge (so each shell is its own 2-manifold), then moved apart by a few
//! micrometres so the separation survives formats that weld by position.

use crate::check::TJunction;
use crate::geom::topology::{corner_of, half_edge, Topology, UnionFind};
use crate::geom::{cross, dot, norm, sub, Mesh};

/// Cuts every facet edge that has T-junction vertices inside it, re-triangulating the facet as a
/// polygon with the extra vertices on its sides. Returns the number of vertices inserted.
pub fn split_t_junctions(mesh: &mut Mesh, tjs: &[TJunction]) -> u64 {
    if tjs.is_empty() {
        return 0;
    }
    let nf = mesh.triangle_count();
    // Per half-edge, the inner vertices by position along it.
    let mut on_edge: std::collections::HashMap<u32, Vec<(f64, u32)>> = Default::default();
    for tj in tjs {
        on_edge
            .entry(tj.half_edge)
            .or_default()
            .push((tj.t, tj.vertex));
    }
    let mut inserted = 0u64;
    let mut out = Vec::with_capacity(mesh.indices.len() + 6 * on_edge.len());
    for f in 0..nf {
        let t = [
            mesh.indices[3 * f],
            mesh.indices[3 * f + 1],
            mesh.indices[3 * f + 2],
        ];
        if !(0..3).any(|k| on_edge.contains_key(&((3 * f + k) as u32))) {
            out.extend_from_slice(&t);
            continue;
        }
        let mut poly = Vec::with_capacity(6);
        for k in 0..3 {
            poly.push(t[k]);
            if let Some(list) = on_edge.get_mut(&((3 * f + k) as u32)) {
                list.sort_by(|a, b| a.0.total_cmp(&b.0));
                list.dedup_by_key(|x| x.1);
                for &(_, v) in list.iter() {
                    if !poly.contains(&v) && !t.contains(&v) {
                        poly.push(v);
                        inserted += 1;
                    }
                }
            }
        }
        let pts: Vec<[f64; 3]> = poly.iter().map(|&v| mesh.vertex(v)).collect();
        match crate::geom::triangulate::triangulate_polygon(&pts) {
            Some(tris) => {
                for tri in tris {
                    out.extend(tri.map(|k| poly[k]));
                }
            }
            None => out.extend_from_slice(&t),
        }
    }
    mesh.indices = out;
    inserted
}

/// Pairs the facets around each edge so that each pair bounds one wedge of material, and
/// duplicates vertices so that the fans of corners not joined through a pair get their own
/// copy. Returns (non-manifold edges seen, vertex copies added).
pub fn split_non_manifold(mesh: &mut Mesh, topo: &Topology) -> (u64, u64) {
    let mut uf = UnionFind::new(mesh.indices.len());
    let mut nm_edges = 0u64;
    let join = |uf: &mut UnionFind, mesh: &Mesh, h: u32, o: u32| {
        let (a, b) = half_edge(mesh, h);
        for v in [a, b] {
            uf.union(corner_of(mesh, h / 3, v), corner_of(mesh, o / 3, v));
        }
    };
    for e in 0..topo.edge_count() {
        let hs = topo.edge(e);
        match hs.len() {
            1 => {}
            2 => join(&mut uf, mesh, hs[0], hs[1]),
            _ => {
                nm_edges += 1;
                for (h, o) in pair_around_edge(mesh, hs) {
                    join(&mut uf, mesh, h, o);
                }
            }
        }
    }
    // One vertex per fan: the first fan keeps the id, later ones get copies.
    let nv = mesh.vertex_count();
    let mut fan_vertex: std::collections::HashMap<u32, u32> = Default::default();
    let mut first_root = vec![u32::MAX; nv];
    let mut split_vertices = Vec::new();
    for f in 0..mesh.triangle_count() {
        if !topo.active[f] {
            continue;
        }
        for k in 0..3 {
            let c = (3 * f + k) as u32;
            let v = mesh.indices[c as usize];
            let r = uf.find(c);
            if first_root[v as usize] == u32::MAX {
                first_root[v as usize] = r;
            }
            if first_root[v as usize] == r {
                continue;
            }
            let id = *fan_vertex.entry(r).or_insert_with(|| {
                let id = (mesh.positions.len() / 3) as u32;
                let p = mesh.positions[3 * v as usize..3 * v as usize + 3].to_vec();
                mesh.positions.extend_from_slice(&p);
                split_vertices.push(v);
                id
            });
            mesh.indices[c as usize] = id;
        }
    }
    let copies = split_vertices.len() as u64;
    if copies > 0 {
        split_vertices.sort_unstable();
        split_vertices.dedup();
        separate(mesh, &split_vertices, nv);
    }
    (nm_edges, copies)
}

/// Moves every copy of a split vertex a hair's breadth into its own fan (towards the centroid of
/// its neighbours), so that the shells no longer touch: a file format without vertex indices
/// (STL) would otherwise weld the copies back together. The move is 10⁻⁵ of the part's
/// diagonal (a few micrometres on a desktop part), at most 1 % of the shortest incident edge.
fn separate(mesh: &mut Mesh, split: &[u32], first_copy: usize) {
    let diag = mesh
        .bounds()
        .map(|b| norm(sub(b.max, b.min)))
        .unwrap_or(0.0);
    let step = 1e-5 * diag;
    let mut moved: std::collections::HashMap<u32, ([f64; 3], u32, f64)> = Default::default();
    let is_split: std::collections::HashSet<u32> = split.iter().copied().collect();
    for t in mesh.indices.chunks_exact(3) {
        for k in 0..3 {
            let v = t[k];
            if (v as usize) < first_copy && !is_split.contains(&v) {
                continue;
            }
            let p = mesh.vertex(v);
            let e = moved.entry(v).or_insert(([0.0; 3], 0, f64::INFINITY));
            for j in [t[(k + 1) % 3], t[(k + 2) % 3]] {
                let q = mesh.vertex(j);
                for (s, x) in e.0.iter_mut().zip(q) {
                    *s += x;
                }
                e.1 += 1;
                e.2 = e.2.min(norm(sub(q, p)));
            }
        }
    }
    for (v, (sum, n, shortest)) in moved {
        let p = mesh.vertex(v);
        let c = sum.map(|x| x / n as f64);
        let d = sub(c, p);
        let l = norm(d);
        if l == 0.0 {
            continue;
        }
        // At least a few units in the last place, or the move would vanish in single precision.
        let ulp = 8.0 * f32::EPSILON as f64 * p.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let s = step.min(0.01 * shortest).max(ulp) / l;
        for a in 0..3 {
            mesh.positions[3 * v as usize + a] = (p[a] + s * d[a]) as f32;
        }
    }
}

/// Facet pairs around a non-manifold edge. Facets are sorted by angle about the edge; a facet
/// traversing the edge as a→b has its material on the side of decreasing angle, so a wedge of
/// material lies between a b→a facet and the next a→b facet counter-clockwise. Such neighbours
/// are paired first; leftovers are paired with their angular neighbours; an odd one stays a
/// boundary edge.
fn pair_around_edge(mesh: &Mesh, hs: &[u32]) -> Vec<(u32, u32)> {
    let (a, b) = half_edge(mesh, hs[0]);
    let (a, b) = (a.min(b), a.max(b));
    let (pa, pb) = (mesh.vertex(a), mesh.vertex(b));
    let d = sub(pb, pa);
    let ld = norm(d);
    if ld == 0.0 {
        return Vec::new();
    }
    let d = d.map(|x| x / ld);
    // A reference direction perpendicular to the edge.
    let seed = if d[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let u = cross(d, seed);
    let v = cross(d, u);
    let mut around: Vec<(f64, u32, bool)> = hs
        .iter()
        .map(|&h| {
            let f = (h / 3) as usize;
            let t = &mesh.indices[3 * f..3 * f + 3];
            let c = *t.iter().find(|&&x| x != a && x != b).unwrap_or(&t[0]);
            let w = sub(mesh.vertex(c), pa);
            let forward = half_edge(mesh, h) == (a, b);
            (dot(w, v).atan2(dot(w, u)), h, forward)
        })
        .collect();
    around.sort_by(|x, y| x.0.total_cmp(&y.0));
    let n = around.len();
    let mut used = vec![false; n];
    let mut pairs = Vec::new();
    for pass in 0..2 {
        for i in 0..n {
            let j = (i + 1) % n;
            if used[i] || used[j] || i == j {
                continue;
            }
            let wedge = !around[i].2 && around[j].2;
            let compatible = around[i].2 != around[j].2;
            if (pass == 0 && wedge) || (pass == 1 && compatible) {
                used[i] = true;
                used[j] = true;
                pairs.push((around[i].1, around[j].1));
            }
        }
    }
    pairs
}
