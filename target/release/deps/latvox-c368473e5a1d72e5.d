/work/main/target/release/deps/latvox-c368473e5a1d72e5.d: src/lib.rs src/error.rs src/ffi/mod.rs src/ffi/cgal.rs src/ffi/vdb.rs src/field.rs src/grid.rs src/mesh.rs src/output.rs src/snap.rs src/stl.rs src/tpms/mod.rs src/tpms/calibrate.rs src/tpms/surface.rs src/verify.rs

/work/main/target/release/deps/latvox-c368473e5a1d72e5: src/lib.rs src/error.rs src/ffi/mod.rs src/ffi/cgal.rs src/ffi/vdb.rs src/field.rs src/grid.rs src/mesh.rs src/output.rs src/snap.rs src/stl.rs src/tpms/mod.rs src/tpms/calibrate.rs src/tpms/surface.rs src/verify.rs

src/lib.rs:
src/error.rs:
src/ffi/mod.rs:
src/ffi/cgal.rs:
src/ffi/vdb.rs:
src/field.rs:
src/grid.rs:
src/mesh.rs:
src/output.rs:
src/snap.rs:
src/stl.rs:
src/tpms/mod.rs:
src/tpms/calibrate.rs:
src/tpms/surface.rs:
src/verify.rs:
