//! Fuzz target: the STL reader never panics, never over-allocates, and yields a sound mesh.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    latvox_fuzz::check(data, latvox_fuzz::io::Format::Stl);
});
