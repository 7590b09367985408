//! Lattices as fields, calibrated: what makes a TPMS lattice ([`tpms`]) or a strut lattice
//! ([`strut`]) at any level, and the map from a density to that level. The capabilities that
//! make parts of them — `tpms`, `strut`, and `fill` with a lattice inside a part — and the
//! renderer that draws them all build on this stage.

pub mod strut;
pub mod tpms;
