//! `topo`: from an element density field to a printable, verified STL and a parametric B-spline
//! CAD model, by feature-preserving cleanup (skeleton-based thin-feature detection, density
//! filtering) and curvature-adaptive B-spline fitting, after Liu S., Li Q., Liu J., Chen W.,
//! Zhang Y., "A realization method for transforming a topology optimization design into additive
//! manufacturing structures", Engineering 4(2), 277–285 (2018). Step numbers in this module's
//! documentation are that paper's.
//!
//! Stages, one module each: [`density`] (input) → [`raster`] (threshold, refine, density
//! filter, volume-keeping level) → [`skeleton`] and [`distance`] (feature size) →
//! [`features`] (thin features, islands, point contacts) → [`mod@clean`] (the repair loop) →
//! [`contour`] (boundary loops) → [`extrude`] (2D) or [`volume`] (3D, OpenVDB) → STL;
//! [`images`] draws every stage; `crate::cad` fits and writes the curves. [`job`] runs the
//! stages on a field; [`mod@file`] runs them from a field file to the part and the files asked
//! for, as `latvox interpret` and `latvox batch` do.

pub mod clean;
pub mod contour;
pub mod density;
pub mod distance;
pub mod extrude;
pub mod features;
pub mod file;
pub mod images;
pub mod job;
pub mod raster;
pub mod skeleton;
pub mod volume;

pub use clean::{clean, CleanOptions, Cleaned};
pub use density::Density;
pub use file::{interpret_file, InterpretFiles, InterpretOptions, InterpretPart};
