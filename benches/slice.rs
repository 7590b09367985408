//! `latvox slice` as a user runs it, each case a process of its own (wall time and peak resident
//! memory from `wait4`, median of `--runs`), beside trimesh's `section_multiplane` (PyPI; load,
//! section and loop assembly, the same mesh and planes) and PrusaSlicer's SLA export (Debian's
//! `prusa-slicer --export-sla`, supports and pad off) where it is installed:
//!
//! - the 10×10×10 gyroid of `latvox tpms` (cells of 5 mm, 9.5 M triangles), 1,000 layers of
//!   0.05 mm; a 5×5×4-cell gyroid (0.95 M triangles), 1,000 layers of 0.02 mm — latvox writing the
//!   per-layer CSV (every loop chained and measured);
//! - the same two parts as SL1 archives (0.05 mm layers), latvox beside PrusaSlicer;
//! - linearity: gyroids of 4×4×2, 8×8×2 and 16×16×2 cells (1×, 4×, 16× the facets), 1,000
//!   layers each.
//!
//! Run: `cargo bench --bench slice -- --runs 3` (`--quick` skips the 9.5 M-triangle part).

#[path = "../tests/common/child.rs"]
mod child;
mod support;

use child::run_measured;
use std::path::Path;
use std::process::{Command, Stdio};
use support::latvox;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Median seconds and peak MB of `runs` runs of `make()`.
fn measure(runs: usize, mut make: impl FnMut() -> Command) -> (f64, f64) {
    let (mut s, mut m) = (Vec::new(), Vec::new());
    for _ in 0..runs {
        let r = run_measured(&mut make());
        assert_eq!(r.code, 0, "{:?} failed", make());
        s.push(r.seconds);
        m.push(r.peak_rss_mb());
    }
    (median(s), median(m))
}

fn have(cmd: &str) -> bool {
    Command::new("sh")
        .args(["-c", &format!("command -v {cmd}")])
        .stdout(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let runs: usize = args
        .iter()
        .position(|a| a == "--runs")
        .map_or(3, |i| args[i + 1].parse().unwrap());
    let quick = args.iter().any(|a| a == "--quick");
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let peer = Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/peers/trimesh_slice.py");
    let make = |name: &str, cells: &str| {
        let r = latvox(
            d,
            &[
                "-q",
                "tpms",
                "--type",
                "gyroid",
                "--cells",
                cells,
                "--cell-size",
                "5",
                "-o",
                name,
            ],
        )
        .status()
        .unwrap();
        assert!(r.success());
    };
    println!(
        "case                                              latvox s   MB   |  peer s (load + section + loops)   MB   ratio   ({runs} runs)"
    );
    let mut parts = vec![("g5x5x4.stl", "5,5,4", 20.0)];
    if !quick {
        parts.push(("g10.stl", "10", 50.0));
    }
    for &(name, cells, height) in &parts {
        make(name, cells);
        let dz = height / 1000.0;
        let z0 = format!("{}", 0.5 * dz);
        let layer = format!("{dz}");
        let (s, m) = measure(runs, || {
            latvox(
                d,
                &["-q", "slice", name, "--csv", "out.csv", "--layer", &layer],
            )
        });
        // trimesh: one run (minutes on the large part), its own timings written to a file.
        let (ps, pm) = measure(1, || {
            let mut c = Command::new("python3");
            c.arg(&peer)
                .args([name, &z0, &layer, "1000"])
                .current_dir(d)
                .stdout(std::fs::File::create(d.join("peer.json")).unwrap());
            c
        });
        let j: serde_json::Value =
            serde_json::from_slice(&std::fs::read(d.join("peer.json")).unwrap()).unwrap();
        println!(
            "{:<48} {s:>9.2} {m:>6.0}   | trimesh {ps:>6.2} ({:.1} + {:.1} + {:.1}, 1 run) {pm:>6.0}  {:>5.1}×",
            format!("{name}: 1,000 layers of {dz} mm, CSV"),
            j["load_s"].as_f64().unwrap(),
            j["section_s"].as_f64().unwrap(),
            j["loops_s"].as_f64().unwrap(),
            ps / s
        );
        let (s, m) = measure(runs, || {
            latvox(
                d,
                &["-q", "slice", name, "-o", "out.sl1", "--layer", "0.05"],
            )
        });
        if have("prusa-slicer") {
            let (ps, pm) = measure(1, || {
                let mut c = Command::new("prusa-slicer");
                c.args([
                    "--export-sla",
                    "--printer-technology",
                    "SLA",
                    "--layer-height",
                    "0.05",
                    "--no-supports-enable",
                    "--no-pad-enable",
                    "--dont-arrange",
                    "--output",
                    "prusa.sl1",
                    name,
                ])
                .current_dir(d)
                .stdout(Stdio::null())
                .stderr(Stdio::null());
                c
            });
            println!(
                "{:<48} {s:>9.2} {m:>6.0}   | PrusaSlicer {ps:>6.2} (1 run)       {pm:>6.0}  {:>5.1}×",
                format!("{name}: SL1, 0.05 mm layers"),
                ps / s
            );
        } else {
            println!(
                "{:<48} {s:>9.2} {m:>6.0}   | PrusaSlicer not installed",
                format!("{name}: SL1, 0.05 mm layers")
            );
        }
    }
    for (k, cells) in [(1, "4,4,2"), (4, "8,8,2"), (16, "16,16,2")] {
        let name = format!("lin{k}.stl");
        make(&name, cells);
        let (s, m) = measure(runs, || {
            latvox(
                d,
                &["-q", "slice", &name, "--csv", "out.csv", "--layer", "0.01"],
            )
        });
        println!(
            "{:<48} {s:>9.2} {m:>6.0}",
            format!("gyroid {cells} cells ({k}× facets): 1,000 layers")
        );
    }
}
