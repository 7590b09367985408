//! TPMS lattices as fields: the surfaces ([`surface`]), the level at a density calibrated on the
//! unit cell ([`calibrate`]), a lattice clipped by its box at any level for the meshing pipeline
//! ([`Lattice`], [`LatticeFamily`]) and graded through a part ([`graded`]).

pub mod calibrate;
pub mod graded;
pub mod surface;

pub use calibrate::{Calibration, FeasibleRange};
pub use surface::{Structure, Surface, TpmsField};

use crate::error::Result;
use crate::field::{Aabb, Field, Vec3};
use crate::geom::Mesh;
use crate::grid::GridSpec;
use crate::mesh::pipeline::{mesh_keyed, Family, MeshingStats, Solid, HALF_WIDTH};

/// The fewest voxels across a sheet's thinnest wall before the resolution is raised.
pub const MIN_WALL_VOXELS: f64 = 1.25;

/// A TPMS lattice clipped by a box: everything needed to mesh it, at a known level.
#[derive(Debug, Clone, Copy)]
pub struct Lattice {
    /// Which minimal surface.
    pub surface: Surface,
    /// Solid on one side of the surface (net) or around it (sheet).
    pub structure: Structure,
    /// The level `t`: net solid where F ≤ t, sheet solid where |F| ≤ t.
    pub level: f64,
    /// Cell size per axis, mm.
    pub cell: Vec3,
    /// The clipping box.
    pub bounds: Aabb,
    /// A lattice point (the phase), mm: the box's lower corner for a part.
    pub phase: Vec3,
}

impl Lattice {
    /// The lattice's field, unclipped, its values clamped to ±`clamp` mm.
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
        let (keyed, stats) = mesh_keyed(self, spec, None, adaptivity, None)?;
        Ok((keyed.into_mesh(), stats))
    }

    /// Volume of the solid inside `b`, a box within the bounds: only the vertices of triangles
    /// that can reach into `b` (within two voxels of it) are snapped.
    pub(crate) fn volume_in(&self, spec: GridSpec, adaptivity: f64, b: &Aabb) -> Result<f64> {
        let within = b.grown(2.0 * spec.voxel);
        let (keyed, _) = mesh_keyed(self, spec, None, adaptivity, Some(&within))?;
        Ok(keyed.to_mesh().volume_in_box(b))
    }
}

impl Solid for Lattice {
    fn field(&self, spec: &GridSpec) -> Box<dyn Field + '_> {
        Box::new(
            Lattice::field(self, spec.half_width * spec.voxel).with_periodic_samples(spec.voxel),
        )
    }

    fn bounds(&self) -> Aabb {
        self.bounds
    }

    fn with_bounds(&self, bounds: Aabb) -> Self {
        Lattice { bounds, ..*self }
    }

    fn period(&self) -> Option<Vec3> {
        (self.phase == self.bounds.min).then_some(self.cell)
    }
}

/// A TPMS part at every level: the family the pipeline searches for the part's density.
#[derive(Debug, Clone, Copy)]
pub struct LatticeFamily {
    /// The part at some level (the level is replaced).
    pub part: Lattice,
}

impl Family for LatticeFamily {
    type Solid = Lattice;

    fn at(&self, level: f64) -> Lattice {
        Lattice { level, ..self.part }
    }

    fn model_fraction(&self, level: f64) -> f64 {
        calibrate::analytic_fraction(self.part.surface, self.part.structure, level)
    }

    fn model_level(&self, fraction: f64) -> f64 {
        calibrate::analytic_level(self.part.surface, self.part.structure, fraction)
    }
}
