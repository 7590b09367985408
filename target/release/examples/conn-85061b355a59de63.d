/work/main/target/release/examples/conn-85061b355a59de63.d: examples/conn.rs

/work/main/target/release/examples/conn-85061b355a59de63: examples/conn.rs

examples/conn.rs:
