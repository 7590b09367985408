//! Strut lattices made by the library's strut job (what `latvox strut` runs): each built-in cell in 10×10×10 cells of 5 mm at density 0.2, 32 voxels per cell, its radius
//! found on a template of its cells, the part copied from the template into a binary STL, with
//! CGAL's checks (self-intersection included). Printed: wall time in this process, meshings of
//! the search, achieved density, triangles, and the process's peak resident memory so far.
//!
//! Run: `cargo bench --bench strut` (add `-- CELL` to run one cell).

use latvox::field::Domain;
use latvox::io::sink::MeshFile;
use latvox::mesh::pipeline::Options;
use latvox::progress::Progress;
use latvox::strut::{Sizing, StrutJob, UnitCell};
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
    let domain = Domain::from_cells([10; 3], [5.0; 3], [0.0; 3]).unwrap();
    println!("10x10x10 cells of 5 mm, density 0.2, 32 voxels per cell, STL with CGAL's checks:");
    for name in latvox::strut::cell::BUILT_IN {
        if only.as_deref().is_some_and(|o| o != name) {
            continue;
        }
        let t = Instant::now();
        let job = StrutJob {
            cell: Arc::new(UnitCell::built_in(name).unwrap()),
            cell_name: name.to_string(),
            sizing: Sizing::Density(0.2),
            blend: 0.0,
            domain,
            resolution: 32,
            auto_resolution: true,
            options: Options {
                self_intersection: true,
                instancing: true,
                ..Default::default()
            },
        };
        let out = dir.path().join("s.stl");
        let mut sink = MeshFile::new(&out, false).unwrap().sink().unwrap();
        let r = job.run_into(&Progress::hidden(), &mut sink).unwrap();
        sink.commit().unwrap();
        let wall = t.elapsed().as_secs_f64();
        let p = &r.part;
        println!(
            "  {name:8} radius {:.4} mm, {} meshing(s), density {:.4}, {} triangles, valid {}: wall {wall:.2} s (model {:.2}, sample {:.2}, mesh {:.2}, snap {:.2}, verify {:.2}, write {:.2}), peak RSS so far {:.0} MB",
            r.radius,
            r.level_search.tried.len(),
            p.achieved_density,
            p.triangles,
            r.verdict().is_valid_solid(),
            p.timings.calibrate,
            p.timings.sample,
            p.timings.mesh,
            p.timings.snap,
            p.timings.verify,
            p.timings.write,
            peak_rss_mb()
        );
    }
}
