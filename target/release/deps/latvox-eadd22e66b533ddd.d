/work/main/target/release/deps/latvox-eadd22e66b533ddd.d: src/main.rs

/work/main/target/release/deps/latvox-eadd22e66b533ddd: src/main.rs

src/main.rs:

# env-dep:CARGO_PKG_VERSION=0.1.0
