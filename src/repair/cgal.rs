//! Safe wrappers over the CGAL repair bridge: self-intersections of any facet subset, and hole
//! filling by triangulation, refinement and fairing.

use crate::error::{Error, Result};
use crate::ffi::cgal_repair::ffi;
use crate::mesh::Mesh;

/// Counts intersecting pairs among the facets `keep` of `mesh` (which must have three distinct
/// vertices each); returns the total and up to `limit` pairs as facet indices of `mesh`.
/// `flip` (per facet of `mesh`), when given, reverses facets so neighbours agree: the answer does
/// not depend on winding, but CGAL can then build its mesh directly instead of orienting a soup.
pub fn soup_self_intersections(
    mesh: &Mesh,
    keep: &[u32],
    flip: Option<&[bool]>,
    limit: usize,
) -> Result<(u64, Vec<(u32, u32)>)> {
    let indices: Vec<u32> = keep
        .iter()
        .flat_map(|&f| {
            let t = &mesh.indices[3 * f as usize..3 * f as usize + 3];
            if flip.is_some_and(|fl| fl[f as usize]) {
                [t[0], t[2], t[1]]
            } else {
                [t[0], t[1], t[2]]
            }
        })
        .collect();
    let r = ffi::cgal_soup_self_intersections(&mesh.positions, &indices, limit)
        .map_err(|e| Error::backend("CGAL self-intersection search", e))?;
    let pairs = r
        .pairs
        .chunks_exact(2)
        .map(|p| (keep[p[0] as usize], keep[p[1] as usize]))
        .collect();
    Ok((r.total, pairs))
}

/// What CGAL added to fill holes.
pub struct Filled {
    /// New vertices (numbered after the mesh's own).
    pub positions: Vec<f32>,
    /// New facets over old and new vertices.
    pub indices: Vec<u32>,
    /// Per hole: closed.
    pub filled: Vec<bool>,
    /// Per hole: fairing succeeded.
    pub faired: Vec<bool>,
}

/// Fills the holes of an oriented 2-manifold `mesh` whose border passes from `starts[i].0` to
/// `starts[i].1` (a hole edge, wound as the filling facets will be).
pub fn fill_holes(mesh: &Mesh, starts: &[(u32, u32)], fair: bool) -> Result<Filled> {
    let flat: Vec<u32> = starts.iter().flat_map(|&(a, b)| [a, b]).collect();
    let r = ffi::cgal_fill_holes(&mesh.positions, &mesh.indices, &flat, fair)
        .map_err(|e| Error::backend("CGAL hole filling", e))?;
    Ok(Filled {
        positions: r.positions,
        indices: r.indices,
        filled: r.filled,
        faired: r.faired,
    })
}
