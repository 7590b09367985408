//! `interpret` benchmarks, with the figures quoted in the book's performance chapter.
//!
//! 1. The 2D pipeline on a 300 × 100 field, nc = 8 (a 2400 × 800 refined grid): the `latvox interpret`
//!    binary from the .npy to the STL (CGAL-verified), the IGES and the DXF. The field is a real
//!    optimisation result: latvox's own half MBB beam, 300 × 100, volume fraction 0.4, rmin 3.
//! 2. A 3D 120 × 40 × 40 field to a verified STL (nc = 2: a 240 × 80 × 80 grid). The field is
//!    top3d's cantilever optimised on 30 × 10 × 10 elements by latvox, upsampled ×4 trilinearly.
//!
//! Wall time and peak resident memory of the child (`wait4`), median of several runs; the
//! fields are made once, before timing. Run: `cargo bench --bench interpret` (`-- --runs N`).

use std::path::Path;
use std::process::Command;
use std::time::Instant;

#[path = "../tests/it/common/child.rs"]
mod child;

/// (wall seconds, peak RSS in MB, exit code) of one run of `cmd`.
fn run_measured(cmd: &mut Command) -> (f64, f64, i32) {
    let m = child::run_measured(cmd);
    (m.seconds, m.peak_rss_mb(), m.code)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

fn write_npy(path: &Path, shape: &[usize], data: &[f64]) {
    let mut buf = Vec::new();
    latvox::io::npy::write(&mut buf, shape, data).unwrap();
    std::fs::write(path, buf).unwrap();
}

/// The 3D field: top3d's cantilever on 30 × 10 × 10, upsampled ×4 (trilinear between element
/// centres), in the (ny, nx, nz) layout.
fn field_3d(path: &Path) {
    use latvox::topopt::{builtin, optimise, FilterKind, Settings};
    let p = builtin("cantilever3d", Some([30, 10, 10])).unwrap();
    let s = Settings::new(0.3, 3.0, 1.5, FilterKind::Density);
    let r = optimise(
        &p,
        &s,
        &latvox::progress::Progress::hidden(),
        |_, _, _, _| {},
    )
    .unwrap();
    let (shape, coarse) = latvox::topopt::to_array(&p, &r.densities);
    let (cy, cx, cz) = (shape[0], shape[1], shape[2]);
    let f = 4;
    let (ny, nx, nz) = (cy * f, cx * f, cz * f);
    let at = |y: usize, x: usize, z: usize| coarse[(y * cx + x) * cz + z];
    let coord = |i: usize, n: usize| {
        let u = ((i as f64 + 0.5) / f as f64 - 0.5).clamp(0.0, (n - 1) as f64);
        let i0 = (u.floor() as usize).min(n.saturating_sub(2));
        (i0, u - i0 as f64)
    };
    let mut data = Vec::with_capacity(nx * ny * nz);
    for y in 0..ny {
        let (y0, ty) = coord(y, cy);
        for x in 0..nx {
            let (x0, tx) = coord(x, cx);
            for z in 0..nz {
                let (z0, tz) = coord(z, cz);
                let mut v = 0.0;
                for k in 0..8 {
                    let (dy, dx, dz) = (k & 1, (k >> 1) & 1, k >> 2);
                    let w = (if dy == 1 { ty } else { 1.0 - ty })
                        * (if dx == 1 { tx } else { 1.0 - tx })
                        * (if dz == 1 { tz } else { 1.0 - tz });
                    v += w * at(y0 + dy, x0 + dx, z0 + dz);
                }
                data.push(v.clamp(0.0, 1.0));
            }
        }
    }
    write_npy(path, &[ny, nx, nz], &data);
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let runs = args
        .iter()
        .position(|a| a == "--runs")
        .and_then(|i| args.get(i + 1))
        .and_then(|s| s.parse().ok())
        .unwrap_or(3usize);
    let exe = env!("CARGO_BIN_EXE_latvox");
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let threads = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1);
    println!("machine: {threads} threads; {runs} runs per case, median reported");

    let f2 = d.join("mbb300.npy");
    let t = Instant::now();
    let st = Command::new(exe)
        .args([
            "topopt",
            "-q",
            "--problem",
            "mbb",
            "--nelx",
            "300",
            "--nely",
            "100",
        ])
        .args(["--volfrac", "0.4", "--rmin", "3", "-o"])
        .arg(&f2)
        .stdout(std::process::Stdio::null())
        .status()
        .unwrap();
    assert!(st.success());
    println!(
        "(setup: the 300 x 100 MBB optimisation took {:.1} s)",
        t.elapsed().as_secs_f64()
    );
    let t = Instant::now();
    let f3 = d.join("c3d.npy");
    field_3d(&f3);
    println!(
        "(setup: the 30 x 10 x 10 top3d cantilever and its upsampling took {:.1} s)",
        t.elapsed().as_secs_f64()
    );

    let cases: Vec<(&str, Vec<String>)> = vec![
        (
            "2D 300x100, nc 8: clean, STL (CGAL incl. self-intersection), IGES, DXF",
            vec![
                "interpret".into(),
                f2.display().to_string(),
                "--element-size".into(),
                "1".into(),
                "--refine".into(),
                "8".into(),
                "--min-feature".into(),
                "0.5".into(),
                "--thickness".into(),
                "5".into(),
                "--iges".into(),
                d.join("m.igs").display().to_string(),
                "--dxf".into(),
                d.join("m.dxf").display().to_string(),
            ],
        ),
        (
            "3D 120x40x40, nc 2: clean, OpenVDB mesh, STL (CGAL incl. self-intersection)",
            vec![
                "interpret".into(),
                f3.display().to_string(),
                "--element-size".into(),
                "1".into(),
                "--refine".into(),
                "2".into(),
                "--min-feature".into(),
                "2".into(),
            ],
        ),
    ];
    for (label, a) in cases {
        let rep = d.join("r.json");
        let stl = d.join("part.stl");
        let (mut walls, mut rss) = (Vec::new(), Vec::new());
        for _ in 0..runs {
            let mut c = Command::new(exe);
            c.args(&a)
                .arg("-o")
                .arg(&stl)
                .arg("--report")
                .arg(&rep)
                .arg("-q")
                .stdout(std::process::Stdio::null());
            let (s, m, code) = run_measured(&mut c);
            assert!(code == 0 || code == 1, "latvox interpret failed ({code})");
            walls.push(s);
            rss.push(m);
        }
        let r: serde_json::Value = serde_json::from_slice(&std::fs::read(&rep).unwrap()).unwrap();
        println!(
            "{label}: wall {:.2} s (median), peak RSS {:.0} MB; clean {}, {} passes, {} triangles, closed {}, volume change {:+.3} %",
            median(walls),
            median(rss),
            r["clean"],
            r["iterations"],
            r["triangles"],
            r["checks"]["closed"],
            100.0 * r["measure_change"].as_f64().unwrap_or(f64::NAN)
        );
        println!("  stage times of the last run (s): {}", r["timings"]);
        if let Some(u) = r["uniform_control_points"].as_u64().filter(|&u| u > 0) {
            println!(
                "  curves: uniform {u} -> adaptive {} control points",
                r["adaptive_control_points"]
            );
        }
    }
}
