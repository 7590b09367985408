//! latvox: implicit descriptions of additive-manufacturing parts (TPMS lattices first) to
//! printable, verified meshes. Rust samples fields and orchestrates; OpenVDB holds the sparse
//! level sets and meshes them; CGAL verifies the result.
//!
//! Stages, one folder each: [`field`] (implicit solids) → [`grid`] (OpenVDB level sets) →
//! [`mesh`] (extraction, snapping, tiles, instancing, and the [`mesh::pipeline`] that takes any
//! clipped field to a verified mesh at its target density) → [`check`] (latvox's checks and
//! CGAL's) → [`io`] (readers, writers, sinks, atomic output).
//! Capabilities: [`tpms`], [`strut`], [`voronoi`] (Voronoi foams), [`repair`] (any mesh file;
//! the STL defects of Qiao Q., "Key technologies of rapid prototyping from 3D STL models"),
//! [`topopt`] (SIMP optimiser), [`interpret`] (density fields to printable parts and CAD),
//! [`cad`] (B-spline curves, IGES, DXF), [`batch`] (many jobs, resumable, sharded over Slurm
//! arrays).
//!
//! # Field → Grid → Mesh
//!
//! Any [`field::Field`] — here a ball of radius 5 mm, an exact signed distance — is sampled
//! into a sparse narrow-band OpenVDB level set on 0.25 mm voxels, meshed, and checked:
//!
//! ```
//! use latvox::field::{Aabb, Field, Vec3};
//! use latvox::grid::{Grid, GridSpec};
//!
//! struct Ball {
//!     radius: f64,
//! }
//!
//! impl Field for Ball {
//!     fn value(&self, p: Vec3) -> f64 {
//!         (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt() - self.radius
//!     }
//!     // An exact distance: the surface is |value| away, never nearer.
//!     fn clearance(&self, p: Vec3) -> f64 {
//!         self.value(p).abs()
//!     }
//! }
//!
//! let ball = Ball { radius: 5.0 };
//! let bounds = Aabb { min: [-6.0; 3], max: [6.0; 3] };
//! let spec = GridSpec::covering(&bounds, 0.25, latvox::mesh::pipeline::HALF_WIDTH);
//! let grid = Grid::sample(&ball, spec)?;
//! let mesh = grid.to_mesh(0.0)?;
//!
//! // Closed: no edge with only one triangle.
//! assert_eq!(mesh.edge_stats().boundary, 0);
//! // The enclosed volume is the ball's, within 1 %.
//! let exact = 4.0 / 3.0 * std::f64::consts::PI * 5.0f64.powi(3);
//! assert!((mesh.volume() / exact - 1.0).abs() < 0.01);
//! // CGAL agrees: closed, wound outward, free of self-intersections.
//! let checks = latvox::verify::cgal::verify(&mesh, true)?;
//! assert!(checks.closed && checks.outward && !checks.self_intersecting);
//! # Ok::<(), latvox::Error>(())
//! ```

#![warn(missing_docs)]

pub mod batch;
pub mod cad;
pub mod check;
pub mod error;
pub(crate) mod ffi;
pub mod fgm;
pub mod field;
pub mod fill;
pub mod geom;
pub mod grid;
pub mod homogenize;
pub mod interpret;
pub mod io;
pub mod lattice;
pub mod mesh;
pub mod progress;
pub mod render;
pub mod repair;
pub mod slice;
pub mod strut;
pub mod topopt;
pub mod tpms;
pub mod verify;
pub mod voronoi;

pub use error::{Error, Result};
