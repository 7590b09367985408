//! Voronoi foams, stochastic lattices: struts along the edges or walls along the faces of the
//! Voronoi diagram of Poisson-disk seeds (or the user's), at an exact density ([`job`]). The
//! foam as a field and its seeds are [`crate::lattice::voronoi`].

pub mod graded;
pub mod job;

pub use crate::lattice::voronoi::{seeds, FoamStats, Spread, Structure};
pub use job::{
    Seeding, Sizing, Spacing, VoronoiBeamsReport, VoronoiJob, VoronoiRange, VoronoiReport,
};
