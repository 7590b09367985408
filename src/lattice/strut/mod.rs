//! Strut (beam) lattices as fields: unit cells of struts ([`cell`]), the lattice as a periodic
//! field evaluated in one cell ([`field`]), the part at every radius for the meshing pipeline
//! ([`lattice`]), the lattice as beams for 3MF ([`beams`]) and graded through a part
//! ([`graded`]).

pub mod beams;
pub mod cell;
pub mod field;
pub mod graded;
pub mod lattice;

pub use cell::UnitCell;
pub use field::StrutField;
pub use lattice::{RadiusModel, StrutFamily, StrutLattice};

/// The fewest voxels across the thinnest strut before the resolution is raised.
pub const MIN_STRUT_VOXELS: f64 = 2.0;
