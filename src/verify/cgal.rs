//! Verification by CGAL: closedness, outward orientation, self-intersection, volume and area,
//! computed by CGAL's Polygon Mesh Processing on a Surface_mesh built from our triangles —
//! an independent second measurement of every mesh latvox writes.

use crate::error::Result;
use crate::ffi::cgal::ffi;
use crate::ffi::Backend;
use crate::geom::Mesh;
use crate::verify::Verdict;

/// What CGAL found.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Verification {
    /// Who checked: `latvox` (its own exact checks), `CGAL`, or `nobody`.
    pub checked_by: &'static str,
    /// The triangles formed an oriented 2-manifold as given (no non-manifold edge or vertex).
    pub manifold: bool,
    /// No boundary edge.
    pub closed: bool,
    /// Closed and oriented with normals pointing out.
    pub outward: bool,
    /// Whether the self-intersection test ran.
    pub self_intersection_checked: bool,
    /// Some pair of non-adjacent triangles intersects.
    pub self_intersecting: bool,
    /// Enclosed volume, mm³ (`null` when the mesh is not closed).
    pub volume: Option<f64>,
    /// Surface area, mm².
    pub area: f64,
    /// Faces of CGAL's mesh.
    pub faces: u64,
    /// Vertices of CGAL's mesh.
    pub vertices: u64,
    /// Edges with only one face.
    pub border_edges: u64,
    /// Connected components.
    pub components: u64,
    /// What CGAL could not check on this mesh, and why (its preconditions did not hold); those
    /// properties count as not holding.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub not_checked: Option<&'static str>,
}

impl Verification {
    /// The verdict on CGAL's findings.
    pub fn verdict(&self) -> Verdict {
        Verdict::from(self)
    }
}

/// Runs CGAL's checks on `mesh`. `self_intersection` turns on the (costlier) intersection test.
pub fn verify(mesh: &Mesh, self_intersection: bool) -> Result<Verification> {
    verify_on(mesh, self_intersection, true)
}

/// [`verify`], with CGAL's self-intersection search on one thread when `parallel` is false (for
/// checks that run beside other work).
pub fn verify_on(mesh: &Mesh, self_intersection: bool, parallel: bool) -> Result<Verification> {
    let r = ffi::cgal_check(&mesh.positions, &mesh.indices, self_intersection, parallel)
        .backend("CGAL mesh check")?;
    Ok(Verification {
        checked_by: "CGAL",
        manifold: r.valid_polygon_mesh,
        closed: r.closed,
        outward: r.outward,
        self_intersection_checked: r.self_intersection_checked,
        self_intersecting: r.self_intersecting,
        volume: r.volume.is_finite().then_some(r.volume),
        area: r.area,
        faces: r.faces,
        vertices: r.vertices,
        border_edges: r.border_edges,
        components: r.components,
        not_checked: not_checked(r.unchecked),
    })
}

/// The steps CGAL refused (bits of the bridge's `unchecked`), in words.
fn not_checked(bits: u8) -> Option<&'static str> {
    match bits & 7 {
        0 => None,
        1 => Some("orientation and volume: a closed shell without an inside (degenerate or flat facets, facets back to back)"),
        2 => Some("self-intersection: the mesh breaks CGAL's preconditions for the search"),
        3 => Some("orientation, volume and self-intersection: the mesh breaks CGAL's preconditions"),
        _ => Some("area, components and more: the mesh breaks CGAL's preconditions"),
    }
}
