//! Grid: a Field sampled into a sparse narrow-band OpenVDB level set.
//!
//! The domain is cut into OpenVDB's 8³ leaf blocks. Each block is tested once, at its centre,
//! against the field's clearance: if the surface is provably farther than the block's half
//! diagonal plus the band, the block is skipped. The survivors are sampled in parallel (rayon)
//! and handed to OpenVDB, which fills the interior sign by flood fill. Memory grows with the
//! surface area, never with the volume of the domain.
//!
//! A grid also comes from a triangle mesh ([`Grid::from_mesh`]) or from smoothing another
//! ([`Grid::smoothed`]); every grid is meshed by [`Grid::to_mesh_at`] (or, for meshing in
//! pieces, by `extract`).

use crate::error::{Error, Result};
use crate::ffi::vdb::{ffi, OwnedGrid};
use crate::ffi::Backend;
use crate::field::{Aabb, Field, Vec3};
use crate::mesh::Mesh;
use rayon::prelude::*;

/// Block `(bx, by, bz)` of a block range starting at `lo` with `n` blocks per axis.
fn block_at(lo: [i64; 3], n: [usize; 3], idx: usize) -> [i64; 3] {
    [
        lo[0] + (idx / (n[1] * n[2])) as i64,
        lo[1] + ((idx / n[2]) % n[1]) as i64,
        lo[2] + (idx % n[2]) as i64,
    ]
}

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

    /// The samples a whole part is meshed from: the region of interest and the narrow band
    /// around it, widened to whole 8³ blocks.
    pub fn padded_region(&self) -> IndexBox {
        let pad = self.half_width.ceil() as i64 + 1;
        IndexBox {
            lo: [-pad; 3],
            hi: [0, 1, 2].map(|a| self.dims[a] + pad),
        }
        .to_blocks()
    }

    pub fn point(&self, i: [i64; 3]) -> Vec3 {
        [0, 1, 2].map(|a| self.origin[a] + (i[a] as f64 + 0.5) * self.voxel)
    }
}

/// A box of sample indices, `lo` inclusive, `hi` exclusive.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct IndexBox {
    pub lo: [i64; 3],
    pub hi: [i64; 3],
}

impl IndexBox {
    pub fn contains(&self, i: [i64; 3]) -> bool {
        (0..3).all(|a| i[a] >= self.lo[a] && i[a] < self.hi[a])
    }

    /// The smallest box of whole 8³ blocks holding this one.
    pub fn to_blocks(&self) -> IndexBox {
        IndexBox {
            lo: self.lo.map(|x| x.div_euclid(8) * 8),
            hi: self.hi.map(|x| (x + 7).div_euclid(8) * 8),
        }
    }

    pub fn voxels(&self) -> u64 {
        (0..3)
            .map(|a| (self.hi[a] - self.lo[a]).max(0) as u64)
            .product()
    }

    /// The box grown by `m` samples on every side.
    pub fn grown(&self, m: i64) -> IndexBox {
        IndexBox {
            lo: self.lo.map(|x| x - m),
            hi: self.hi.map(|x| x + m),
        }
    }
}

/// Sample values are kept at least this fraction of a voxel away from zero, so that no edge
/// crossing falls on a sample and every extracted point lies strictly inside its voxel (see
/// `extract`). The nudge is far below anything the mesh can show.
pub const MIN_ABS_VALUE_VOXELS: f64 = 1.0 / 64.0;

const MESHING: &str = "meshing the level set (OpenVDB volumeToMesh)";

/// OpenVDB's level-set smoothing flows (`LevelSetFilter`), for [`Grid::smoothed`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Smoothing {
    Gaussian,
    MeanCurvature,
    Laplacian,
    Mean,
}

/// A sparse narrow-band level set held by OpenVDB.
pub struct Grid {
    inner: OwnedGrid,
    pub spec: GridSpec,
    /// Global sample index of the OpenVDB grid's index (0, 0, 0). OpenVDB sees indices relative
    /// to it, so its coordinates stay small however far the grid lies from the part's origin.
    pub frame: [i64; 3],
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
        Self::sample_box(field, spec, spec.padded_region())
    }

    /// Samples `field` on the narrow band within the leaf blocks that cover `region` (sample
    /// indices of `spec`).
    pub fn sample_box(field: &dyn Field, spec: GridSpec, region: IndexBox) -> Result<Grid> {
        let h = spec.voxel;
        let band = spec.half_width * h;
        let lo = region.lo.map(|x| x.div_euclid(8));
        let hi = region.hi.map(|x| (x - 1).div_euclid(8));
        let n = [0, 1, 2].map(|a| (hi[a] - lo[a] + 1).max(0) as usize);
        let total = n[0] * n[1] * n[2];
        let frame = lo.map(|b| b * 8);
        // Half diagonal of a block of 8 samples spaced h apart: from its centre to a corner sample.
        let reach = 3.5 * h * 3f64.sqrt() + band;
        let bandf = band as f32;
        let eps = (MIN_ABS_VALUE_VOXELS * h) as f32;

        // Pass 1: which blocks can hold the band (cheap: one clearance per block).
        let candidates: Vec<usize> = (0..total)
            .into_par_iter()
            .filter(|&idx| {
                let b = block_at(lo, n, idx);
                let p0 = spec.point(b.map(|c| c * 8));
                let centre = [0, 1, 2].map(|a| p0[a] + 3.5 * h);
                field.clearance(centre) <= reach
            })
            .collect();
        // Pass 2: sample them straight into one flat buffer, then drop blocks the band missed.
        let mut values = vec![0.0f32; candidates.len() * 512];
        let keep: Vec<bool> = values
            .par_chunks_mut(512)
            .zip(candidates.par_iter())
            .map(|(vals, &idx)| {
                let b = block_at(lo, n, idx);
                let vals: &mut [f32; 512] = vals.try_into().expect("512 values per block");
                field.sample_block(spec.point(b.map(|c| c * 8)), h, vals);
                if !vals.iter().any(|v| v.abs() < bandf) {
                    return false;
                }
                for v in vals.iter_mut() {
                    *v = v.clamp(-bandf, bandf);
                    if v.abs() < eps {
                        *v = if *v < 0.0 { -eps } else { eps };
                    }
                }
                true
            })
            .collect();
        let mut origins = Vec::with_capacity(candidates.len() * 3);
        let mut w = 0;
        for (k, &idx) in candidates.iter().enumerate() {
            if !keep[k] {
                continue;
            }
            let b = block_at(lo, n, idx);
            origins.extend((0..3).map(|a| (b[a] * 8 - frame[a]) as i32));
            if w != k {
                values.copy_within(k * 512..(k + 1) * 512, w * 512);
            }
            w += 1;
        }
        values.truncate(w * 512);
        let sampled = w as u64;
        let grid_origin = spec.point(frame).map(|x| x - 0.5 * h);
        let inner =
            ffi::vdb_grid_from_leaves(h, &grid_origin, spec.half_width as f32, &origins, &values)
                .backend("building the OpenVDB grid")?;
        Ok(Grid {
            inner: inner.into(),
            spec,
            frame,
            blocks_tested: total as u64,
            blocks_sampled: sampled,
        })
    }

    /// The level set of a triangle mesh at `voxel` mm, by OpenVDB's meshToLevelSet: a signed
    /// distance `half_width` voxels each side of the surface, its sign found by flood-filling the
    /// outside, so overlapping shells merge and facet orientation does not matter. OpenVDB's index
    /// (0, 0, 0) sits at the coordinate origin.
    pub fn from_mesh(mesh: &Mesh, voxel: f64, half_width: f64) -> Result<Grid> {
        let inner =
            ffi::vdb_grid_from_mesh(&mesh.positions, &mesh.indices, voxel, half_width as f32)
                .backend("building a level set from the mesh (OpenVDB meshToLevelSet)")?;
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
            half_width,
        };
        Ok(Grid {
            inner: inner.into(),
            spec,
            frame: lo.map(|i| -i),
            blocks_tested: 0,
            blocks_sampled: 0,
        })
    }

    /// This level set smoothed by `iterations` passes of OpenVDB's `LevelSetFilter`, after
    /// OpenVDB rebuilds it as a signed distance `half_width` voxels each side of its zero set
    /// (the filter needs a distance field, and the band bounds the offsets that can be meshed
    /// afterwards with [`Grid::to_mesh_at`]).
    pub fn smoothed(&self, mode: Smoothing, iterations: u32, half_width: f64) -> Result<Grid> {
        let mode = match mode {
            Smoothing::Gaussian => ffi::SmoothingMode::Gaussian,
            Smoothing::MeanCurvature => ffi::SmoothingMode::MeanCurvature,
            Smoothing::Laplacian => ffi::SmoothingMode::Laplacian,
            Smoothing::Mean => ffi::SmoothingMode::Mean,
        };
        let inner = ffi::vdb_smoothed(&self.inner, mode, iterations, half_width as f32)
            .backend("smoothing the level set (OpenVDB LevelSetFilter)")?;
        Ok(Grid {
            inner: inner.into(),
            spec: GridSpec {
                half_width,
                ..self.spec
            },
            ..*self
        })
    }

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

    pub fn active_voxels(&self) -> u64 {
        ffi::vdb_active_voxels(&self.inner)
    }

    pub fn memory_bytes(&self) -> u64 {
        ffi::vdb_memory_bytes(&self.inner)
    }

    /// Writes the grid as a `.vdb` file.
    pub fn write_vdb(&self, path: &std::path::Path) -> Result<()> {
        let s = path
            .to_str()
            .ok_or_else(|| Error::invalid(format!("{}: path is not UTF-8", path.display())))?;
        ffi::vdb_write(&self.inner, s).backend("writing the .vdb file")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const BOX: Aabb = Aabb {
        min: [0.0; 3],
        max: [10.0, 8.0, 6.0],
    };

    /// A 10 × 8 × 6 mm box (an exact distance field) sampled at `voxel` mm.
    fn box_grid(voxel: f64) -> Grid {
        Grid::sample(&BOX, GridSpec::covering(&BOX, voxel, 3.0)).unwrap()
    }

    fn closed(m: &Mesh) -> bool {
        let s = m.edge_stats();
        s.boundary == 0 && s.non_manifold == 0 && s.misoriented == 0
    }

    #[test]
    fn iso_values_offset_the_surface() {
        let g = box_grid(0.5);
        let (m0, m1) = (g.to_mesh(0.0).unwrap(), g.to_mesh_at(0.5, 0.0).unwrap());
        assert!(closed(&m0) && closed(&m1));
        // The box, and the box grown by 0.5 mm: faces, quarter cylinders along 96 mm of edges,
        // eighth spheres at the corners.
        let grown = 480.0
            + 376.0 * 0.5
            + std::f64::consts::PI * 0.25 / 4.0 * 96.0
            + 4.0 / 3.0 * std::f64::consts::PI * 0.125;
        assert!((m0.volume() / 480.0 - 1.0).abs() < 0.02, "{}", m0.volume());
        assert!((m1.volume() / grown - 1.0).abs() < 0.02, "{}", m1.volume());
    }

    #[test]
    fn a_mesh_becomes_a_level_set_of_the_same_solid() {
        let m = box_grid(0.5).to_mesh(0.0).unwrap();
        let g = Grid::from_mesh(&m, 0.25, 3.0).unwrap();
        assert!(g.active_voxels() > 0);
        let r = g.to_mesh(0.0).unwrap();
        assert!(closed(&r));
        assert!(
            (r.volume() / m.volume() - 1.0).abs() < 0.01,
            "{}",
            r.volume()
        );
        // Reversed facets give the same solid: the sign comes from the outside, not the winding.
        let mut flipped = m.clone();
        flipped.flip();
        let f = Grid::from_mesh(&flipped, 0.25, 3.0)
            .unwrap()
            .to_mesh(0.0)
            .unwrap();
        assert!((f.volume() - r.volume()).abs() < 1e-3 * r.volume());
    }

    #[test]
    fn smoothing_rounds_edges_and_keeps_faces() {
        let g = box_grid(0.25);
        let m = g.to_mesh(0.0).unwrap();
        for mode in [
            Smoothing::Gaussian,
            Smoothing::MeanCurvature,
            Smoothing::Laplacian,
            Smoothing::Mean,
        ] {
            let s = g.smoothed(mode, 2, 6.0).unwrap();
            assert_eq!(s.spec.half_width, 6.0);
            let sm = s.to_mesh(0.0).unwrap();
            assert!(closed(&sm), "{mode:?}");
            // Edges and corners rounded: less area, a little less volume. Flat faces stay put.
            let (a, v) = (sm.area(), sm.volume());
            assert!(a < m.area(), "{mode:?}: area {a}");
            assert!(
                v < m.volume() && v > 0.9 * m.volume(),
                "{mode:?}: volume {v}"
            );
            let b = sm.bounds().unwrap();
            for k in 0..3 {
                assert!((b.min[k] - BOX.min[k]).abs() < 0.01, "{mode:?}: {b:?}");
                assert!((b.max[k] - BOX.max[k]).abs() < 0.01, "{mode:?}: {b:?}");
            }
            // The wider band (1.5 mm) holds offsets the sampled one (0.75 mm) could not.
            assert!(g.to_mesh_at(1.0, 0.0).unwrap().indices.is_empty());
            assert!(s.to_mesh_at(1.0, 0.0).unwrap().volume() > v + 0.9 * a);
        }
    }

    #[test]
    fn writes_an_openvdb_file() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("box.vdb");
        box_grid(0.5).write_vdb(&p).unwrap();
        let bytes = std::fs::read(&p).unwrap();
        // OpenVDB's magic number, 0x56444220, little-endian.
        assert_eq!(&bytes[..4], &[0x20, 0x42, 0x44, 0x56]);
    }
}
