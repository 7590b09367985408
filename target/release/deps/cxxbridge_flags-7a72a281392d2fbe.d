/work/main/target/release/deps/cxxbridge_flags-7a72a281392d2fbe.d: /root/.cargo/registry/src/index.crates.io-1949cf8c6b5b557f/cxxbridge-flags-1.0.205/src/lib.rs /root/.cargo/registry/src/index.crates.io-1949cf8c6b5b557f/cxxbridge-flags-1.0.205/src/impl.rs

/work/main/target/release/deps/libcxxbridge_flags-7a72a281392d2fbe.rlib: /root/.cargo/registry/src/index.crates.io-1949cf8c6b5b557f/cxxbridge-flags-1.0.205/src/lib.rs /root/.cargo/registry/src/index.crates.io-1949cf8c6b5b557f/cxxbridge-flags-1.0.205/src/impl.rs

/work/main/target/release/deps/libcxxbridge_flags-7a72a281392d2fbe.rmeta: /root/.cargo/registry/src/index.crates.io-1949cf8c6b5b557f/cxxbridge-flags-1.0.205/src/lib.rs /root/.cargo/registry/src/index.crates.io-1949cf8c6b5b557f/cxxbridge-flags-1.0.205/src/impl.rs

/root/.cargo/registry/src/index.crates.io-1949cf8c6b5b557f/cxxbridge-flags-1.0.205/src/lib.rs:
/root/.cargo/registry/src/index.crates.io-1949cf8c6b5b557f/cxxbridge-flags-1.0.205/src/impl.rs:
