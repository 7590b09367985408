//! Where Rust calls C++: one bridge per library (OpenVDB, CGAL), each compiled as its own
//! translation unit. Nothing here is public; safe wrappers live in `grid`, `verify` and `repair`.

pub(crate) mod cgal;
pub(crate) mod cgal_repair;
pub(crate) mod vdb;
pub(crate) mod vdb_filter;
pub(crate) mod vdb_remesh;
