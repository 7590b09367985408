//! Hole filling. A planar loop (every vertex within a small fraction of the loop's size from its
//! best plane) is filled by triangulating the loop itself — ear clipping of the outline, so an
//! L-shaped or notched hole gets exactly its own area, never a convex hull. Any other loop goes to
//! CGAL's triangulate–refine–fair, which adds interior vertices and smooths them so the patch
//! continues the surrounding curvature.

use super::cgal;
use crate::error::Result;
use crate::field::Vec3;
use crate::mesh::{dot, norm, sub, Mesh};
use crate::topology::BoundaryLoop;
use crate::triangulate::{newell_normal, triangulate_polygon};

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

/// Whether all vertices of the facets `members` lie in one plane (that of the largest facet).
pub fn is_flat(mesh: &Mesh, members: &[u32]) -> bool {
    let Some(&big) = members.iter().max_by(|&&a, &&b| {
        let area = |f: u32| {
            let [p, q, r] = mesh.triangle(f as usize);
            norm(crate::mesh::cross(sub(q, p), sub(r, p)))
        };
        area(a).total_cmp(&area(b))
    }) else {
        return false;
    };
    let [p, q, r] = mesh.triangle(big as usize);
    let n = crate::mesh::cross(sub(q, p), sub(r, p));
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
    match cgal::fill_holes(mesh, &curved, fair) {
        Ok(f) => {
            mesh.positions.extend_from_slice(&f.positions);
            mesh.indices.extend_from_slice(&f.indices);
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
