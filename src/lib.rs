//! latvox: implicit descriptions of additive-manufacturing parts (TPMS lattices first) to
//! printable, verified meshes. Rust samples fields and orchestrates; OpenVDB holds the sparse
//! level sets and meshes them; CGAL verifies the result.
//!
//! Stages, one folder each: [`field`] (implicit solids) → [`grid`] (OpenVDB level sets) →
//! [`mesh`] (extraction, snapping, tiles, instancing, and the [`mesh::pipeline`] that takes any
//! clipped field to a verified mesh at its target density) → [`check`] (latvox's checks and
//! CGAL's) → [`io`] (readers, writers, sinks, atomic output).
//! Capabilities: [`tpms`], [`repair`] (any mesh file, seed 001's defects), [`topopt`] (SIMP
//! optimiser), [`interpret`] (density fields to printable parts and CAD), [`cad`] (B-spline
//! curves, IGES, DXF), [`batch`] (many jobs, resumable, sharded over Slurm arrays).

pub mod batch;
pub mod cad;
pub mod check;
pub mod error;
pub(crate) mod ffi;
pub mod field;
pub mod grid;
pub mod interpret;
pub mod io;
pub mod mesh;
pub mod progress;
pub mod repair;
pub mod topopt;
pub mod tpms;

pub use error::{Error, Result};
