//! latvox's integration tests: one binary (each test binary links OpenVDB and CGAL), a module per
//! capability. They run the `latvox` executable and the library on real inputs and check the
//! results with independent computations (`common`, `meshkit`, the Python checkers in
//! `tests/checkers`, CGAL, admesh, trimesh, manifold3d, lib3mf, shapely, OpenVDB's Python module).
//!
//! Two tiers: `cargo test --release` runs the main tier; the long tier (`#[ignore]`d here, named
//! "long:") runs with `cargo test --release -- --ignored`.

mod common;
mod meshkit;

mod batch;
mod beam_lattice;
mod check_repair;
mod density;
mod density_property;
mod docs;
mod feasible;
mod fgm;
mod fill;
mod formats;
mod fuzz;
mod graded;
mod homogenize;
mod implicit_slices;
mod instancing;
mod interpret;
mod part_files;
mod python;
mod render;
mod scale;
mod self_intersect;
mod simplify;
mod slice;
mod slurm;
mod strut;
mod strut_cli;
mod tidy;
mod tiling;
mod topopt;
mod tpms_cli;
mod view;
mod voronoi;
