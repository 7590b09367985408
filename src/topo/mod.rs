//! `topo`: seed 003's path from an element density field to a printable, verified STL and a
//! parametric B-spline CAD model.
pub mod density;
pub mod npy;

pub use density::Density;
