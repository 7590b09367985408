//! The mesh type and polygon triangulation, compiled from latvox's source files without the
//! meshing stages beside them (which need OpenVDB).

#[path = "../../src/mesh/indexed.rs"]
mod indexed;
pub use indexed::*;
#[path = "../../src/mesh/triangulate.rs"]
pub mod triangulate;
