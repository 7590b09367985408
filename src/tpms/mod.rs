//! TPMS lattices: a surface, a structure, a target volume fraction and a box, to a closed mesh
//! whose volume fraction is the target.
//!
//! Pipeline: [`calibrate`] the level on the unit cell (the lattice itself is
//! [`crate::lattice::tpms`]) (a first guess) → [`crate::mesh::pipeline`]:
//! sample the lattice clipped by its box into an OpenVDB narrow band, mesh, snap, measure the
//! part and correct the level until its density is the target, verify with CGAL, write.
//!
//! The lattice's phase is anchored at the box's lower corner, and the voxel size divides the
//! cell, so every whole cell of the part is meshed exactly like the calibration's unit cell.

pub mod blend;
pub mod graded;
pub mod job;
pub mod mapped;

pub use crate::lattice::tpms::{
    calibrate, surface, Calibration, FeasibleRange, Lattice, LatticeFamily, Structure, Surface,
    TpmsField,
};
pub use job::{TpmsJob, TpmsReport};

pub use crate::field::domain::Domain;
pub use crate::mesh::pipeline::{MeshingStats, HALF_WIDTH};
