/work/main/target/release/deps/latvox-7079050377d82fa9.d: src/lib.rs src/error.rs src/ffi/mod.rs src/ffi/cgal.rs src/ffi/vdb.rs src/field.rs src/grid.rs src/mesh.rs src/output.rs src/progress.rs src/snap.rs src/stl.rs src/tpms/mod.rs src/tpms/calibrate.rs src/tpms/job.rs src/tpms/surface.rs src/verify.rs

/work/main/target/release/deps/latvox-7079050377d82fa9: src/lib.rs src/error.rs src/ffi/mod.rs src/ffi/cgal.rs src/ffi/vdb.rs src/field.rs src/grid.rs src/mesh.rs src/output.rs src/progress.rs src/snap.rs src/stl.rs src/tpms/mod.rs src/tpms/calibrate.rs src/tpms/job.rs src/tpms/surface.rs src/verify.rs

src/lib.rs:
src/error.rs:
src/ffi/mod.rs:
src/ffi/cgal.rs:
src/ffi/vdb.rs:
src/field.rs:
src/grid.rs:
src/mesh.rs:
src/output.rs:
src/progress.rs:
src/snap.rs:
src/stl.rs:
src/tpms/mod.rs:
src/tpms/calibrate.rs:
src/tpms/job.rs:
src/tpms/surface.rs:
src/verify.rs:
