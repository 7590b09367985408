//! TPMS lattices: a surface, a structure, a target volume fraction and a box, to a closed mesh
//! whose volume fraction is the target.
//!
//! Pipeline: [`calibrate`] the level on the unit cell → sample the lattice clipped by its box into
//! an OpenVDB narrow band ([`crate::grid`]) → mesh with volumeToMesh → [`crate::snap`] vertices
//! onto the exact surface and box edges → verify with CGAL ([`crate::verify`]).
//!
//! The lattice's phase is anchored at the box's lower corner, and the voxel size divides the
//! cell, so every whole cell of the part is meshed exactly like the calibration's unit cell.

pub mod calibrate;
pub mod instance;
pub mod job;
pub mod surface;

pub use calibrate::{Calibration, FeasibleRange};
pub use job::{TpmsJob, TpmsReport};
pub use surface::{Structure, Surface, TpmsField};

use crate::error::{Error, Result};
use crate::extract::KeyedMesh;
use crate::field::{Aabb, Intersection, Vec3};
use crate::grid::{Grid, GridSpec, IndexBox};
use crate::mesh::Mesh;
use crate::snap::SnapStats;

/// Default narrow-band half width, voxels.
pub const HALF_WIDTH: f64 = 3.0;

/// A TPMS lattice clipped by a box: everything needed to mesh it, at a known level.
#[derive(Debug, Clone, Copy)]
pub struct Lattice {
    pub surface: Surface,
    pub structure: Structure,
    pub level: f64,
    /// Cell size per axis, mm.
    pub cell: Vec3,
    /// The clipping box.
    pub bounds: Aabb,
    /// A lattice point (the phase), mm: the box's lower corner for a part.
    pub phase: Vec3,
}

/// Statistics of one meshing pass.
#[derive(Debug, Clone, Copy, Default, serde::Serialize)]
pub struct MeshingStats {
    pub voxel_size: f64,
    pub blocks_tested: u64,
    pub blocks_sampled: u64,
    pub active_voxels: u64,
    pub grid_bytes: u64,
    pub snap: SnapStats,
    pub sample_seconds: f64,
    pub mesh_seconds: f64,
    pub snap_seconds: f64,
}

impl MeshingStats {
    /// Adds another pass's counts and times (tiles of one part).
    pub fn add(&mut self, o: &MeshingStats) {
        self.voxel_size = o.voxel_size;
        self.blocks_tested += o.blocks_tested;
        self.blocks_sampled += o.blocks_sampled;
        self.active_voxels += o.active_voxels;
        self.grid_bytes = self.grid_bytes.max(o.grid_bytes);
        self.snap += o.snap;
        self.sample_seconds += o.sample_seconds;
        self.mesh_seconds += o.mesh_seconds;
        self.snap_seconds += o.snap_seconds;
    }
}

impl Lattice {
    pub fn field(&self, clamp: f64) -> TpmsField {
        TpmsField::new(
            self.surface,
            self.structure,
            self.level,
            self.cell,
            self.phase,
            clamp,
        )
    }

    /// Samples, meshes and snaps the lattice on voxels of size `voxel`, with voxel cells tiling
    /// the box from its lower corner.
    pub fn mesh(&self, voxel: f64, adaptivity: f64) -> Result<(Mesh, MeshingStats)> {
        let spec = GridSpec::covering(&self.bounds, voxel, HALF_WIDTH);
        let (keyed, stats) = self.mesh_keyed(spec, adaptivity)?;
        Ok((keyed.to_mesh(), stats))
    }

    /// Samples, meshes and snaps the lattice on `spec`, keeping each vertex's key.
    pub(crate) fn mesh_keyed(
        &self,
        spec: GridSpec,
        adaptivity: f64,
    ) -> Result<(KeyedMesh, MeshingStats)> {
        self.mesh_keyed_in(spec, None, adaptivity)
    }

    /// [`Lattice::mesh_keyed`] on the blocks covering `region` only (a tile), or on the whole
    /// padded grid.
    pub(crate) fn mesh_keyed_in(
        &self,
        spec: GridSpec,
        region: Option<IndexBox>,
        adaptivity: f64,
    ) -> Result<(KeyedMesh, MeshingStats)> {
        self.mesh_keyed_snapped(spec, region, adaptivity, None)
    }

    /// Volume of the solid inside `b`, a box within the bounds: only the vertices of triangles
    /// that can reach into `b` (within two voxels of it) are snapped.
    pub(crate) fn volume_in(&self, spec: GridSpec, adaptivity: f64, b: &Aabb) -> Result<f64> {
        let within = b.grown(2.0 * spec.voxel);
        let (keyed, _) = self.mesh_keyed_snapped(spec, None, adaptivity, Some(&within))?;
        Ok(keyed.to_mesh().volume_in_box(b))
    }

    fn mesh_keyed_snapped(
        &self,
        spec: GridSpec,
        region: Option<IndexBox>,
        adaptivity: f64,
        snap_within: Option<&Aabb>,
    ) -> Result<(KeyedMesh, MeshingStats)> {
        use std::time::Instant;
        let tpms = self
            .field(spec.half_width * spec.voxel)
            .with_periodic_samples(spec.voxel);
        let solid = Intersection {
            a: tpms,
            b: self.bounds,
        };
        let t = Instant::now();
        let grid = match region {
            Some(r) => Grid::sample_box(&solid, spec, r)?,
            None => Grid::sample(&solid, spec)?,
        };
        let sample_seconds = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let mut keyed = if adaptivity == 0.0 {
            KeyedMesh::extract(&grid)?
        } else {
            KeyedMesh::from_adaptive(&grid.to_mesh(adaptivity)?, &spec)
        };
        let mesh_seconds = t.elapsed().as_secs_f64();
        let stats = MeshingStats {
            voxel_size: spec.voxel,
            blocks_tested: grid.blocks_tested,
            blocks_sampled: grid.blocks_sampled,
            active_voxels: grid.active_voxels(),
            grid_bytes: grid.memory_bytes(),
            sample_seconds,
            mesh_seconds,
            ..Default::default()
        };
        drop(grid);
        let t = Instant::now();
        let snap_stats =
            crate::snap::snap_within(&mut keyed, &tpms, &self.bounds, &spec, snap_within);
        Ok((
            keyed,
            MeshingStats {
                snap: snap_stats,
                snap_seconds: t.elapsed().as_secs_f64(),
                ..stats
            },
        ))
    }
}

/// How the box is given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Domain {
    /// Cell size per axis, mm.
    pub cell: Vec3,
    /// Box size per axis, mm.
    pub size: Vec3,
    /// Lower corner of the box, mm.
    pub origin: Vec3,
}

impl Domain {
    /// Whole cells: `counts` cells of size `cell` per axis.
    pub fn from_cells(counts: [u32; 3], cell: Vec3, origin: Vec3) -> Result<Domain> {
        if counts.contains(&0) {
            return Err(Error::invalid("cell counts must be at least 1"));
        }
        Self::checked(cell, [0, 1, 2].map(|a| counts[a] as f64 * cell[a]), origin)
    }

    /// Overall dimensions `size` with `counts` cells per axis.
    pub fn from_size_and_cells(size: Vec3, counts: [u32; 3], origin: Vec3) -> Result<Domain> {
        if counts.contains(&0) {
            return Err(Error::invalid("cell counts must be at least 1"));
        }
        Self::checked([0, 1, 2].map(|a| size[a] / counts[a] as f64), size, origin)
    }

    /// Overall dimensions `size` filled with cells of size `cell` (partial cells at the far side).
    pub fn from_size_and_cell(size: Vec3, cell: Vec3, origin: Vec3) -> Result<Domain> {
        Self::checked(cell, size, origin)
    }

    fn checked(cell: Vec3, size: Vec3, origin: Vec3) -> Result<Domain> {
        for a in 0..3 {
            if !(cell[a] > 0.0 && cell[a].is_finite()) {
                return Err(Error::invalid(format!(
                    "cell size must be positive, got {}",
                    cell[a]
                )));
            }
            if !(size[a] > 0.0 && size[a].is_finite()) {
                return Err(Error::invalid(format!(
                    "box size must be positive, got {}",
                    size[a]
                )));
            }
            if !origin[a].is_finite() {
                return Err(Error::invalid("origin must be finite"));
            }
        }
        Ok(Domain { cell, size, origin })
    }

    pub fn bounds(&self) -> Aabb {
        Aabb {
            min: self.origin,
            max: [0, 1, 2].map(|a| self.origin[a] + self.size[a]),
        }
    }

    /// Cells per axis (fractional where the box ends inside a cell).
    pub fn counts(&self) -> Vec3 {
        [0, 1, 2].map(|a| self.size[a] / self.cell[a])
    }
}
