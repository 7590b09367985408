//! Safe wrappers over CGAL's repair steps: hole filling by triangulation, refinement and
//! fairing.

use crate::error::Result;
use crate::ffi::cgal::ffi;
use crate::ffi::Backend;
use crate::geom::Mesh;

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
        .backend("CGAL hole filling")?;
    Ok(Filled {
        positions: r.positions,
        indices: r.indices,
        filled: r.filled,
        faired: r.faired,
    })
}
