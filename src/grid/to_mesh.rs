//! A grid meshed by OpenVDB's volumeToMesh, triangles wound outward.

use super::Grid;
use crate::error::Result;
use crate::ffi::vdb::ffi;
use crate::ffi::Backend;
use crate::geom::Mesh;

const MESHING: &str = "meshing the level set (OpenVDB volumeToMesh)";

impl Grid {
    /// OpenVDB's volumeToMesh in index space, each point tied to its voxel and edge group, in
    /// this grid's global sample indices.
    pub(crate) fn extract(&self) -> Result<ffi::Extraction> {
        let mut out = ffi::Extraction::default();
        ffi::vdb_extract(&self.inner, &mut out).backend(MESHING)?;
        for v in out.voxels.chunks_exact_mut(3) {
            for (x, f) in v.iter_mut().zip(self.frame) {
                *x += f as i32;
            }
        }
        Ok(out)
    }

    /// Meshes the zero level set with OpenVDB's volumeToMesh; triangles wound outward.
    pub fn to_mesh(&self, adaptivity: f64) -> Result<Mesh> {
        self.to_mesh_at(0.0, adaptivity)
    }

    /// Meshes the level set `isovalue` mm (positive: the surface offset outwards) with OpenVDB's
    /// volumeToMesh; triangles wound outward. The offset must stay inside the narrow band.
    pub fn to_mesh_at(&self, isovalue: f64, adaptivity: f64) -> Result<Mesh> {
        let mut positions = Vec::new();
        let mut indices = Vec::new();
        ffi::vdb_volume_to_mesh(
            &self.inner,
            isovalue,
            adaptivity,
            &mut positions,
            &mut indices,
        )
        .backend(MESHING)?;
        Ok(Mesh { positions, indices })
    }
}
