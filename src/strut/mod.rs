//! Strut (beam) lattices: unit cells of struts ([`cell`]) and the lattice as a periodic field
//! evaluated in one cell ([`field`]), the part at every radius for the meshing pipeline
//! ([`lattice`]), the lattice as beams for 3MF ([`beams`]), the lattice graded
//! ([`graded`]) and the job that makes a part to a
//! density or radius ([`job`]).

pub mod beams;
pub mod cell;
pub mod field;
pub mod graded;
pub mod job;
pub mod lattice;

pub use cell::UnitCell;
pub use field::StrutField;
pub use job::{BeamsReport, Sizing, StrutJob, StrutReport};
pub use lattice::{RadiusModel, StrutFamily, StrutLattice};
