/work/main/target/release/deps/termcolor-c8b9efa1ee45c78d.d: /root/.cargo/registry/src/index.crates.io-1949cf8c6b5b557f/termcolor-1.4.1/src/lib.rs

/work/main/target/release/deps/libtermcolor-c8b9efa1ee45c78d.rlib: /root/.cargo/registry/src/index.crates.io-1949cf8c6b5b557f/termcolor-1.4.1/src/lib.rs

/work/main/target/release/deps/libtermcolor-c8b9efa1ee45c78d.rmeta: /root/.cargo/registry/src/index.crates.io-1949cf8c6b5b557f/termcolor-1.4.1/src/lib.rs

/root/.cargo/registry/src/index.crates.io-1949cf8c6b5b557f/termcolor-1.4.1/src/lib.rs:
