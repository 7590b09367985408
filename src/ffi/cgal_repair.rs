//! The CGAL repair bridge (cpp/cgal_repair.cc). Raw declarations only; `crate::repair::cgal`
//! wraps them safely.

#[cxx::bridge(namespace = "latvox")]
pub(crate) mod ffi {
    /// Intersecting facet pairs of a soup.
    struct SoupIntersections {
        total: u64,
        /// Up to `limit` pairs, flattened, as facet indices in input order.
        pairs: Vec<u32>,
    }

    /// What hole filling added: vertices numbered after the input's, facets over both.
    struct HoleFill {
        positions: Vec<f32>,
        indices: Vec<u32>,
        /// Per requested hole: closed, and (if fairing was asked for) faired.
        filled: Vec<bool>,
        faired: Vec<bool>,
    }

    unsafe extern "C++" {
        include!("latvox/cpp/cgal_repair.h");

        /// Searches each tile (`tile_faces[tile_starts[t]..tile_starts[t + 1]]`) on its own;
        /// pairs found in several tiles count once.
        fn cgal_soup_self_intersections(
            positions: &[f32],
            indices: &[u32],
            tile_faces: &[u32],
            tile_starts: &[u32],
            limit: usize,
        ) -> Result<SoupIntersections>;

        /// Fills the holes whose border runs from `hole_starts[2i]` to `hole_starts[2i + 1]`.
        fn cgal_fill_holes(
            positions: &[f32],
            indices: &[u32],
            hole_starts: &[u32],
            fair: bool,
        ) -> Result<HoleFill>;
    }
}
