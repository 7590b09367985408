//! Strut lattices through the library's pipeline (the `latvox strut` command is still to come):
//! each built-in cell in 10×10×10 cells of 5 mm at density 0.2, 32 voxels per cell, its radius
//! found on a template of its cells, the part copied from the template into a binary STL, with
//! CGAL's checks (self-intersection included). Printed: wall time in this process, meshings of
//! the search, achieved density, triangles, and the process's peak resident memory so far.
//!
//! Run: `cargo bench --bench strut` (add `-- CELL` to run one cell).

use latvox::field::Aabb;
use latvox::io::sink::MeshFile;
use latvox::mesh::pipeline::{self, Family, Options, Route};
use latvox::progress::Progress;
use latvox::strut::{StrutFamily, StrutLattice, UnitCell};
use std::sync::Arc;
use std::time::Instant;

/// The process's peak resident memory, MB (`VmHWM`).
fn peak_rss_mb() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse::<f64>().ok())
        })
        .map_or(f64::NAN, |kb| kb / 1024.0)
}

fn main() {
    let only: Option<String> = std::env::args().skip(1).find(|a| !a.starts_with('-'));
    let dir = tempfile::tempdir().unwrap();
    let (cells, cell_size, resolution, target) = (10.0, 5.0, 32.0, 0.2);
    let voxel = cell_size / resolution;
    let bounds = Aabb {
        min: [0.0; 3],
        max: [cells * cell_size; 3],
    };
    let opts = Options {
        self_intersection: true,
        instancing: true,
        ..Default::default()
    };
    println!("10x10x10 cells of 5 mm, density 0.2, 32 voxels per cell, STL with CGAL's checks:");
    for name in latvox::strut::cell::BUILT_IN {
        if only.as_deref().is_some_and(|o| o != name) {
            continue;
        }
        let t = Instant::now();
        let family = StrutFamily::new(StrutLattice {
            cell: Arc::new(UnitCell::built_in(name).unwrap()),
            size: [cell_size; 3],
            radius: 0.0,
            blend: 0.0,
            bounds,
            phase: bounds.min,
        });
        let start = family.model_level(target);
        let route = Route::choose(&family.at(start), voxel, &opts);
        let solved = pipeline::solve(&family, target, start, voxel, route, &opts).unwrap();
        let (radius, meshings) = (solved.best.level, solved.tried.len());
        let out = dir.path().join("s.stl");
        let file = MeshFile::new(&out, false).unwrap();
        let mut sink = file.sink().unwrap();
        let written = pipeline::write(
            &family,
            solved.best,
            voxel,
            route,
            &opts,
            &Progress::hidden(),
            &mut sink,
        )
        .unwrap();
        sink.commit().unwrap();
        let wall = t.elapsed().as_secs_f64();
        println!(
            "  {name:8} radius {radius:.4} mm, {meshings} meshing(s), density {:.4}, {} triangles, valid {}: wall {wall:.2} s, peak RSS so far {:.0} MB",
            written.measures.volume / (cells * cell_size).powi(3),
            written.measures.triangles,
            written.checks.verdict().is_valid_solid(),
            peak_rss_mb()
        );
    }
}
