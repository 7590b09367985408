//! Lattice-filled parts: a part's mesh kept as a solid skin, its core filled with any latvox
//! lattice (TPMS or struts) at an exact density, solids kept whole where asked — one field
//! ([`shape`]) through the meshing pipeline, one job ([`job`]) from the part's file to the
//! verified mesh, graded where the density varies through the part ([`graded`]); and the same part traced from its meshes for pictures, unmeshed ([`traced`]).

pub mod graded;
pub mod job;
pub mod shape;
pub mod traced;

pub use job::{FillJob, FillReport, Infilling};
pub use shape::{FillFamily, FillSolid, Infill, Shape};
