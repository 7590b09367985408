//! A triangle mesh to a level set (OpenVDB's meshToLevelSet).

use super::{Grid, GridSpec};
use crate::error::Result;
use crate::ffi::vdb::ffi;
use crate::ffi::Backend;
use crate::mesh::Mesh;

impl Grid {
    /// The level set of a triangle mesh at `voxel` mm, by OpenVDB's meshToLevelSet: a signed
    /// distance `half_width` voxels each side of the surface, its sign found by flood-filling the
    /// outside, so overlapping shells merge and facet orientation does not matter. OpenVDB's index
    /// (0, 0, 0) sits at the coordinate origin.
    pub fn from_mesh(mesh: &Mesh, voxel: f64, half_width: f64) -> Result<Grid> {
        Self::distance_to_mesh(mesh, voxel, half_width, half_width)
    }

    /// The signed distance to a triangle mesh at `voxel` mm, as [`Grid::from_mesh`], exact
    /// `exterior` voxels outside the surface and `interior` voxels inside it; beyond, the grid
    /// holds `±exterior·voxel` and `−interior·voxel` (lower bounds on the distance).
    pub fn distance_to_mesh(mesh: &Mesh, voxel: f64, exterior: f64, interior: f64) -> Result<Grid> {
        let inner = ffi::vdb_grid_from_mesh(
            &mesh.positions,
            &mesh.indices,
            voxel,
            exterior as f32,
            interior as f32,
        )
        .backend("building a level set from the mesh (OpenVDB meshToSignedDistanceField)")?;
        // Sample `frame + i` of the spec is OpenVDB's voxel `i`, at `i·voxel` mm.
        let (lo, hi) = match mesh.bounds() {
            Some(b) => (
                b.min.map(|x| (x / voxel).floor() as i64),
                b.max.map(|x| (x / voxel).ceil() as i64),
            ),
            None => ([0; 3], [0; 3]),
        };
        let spec = GridSpec {
            origin: lo.map(|i| (i as f64 - 0.5) * voxel),
            voxel,
            dims: [0, 1, 2].map(|a| hi[a] - lo[a] + 1),
            half_width: exterior,
        };
        Ok(Grid {
            inner: inner.into(),
            spec,
            frame: lo.map(|i| -i),
            blocks_tested: 0,
            blocks_sampled: 0,
        })
    }
}
