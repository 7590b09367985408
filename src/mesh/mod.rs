//! Meshing: what makes a mesh from a grid and gets it out (the mesh type is
//! [`crate::geom::Mesh`]).
//!
//! [`extract`] meshes a level set with every
//! vertex named by its voxel and edge group, [`snap`] moves the vertices onto the exact surface,
//! [`tile`] and [`instance`] mesh large parts in pieces that weld exactly, [`pieces`] finds the
//! fragments a box cuts loose, and [`pipeline`] puts them together: any clipped field to a
//! verified mesh at its target density, streamed to a sink, at the resolution [`resolution`]
//! finds it needs,
//! reported the same way for every capability ([`report`]) and written where [`output`] says; [`graded`] meets a density that
//! varies through the part, cell by cell ([`cells`] measures them).

pub mod cells;
pub mod extract;
pub mod graded;
pub mod instance;
pub mod output;
pub mod part;
pub mod pieces;
pub mod pipeline;
pub mod report;
pub mod resolution;
pub mod simplify;
pub mod snap;
pub mod tile;
