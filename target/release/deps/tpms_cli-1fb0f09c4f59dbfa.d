/work/main/target/release/deps/tpms_cli-1fb0f09c4f59dbfa.d: tests/tpms_cli.rs tests/common/mod.rs

/work/main/target/release/deps/tpms_cli-1fb0f09c4f59dbfa: tests/tpms_cli.rs tests/common/mod.rs

tests/tpms_cli.rs:
tests/common/mod.rs:

# env-dep:CARGO_BIN_EXE_latvox=/work/main/target/release/latvox
