/work/main/target/release/examples/probe-13a82f6882e2826f.d: examples/probe.rs

/work/main/target/release/examples/probe-13a82f6882e2826f: examples/probe.rs

examples/probe.rs:
