//! latvox: implicit descriptions of additive-manufacturing parts (TPMS lattices first) to
//! printable, verified meshes. Rust samples fields and orchestrates; OpenVDB holds the sparse
//! level sets and meshes them; CGAL verifies the result.
//!
//! Stages, one module each: [`field`] → [`grid`] → [`extract`] → [`mesh`] → [`verify`] →
//! [`io`] / [`sink`] (files).
//! Capabilities: [`tpms`], [`check`] and [`repair`] (any mesh file; the STL defects of
//! Qiao Q., "Key technologies of rapid prototyping from 3D STL models"),
//! [`topopt`] (SIMP optimiser), [`topo`] (density fields to STL and CAD), [`cad`] (B-spline
//! curves, IGES, DXF), [`batch`] (many jobs, resumable, sharded over Slurm arrays).

#![warn(missing_docs)]

pub mod batch;
pub mod cad;
pub mod check;
pub mod error;
pub mod extract;
pub(crate) mod ffi;
pub mod field;
pub mod grid;
pub mod instance;
pub mod io;
pub mod mesh;
pub mod output;
pub mod pieces;
pub mod pipeline;
pub mod progress;
pub mod repair;
pub mod sink;
pub mod snap;
pub mod tile;
pub mod topo;
pub mod topology;
pub mod topopt;
pub mod tpms;
pub mod triangulate;
pub mod verify;

pub use error::{Error, Result};
