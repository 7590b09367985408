/work/main/target/release/deps/latvox-c1c8a2f7fa86a03a.d: src/main.rs

/work/main/target/release/deps/latvox-c1c8a2f7fa86a03a: src/main.rs

src/main.rs:

# env-dep:CARGO_PKG_VERSION=0.1.0
