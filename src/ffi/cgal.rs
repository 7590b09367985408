//! The CGAL half of the C++ bridge. Raw declarations only; `crate::check::cgal` wraps them safely.

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

    unsafe extern "C++" {
        include!("latvox/cpp/cgal.h");

        fn cgal_check(
            positions: &[f32],
            indices: &[u32],
            self_intersection: bool,
            parallel: bool,
        ) -> Result<CgalReport>;

        /// Up to `limit` intersecting face pairs, flattened (face indices in input order).
        fn cgal_self_intersections(
            positions: &[f32],
            indices: &[u32],
            limit: usize,
        ) -> Result<Vec<u32>>;
    }
}
