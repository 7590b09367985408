//! Voronoi strut foams beside the peer a user of mesh booleans would write: the same seeds,
//! the same strut radius, SciPy's Voronoi edges as capsules unioned by manifold3d
//! (`benches/peers/manifold_voronoi.py`). For boxes of 20 and 30 mm with cells of 3 mm: wall
//! time, peak memory and triangles of each (one run each unless `-- --runs N`), and whether
//! `latvox check` finds each output a closed, valid solid.
//!
//! Run: `cargo bench --bench voronoi`.

use std::process::Command;
mod support;
use support::{median, runs_arg, time_and_peak};

fn triangles(path: &std::path::Path) -> u64 {
    let d = std::fs::read(path).unwrap();
    u32::from_le_bytes(d[80..84].try_into().unwrap()) as u64
}

/// Whether `latvox check` finds the file a valid solid (exit 0).
fn valid(dir: &std::path::Path, file: &str) -> bool {
    Command::new(env!("CARGO_BIN_EXE_latvox"))
        .args(["check", file, "-q"])
        .current_dir(dir)
        .output()
        .unwrap()
        .status
        .success()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let runs = runs_arg(&args, 1);
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let peer = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/benches/peers/manifold_voronoi.py"
    );
    println!("Voronoi net, cells of 3 mm, struts of radius 0.3 mm, 12 voxels per spacing");
    println!("box     cells  tool        wall s  peak MB  triangles  valid");
    for size in ["20", "30"] {
        let seeds = format!("seeds{size}.csv");
        let ours = [
            "voronoi",
            "--spacing",
            "3",
            "--radius",
            "0.3",
            "--size",
            size,
            "-r",
            "12",
            "-q",
            "--seeds-out",
            &seeds,
            "-o",
            "ours.stl",
            "--report",
            "ours.json",
        ];
        let t: Vec<(f64, f64)> = (0..runs)
            .map(|_| time_and_peak(d, env!("CARGO_BIN_EXE_latvox"), &ours))
            .collect();
        let report: serde_json::Value =
            serde_json::from_slice(&std::fs::read(d.join("ours.json")).unwrap()).unwrap();
        let cells = report["foam"]["cells"].as_u64().unwrap();
        println!(
            "{size:>3} mm  {cells:>5}  latvox    {:>8.2}  {:>7.0}  {:>9}  {}",
            median(t.iter().map(|x| x.0).collect()),
            median(t.iter().map(|x| x.1).collect()),
            triangles(&d.join("ours.stl")),
            valid(d, "ours.stl")
        );
        let t: Vec<(f64, f64)> = (0..runs)
            .map(|_| time_and_peak(d, "python3", &[peer, &seeds, "0.3", size, "peer.stl"]))
            .collect();
        println!(
            "{size:>3} mm  {cells:>5}  manifold3d{:>8.2}  {:>7.0}  {:>9}  {}",
            median(t.iter().map(|x| x.0).collect()),
            median(t.iter().map(|x| x.1).collect()),
            triangles(&d.join("peer.stl")),
            valid(d, "peer.stl")
        );
    }
}
