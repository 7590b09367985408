//! Strut (beam) lattices: the job that makes a part to a density or radius ([`job`]), graded
//! through the part ([`graded`]). The lattice itself — unit cells, the periodic field, the part
//! at every radius, beams for 3MF — is [`crate::lattice::strut`].

pub mod graded;
pub mod job;

pub use crate::lattice::strut::{
    beams, cell, field, lattice, RadiusModel, StrutFamily, StrutField, StrutLattice, UnitCell,
};
pub use job::{BeamsReport, Sizing, StrutJob, StrutReport};
