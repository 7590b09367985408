//! TPMS lattices: a surface, a structure, a target volume fraction, a box — to a closed,
//! verified mesh whose volume fraction is the target.
//!
//! Pipeline: calibrate the level on the unit cell → sample the lattice clipped by its box into
//! an OpenVDB narrow band → mesh with volumeToMesh → verify with CGAL.

pub mod calibrate;
pub mod surface;

pub use surface::{Structure, Surface, TpmsField};
