//! Lattices as fields, calibrated: what makes a TPMS lattice ([`tpms`]), a strut lattice
//! ([`strut`]) or a Voronoi foam ([`voronoi`]) at any level, and the map from a density to that
//! level ([`model`] where it is sampled). The capabilities that
//! make parts of them — `tpms`, `strut`, and `fill` with a lattice inside a part — and the
//! renderer that draws them all build on this stage.

pub mod model;
pub mod strut;
pub mod tpms;
pub mod voronoi;
