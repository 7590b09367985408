//! Hole filling. A planar loop (every vertex within a small fraction of the loop's size from its
//! best plane) is filled by triangulating the loop itself — ear clipping of the outline, so an
//! L-shaped or notched hole gets exactly its own area, never a convex hull. Any other loop goes to
//! CGAL's triangulate–refine–fair, which adds interior vertices and smooths them so the patch
//! continues the surrounding curvature.

use super::cgal;
use crate::error::Result;
use crate::field::Vec3;
use crate::geom::topology::BoundaryLoop;
use crate::geom::triangulate::{newell_normal, triangulate_polygon};
use crate::geom::{dot, norm, sub, Mesh};

/// A loop is planar when no vertex is farther than this fraction of its bounding-box diagonal
/// from its best plane.
pub const PLANAR_REL: f64 = 1e-4;

/// What hole filling did.
#[derive(Debug, Default, Clone, Copy)]
pub struct HoleStats {
    pub planar: u64,
    pub curved: u64,
    pub faired: u64,
    pub facets_added: u64,
    /// Loops that could not be filled.
    pub failed: u64,
}

fn is_planar(pts: &[Vec3]) -> bool {
    let n = newell_normal(pts);
    let ln = norm(n);
    if ln == 0.0 {
        return false;
    }
    let n = n.map(|x| x / ln);
    let c = [0, 1, 2].map(|a| pts.iter().map(|p| p[a]).sum::<f64>() / pts.len() as f64);
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in pts {
        for a in 0..3 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    let tol = PLANAR_REL * norm(sub(hi, lo));
    pts.iter().all(|p| dot(sub(*p, c), n).abs() <= tol)
}

/// Rings of facets around a curved hole handed to CGAL with it.
const RINGS: usize = 3;

/// The facets within `rings` vertex rings of the loops that start with the hole edges `curved`,
/// as a mesh over its own vertices, and the global id of each of its vertices.
fn neighbourhood(
    mesh: &Mesh,
    loops: &[BoundaryLoop],
    curved: &[(u32, u32)],
    rings: usize,
) -> (Mesh, Vec<u32>) {
    let nv = mesh.vertex_count();
    let mut around: Vec<Vec<u32>> = vec![Vec::new(); nv];
    for (f, t) in mesh.indices.chunks_exact(3).enumerate() {
        for &v in t {
            around[v as usize].push(f as u32);
        }
    }
    let mut near = vec![false; nv];
    let mut frontier: Vec<u32> = loops
        .iter()
        .filter(|l| curved.contains(&(l.vertices[0], l.vertices[1])))
        .flat_map(|l| l.vertices.iter().copied())
        .collect();
    for &v in &frontier {
        near[v as usize] = true;
    }
    let mut taken = vec![false; mesh.triangle_count()];
    for _ in 0..rings {
        let mut next = Vec::new();
        for &v in &frontier {
            for &f in &around[v as usize] {
                if taken[f as usize] {
                    continue;
                }
                taken[f as usize] = true;
                for &w in &mesh.indices[3 * f as usize..3 * f as usize + 3] {
                    if !near[w as usize] {
                        near[w as usize] = true;
                        next.push(w);
                    }
                }
            }
        }
        frontier = next;
    }
    let mut local = vec![u32::MAX; nv];
    let mut global = Vec::new();
    let mut sub = Mesh::default();
    for (f, t) in mesh.indices.chunks_exact(3).enumerate() {
        if !taken[f] {
            continue;
        }
        for &v in t {
            if local[v as usize] == u32::MAX {
                local[v as usize] = global.len() as u32;
                global.push(v);
                sub.positions
                    .extend_from_slice(&mesh.positions[3 * v as usize..3 * v as usize + 3]);
            }
            sub.indices.push(local[v as usize]);
        }
    }
    (sub, global)
}

/// Whether all vertices of the facets `members` lie in one plane (that of the largest facet).
pub fn is_flat(mesh: &Mesh, members: &[u32]) -> bool {
    let Some(&big) = members.iter().max_by(|&&a, &&b| {
        let area = |f: u32| {
            let [p, q, r] = mesh.triangle(f as usize);
            norm(crate::geom::cross(sub(q, p), sub(r, p)))
        };
        area(a).total_cmp(&area(b))
    }) else {
        return false;
    };
    let [p, q, r] = mesh.triangle(big as usize);
    let n = crate::geom::cross(sub(q, p), sub(r, p));
    let ln = norm(n);
    if ln == 0.0 {
        return false;
    }
    let pts: Vec<Vec3> = members
        .iter()
        .flat_map(|&f| mesh.triangle(f as usize))
        .collect();
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for x in &pts {
        for a in 0..3 {
            lo[a] = lo[a].min(x[a]);
            hi[a] = hi[a].max(x[a]);
        }
    }
    let tol = PLANAR_REL * norm(sub(hi, lo));
    pts.iter().all(|x| (dot(sub(*x, p), n) / ln).abs() <= tol)
}

/// Fills the closed `loops` of `mesh` (an oriented 2-manifold apart from its holes).
/// `fair` selects CGAL's fairing for curved holes (otherwise triangulate and refine only).
pub fn fill(mesh: &mut Mesh, loops: &[BoundaryLoop], fair: bool) -> Result<HoleStats> {
    let mut stats = HoleStats::default();
    let mut curved: Vec<(u32, u32)> = Vec::new();
    let mut added = Vec::new();
    for l in loops.iter().filter(|l| l.closed && l.vertices.len() >= 3) {
        let pts: Vec<Vec3> = l.vertices.iter().map(|&v| mesh.vertex(v)).collect();
        if is_planar(&pts) {
            if let Some(tris) = triangulate_polygon(&pts) {
                for t in tris {
                    added.extend(t.map(|k| l.vertices[k]));
                }
                stats.planar += 1;
                continue;
            }
        }
        curved.push((l.vertices[0], l.vertices[1]));
    }
    stats.facets_added += (added.len() / 3) as u64;
    mesh.indices.extend_from_slice(&added);
    if curved.is_empty() {
        return Ok(stats);
    }
    // CGAL gets only the facets near the holes (a few rings around each loop): refining and
    // fairing look no farther, and a million-facet part need not be rebuilt as a Surface_mesh.
    let (sub, global) = neighbourhood(mesh, loops, &curved, RINGS);
    let local_of: std::collections::HashMap<u32, u32> = global
        .iter()
        .enumerate()
        .map(|(l, &g)| (g, l as u32))
        .collect();
    let starts: Vec<(u32, u32)> = curved
        .iter()
        .map(|(a, b)| (local_of[a], local_of[b]))
        .collect();
    match cgal::fill_holes(&sub, &starts, fair) {
        Ok(f) => {
            let first_new = mesh.vertex_count() as u32;
            let nv_sub = sub.vertex_count() as u32;
            mesh.positions.extend_from_slice(&f.positions);
            mesh.indices.extend(f.indices.iter().map(|&i| {
                if i < nv_sub {
                    global[i as usize]
                } else {
                    first_new + (i - nv_sub)
                }
            }));
            stats.facets_added += (f.indices.len() / 3) as u64;
            for (ok, faired) in f.filled.iter().zip(&f.faired) {
                if *ok {
                    stats.curved += 1;
                    stats.faired += *faired as u64;
                } else {
                    stats.failed += 1;
                }
            }
        }
        // The rest of the mesh is still not a clean 2-manifold: the holes stay open, and are
        // reported with their shells.
        Err(_) => stats.failed += curved.len() as u64,
    }
    Ok(stats)
}
