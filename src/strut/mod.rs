//! Strut (beam) lattices: unit cells of struts ([`cell`]) and the lattice as a periodic field
//! evaluated in one cell ([`field`]), for the meshing pipeline.

pub mod cell;
pub mod field;
pub mod lattice;

pub use cell::UnitCell;
pub use field::StrutField;
pub use lattice::{RadiusModel, StrutFamily, StrutLattice};
