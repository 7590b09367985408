//! Meshes sized by a tolerance (`--tolerance MM`), in one run:
//!
//! 1. A 3×3×3-cell gyroid net at 30 % (5 mm cells, 32 voxels per cell) and a 2×2×2-cell
//!    Schwarz D sheet: latvox at half a voxel (0.078 mm) beside its uniform mesh decimated by a
//!    mesh-only simplifier to the same triangle count (fast-simplification from PyPI, quadric
//!    error edge collapses: `benches/peers/decimate.py`). For each: the largest distance from
//!    the exact surface (points sampled on every triangle against the published formula, at the
//!    level latvox reports, or the box's face where nearer), closedness and self-intersections
//!    (`latvox check`), the density, the time.
//! 2. A 10×10×10-cell gyroid net: the uniform mesh (copied cell by cell) beside the mesh at half
//!    a voxel: wall time, peak memory, triangles, file size.
//!
//! Run: `cargo bench --bench simplify` (add `-- --runs N`, default 3 for the small parts, 1 for
//! the large one).

use std::path::Path;
use std::process::Command;
mod support;
use support::{latvox, median, runs_arg, time_and_peak};

/// Wall seconds and peak resident memory (MB) of latvox with `args`.
fn timed(dir: &Path, args: &[&str]) -> (f64, f64) {
    time_and_peak(dir, env!("CARGO_BIN_EXE_latvox"), args)
}

fn read_stl(path: &Path) -> Vec<[[f64; 3]; 3]> {
    let d = std::fs::read(path).unwrap();
    let n = u32::from_le_bytes(d[80..84].try_into().unwrap()) as usize;
    (0..n)
        .map(|i| {
            let r = &d[84 + 50 * i + 12..84 + 50 * i + 48];
            let f = |k: usize| f32::from_le_bytes(r[4 * k..4 * k + 4].try_into().unwrap()) as f64;
            [0, 1, 2].map(|c| [0, 1, 2].map(|a| f(3 * c + a)))
        })
        .collect()
}

/// The published gyroid and Schwarz D functions of period `a`, and their gradients.
fn tpms(ty: &str, p: [f64; 3], a: f64) -> (f64, [f64; 3]) {
    let w = 2.0 * std::f64::consts::PI / a;
    let f = |q: [f64; 3]| {
        let (x, y, z) = (w * q[0], w * q[1], w * q[2]);
        let (c, s) = (f64::cos, f64::sin);
        match ty {
            "gyroid" => c(x) * s(y) + c(y) * s(z) + c(z) * s(x),
            _ => s(x) * s(y) * s(z) + s(x) * c(y) * c(z) + c(x) * s(y) * c(z) + c(x) * c(y) * s(z),
        }
    };
    let e = 1e-6;
    let g = [0, 1, 2].map(|k| {
        let (mut u, mut d) = (p, p);
        u[k] += e;
        d[k] -= e;
        (f(u) - f(d)) / (2.0 * e)
    });
    (f(p), g)
}

/// The largest distance from points on `tris` (a barycentric grid of 8 steps) to the part's
/// surface: the level set (`|F| = t` for a sheet), or the box's face where nearer.
fn deviation(tris: &[[[f64; 3]; 3]], ty: &str, sheet: bool, t: f64, cell: f64, size: f64) -> f64 {
    let n = 8;
    let mut worst: f64 = 0.0;
    for tri in tris {
        for i in 0..=n {
            for j in 0..=n - i {
                let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                let p =
                    [0, 1, 2].map(|k| u * tri[0][k] + v * tri[1][k] + (1.0 - u - v) * tri[2][k]);
                let (f, g) = tpms(ty, p, cell);
                let gl = g.iter().map(|x| x * x).sum::<f64>().sqrt();
                let surface = if sheet {
                    (f.abs() - t).abs()
                } else {
                    (f - t).abs()
                } / gl;
                let face = (0..3)
                    .map(|k| p[k].min(size - p[k]))
                    .fold(f64::INFINITY, f64::min);
                worst = worst.max(surface.min(face.max(0.0)));
            }
        }
    }
    worst
}

/// `latvox check`'s verdict on `file`: (valid solid, boundary edges, self-intersections, volume).
fn check(dir: &Path, file: &str) -> (bool, u64, u64, f64) {
    let out = Command::new(env!("CARGO_BIN_EXE_latvox"))
        .args(["check", file, "--json"])
        .current_dir(dir)
        .output()
        .unwrap();
    let r: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let c = &r["check"];
    (
        r["valid_solid"].as_bool().unwrap(),
        c["boundary_edges"].as_u64().unwrap(),
        c["self_intersections"].as_u64().unwrap(),
        c["volume"].as_f64().unwrap(),
    )
}

fn small(dir: &Path, runs: usize, ty: &str, sheet: bool, cells: u32) {
    let structure = if sheet { "sheet" } else { "net" };
    let line = format!("tpms --type {ty} --structure {structure} --density 0.3 --cells {cells}");
    let base: Vec<&str> = line.split_whitespace().collect();
    let uniform = [&base[..], &["-o", "u.stl"]].concat();
    assert!(latvox(dir, &uniform).status().unwrap().success());
    let ours = [
        &base[..],
        &["--tolerance", "0.078", "-o", "s.stl", "--report", "s.json"],
    ]
    .concat();
    let ours_s = median((0..runs).map(|_| timed(dir, &ours).0).collect());
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("s.json")).unwrap()).unwrap();
    let t = r["level"].as_f64().unwrap();
    let target = read_stl(&dir.join("s.stl")).len();
    let peer_s = median(
        (0..runs)
            .map(|_| {
                let out = Command::new("python3")
                    .arg(concat!(
                        env!("CARGO_MANIFEST_DIR"),
                        "/benches/peers/decimate.py"
                    ))
                    .args(["u.stl", &target.to_string(), "p.stl"])
                    .current_dir(dir)
                    .output()
                    .unwrap();
                assert!(
                    out.status.success(),
                    "{}",
                    String::from_utf8_lossy(&out.stderr)
                );
                String::from_utf8_lossy(&out.stdout)
                    .trim()
                    .parse::<f64>()
                    .unwrap()
            })
            .collect(),
    );
    let size = 5.0 * cells as f64;
    let uniform_n = read_stl(&dir.join("u.stl")).len();
    println!(
        "{ty} {structure}, {cells}³ cells, uniform {uniform_n} triangles; latvox at 0.078 mm {ours_s:.2} s (meshing included), fast-simplification {peer_s:.2} s (decimation only)"
    );
    println!("  mesh                  triangles  max deviation mm  valid solid  open edges  self-intersections  density");
    for (name, file) in [
        ("latvox --tolerance", "s.stl"),
        ("fast-simplification", "p.stl"),
        ("uniform", "u.stl"),
    ] {
        let tris = read_stl(&dir.join(file));
        let d = deviation(&tris, ty, sheet, t, 5.0, size);
        let (valid, open, crossing, volume) = check(dir, file);
        println!(
            "  {name:<20}  {:>9}  {d:>16.4}  {valid:>11}  {open:>10}  {crossing:>18}  {:.4}",
            tris.len(),
            volume / size.powi(3)
        );
    }
}

fn large(dir: &Path, runs: usize) {
    let base: Vec<&str> = "tpms --type gyroid --density 0.3 --cells 10"
        .split(' ')
        .collect();
    println!("gyroid net, 10³ cells of 5 mm, 32 voxels per cell");
    println!("  mesh                  wall s  peak MB  triangles  file MB");
    for (name, extra) in [
        ("uniform (copied cells)", &[][..]),
        ("--tolerance 0.078", &["--tolerance", "0.078"][..]),
    ] {
        let args = [&base[..], extra, &["-o", "l.stl"]].concat();
        let t: Vec<(f64, f64)> = (0..runs).map(|_| timed(dir, &args)).collect();
        let wall = median(t.iter().map(|x| x.0).collect());
        let peak = t.iter().map(|x| x.1).fold(0.0, f64::max);
        let bytes = std::fs::metadata(dir.join("l.stl")).unwrap().len();
        println!(
            "  {name:<22}  {wall:>6.1}  {peak:>7.0}  {:>9}  {:>7.1}",
            (bytes - 84) / 50,
            bytes as f64 / 1e6
        );
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let runs = runs_arg(&args, 3);
    let dir = tempfile::tempdir().unwrap();
    small(dir.path(), runs, "gyroid", false, 3);
    small(dir.path(), runs, "d", true, 2);
    large(dir.path(), runs_arg(&args, 1).min(runs).max(1));
}
