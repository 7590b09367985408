//! Functionally graded material (FGM) by distance fields: a part's geometry as a signed
//! distance field (from a scanned point cloud or a mesh), its material as fractions that are
//! functions of the distance to material features, so that every iso-surface of that distance
//! has one composition — heterogeneous material modelling with distance fields (Biswas, Shapiro
//! and Tsukanov, "Heterogeneous material modeling with distance fields", Computer Aided
//! Geometric Design 21, 2004).
//!
//! - [`cloud`]: points made ready (normals estimated and oriented, spacing, areas);
//! - [`geometry`]: the signed distance [`crate::field::Field`] of a scan (its sign by fast
//!   generalised winding numbers of the oriented points, [`crate::geom::winding`]), sampled
//!   into a grid;
//! - [`material`]: features, the distance to them, laws and compositions;
//! - [`job`]: geometry → grid → mesh (checked) → material distance, and the `.vdb` and meshes;
//! - [`stack`]: voxel-print PNG stacks by error diffusion;
//! - [`preview`]: a section coloured by composition, with a legend;
//! - [`plane`]: a plane contour → a signed distance image, its outline and a picture.

pub mod cloud;
pub mod geometry;
pub mod job;
pub mod material;
pub mod plane;
pub mod preview;
pub mod stack;

pub use geometry::Sign;
pub use job::{Fgm, FgmJob, Geometry};
