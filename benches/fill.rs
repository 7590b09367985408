//! A part filled by the library's fill job (what `latvox fill` runs): a torus `--size` mm
//! across (radii 0.35 and 0.15 of it; 512 × 256 facets), a 1 mm skin, a gyroid net at density
//! 0.2 of the core in cells of `--cell` mm, on voxels of `--voxel` mm, meshed within the
//! `--memory` budget (tiles when the part's grid would not fit) and streamed through STL records
//! that are dropped. Printed: wall time and stage times, meshings, the fill's density, the
//! triangles, the distance grid's memory and the process's peak resident memory.
//!
//! Run: `cargo bench --bench fill -- --size 100 --cell 2 --voxel 0.1 --memory 2G`.

use latvox::fill::{FillJob, Infilling};
use latvox::mesh::pipeline::Options;
use latvox::progress::Progress;
use latvox::tpms::{Structure, Surface};
use std::time::Instant;
mod support;
use support::{peak_rss_mb, torus, DiscardedStl};

fn arg(args: &[String], name: &str, default: &str) -> String {
    args.iter()
        .position(|a| a == name)
        .map_or(default.to_string(), |i| args[i + 1].clone())
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let size: f64 = arg(&args, "--size", "40").parse().unwrap();
    let cell: f64 = arg(&args, "--cell", "2").parse().unwrap();
    let voxel: f64 = arg(&args, "--voxel", "0.1").parse().unwrap();
    let memory: u64 = arg(&args, "--memory", "2048").parse::<u64>().unwrap() << 20;
    let resolution = (cell / voxel).round() as u32;
    let t = Instant::now();
    let job = FillJob {
        grading: None,
        part: torus(0.35 * size, 0.15 * size, 512, 256),
        part_name: format!("a torus {size} mm across"),
        keep: Vec::new(),
        skin: 1.0,
        lattice: Infilling::Tpms {
            surface: Surface::Gyroid,
            structure: Structure::Net,
        },
        lattice_name: "gyroid net".into(),
        cell: [cell; 3],
        density: 0.2,
        blend: 0.0,
        drain: None,
        resolution,
        auto_resolution: false,
        options: Options {
            verify: latvox::verify::Verify::Full,
            instancing: false,
            memory: Some(memory),
            ..Default::default()
        },
    };
    let mut sink = DiscardedStl::default();
    let r = job.run_into(&Progress::hidden(), &mut sink).unwrap();
    let p = &r.part;
    let tm = &p.timings;
    let cells = p.bounds.volume() / cell.powi(3);
    println!(
        "torus {size} mm across ({cells:.0} cells of {cell} mm in its box), skin 1 mm, gyroid net 0.2, voxel {:.4} mm, memory budget {} MB: {} meshings, fill density {:.4}, {} triangles ({:.1} GB of STL, dropped), {}, {} fragments removed, one piece {:?}, valid {}: wall {:.1} s (sample {:.1}, mesh {:.1}, verify {:.1}, write {:.1}), distance grid {:.0} MB, peak RSS {:.0} MB",
        r.voxel_size,
        memory >> 20,
        r.level_search.tried.len() + 2,
        p.achieved_density,
        sink.triangles,
        (84 + 50 * sink.triangles) as f64 / 1e9,
        match p.tiling {
            Some(t) => format!("{} tiles of {} voxels", t.tiles, t.tile_samples),
            None => "whole".to_string(),
        },
        p.fragments.count,
        p.one_piece,
        r.verdict().is_valid_solid(),
        t.elapsed().as_secs_f64(),
        tm.sample,
        tm.mesh,
        tm.verify,
        tm.write,
        r.distance_grid_bytes as f64 / 1e6,
        peak_rss_mb()
    );
}
