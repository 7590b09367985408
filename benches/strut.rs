//! Strut lattices made by the library's strut job (what `latvox strut` runs): each built-in cell in 10×10×10 cells of 5 mm at density 0.2, 32 voxels per cell, its radius
//! found on a template of its cells, the part copied from the template into a binary STL, the
//! template verified in full (self-intersection included). Printed: wall time in this process, meshings of
//! the search, achieved density, triangles, and the process's peak resident memory so far.
//!
//! Run: `cargo bench --bench strut` (add `-- CELL` to run one cell); `-- --scale N` for the
//! memory of N×N×N BCC cells (see [`scale`]).

use latvox::field::Domain;
use latvox::mesh::output::MeshFile;
use latvox::mesh::pipeline::Options;
use latvox::progress::Progress;
use latvox::strut::{Sizing, StrutJob, UnitCell};
use std::sync::Arc;
use std::time::Instant;
mod support;
use support::{peak_rss_mb, DiscardedStl};

/// `--scale N`: N×N×N BCC cells of 5 mm, struts of radius 0.35 mm, 16 voxels per cell, copied
/// from a template and streamed through STL records that are dropped (100³ cells would be a
/// file of some 80 GB); prints the time and the process's peak resident memory. Run once per
/// size, each in its own process, to compare peaks.
fn scale(n: u32) {
    let t = Instant::now();
    let job = StrutJob {
        grading: None,
        cell: Arc::new(UnitCell::built_in("bcc").unwrap()),
        cell_name: "bcc".into(),
        sizing: Sizing::Radius(0.35),
        blend: 0.0,
        domain: Domain::from_cells([n; 3], [5.0; 3], [0.0; 3]).unwrap(),
        resolution: 16,
        auto_resolution: false,
        options: Options {
            verify: latvox::verify::Verify::Full,
            instancing: true,
            ..Default::default()
        },
    };
    let mut sink = DiscardedStl::default();
    let r = job.run_into(&Progress::hidden(), &mut sink).unwrap();
    println!(
        "{n}x{n}x{n} bcc cells ({} struts), radius 0.35 mm, 16 voxels per cell: {} triangles ({:.1} GB of STL, dropped), valid {}, {:.1} s, peak RSS {:.0} MB",
        8 * (n as u64).pow(3),
        sink.triangles,
        (84 + 50 * sink.triangles) as f64 / 1e9,
        r.verdict().is_valid_solid(),
        t.elapsed().as_secs_f64(),
        peak_rss_mb()
    );
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if let Some(i) = args.iter().position(|a| a == "--scale") {
        scale(args[i + 1].parse().expect("--scale N"));
        return;
    }
    let only: Option<String> = std::env::args().skip(1).find(|a| !a.starts_with('-'));
    let dir = tempfile::tempdir().unwrap();
    let domain = Domain::from_cells([10; 3], [5.0; 3], [0.0; 3]).unwrap();
    println!("10x10x10 cells of 5 mm, density 0.2, 32 voxels per cell, STL, template verified:");
    for name in latvox::strut::cell::BUILT_IN {
        if only.as_deref().is_some_and(|o| o != name) {
            continue;
        }
        let t = Instant::now();
        let job = StrutJob {
            grading: None,
            cell: Arc::new(UnitCell::built_in(name).unwrap()),
            cell_name: name.to_string(),
            sizing: Sizing::Density(0.2),
            blend: 0.0,
            domain,
            resolution: 32,
            auto_resolution: true,
            options: Options {
                verify: latvox::verify::Verify::Full,
                instancing: true,
                ..Default::default()
            },
        };
        // A new file each time: replacing the last part's hundreds of megabytes would time the
        // file system's freeing them.
        let out = dir.path().join(format!("{name}.stl"));
        let mut sink = MeshFile::new(&out, false).unwrap().sink().unwrap();
        let r = job.run_into(&Progress::hidden(), &mut sink).unwrap();
        sink.commit().unwrap();
        let wall = t.elapsed().as_secs_f64();
        std::fs::remove_file(&out).unwrap();
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
