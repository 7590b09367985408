/work/main/target/release/examples/si-4b20d91a90bd0c8d.d: examples/si.rs

/work/main/target/release/examples/si-4b20d91a90bd0c8d: examples/si.rs

examples/si.rs:
