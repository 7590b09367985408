//! Verification benchmarks, with the figures quoted in README ("Verification").
//!
//! Parts meshed whole (`--no-instancing`), so that the whole part must be verified:
//! 1. an 8×8×8 Schwarz-D net of 6 mm cells at 32 voxels per cell (5.9 M triangles);
//! 2. a 10×10×10 gyroid net of 5 mm cells at 32 voxels per cell (9.5 M triangles);
//! 3. a 3×3×3 Schwarz-D sheet of 6 mm cells at 32 voxels per cell.
//!
//! For each, the `latvox tpms` command as a user runs it (default `--verify full`): the job's
//! own timings from its report, medians of `--runs` runs — verification beside sample + mesh +
//! snap, and the whole job. Then, on the STL it wrote, read back in a child process each:
//! latvox's verification (fan checks and the exact self-intersection search) and CGAL's global
//! test (its Surface_mesh built from the triangles, closedness, orientation, volume, and
//! `does_self_intersect` in parallel), each child's time and peak memory (reading the file
//! included, the same for both); the two verdicts must agree.
//!
//! Run: `cargo bench --bench verify` (`-- --runs N`, `-- --parts 1,3`).

use latvox::io::ReadOptions;
use latvox::progress::Progress;
use latvox::verify::{verify, Verify};
use std::path::Path;
use std::process::Command;
use std::time::Instant;

mod support;

fn arg<'a>(args: &'a [String], name: &str, default: &'a str) -> &'a str {
    args.iter()
        .position(|a| a == name)
        .map_or(default, |i| args[i + 1].as_str())
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

/// Child mode: read `file`, verify it the way `how` names, print one JSON line.
fn child(how: &str, file: &Path) {
    let mesh = latvox::io::read(file, &ReadOptions::default())
        .expect("reading the part")
        .mesh;
    let t = Instant::now();
    let v = match how {
        "latvox" => verify(&mesh, Verify::Full, &Progress::hidden()),
        _ => verify(&mesh, Verify::Cgal, &Progress::hidden()),
    }
    .expect("verifying");
    let seconds = t.elapsed().as_secs_f64();
    println!(
        "{}",
        serde_json::json!({
            "seconds": seconds,
            "peak_mb": support::peak_rss_mb(),
            "valid": v.verdict().is_valid_solid(),
            "closed": v.closed,
            "manifold": v.manifold,
            "outward": v.outward,
            "self_intersecting": v.self_intersecting,
            "volume": v.volume,
            "triangles": mesh.triangle_count(),
        })
    );
}

fn run_child(how: &str, file: &Path) -> serde_json::Value {
    let exe = std::env::current_exe().unwrap();
    let out = Command::new(exe)
        .args(["--child", how])
        .arg(file)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{how}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if let Some(i) = args.iter().position(|a| a == "--child") {
        child(&args[i + 1], Path::new(&args[i + 2]));
        return;
    }
    let runs: usize = arg(&args, "--runs", "3").parse().unwrap();
    let parts: Vec<usize> = arg(&args, "--parts", "1,2,3")
        .split(',')
        .map(|s| s.parse().unwrap())
        .collect();
    let dir = tempfile::tempdir().unwrap();
    let exe = env!("CARGO_BIN_EXE_latvox");
    let all = [
        ("8×8×8 D net, 6 mm cells", ["d", "net", "8", "6"]),
        (
            "10×10×10 gyroid net, 5 mm cells",
            ["gyroid", "net", "10", "5"],
        ),
        ("3×3×3 D sheet, 6 mm cells", ["d", "sheet", "3", "6"]),
    ];
    println!("Verification: parts meshed whole at 32 voxels per cell, density 0.3; medians of {runs} runs");
    for &p in &parts {
        let (name, [ty, st, cells, size]) = all[p - 1];
        let stl = dir.path().join(format!("part{p}.stl"));
        let report = dir.path().join(format!("part{p}.json"));
        let mut t = [(); 4].map(|_| Vec::new());
        for _ in 0..runs {
            let out = Command::new(exe)
                .args([
                    "tpms",
                    "-q",
                    "--type",
                    ty,
                    "--structure",
                    st,
                    "--density",
                    "0.3",
                ])
                .args(["--cells", cells, "--cell-size", size, "--no-instancing"])
                .arg("-o")
                .arg(&stl)
                .arg("--report")
                .arg(&report)
                .output()
                .unwrap();
            assert_eq!(out.status.code(), Some(0), "{name}");
            let r: serde_json::Value =
                serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
            let s = |k: &str| r["timings"][k].as_f64().unwrap();
            t[0].push(s("sample") + s("mesh") + s("snap"));
            t[1].push(s("verify"));
            t[2].push(s("total"));
            t[3].push(r["triangles"].as_f64().unwrap());
        }
        let [make, ver, total, tris] = t.map(median);
        println!("\n{p}. {name}: {tris:.0} triangles");
        println!(
            "   latvox tpms: sample+mesh+snap {make:.2} s, verify {ver:.2} s ({:.2}×), whole job {total:.2} s",
            ver / make
        );
        let ours: Vec<serde_json::Value> = (0..runs).map(|_| run_child("latvox", &stl)).collect();
        let theirs = run_child("cgal", &stl);
        let secs = median(
            ours.iter()
                .map(|o| o["seconds"].as_f64().unwrap())
                .collect(),
        );
        let mb = median(
            ours.iter()
                .map(|o| o["peak_mb"].as_f64().unwrap())
                .collect(),
        );
        let o = &ours[0];
        println!(
            "   on the written STL: latvox {secs:.2} s, peak {mb:.0} MB   CGAL {:.2} s, peak {:.0} MB   ({:.1}× faster)",
            theirs["seconds"].as_f64().unwrap(),
            theirs["peak_mb"].as_f64().unwrap(),
            theirs["seconds"].as_f64().unwrap() / secs
        );
        for k in [
            "valid",
            "closed",
            "manifold",
            "outward",
            "self_intersecting",
        ] {
            assert_eq!(o[k], theirs[k], "{name}: {k} differs");
        }
        let (v, w) = (
            o["volume"].as_f64().unwrap(),
            theirs["volume"].as_f64().unwrap(),
        );
        assert!((v - w).abs() <= 1e-9 * w.abs());
        println!(
            "   same verdict: valid solid {} (closed, manifold, outward, no self-intersection); volume {v:.3} mm³ both",
            o["valid"]
        );
    }
}
