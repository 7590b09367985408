//! Remeshing through OpenVDB (the print shop's "shrink wrap"): the facets become a narrow-band
//! level set at the given voxel size and its zero iso-surface becomes the new mesh. Whatever
//! cannot be mended locally — self-intersections, overlapping shells, slivers — disappears; the
//! result is closed and manifold at that resolution, and features smaller than a voxel are lost.

use crate::error::{Error, Result};
use crate::grid::Grid;
use crate::mesh::Mesh;

/// Rebuilds `mesh` at `voxel` mm (adaptivity 0: uniform triangles). Returns the new mesh and the
/// number of active voxels used.
pub fn remesh(mesh: &Mesh, voxel: f64) -> Result<(Mesh, u64)> {
    if !(voxel > 0.0 && voxel.is_finite()) {
        return Err(Error::invalid(
            "remesh voxel size must be a positive length in mm",
        ));
    }
    if let Some(b) = mesh.bounds() {
        let s = b.size();
        let cells = s.iter().map(|x| x / voxel).fold(0.0, f64::max);
        if cells > 100_000.0 {
            return Err(Error::invalid(format!(
                "remesh voxel {voxel} mm is too fine for a part {:.1} mm across ({cells:.0} voxels per axis)",
                s.iter().fold(0.0f64, |m, x| m.max(*x))
            )));
        }
    }
    let grid = Grid::from_mesh(mesh, voxel, 3.0)?;
    Ok((grid.to_mesh(0.0)?, grid.active_voxels()))
}
