/work/main/target/release/examples/conn-b3750b6a7977711c.d: examples/conn.rs

/work/main/target/release/examples/conn-b3750b6a7977711c: examples/conn.rs

examples/conn.rs:
