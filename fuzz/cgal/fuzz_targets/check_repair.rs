//! Fuzz target: meshes from the bytes through `check`, CGAL's checks, `repair` and
//! `repair --solid` (see `latvox_fuzz_cgal::check_repair`). Run with LATVOX_EXE naming a built
//! `latvox`, so that unions run under their time limit as the command runs them.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| latvox_fuzz_cgal::check_repair(data));
