//! Batch benchmark, with the figures quoted in README: 40 small TPMS jobs (4 types × 5 densities
//! × net and sheet, 2×2×2 cells of 5 mm, then 1 cell, 16 voxels per cell, each with its JSON
//! report) run
//!
//! 1. as 40 `latvox tpms` invocations in a shell loop (`bash loop.sh`), and
//! 2. as one `latvox batch jobs.toml` (default workers: one per thread; and `--workers 1`),
//!
//! each in a fresh folder, wall time and CPU time (user + system) of the whole, median of several
//! runs; the ratio is loop time over batch time within each run (the three cases of a run follow
//! each other, so they share the machine's load), median over the runs. The parts of both are
//! compared (level and triangle count).
//!
//! Run: `cargo bench --bench batch` (add `-- --runs N` to change the repeat count).

use std::path::Path;
use std::process::Command;
use std::time::Instant;

const TYPES: [&str; 4] = ["gyroid", "d", "p", "iwp"];
const DENSITIES: [f64; 5] = [0.25, 0.3, 0.35, 0.4, 0.45];
const STRUCTURES: [&str; 2] = ["net", "sheet"];

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

/// User + system CPU seconds of all finished children (and theirs: the loop's latvox runs).
fn children_cpu() -> f64 {
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: getrusage fills the struct it is given.
    unsafe { libc::getrusage(libc::RUSAGE_CHILDREN, &mut u) };
    let t = |v: libc::timeval| v.tv_sec as f64 + v.tv_usec as f64 * 1e-6;
    t(u.ru_utime) + t(u.ru_stime)
}

/// Wall and CPU seconds of `cmd`, which must succeed.
fn timed(cmd: &mut Command) -> (f64, f64) {
    let cpu = children_cpu();
    let start = Instant::now();
    let out = cmd.output().expect("spawn");
    let secs = start.elapsed().as_secs_f64();
    let cpu = children_cpu() - cpu;
    assert!(
        out.status.success(),
        "{:?} failed: {}",
        cmd,
        String::from_utf8_lossy(&out.stderr)
    );
    (secs, cpu)
}

/// The machine is shared: its load is part of the result.
fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_default()
}

fn fresh(dir: &Path) {
    let _ = std::fs::remove_dir_all(dir);
    std::fs::create_dir_all(dir.join("out")).unwrap();
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let runs = args
        .iter()
        .position(|a| a == "--runs")
        .and_then(|i| args.get(i + 1))
        .and_then(|s| s.parse().ok())
        .unwrap_or(3usize);
    let tmp = tempfile::tempdir().unwrap();
    println!(
        "load average (1, 5, 15 min) at the start: {}",
        load_average()
    );
    for cells in [2, 1] {
        measure(tmp.path(), cells, runs);
    }
    println!("load average (1, 5, 15 min) at the end: {}", load_average());
}

/// The 40 jobs with `cells`³ cells each, as a loop and as a batch, `runs` times.
fn measure(tmp: &Path, cells: u32, runs: usize) {
    let exe = env!("CARGO_BIN_EXE_latvox");
    let threads = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1);
    let common = format!("cells = {cells}\ncell-size = 5\nresolution = 16\n");
    let jobs = format!(
        "[defaults]\n{common}\n[[sweep]]\ncommand = \"tpms\"\noutput = \"out/{{type}}-{{structure}}-{{density}}.stl\"\n\
         type = {TYPES:?}\nstructure = {STRUCTURES:?}\ndensity = {DENSITIES:?}\n"
    );
    let mut script = String::from("set -e\n");
    let mut names = Vec::new();
    for t in TYPES {
        for s in STRUCTURES {
            for d in DENSITIES {
                let name = format!("out/{t}-{s}-{d}");
                script.push_str(&format!(
                    "'{exe}' tpms --type {t} --structure {s} --density {d} --cells {cells} --cell-size 5 \
                     --resolution 16 -q -o {name}.stl --report {name}.json > /dev/null\n"
                ));
                names.push(name);
            }
        }
    }
    assert_eq!(names.len(), 40);

    let (loop_dir, batch_dir) = (tmp.join("loop"), tmp.join("batch"));
    // (label, wall times, CPU times)
    let mut cases: Vec<(String, Vec<f64>, Vec<f64>)> = vec![
        ("shell loop of 40 `latvox tpms`".into(), vec![], vec![]),
        (
            format!("`latvox batch`, {threads} workers (default)"),
            vec![],
            vec![],
        ),
        ("`latvox batch --workers 1`".into(), vec![], vec![]),
    ];
    for _ in 0..runs {
        fresh(&loop_dir);
        std::fs::write(loop_dir.join("loop.sh"), &script).unwrap();
        let (wall, cpu) = timed(Command::new("bash").arg("loop.sh").current_dir(&loop_dir));
        cases[0].1.push(wall);
        cases[0].2.push(cpu);
        for (k, extra) in [(1, vec![]), (2, vec!["--workers", "1"])] {
            fresh(&batch_dir);
            std::fs::write(batch_dir.join("jobs.toml"), &jobs).unwrap();
            let (wall, cpu) = timed(
                Command::new(exe)
                    .args(["batch", "jobs.toml", "-q"])
                    .args(&extra)
                    .current_dir(&batch_dir),
            );
            cases[k].1.push(wall);
            cases[k].2.push(cpu);
        }
    }
    // Same parts: same level (to its last bits, which vary with the order of parallel sums) and
    // triangle count in every report.
    for n in &names {
        let report = |d: &Path| -> serde_json::Value {
            serde_json::from_slice(&std::fs::read(d.join(format!("{n}.json"))).unwrap()).unwrap()
        };
        let (a, b) = (report(&loop_dir), report(&batch_dir));
        let level = |r: &serde_json::Value| r["level"].as_f64().unwrap();
        assert!(
            (level(&a) - level(&b)).abs() < 1e-9 && a["triangles"] == b["triangles"],
            "{n}: the loop and the batch made different parts"
        );
    }
    println!(
        "machine: {threads} threads; 40 TPMS jobs (4 types x 2 structures x 5 densities, {cells}x{cells}x{cells} cells, 16 voxels/cell, STL + JSON report each); {runs} runs, median wall time"
    );
    // The machine is shared: the three cases of a run follow each other closely, so the ratio
    // is taken within each run and its median reported.
    let loops = cases[0].1.clone();
    for (label, times, cpu) in &cases {
        let m = median(times.clone());
        let ratio = median(loops.iter().zip(times).map(|(l, t)| l / t).collect());
        println!(
            "{label:<40} wall {m:6.2} s   loop/this = {ratio:.2}x   CPU {:6.2} s   (wall of each run: {})",
            median(cpu.clone()),
            times
                .iter()
                .map(|t| format!("{t:.2}"))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
}
