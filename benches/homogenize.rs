//! Numerical homogenisation (`latvox homogenize`, the library's `homogenize::homogenize`): a
//! gyroid net and a BCC strut cell at density 0.2 on 40³, 64³ and 128³ voxels, and Dong, Tang &
//! Zhao's grid cell (radius 0.1, 40³, centre voxelisation) beside an independent NumPy/SciPy
//! transcription of the same method with a direct sparse solve (`tests/reference/homogenize.py`)
//! in the same run. Each case runs in its own process so that its
//! peak resident memory is its own; printed: median wall time of the runs, peak RSS, solver
//! iterations and unknowns.
//!
//! Run: `cargo bench --bench homogenize` (add `-- --runs N`).

use latvox::homogenize::{self, Amount, Cell, Lattice, Material, Settings, Voxelization};
use latvox::lattice::strut::UnitCell;
use latvox::lattice::tpms::{Structure, Surface};
use latvox::progress::Progress;
use std::process::Command;
use std::sync::Arc;
use std::time::Instant;
mod support;
use support::median;

fn settings(case: &str, n: usize) -> Settings {
    let (lattice, amount, rule, material) = match case {
        "gyroid" => (
            Lattice::Tpms(Surface::Gyroid, Structure::Net),
            Amount::Density(0.2),
            Voxelization::Fraction,
            Material::from_young(1.0, 0.3).unwrap(),
        ),
        "bcc" => (
            Lattice::Strut(Arc::new(UnitCell::built_in("bcc").unwrap())),
            Amount::Density(0.2),
            Voxelization::Fraction,
            Material::from_young(1.0, 0.3).unwrap(),
        ),
        "grid" => (
            Lattice::Strut(Arc::new(UnitCell::built_in("sc").unwrap())),
            Amount::Parameter(0.1),
            Voxelization::Centres,
            Material::from_lame(115.4, 79.6).unwrap(),
        ),
        _ => panic!("unknown case {case}"),
    };
    Settings {
        cell: Cell {
            lattice,
            size: [1.0; 3],
        },
        amount,
        voxels: [n; 3],
        voxelization: rule,
        material,
        tolerance: 1e-8,
    }
}

/// One case in this process: prints "seconds peak_mb iterations unknowns C11".
fn one(case: &str, n: usize) {
    let t = Instant::now();
    let h = homogenize::homogenize(&settings(case, n), &Progress::hidden()).unwrap();
    println!(
        "{} {} {} {} {}",
        t.elapsed().as_secs_f64(),
        support::peak_rss_mb(),
        h.solver.iterations,
        h.solver.unknowns,
        h.stiffness[0][0]
    );
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if let Some(i) = args.iter().position(|a| a == "--one") {
        one(&args[i + 1], args[i + 2].parse().unwrap());
        return;
    }
    let runs: usize = args
        .iter()
        .position(|a| a == "--runs")
        .and_then(|i| args.get(i + 1)?.parse().ok())
        .unwrap_or(3);
    let exe = std::env::current_exe().unwrap();
    println!(
        "{runs} runs per case (one at 128³), median wall time; peak RSS of the case's process"
    );
    for (case, n) in [
        ("grid", 40),
        ("gyroid", 40),
        ("gyroid", 64),
        ("gyroid", 128),
        ("bcc", 40),
        ("bcc", 64),
        ("bcc", 128),
    ] {
        let runs = if n >= 128 { 1 } else { runs };
        let mut times = Vec::new();
        let mut last = String::new();
        for _ in 0..runs {
            let o = Command::new(&exe)
                .args(["--one", case, &n.to_string()])
                .output()
                .unwrap();
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
            last = String::from_utf8_lossy(&o.stdout).trim().to_string();
            times.push(last.split(' ').next().unwrap().parse::<f64>().unwrap());
        }
        let f: Vec<&str> = last.split(' ').collect();
        println!(
            "latvox {case:6} {n:3}³ voxels: {:7.2} s, peak RSS {:6.0} MB, {} CG iterations, {} unknowns, C11 {}",
            median(times),
            f[1].parse::<f64>().unwrap(),
            f[2],
            f[3],
            f[4]
        );
        if case == "grid" {
            let script = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/reference/homogenize.py");
            let mut times = Vec::new();
            let mut peak = 0.0;
            let mut out = String::new();
            for _ in 0..runs {
                let o = Command::new("/usr/bin/time")
                    .args([
                        "-f", "%e %M", "python3", script, "sc", "0.1", "40", "115.4", "79.6",
                    ])
                    .output()
                    .unwrap();
                assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
                let err = String::from_utf8_lossy(&o.stderr);
                let mut f = err.split_whitespace().rev();
                peak = f.next().unwrap().parse::<f64>().unwrap() / 1024.0;
                times.push(f.next().unwrap().parse::<f64>().unwrap());
                out = String::from_utf8_lossy(&o.stdout).into_owned();
            }
            let c11 = serde_json::from_str::<serde_json::Value>(&out).unwrap()["C"][0][0].clone();
            println!(
                "SciPy  grid    40³ voxels: {:7.2} s, peak RSS {:6.0} MB (direct sparse solve), C11 {c11}",
                median(times),
                peak
            );
        }
    }
}
