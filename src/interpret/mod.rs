//! `topo`: seed 003's path from an element density field to a printable, verified STL and a
//! parametric B-spline CAD model.
//!
//! Stages, one module each: [`density`] (input) → [`raster`] (threshold, refine, density
//! filter, volume-keeping level) → [`skeleton`] and [`distance`] (feature size) →
//! [`features`] (thin features, islands, point contacts) → [`clean`] (the repair loop) →
//! [`contour`] (boundary loops) → [`extrude`] (2D) or [`volume`] (3D, OpenVDB) → STL;
//! [`images`] draws every stage; `crate::cad` fits and writes the curves.

pub mod clean;
pub mod contour;
pub mod density;
pub mod distance;
pub mod extrude;
pub mod features;
pub mod images;
pub mod job;
pub mod raster;
pub mod skeleton;
pub mod volume;

pub use clean::{clean, CleanOptions, Cleaned};
pub use density::Density;
