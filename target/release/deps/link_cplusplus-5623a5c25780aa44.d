/work/main/target/release/deps/link_cplusplus-5623a5c25780aa44.d: /root/.cargo/registry/src/index.crates.io-1949cf8c6b5b557f/link-cplusplus-1.0.12/src/lib.rs

/work/main/target/release/deps/liblink_cplusplus-5623a5c25780aa44.rlib: /root/.cargo/registry/src/index.crates.io-1949cf8c6b5b557f/link-cplusplus-1.0.12/src/lib.rs

/work/main/target/release/deps/liblink_cplusplus-5623a5c25780aa44.rmeta: /root/.cargo/registry/src/index.crates.io-1949cf8c6b5b557f/link-cplusplus-1.0.12/src/lib.rs

/root/.cargo/registry/src/index.crates.io-1949cf8c6b5b557f/link-cplusplus-1.0.12/src/lib.rs:
