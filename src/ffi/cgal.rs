//! The CGAL bridge (`cpp/cgal.h`, implemented by `cpp/cgal_*.cc`). Raw declarations only;
//! `crate::verify::cgal` and `crate::repair::cgal` wrap them safely.

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
        /// Steps whose CGAL preconditions the mesh broke, so they did not run: bit 1
        /// orientation and volume, bit 2 self-intersection, bit 4 area and components.
        unchecked: u8,
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

    /// The union of closed shells, or why there is none.
    struct ShellUnion {
        ok: bool,
        /// Why not (a failed precondition, a non-manifold result), when `ok` is false.
        reason: String,
        positions: Vec<f64>,
        indices: Vec<u32>,
    }

    /// Distances from points to a soup's facets, and (when asked and the soup is a closed
    /// 2-manifold) whether each point is inside; `inside` is empty otherwise.
    struct PointDistances {
        distances: Vec<f64>,
        inside: Vec<bool>,
    }

    /// The finite part of the Voronoi diagram of points, from their Delaunay triangulation.
    struct VoronoiDiagram {
        /// Distinct points triangulated (duplicates merged).
        seeds_used: u64,
        /// Voronoi vertices (circumcentres of the finite Delaunay cells), xyz triples.
        vertices: Vec<f64>,
        /// Voronoi edges as vertex pairs, flattened.
        edges: Vec<u32>,
        /// Per Voronoi face, the two points (input indices) it lies between, flattened.
        face_seeds: Vec<u32>,
        /// Per face, the range of `face_vertices` holding its polygon (CSR).
        face_starts: Vec<u32>,
        face_vertices: Vec<u32>,
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

        /// The union of the closed shells `indices[3 * shell_starts[s]..3 * shell_starts[s + 1]]`
        /// by corefinement.
        fn cgal_union(
            positions: &[f32],
            indices: &[u32],
            shell_starts: &[u32],
        ) -> Result<ShellUnion>;

        /// Distances from `points` (xyz triples) to the facets of the soup.
        fn cgal_distances(
            positions: &[f32],
            indices: &[u32],
            points: &[f64],
            classify: bool,
        ) -> Result<PointDistances>;

        /// For each facet of the soup, how far a ray from its centroid along its normal and
        /// against it travels before it meets another facet (the nearer; infinity if neither
        /// does): the wall's thickness or the gap in front of it.
        fn cgal_facet_reach(positions: &[f32], indices: &[u32]) -> Result<Vec<f64>>;

        /// The finite Voronoi diagram of `points` (xyz triples).
        fn cgal_voronoi(points: &[f64]) -> Result<VoronoiDiagram>;
    }
}
