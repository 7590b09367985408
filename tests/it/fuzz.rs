//! Fuzzing inside `cargo test`, each run bounded in time; new corpus entries go to a temporary
//! folder, so the tree stays clean.
//!
//! - The mesh readers: each cargo-fuzz target (`fuzz/fuzz_targets`) runs from its committed seed
//!   corpus (`fuzz/corpus/TARGET`) under AddressSanitizer, with a 2 GB memory limit. A crash, a
//!   panic, an over-allocation or a broken mesh invariant fails the test. Needs a nightly
//!   toolchain and cargo-fuzz (scripts/install-deps.sh installs them).
//! - `check` and `repair`, CGAL and OpenVDB behind them: the `check_repair` target
//!   (`fuzz/cgal`) replayed on its corpus and random mutations of it, built with this crate.

use crate::common;

use std::path::Path;
use std::process::Command;

/// Seconds of fuzzing per reader.
const SECONDS: u32 = 12;
const TARGETS: [&str; 5] = ["stl", "obj", "off", "ply", "threemf"];

/// `cargo +nightly fuzz SUBCOMMAND` on the fuzz project in `dir`, with `args` after it.
fn cargo_fuzz(dir: &Path, args: &[&str]) -> Command {
    let mut c = Command::new("cargo");
    c.arg("+nightly").arg("fuzz").args(args).current_dir(dir);
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

/// Builds the fuzz project in `dir`.
fn build(dir: &Path) {
    let out = cargo_fuzz(dir, &["build", "--release"])
        .output()
        .expect("run cargo (rustup with a nightly toolchain: scripts/install-deps.sh)");
    assert!(
        out.status.success(),
        "cargo +nightly fuzz build failed (scripts/install-deps.sh installs cargo-fuzz and nightly):\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Runs `target` of the fuzz project in `dir` for `seconds` from the seeds in `seeds`; returns
/// libFuzzer's execution count.
fn fuzz(dir: &Path, target: &str, seeds: &Path, seconds: u32) -> u64 {
    assert!(
        std::fs::read_dir(seeds).map(|d| d.count()).unwrap_or(0) > 0,
        "no seed corpus in {}",
        seeds.display()
    );
    let work = tempfile::tempdir().unwrap();
    let corpus = work.path().join("corpus");
    std::fs::create_dir(&corpus).unwrap();
    let out = cargo_fuzz(dir, &["run", "--release", target])
        .arg(&corpus)
        .arg(seeds)
        .arg("--")
        .arg(format!("-max_total_time={seconds}"))
        .arg("-rss_limit_mb=2048")
        .arg("-malloc_limit_mb=1024")
        .arg(format!("-artifact_prefix={}/", work.path().display()))
        .output()
        .unwrap();
    let log = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "fuzz target {target} failed:\n{}",
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
    log.lines()
        .find_map(|l| {
            l.strip_prefix("Done ")?
                .split_whitespace()
                .next()?
                .parse()
                .ok()
        })
        .unwrap_or_else(|| panic!("no run count from libFuzzer for {target}:\n{log}"))
}

#[test]
fn every_reader_survives_fuzzing() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = root.join("fuzz");
    build(&dir);
    let mut summary = Vec::new();
    for t in TARGETS {
        let runs = fuzz(&dir, t, &dir.join("corpus").join(t), SECONDS);
        assert!(runs > 1000, "{t}: only {runs} executions in {SECONDS} s");
        summary.push(format!("{t} {runs}"));
    }
    eprintln!(
        "fuzz executions in {SECONDS} s per target: {}",
        summary.join(", ")
    );
}

#[path = "../../fuzz/cgal/src/lib.rs"]
mod check_repair;

/// How long the replay of the check-and-repair corpus goes on mutating it, seconds.
const MUTATION_SECONDS: u64 = 20;

/// The `check_repair` fuzz target (`fuzz/cgal`: meshes with corners on a coarse grid through
/// check, CGAL's checks, repair and `repair --solid`) on its committed corpus, then on random
/// mutations of it (bytes changed, inserted, dropped, entries spliced) for a bounded time: never
/// a panic, an abort or a backend error, every solid made valid by latvox's check and CGAL's.
/// Coverage-guided runs of the same target: `cargo +nightly fuzz run --fuzz-dir fuzz/cgal -s none
/// check_repair` (building the C++ bridges again takes ten minutes, so `cargo test` replays).
#[test]
fn check_and_repair_hold_on_the_fuzz_corpus_and_its_mutations() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/cgal/corpus/check_repair");
    let mut corpus: Vec<(String, Vec<u8>)> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| {
            let p = e.unwrap().path();
            (p.display().to_string(), std::fs::read(&p).unwrap())
        })
        .collect();
    corpus.sort();
    assert!(
        corpus.len() >= 7,
        "seed corpus missing in {}",
        dir.display()
    );
    let solids = corpus
        .iter()
        .filter(|(_, d)| check_repair::mesh(d).is_some())
        .count();
    assert!(solids >= 7, "only {solids} corpus entries make a mesh");
    for (name, data) in &corpus {
        let r = std::panic::catch_unwind(|| check_repair::check_repair(data));
        assert!(r.is_ok(), "corpus entry {name} fails");
    }
    let mut rng = common::Rng(0xc6a1);
    let start = std::time::Instant::now();
    let mut runs = 0;
    while start.elapsed().as_secs() < MUTATION_SECONDS {
        let mut data = corpus[rng.below(corpus.len() as u64) as usize].1.clone();
        for _ in 0..1 + rng.below(4) {
            let n = data.len().max(1) as u64;
            let at = rng.below(n) as usize;
            match rng.below(5) {
                0 if !data.is_empty() => data[at] = rng.below(256) as u8,
                1 if !data.is_empty() => data[at] ^= 1 << rng.below(8),
                2 => data.insert(at.min(data.len()), rng.below(256) as u8),
                3 if data.len() > 1 => {
                    data.remove(at);
                }
                _ => {
                    let other = &corpus[rng.below(corpus.len() as u64) as usize].1;
                    let from = rng.below(other.len() as u64) as usize;
                    data.truncate(at);
                    data.extend_from_slice(&other[from..]);
                }
            }
        }
        let r = std::panic::catch_unwind(|| check_repair::check_repair(&data));
        assert!(r.is_ok(), "mutated input fails: {data:?}");
        runs += 1;
    }
    eprintln!(
        "check and repair: {} corpus entries, {runs} mutations in {MUTATION_SECONDS} s",
        corpus.len()
    );
}
