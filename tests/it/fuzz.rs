//! Fuzzing inside `cargo test`, each run bounded in time; new corpus entries go to a temporary
//! folder, so the tree stays clean.
//!
//! - The mesh readers: in the main tier, each reader on its seed corpus (`fuzz/corpus/TARGET`)
//!   and random mutations of it, in this process, with the invariants the fuzz targets assert.
//!   In the long tier, each cargo-fuzz target (`fuzz/fuzz_targets`) runs coverage-guided from the
//!   same seeds under AddressSanitizer, with a 2 GB memory limit: a crash, a panic, an
//!   over-allocation or a broken mesh invariant fails the test. Needs a nightly toolchain and
//!   cargo-fuzz (`scripts/install-deps.sh --tests` installs them).
//! - `check` and `repair`, CGAL and OpenVDB behind them: the `check_repair` target
//!   (`fuzz/cgal`) replayed on its corpus and random mutations of it, built with this crate: a
//!   sample of the corpus and a few seconds of mutations in the main tier, the rest of it and
//!   20 s in the long tier.

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

/// What every reader's output must be, as the fuzz targets assert (`fuzz/src/lib.rs`): indices
/// name vertices, coordinates are finite, a normal per facet, and welding keeps all of that.
fn check_parsed(data: &[u8], format: latvox::io::Format) {
    if let Ok(p) = latvox::io::parse(data, format) {
        let m = p.mesh;
        let nv = m.vertex_count();
        assert!(m.indices.len() % 3 == 0 && m.positions.len() % 3 == 0);
        assert!(m.indices.iter().all(|&i| (i as usize) < nv));
        assert!(m.positions.iter().all(|x| x.is_finite()));
        if let Some(n) = &p.normals {
            assert_eq!(n.len(), m.triangle_count());
        }
        let mut welded = m.clone();
        latvox::io::weld::weld_tolerance(&mut welded, 1e-3);
        assert_eq!(welded.indices.len(), m.indices.len());
        assert!(welded
            .indices
            .iter()
            .all(|&i| (i as usize) < welded.vertex_count()));
    }
}

/// `data` with one to four random changes: bytes set, flipped, inserted or dropped, or its
/// tail replaced by another entry's.
fn mutate(rng: &mut common::Rng, data: &mut Vec<u8>, corpus: &[Vec<u8>]) {
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
                let other = &corpus[rng.below(corpus.len() as u64) as usize];
                let from = rng.below(other.len().max(1) as u64) as usize;
                data.truncate(at);
                data.extend_from_slice(&other[from.min(other.len())..]);
            }
        }
    }
}

#[test]
fn every_reader_takes_its_seeds_and_their_mutations() {
    use latvox::io::Format;
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus");
    let formats = [
        ("stl", Format::Stl),
        ("obj", Format::Obj),
        ("off", Format::Off),
        ("ply", Format::Ply),
        ("threemf", Format::ThreeMf),
    ];
    let mut rng = common::Rng(0x5eed);
    for (target, format) in formats {
        let corpus: Vec<Vec<u8>> = std::fs::read_dir(root.join(target))
            .unwrap()
            .map(|e| std::fs::read(e.unwrap().path()).unwrap())
            .collect();
        assert!(!corpus.is_empty(), "no seed corpus for {target}");
        for data in &corpus {
            check_parsed(data, format);
        }
        let start = std::time::Instant::now();
        while start.elapsed().as_secs_f64() < 1.0 {
            let mut data = corpus[rng.below(corpus.len() as u64) as usize].clone();
            mutate(&mut rng, &mut data, &corpus);
            let r = std::panic::catch_unwind(|| check_parsed(&data, format));
            assert!(r.is_ok(), "{target} reader fails on {data:?}");
        }
    }
}

#[test]
#[ignore = "long: cargo fuzz builds a sanitized project and fuzzes each reader for 12 s"]
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

/// The `check_repair` fuzz target (`fuzz/cgal`: meshes with corners on a coarse grid through
/// check, CGAL's checks, repair and `repair --solid`) on its committed corpus (every `stride`-th
/// entry, or with `rest` every other one), then on random mutations of it (bytes changed,
/// inserted, dropped, entries spliced) for
/// `seconds`: never a panic, an abort or a backend error, every solid made valid by latvox's check
/// and CGAL's. Coverage-guided runs of the same target: `cargo +nightly fuzz run --fuzz-dir
/// fuzz/cgal -s none check_repair` (building the C++ bridges again takes ten minutes, so `cargo
/// test` replays).
fn check_and_repair_replay(stride: usize, rest: bool, seconds: f64) {
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
    let mut replayed = 0;
    for (i, (name, data)) in corpus.iter().enumerate() {
        if (i % stride == 0) == rest {
            continue;
        }
        replayed += 1;
        let r = std::panic::catch_unwind(|| check_repair::check_repair(data));
        assert!(r.is_ok(), "corpus entry {name} fails");
    }
    let entries: Vec<Vec<u8>> = corpus.iter().map(|(_, d)| d.clone()).collect();
    let mut rng = common::Rng(0xc6a1);
    let start = std::time::Instant::now();
    let mut runs = 0;
    while start.elapsed().as_secs_f64() < seconds {
        let mut data = entries[rng.below(entries.len() as u64) as usize].clone();
        mutate(&mut rng, &mut data, &entries);
        let r = std::panic::catch_unwind(|| check_repair::check_repair(&data));
        assert!(r.is_ok(), "mutated input fails: {data:?}");
        runs += 1;
    }
    eprintln!(
        "check and repair: {replayed} of {} corpus entries, {runs} mutations in {seconds} s",
        corpus.len()
    );
}

#[test]
fn check_and_repair_hold_on_a_sample_of_the_fuzz_corpus_and_its_mutations() {
    check_and_repair_replay(16, false, 3.0);
}

#[test]
#[ignore = "long: the rest of the check-and-repair corpus and 20 s of its mutations"]
fn check_and_repair_hold_on_the_fuzz_corpus_and_its_mutations() {
    check_and_repair_replay(16, true, 20.0);
}
