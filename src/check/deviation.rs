//! How far one mesh lies from another, one-sided both ways: from every vertex of each to the
//! nearest point of the other's facets, exactly (CGAL's AABB tree, double precision). Vertices
//! sample the surface: the largest distance found is a lower bound on the Hausdorff distance,
//! reached wherever the farthest point is a vertex (corners, and every point of a remesh).
//!
//! Read from the input's vertices, a solid made by a union has no surface where the input's
//! shells overlapped: input vertices strictly inside the result (by CGAL's side-of-mesh test)
//! belong to such inner walls, and are counted apart instead of as deviation.

use crate::error::Result;
use crate::ffi::cgal::ffi;
use crate::ffi::Backend;
use crate::geom::Mesh;

/// Distances from one mesh's vertices to another's facets, mm.
#[derive(Debug, Clone, Copy, Default, serde::Serialize)]
pub struct Distances {
    /// Largest.
    pub max: f64,
    /// Mean over the vertices measured.
    pub mean: f64,
    /// Vertices measured.
    pub vertices: u64,
}

/// The deviation between an input mesh and what was made of it.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Deviation {
    /// From the output's vertices to the input's facets.
    pub output_to_input: Distances,
    /// From the input's vertices to the output's facets (inner walls left out).
    pub input_to_output: Distances,
    /// Input vertices strictly inside the output: walls that are now inside the solid.
    pub input_vertices_inside: u64,
}

/// Measures how far `output` lies from `input` and back; `output` should be a closed solid for
/// inner walls to be told apart (otherwise every input vertex counts).
pub fn deviation(input: &Mesh, output: &Mesh) -> Result<Deviation> {
    let to_input = ffi::cgal_distances(&input.positions, &input.indices, &used(output), false)
        .backend("CGAL distances")?;
    let to_output = ffi::cgal_distances(&output.positions, &output.indices, &used(input), true)
        .backend("CGAL distances")?;
    let inside = &to_output.inside;
    let on: Vec<f64> = (to_output.distances.iter().enumerate())
        .filter(|(i, _)| !inside.get(*i).copied().unwrap_or(false))
        .map(|(_, d)| *d)
        .collect();
    Ok(Deviation {
        output_to_input: summary(&to_input.distances),
        input_to_output: summary(&on),
        input_vertices_inside: inside.iter().filter(|b| **b).count() as u64,
    })
}

/// The vertices `mesh`'s facets use, as xyz triples.
fn used(mesh: &Mesh) -> Vec<f64> {
    let mut used = vec![false; mesh.vertex_count()];
    for &i in &mesh.indices {
        used[i as usize] = true;
    }
    (0..mesh.vertex_count())
        .filter(|&v| used[v])
        .flat_map(|v| mesh.vertex(v as u32))
        .collect()
}

fn summary(d: &[f64]) -> Distances {
    if d.is_empty() {
        return Distances::default();
    }
    Distances {
        max: d.iter().fold(0.0, |m, x| m.max(*x)),
        mean: d.iter().sum::<f64>() / d.len() as f64,
        vertices: d.len() as u64,
    }
}
