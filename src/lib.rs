//! latvox: implicit descriptions of additive-manufacturing parts (TPMS lattices first) to
//! printable, verified meshes. Rust samples fields and orchestrates; OpenVDB holds the sparse
//! level sets and meshes them; CGAL verifies the result.
//!
//! Stages, one module each: [`field`] → [`grid`] → [`mesh`] → [`verify`] → [`io`] (files).
//! Capabilities: [`tpms`], [`check`] and [`repair`] (any mesh file, seed 001's defects).

pub mod check;
pub mod error;
pub mod extract;
pub(crate) mod ffi;
pub mod field;
pub mod grid;
pub mod io;
pub mod mesh;
pub mod output;
pub mod progress;
pub mod repair;
pub mod snap;
pub mod topology;
pub mod tpms;
pub mod triangulate;
pub mod verify;

pub use error::{Error, Result};
