//! Graded TPMS lattices beside uniform ones: 10×10×10 gyroid net cells of 5 mm at 32 voxels per
//! cell, made by the library's tpms job (what `latvox tpms` runs) and streamed through STL records
//! that are dropped, fully verified (self-intersections included):
//!
//! - `uniform-instanced`: density 0.25, its cells copied from a meshed template;
//! - `uniform-whole`: density 0.25 meshed whole (`--no-instancing`), as a graded part must be;
//! - `graded-whole`: graded 0.1 → 0.4 along z (mean 0.25), meshed whole, every cell measured;
//! - `graded-tiled`: the same within a 500 MB budget, meshed tile by tile.
//!
//! Each configuration runs `--runs` times (3 by default), each run in a process of its own (so
//! that each peak resident memory is its own). Printed per configuration: median, min and max
//! wall time, peak RSS, triangles, meshings and the largest whole-cell density error.
//!
//! Run: `cargo bench --bench graded` (`-- --runs N`).

use latvox::field::density::DensityField;
use latvox::field::Domain;
use latvox::mesh::graded::Grading;
use latvox::progress::Progress;
use latvox::tpms::{Structure, Surface, TpmsJob};
use std::sync::Arc;
use std::time::Instant;
mod support;
use support::{peak_rss_mb, DiscardedStl};

const CONFIGS: [&str; 4] = [
    "uniform-instanced",
    "uniform-whole",
    "graded-whole",
    "graded-tiled",
];

/// Runs one configuration in this process; prints `wall rss triangles meshings error`.
fn one(config: &str) {
    let domain = Domain::from_cells([10; 3], [5.0; 3], [0.0; 3]).unwrap();
    let graded = config.starts_with("graded");
    let job = TpmsJob {
        surface: Surface::Gyroid,
        structure: Structure::Net,
        density: 0.25,
        domain,
        resolution: 32,
        adaptivity: 0.0,
        tolerance: None,
        allow_islands: false,
        auto_resolution: true,
        verify: latvox::verify::Verify::Full,
        instancing: config == "uniform-instanced",
        tile: None,
        memory: (config == "graded-tiled").then_some(500 << 20),
        keep_fragments: false,
        grading: graded.then(|| Grading {
            field: Arc::new(DensityField::grade("z:0.1:0.4", &domain.bounds()).unwrap()),
            clamp: false,
        }),
        blend: None,
        cell_map: None,
    };
    let t = Instant::now();
    let mut sink = DiscardedStl::default();
    let r = job.run_into(&Progress::hidden(), &mut sink).unwrap();
    assert!(r.verdict().is_valid_solid(), "{config}: {:?}", r.verdict());
    let (meshings, error) = match &r.grading {
        Some(g) => (g.meshings, g.max_cell_error),
        None => (
            r.level_search.tried.len() as u32,
            r.part.density_error.unwrap().abs(),
        ),
    };
    println!(
        "{:.3} {:.0} {} {meshings} {error:.5}",
        t.elapsed().as_secs_f64(),
        peak_rss_mb(),
        sink.triangles
    );
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if let Some(i) = args.iter().position(|a| a == "--one") {
        one(&args[i + 1]);
        return;
    }
    let runs: usize = args
        .iter()
        .position(|a| a == "--runs")
        .map_or(3, |i| args[i + 1].parse().expect("--runs N"));
    let me = std::env::current_exe().unwrap();
    println!(
        "10×10×10 gyroid net cells of 5 mm, 32 voxels per cell, verified in full; {runs} runs each"
    );
    println!(
        "{:<18} {:>9} {:>9} {:>9} {:>9} {:>11} {:>8} {:>10}",
        "configuration", "median s", "min s", "max s", "peak MB", "triangles", "meshings", "error"
    );
    let mut medians = Vec::new();
    for config in CONFIGS {
        let mut walls = Vec::new();
        let mut last = Vec::new();
        for _ in 0..runs {
            let out = std::process::Command::new(&me)
                .args(["--one", config])
                .output()
                .unwrap();
            assert!(
                out.status.success(),
                "{}",
                String::from_utf8_lossy(&out.stderr)
            );
            let line = String::from_utf8_lossy(&out.stdout).trim().to_string();
            last = line.split(' ').map(str::to_string).collect();
            walls.push(last[0].parse::<f64>().unwrap());
        }
        walls.sort_by(f64::total_cmp);
        let median = walls[walls.len() / 2];
        medians.push(median);
        println!(
            "{config:<18} {median:>9.2} {:>9.2} {:>9.2} {:>9} {:>11} {:>8} {:>10}",
            walls[0],
            walls[walls.len() - 1],
            last[1],
            last[2],
            last[3],
            last[4]
        );
    }
    println!(
        "graded-whole / uniform-whole: {:.2}×; graded-whole / uniform-instanced: {:.2}×",
        medians[2] / medians[1],
        medians[2] / medians[0]
    );
}
