//! latvox: implicit descriptions of additive-manufacturing parts (TPMS lattices first) to
//! printable, verified meshes. Rust samples fields and orchestrates; OpenVDB holds the sparse
//! level sets and meshes them; CGAL verifies the result.
//!
//! Stages, one module each: [`field`] → [`grid`] → [`mesh`] → [`verify`] → [`stl`] (output).
//! Capabilities: [`tpms`], [`topopt`] (SIMP optimiser), [`topo`] (density fields to STL and CAD),
//! [`cad`] (B-spline curves, IGES, DXF), [`batch`] (many jobs, resumable, sharded over Slurm
//! arrays).

pub mod batch;
pub mod cad;
pub mod error;
pub mod extract;
pub(crate) mod ffi;
pub mod field;
pub mod grid;
pub mod mesh;
pub mod output;
pub mod progress;
pub mod sink;
pub mod snap;
pub mod stl;
pub mod topo;
pub mod topopt;
pub mod tpms;
pub mod verify;

pub use error::{Error, Result};
