//! TPMS benchmarks, with the figures quoted in README.
//!
//! 1. The main job at scale: 10×10×10 gyroid cells, net, density 0.30, 32 voxels per cell (a
//!    320³ grid), run as the `latvox` binary writing its STL: wall time and peak resident memory
//!    (the child's own `ru_maxrss`, from wait4), median of several runs.
//! 2. Scale: 10³ and 30³ gyroid cells at 16 voxels per cell, instanced (STL and 3MF), meshed
//!    whole, and in tiles of a small memory budget: wall time and peak resident memory.
//! 3. Calibration alone, for every type and structure at density 0.30, in a fresh process each
//!    (so the per-process sample tables are built inside the timing, as a CLI run pays them).
//! 4. The level search on parts that are not whole numbers of cells (the density promise): for
//!    each, the meshings the search needed, where it measured, the achieved density, and the
//!    wall time.
//!
//! Run: `cargo bench --bench tpms` (add `-- --runs N` to change the repeat count, `-- --section K`
//! to run section K alone).

use std::path::Path;
use std::process::Command;

#[path = "../tests/it/common/child.rs"]
mod child;

/// (wall seconds, peak RSS in MB, exit code) of one run of `cmd`.
fn run_measured(cmd: &mut Command) -> (f64, f64, i32) {
    let m = child::run_measured(cmd);
    (m.seconds, m.peak_rss_mb(), m.code)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

/// Runs `latvox ARGS -o out --report out.json` `runs` times: median wall time (s), median peak
/// RSS (MB), and the last run's report.
fn measure(exe: &str, args: &[&str], out: &Path, runs: usize) -> (f64, f64, serde_json::Value) {
    let report = out.with_extension("json");
    let mut walls = Vec::new();
    let mut rss = Vec::new();
    for _ in 0..runs {
        let mut c = Command::new(exe);
        c.args(args)
            .arg("-o")
            .arg(out)
            .arg("--report")
            .arg(&report)
            .stdout(std::process::Stdio::null());
        let (s, m, code) = run_measured(&mut c);
        assert_eq!(code, 0, "latvox {} failed", args.join(" "));
        let rep: serde_json::Value =
            serde_json::from_slice(&std::fs::read(&report).unwrap()).unwrap();
        println!(
            "    run: wall {s:.2} s, peak RSS {m:.0} MB, write stage {:.2} s",
            rep["timings"]["write"].as_f64().unwrap_or(f64::NAN)
        );
        walls.push(s);
        rss.push(m);
    }
    let rep = serde_json::from_slice(&std::fs::read(&report).unwrap()).unwrap();
    (median(walls), median(rss), rep)
}

/// The written part in one line: triangles, file size, achieved density.
fn part(rep: &serde_json::Value, out: &Path) -> String {
    format!(
        "{} triangles, file {:.0} MB, achieved density {:.5}",
        rep["triangles"],
        std::fs::metadata(out).unwrap().len() as f64 / 1e6,
        rep["achieved_density"].as_f64().unwrap()
    )
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let runs = args
        .iter()
        .position(|a| a == "--runs")
        .and_then(|i| args.get(i + 1))
        .and_then(|s| s.parse().ok())
        .unwrap_or(3usize);
    let exe = env!("CARGO_BIN_EXE_latvox");
    let dir = tempfile::tempdir().unwrap();
    let threads = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1);
    println!("machine: {threads} threads; {runs} runs per case, median reported");
    let section = args
        .iter()
        .position(|a| a == "--section")
        .and_then(|i| args.get(i + 1))
        .and_then(|s| s.parse::<u32>().ok());
    let run_section = |k: u32| section.is_none_or(|s| s == k);

    let gyroid = [
        "tpms",
        "-t",
        "gyroid",
        "--structure",
        "net",
        "-d",
        "0.3",
        "--quiet",
    ];
    if run_section(1) {
        for (label, extra) in [
            ("full pipeline (checks incl. self-intersection)", vec![]),
            (
                "without the self-intersection test",
                vec!["--verify", "fast"],
            ),
        ] {
            let mut args = gyroid.to_vec();
            args.extend(["--cells", "10", "--cell-size", "5", "--resolution", "32"]);
            args.extend(extra);
            let out = dir.path().join("g10.stl");
            let (wall, rss, rep) = measure(exe, &args, &out, runs);
            println!(
                "gyroid net 0.30, 10x10x10 cells, 320^3 grid, {label}: wall {wall:.2} s (median), peak RSS {rss:.0} MB; {}",
                part(&rep, &out)
            );
            println!("  stage times of the last run (s): {}", rep["timings"]);
        }
    }
    if run_section(2) {
        println!("scale: gyroid net 0.30, 16 voxels per cell, 5 mm cells, STL or 3MF written:");
        for (label, cells, file, extra) in [
            ("10x10x10 cells, instanced, STL", "10", "s.stl", vec![]),
            ("30x30x30 cells, instanced, STL", "30", "s.stl", vec![]),
            ("30x30x30 cells, instanced, 3MF", "30", "s.3mf", vec![]),
            (
                "10x10x10 cells, whole part meshed at once",
                "10",
                "s.stl",
                vec!["--no-instancing"],
            ),
            (
                "10x10x10 cells, tiles for a 64 MB budget",
                "10",
                "s.stl",
                vec!["--no-instancing", "--memory", "64M"],
            ),
        ] {
            let mut args = gyroid.to_vec();
            args.extend(["--cells", cells, "--cell-size", "5", "--resolution", "16"]);
            args.extend(extra);
            let out = dir.path().join(file);
            let (wall, rss, rep) = measure(exe, &args, &out, runs);
            println!(
                "  {label}: wall {wall:.2} s, peak RSS {rss:.0} MB (medians); {}",
                part(&rep, &out)
            );
            let _ = std::fs::remove_file(&out);
        }
    }
    if run_section(3) {
        println!(
            "calibration alone (density 0.30, 32 voxels per cell, 3x3x3 cells, fresh process):"
        );
        for t in ["p", "gyroid", "d", "iwp", "s", "frd", "neovius"] {
            for st in ["net", "sheet"] {
                let mut cal = Vec::new();
                let report = dir.path().join("c.json");
                for _ in 0..runs {
                    let mut c = Command::new(exe);
                    c.args(["tpms", "--type", t, "--structure", st, "--density", "0.3"])
                        .args([
                            "--cells",
                            "3",
                            "--cell-size",
                            "5",
                            "--quiet",
                            "--allow-islands",
                        ])
                        .arg("-o")
                        .arg(dir.path().join("c.stl"))
                        .arg("--report")
                        .arg(&report)
                        .stdout(std::process::Stdio::null())
                        .stderr(std::process::Stdio::null());
                    let (_, _, code) = run_measured(&mut c);
                    assert!(code == 0 || code == 1, "latvox failed on {t} {st}");
                    let rep: serde_json::Value =
                        serde_json::from_slice(&std::fs::read(&report).unwrap()).unwrap();
                    cal.push(rep["timings"]["calibrate"].as_f64().unwrap() * 1e3);
                }
                println!("  {t:8} {st:6} calibration {:.1} ms (median)", median(cal));
            }
        }
    }
    if run_section(4) {
        println!("level search on parts of partial cells (32 voxels per cell unless given):");
        for case in [
            "-t iwp -d 0.448 --size 8.46,11.79,9.0 --cell-size 4.9",
            "-t p -d 0.47 --size 12.23,8.97,11.58 --cell-size 5.26",
            "-t n -d 0.477 --size 7.96,6.3,9.17 --cell-size 5.01",
            "-t g -d 0.3 --size 23.7,17.3,9.1 --cell-size 5",
            "-t g -d 0.3 --cells 2 --cell-size 5 --resolution 12",
            "-t g -d 0.3 --cells 4 --cell-size 5",
        ] {
            let mut args = vec!["tpms", "--quiet"];
            args.extend(case.split(' '));
            let out = dir.path().join("l.stl");
            let (wall, _, rep) = measure(exe, &args, &out, runs);
            let search = &rep["level_search"];
            println!(
                "  {case}: {} meshing(s) on the {}, density {:.4}, wall {wall:.2} s (median)",
                search["tried"].as_array().map_or(0, |t| t.len()),
                search["measured_on"].as_str().unwrap_or("?"),
                rep["achieved_density"].as_f64().unwrap_or(f64::NAN),
            );
        }
    }
}
