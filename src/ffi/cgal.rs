//! The CGAL bridge (`cpp/cgal.h`, implemented by `cpp/cgal_*.cc`). Raw declarations only;
//! `crate::check::cgal` and `crate::repair::cgal` wrap them safely.

#[cxx::bridge(namespace = "latvox")]
pub(crate) mod ffi {
    /// What CGAL found on a triangle mesh.
    #[derive(Debug, Clone, Copy)]
    struct CgalReport {
        /// The soup was an oriented 2-manifold as given (no fix-up was needed to build it).
        valid_polygon_mesh: bool,
        closed: bool,
        outward: bool,
        self_intersection_checked: bool,
        self_intersecting: bool,
        volume: f64,
        area: f64,
        faces: u64,
        vertices: u64,
        border_edges: u64,
        components: u64,
    }

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
        include!("latvox/cpp/cgal.h");

        fn cgal_check(
            positions: &[f32],
            indices: &[u32],
            self_intersection: bool,
            parallel: bool,
        ) -> Result<CgalReport>;

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
