//! Voronoi foams: stochastic lattices whose members follow the Voronoi diagram of seed points —
//! struts along its edges (`net`) or walls along its faces (`sheet`) — as fields for the meshing
//! pipeline, at any strut radius or wall thickness ([`foam`]); the seeds themselves
//! ([`seeds`]) and their diagram, CGAL's ([`diagram`]); foams that tile space ([`periodic`]).

pub mod diagram;
pub mod foam;
pub mod graded;
pub mod periodic;
pub mod seeds;

pub use foam::{Foam, FoamFamily, FoamSolid, FoamStats, Pore, Spread, Structure};
