/work/main/target/release/deps/density-732d6a417e7013e7.d: tests/density.rs

/work/main/target/release/deps/density-732d6a417e7013e7: tests/density.rs

tests/density.rs:
