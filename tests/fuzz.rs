//! Fuzzing the mesh readers inside `cargo test`: each cargo-fuzz target (fuzz/fuzz_targets) runs
//! for a bounded time from its committed seed corpus (fuzz/corpus/TARGET), under AddressSanitizer,
//! with a 2 GB memory limit. A crash, a panic, an over-allocation or a broken mesh invariant
//! fails the test. New corpus entries go to a temporary folder, so the tree stays clean.
//!
//! Needs a nightly toolchain and cargo-fuzz (scripts/install-deps.sh installs them).

use std::path::Path;
use std::process::Command;

/// Seconds of fuzzing per reader.
const SECONDS: u32 = 12;
const TARGETS: [&str; 5] = ["stl", "obj", "off", "ply", "threemf"];

fn cargo_fuzz(root: &Path) -> Command {
    let mut c = Command::new("cargo");
    c.arg("+nightly").arg("fuzz").current_dir(root.join("fuzz"));
    // The outer cargo's settings are for the outer build, not this one.
    for v in [
        "CARGO_TARGET_DIR",
        "RUSTFLAGS",
        "CARGO_ENCODED_RUSTFLAGS",
        "RUSTC",
        "RUSTC_WRAPPER",
        "RUSTUP_TOOLCHAIN",
        "CARGO_BUILD_TARGET",
    ] {
        c.env_remove(v);
    }
    c
}

#[test]
fn every_reader_survives_fuzzing() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let out = cargo_fuzz(root)
        .args(["build", "--release"])
        .output()
        .expect("run cargo (rustup with a nightly toolchain: scripts/install-deps.sh)");
    assert!(
        out.status.success(),
        "cargo +nightly fuzz build failed (scripts/install-deps.sh installs cargo-fuzz and nightly):\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut summary = Vec::new();
    for t in TARGETS {
        let seeds = root.join("fuzz/corpus").join(t);
        assert!(
            std::fs::read_dir(&seeds).map(|d| d.count()).unwrap_or(0) > 0,
            "no seed corpus in {}",
            seeds.display()
        );
        let work = tempfile::tempdir().unwrap();
        let corpus = work.path().join("corpus");
        std::fs::create_dir(&corpus).unwrap();
        let out = cargo_fuzz(root)
            .args(["run", "--release", t])
            .arg(&corpus)
            .arg(&seeds)
            .arg("--")
            .arg(format!("-max_total_time={SECONDS}"))
            .arg("-rss_limit_mb=2048")
            .arg("-malloc_limit_mb=1024")
            .arg(format!("-artifact_prefix={}/", work.path().display()))
            .output()
            .unwrap();
        let log = String::from_utf8_lossy(&out.stderr);
        assert!(
            out.status.success(),
            "fuzz target {t} failed:\n{}",
            log.lines()
                .rev()
                .take(60)
                .collect::<Vec<_>>()
                .into_iter()
                .rev()
                .collect::<Vec<_>>()
                .join("\n")
        );
        // libFuzzer ends with "Done N runs in S second(s)".
        let runs: u64 = log
            .lines()
            .find_map(|l| {
                l.strip_prefix("Done ")?
                    .split_whitespace()
                    .next()?
                    .parse()
                    .ok()
            })
            .unwrap_or_else(|| panic!("no run count from libFuzzer for {t}:\n{log}"));
        assert!(runs > 1000, "{t}: only {runs} executions in {SECONDS} s");
        summary.push(format!("{t} {runs}"));
    }
    eprintln!(
        "fuzz executions in {SECONDS} s per target: {}",
        summary.join(", ")
    );
}
