//! How far rays from a mesh's facets travel before they meet another facet: along the facet's
//! normal (the gap in front of it: a hole's or a slot's width) and against it (the wall behind
//! it: a plate's thickness, a rod's diameter). The smallest is the part's smallest feature,
//! which an automatic voxel size must resolve.

use crate::ffi::cgal::ffi;

/// For each of the facets `indices` (triples into `positions`), the nearer of the two reaches
/// (mm) from its centroid to another of these facets, by CGAL's AABB tree; infinity where neither
/// ray meets one, or where CGAL cannot trace them.
pub fn facet_reach(positions: &[f32], indices: &[u32]) -> Vec<f64> {
    ffi::cgal_facet_reach(positions, indices)
        .unwrap_or_else(|_| vec![f64::INFINITY; indices.len() / 3])
}
