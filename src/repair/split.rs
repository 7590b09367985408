//! Splitting steps of repair: edges cut at T-junction vertices (so neighbours share whole
//! edges), and vertices duplicated where shells or sheets touch only at a vertex or along a
//! non-manifold edge (so each shell is its own 2-manifold).

use crate::check::TJunction;
use crate::mesh::{cross, dot, norm, sub, Mesh};
use crate::topology::{corner_of, half_edge, Topology, UnionFind};

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
        on_edge.entry(tj.half_edge).or_default().push((tj.t, tj.vertex));
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
        match crate::triangulate::triangulate_polygon(&pts) {
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
    let mut copies = 0u64;
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
                copies += 1;
                let id = (mesh.positions.len() / 3) as u32;
                let p = mesh.positions[3 * v as usize..3 * v as usize + 3].to_vec();
                mesh.positions.extend_from_slice(&p);
                id
            });
            mesh.indices[c as usize] = id;
        }
    }
    (nm_edges, copies)
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
