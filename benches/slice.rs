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
//! - without a mesh: a 50 mm cube with a 1 mm skin filled with a gyroid (cells of 5 mm,
//!   density 0.2) sliced from its part file into 1,000 PNG masks at 50 µm pixels, beside
//!   `latvox fill` meshing it and the mesh sliced to the same masks.
//!
//! Run: `cargo bench --bench slice -- --runs 3` (`--quick` skips the 9.5 M-triangle part;
//! `--implicit` runs only the part-file case).

#[path = "../tests/it/common/child.rs"]
mod child;
mod support;

use child::run_measured;
use std::path::Path;
use std::process::{Command, Stdio};
use support::{latvox, median, runs_arg};

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
    let runs = runs_arg(&args, 3);
    let quick = args.iter().any(|a| a == "--quick");
    let implicit_only = args.iter().any(|a| a == "--implicit");
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
    if implicit_only {
        parts.clear();
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
    let lin: &[(u32, &str)] = if implicit_only {
        &[]
    } else {
        &[(1, "4,4,2"), (4, "8,8,2"), (16, "16,16,2")]
    };
    for &(k, cells) in lin {
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
    // Without a mesh: the filled cube's part file sliced to 1,000 masks; then meshed and sliced.
    let cube: Vec<u8> = {
        let (lo, hi) = ([0.0f32; 3], [50.0f32; 3]);
        let m = latvox::geom::Mesh::cuboid(lo, hi);
        let mut b = vec![0u8; 80];
        b.extend((m.triangle_count() as u32).to_le_bytes());
        for t in m.indices.chunks_exact(3) {
            b.extend([0u8; 12]);
            for &v in t {
                for a in 0..3 {
                    b.extend(m.positions[3 * v as usize + a].to_le_bytes());
                }
            }
            b.extend([0u8; 2]);
        }
        b
    };
    std::fs::write(d.join("cube.stl"), cube).unwrap();
    std::fs::write(
        d.join("cube.toml"),
        "command = \"fill\"\ninput = \"cube.stl\"\nskin = 1\nlattice = \"gyroid\"\ncell-size = 5\ndensity = 0.2\n",
    )
    .unwrap();
    let masks = ["-o", "masks/", "--pixel", "0.05", "--layer", "0.05"];
    let with = |head: &[&'static str]| -> Vec<String> {
        head.iter()
            .chain(masks.iter())
            .map(|s| s.to_string())
            .collect()
    };
    let implicit = with(&["-q", "slice", "cube.toml"]);
    let (s, m) = measure(1, || {
        latvox(d, &implicit.iter().map(String::as_str).collect::<Vec<_>>())
    });
    println!(
        "{:<48} {s:>9.2} {m:>6.0}   (1 run)",
        "filled 50 mm cube: part file → 1,000 PNG masks"
    );
    let (s1, m1) = measure(1, || {
        latvox(
            d,
            &["-q", "fill", "--part", "cube.toml", "-o", "cube-filled.stl"],
        )
    });
    let meshed = with(&["-q", "slice", "cube-filled.stl"]);
    let (s2, m2) = measure(1, || {
        latvox(d, &meshed.iter().map(String::as_str).collect::<Vec<_>>())
    });
    println!(
        "{:<48} {:>9.2} {:>6.0}   (fill {s1:.2} s + slice {s2:.2} s, 1 run)",
        "filled 50 mm cube: meshed, then 1,000 PNG masks",
        s1 + s2,
        m1.max(m2)
    );
}
