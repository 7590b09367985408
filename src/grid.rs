//! Grid: a Field sampled into a sparse narrow-band OpenVDB level set.
//!
//! The domain is cut into OpenVDB's 8³ leaf blocks. Each block is tested once, at its centre,
//! against the field's clearance: if the surface is provably farther than the block's half
//! diagonal plus the band, the block is skipped. The survivors are sampled in parallel (rayon)
//! and handed to OpenVDB, which fills the interior sign by flood fill. Memory grows with the
//! surface area, never with the volume of the domain.

use crate::error::{Error, Result};
use crate::ffi::vdb::ffi;
use crate::field::{Aabb, Field, Vec3};
use crate::mesh::Mesh;
use rayon::prelude::*;

/// Where and how finely to sample: voxel `(i, j, k)` is the point `origin + (i + ½, j + ½, k + ½)·h`.
#[derive(Debug, Clone, Copy)]
pub struct GridSpec {
    /// Lower corner of voxel (0, 0, 0)'s cell, mm.
    pub origin: Vec3,
    /// Voxel size, mm.
    pub voxel: f64,
    /// Voxel counts per axis covering the region of interest.
    pub dims: [i64; 3],
    /// Narrow-band half width, in voxels.
    pub half_width: f64,
}

impl GridSpec {
    /// A grid whose voxel cells tile `bounds` from its lower corner.
    pub fn covering(bounds: &Aabb, voxel: f64, half_width: f64) -> Self {
        let s = bounds.size();
        let dims = [0, 1, 2].map(|a| ((s[a] / voxel) - 1e-9).ceil().max(1.0) as i64);
        GridSpec {
            origin: bounds.min,
            voxel,
            dims,
            half_width,
        }
    }

    pub fn point(&self, i: [i64; 3]) -> Vec3 {
        [0, 1, 2].map(|a| self.origin[a] + (i[a] as f64 + 0.5) * self.voxel)
    }
}

/// A sparse narrow-band level set held by OpenVDB.
pub struct Grid {
    inner: cxx::UniquePtr<ffi::VdbGrid>,
    pub spec: GridSpec,
    /// Leaf blocks that were tested, and that were sampled.
    pub blocks_tested: u64,
    pub blocks_sampled: u64,
}

/// Sets the thread count of OpenVDB's TBB pool (0 = TBB's default).
pub fn set_backend_threads(n: usize) {
    ffi::vdb_set_threads(n);
}

impl Grid {
    /// Samples `field` on the narrow band of its zero set within the padded region of `spec`.
    pub fn sample(field: &dyn Field, spec: GridSpec) -> Result<Grid> {
        let h = spec.voxel;
        let band = spec.half_width * h;
        let pad = spec.half_width.ceil() as i64 + 1;
        let lo = [(-pad).div_euclid(8); 3];
        let hi = [0, 1, 2].map(|a| (spec.dims[a] + pad).div_euclid(8));
        let n = [0, 1, 2].map(|a| (hi[a] - lo[a] + 1) as usize);
        let total = n[0] * n[1] * n[2];
        // Half diagonal of a block of 8 samples spaced h apart: from its centre to a corner sample.
        let reach = 3.5 * h * 3f64.sqrt() + band;

        let blocks: Vec<([i32; 3], Box<[f32; 512]>)> = (0..total)
            .into_par_iter()
            .filter_map(|idx| {
                let b = [
                    lo[0] + (idx / (n[1] * n[2])) as i64,
                    lo[1] + ((idx / n[2]) % n[1]) as i64,
                    lo[2] + (idx % n[2]) as i64,
                ];
                let first = [b[0] * 8, b[1] * 8, b[2] * 8];
                let p0 = spec.point(first);
                let centre = [0, 1, 2].map(|a| p0[a] + 3.5 * h);
                if field.clearance(centre) > reach {
                    return None;
                }
                let mut vals = Box::new([0.0f32; 512]);
                field.sample_block(p0, h, &mut vals);
                let bandf = band as f32;
                if !vals.iter().any(|v| v.abs() < bandf) {
                    return None;
                }
                for v in vals.iter_mut() {
                    *v = v.clamp(-bandf, bandf);
                }
                Some((first.map(|c| c as i32), vals))
            })
            .collect();

        let mut origins = Vec::with_capacity(blocks.len() * 3);
        let mut values = Vec::with_capacity(blocks.len() * 512);
        for (o, v) in &blocks {
            origins.extend_from_slice(o);
            values.extend_from_slice(&v[..]);
        }
        let sampled = blocks.len() as u64;
        drop(blocks);
        let inner =
            ffi::vdb_grid_from_leaves(h, &spec.origin, spec.half_width as f32, &origins, &values)
                .map_err(|e| Error::backend("building the OpenVDB grid", e))?;
        Ok(Grid {
            inner,
            spec,
            blocks_tested: total as u64,
            blocks_sampled: sampled,
        })
    }

    /// Meshes the zero level set with OpenVDB's volumeToMesh; triangles wound outward.
    pub fn to_mesh(&self, adaptivity: f64) -> Result<Mesh> {
        let mut positions = Vec::new();
        let mut indices = Vec::new();
        ffi::vdb_volume_to_mesh(&self.inner, adaptivity, &mut positions, &mut indices)
            .map_err(|e| Error::backend("meshing the level set (OpenVDB volumeToMesh)", e))?;
        Ok(Mesh { positions, indices })
    }

    pub fn active_voxels(&self) -> u64 {
        ffi::vdb_active_voxels(&self.inner)
    }

    pub fn leaf_count(&self) -> u64 {
        ffi::vdb_leaf_count(&self.inner)
    }

    pub fn memory_bytes(&self) -> u64 {
        ffi::vdb_memory_bytes(&self.inner)
    }

    /// Writes the grid as a `.vdb` file.
    pub fn write_vdb(&self, path: &std::path::Path) -> Result<()> {
        let s = path
            .to_str()
            .ok_or_else(|| Error::invalid(format!("{}: path is not UTF-8", path.display())))?;
        ffi::vdb_write(&self.inner, s).map_err(|e| Error::backend("writing the .vdb file", e))
    }
}
