/work/main/target/release/deps/scratch-32eab72eb69deef9.d: /root/.cargo/registry/src/index.crates.io-1949cf8c6b5b557f/scratch-1.0.9/src/lib.rs

/work/main/target/release/deps/libscratch-32eab72eb69deef9.rlib: /root/.cargo/registry/src/index.crates.io-1949cf8c6b5b557f/scratch-1.0.9/src/lib.rs

/work/main/target/release/deps/libscratch-32eab72eb69deef9.rmeta: /root/.cargo/registry/src/index.crates.io-1949cf8c6b5b557f/scratch-1.0.9/src/lib.rs

/root/.cargo/registry/src/index.crates.io-1949cf8c6b5b557f/scratch-1.0.9/src/lib.rs:

# env-dep:OUT_DIR=/work/main/target/release/build/scratch-0374014b3a0a8c06/out
