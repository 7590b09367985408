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
//! pieces, by `extract`). One operation per file, as OpenVDB's `tools/` does: `sample` (from a
//! field), `from_mesh`, `smooth`, `to_mesh`, `write` (.vdb); the type, its spec and its measures
//! here.

use crate::ffi::vdb::{ffi, OwnedGrid};
use crate::field::{Aabb, Vec3};

mod from_mesh;
mod probe;
mod read;
mod sample;
mod smooth;
mod to_mesh;
mod values;
mod write;

pub use probe::{distance_clearance, SPARE_VOXELS};
pub use read::read_values;
pub use write::write_vdb_grids;

pub use smooth::Smoothing;

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

    /// The centre of sample `i`, mm.
    pub fn point(&self, i: [i64; 3]) -> Vec3 {
        [0, 1, 2].map(|a| self.origin[a] + (i[a] as f64 + 0.5) * self.voxel)
    }
}

/// A box of sample indices, `lo` inclusive, `hi` exclusive.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct IndexBox {
    /// First sample index per axis (inclusive).
    pub lo: [i64; 3],
    /// One past the last sample index per axis.
    pub hi: [i64; 3],
}

impl IndexBox {
    /// Whether sample `i` lies in the box.
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

    /// Number of samples in the box (0 when empty).
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

/// A sparse narrow-band level set held by OpenVDB.
pub struct Grid {
    inner: OwnedGrid,
    /// Where and how finely the grid was sampled.
    pub spec: GridSpec,
    /// Global sample index of the OpenVDB grid's index (0, 0, 0). OpenVDB sees indices relative
    /// to it, so its coordinates stay small however far the grid lies from the part's origin.
    pub frame: [i64; 3],
    /// Leaf blocks tested against the field's clearance.
    pub blocks_tested: u64,
    /// Leaf blocks sampled (those the band reached).
    pub blocks_sampled: u64,
}

/// Sets the thread count of OpenVDB's TBB pool (0 = TBB's default).
pub fn set_backend_threads(n: usize) {
    ffi::vdb_set_threads(n);
}

impl Grid {
    /// Active voxels (OpenVDB's count: the narrow band).
    pub fn active_voxels(&self) -> u64 {
        ffi::vdb_active_voxels(&self.inner)
    }

    /// Memory OpenVDB reports for the grid, bytes.
    pub fn memory_bytes(&self) -> u64 {
        ffi::vdb_memory_bytes(&self.inner)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Mesh;

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
