//! Voronoi strut foams beside the peer a user of mesh booleans would write: the same seeds,
//! the same strut radius, SciPy's Voronoi edges as capsules unioned by manifold3d
//! (`benches/peers/manifold_voronoi.py`). For boxes of 20 and 30 mm with cells of 3 mm: wall
//! time, peak memory and triangles of each (one run each unless `-- --runs N`), and whether
//! `latvox check` finds each output a closed, valid solid.
//!
//! Run: `cargo bench --bench voronoi`; `-- --scale N` for the memory of a periodic net of
//! N×N×N foam cells (see [`scale`]).

use latvox::field::Aabb;
use latvox::mesh::pipeline::Options;
use latvox::progress::Progress;
use latvox::voronoi::{Seeding, Sizing, Spacing, Structure, VoronoiJob};
use std::process::Command;
use std::time::Instant;
mod support;
use support::{median, peak_rss_mb, runs_arg, time_and_peak, DiscardedStl};

/// `--scale N`: a periodic Voronoi net of N×N×N foam cells of 3 mm (a box of 3N mm), its
/// repeating cell 12 mm (some 64 seeds), struts of radius 0.3 mm, 10 voxels per spacing (40 per repeating cell), copied
/// from a template and streamed through STL records that are dropped; prints the time and the
/// process's peak resident memory. Run once per size, each in its own process, to compare peaks.
fn scale(n: u32) {
    let t = Instant::now();
    let edge = 3.0 * n as f64;
    let job = VoronoiJob {
        structure: Structure::Net,
        seeding: Seeding::Poisson {
            spacing: Spacing::Uniform(3.0),
            seed: 1,
            regularity: 0.0,
        },
        sizing: Sizing::Level(0.3),
        bounds: Aabb {
            min: [0.0; 3],
            max: [edge; 3],
        },
        resolution: 10,
        period: Some(12.0),
        pores: 0.0,
        auto_resolution: false,
        grading: None,
        options: Options {
            verify: latvox::verify::Verify::Full,
            instancing: true,
            ..Default::default()
        },
    };
    let mut sink = DiscardedStl::default();
    let r = job.run_into(&Progress::hidden(), &mut sink).unwrap();
    println!(
        "{n}x{n}x{n} foam cells ({edge} mm box, {} seeds a repeating cell of 12 mm, {:?} cells copied from a template of {:?}), radius 0.3 mm, 10 voxels per spacing: {} triangles ({:.1} GB of STL, dropped), density {:.4}, valid {}, {:.1} s, peak RSS {:.0} MB",
        r.foam.cells,
        r.part.instancing.as_ref().map(|i| i.part_cells),
        r.part.instancing.as_ref().map(|i| i.template_cells),
        sink.triangles,
        (84 + 50 * sink.triangles) as f64 / 1e9,
        r.part.achieved_density,
        r.verdict().is_valid_solid(),
        t.elapsed().as_secs_f64(),
        peak_rss_mb()
    );
}

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
    if let Some(i) = args.iter().position(|a| a == "--scale") {
        scale(args[i + 1].parse().expect("--scale N"));
        return;
    }
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
