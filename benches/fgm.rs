//! `latvox fgm` as a user runs it, each case a process of its own (wall time and peak resident
//! memory from `wait4`, median of `--runs`): a scan of a torus 100 mm across (ring radius 35
//! mm, tube radius 15 mm; `--points` points, area-uniform, ±0.02 mm of noise along the normal,
//! no normals in the file) → signed distance grid → two materials graded from the skin (a
//! smooth step over 5 mm) → a `.vdb` (sdf, distance, both materials), the part's mesh and a
//! PolyJet PNG stack (600 × 300 dpi, `--layer` mm layers), at each of `--voxels` mm. Printed per
//! voxel: wall time, peak memory, the narrow band's voxels and OpenVDB's memory for it, the
//! stage times of latvox's report, and the volume's error against the torus's 2π²Rr².
//!
//! `--peer 0.4,0.2`: then, at each of those voxels, the signed distance alone (`--vdb`, no stack,
//! `--verify none`) beside a libigl user's (`benches/peers/igl_winding.py`: libigl's fast
//! winding numbers of the oriented points for the sign, given the scan's exact normals, and the
//! distance to the nearest point, at every voxel of latvox's band and 200 000 beyond it, read by
//! OpenVDB's Python module, `benches/peers/vdb_dense.py`): seconds, and both fields' errors
//! against the torus's exact distance — in the band (mean, 99th percentile, largest) and the
//! voxels of the wrong sign.
//!
//! Run: `cargo bench --bench fgm -- --runs 1 --points 1000000 --voxels 0.4,0.2,0.1 --layer 0.27
//! [--peer 0.4,0.2]`.

#[path = "../tests/it/common/child.rs"]
mod child;
mod support;

use child::run_measured;
use std::f64::consts::PI;
use std::io::Write;
use support::{latvox, median, runs_arg};

fn arg(args: &[String], name: &str, default: &str) -> String {
    args.iter()
        .position(|a| a == name)
        .map_or(default.to_string(), |i| args[i + 1].clone())
}

/// splitmix64, for a reproducible scan.
struct Rng(u64);
impl Rng {
    fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let runs = runs_arg(&args, 1);
    let n: usize = arg(&args, "--points", "1000000").parse().unwrap();
    let layer = arg(&args, "--layer", "0.27");
    let voxels: Vec<String> = arg(&args, "--voxels", "0.4,0.2,0.1")
        .split(',')
        .filter(|v| !v.is_empty())
        .map(str::to_string)
        .collect();
    let peer: Vec<String> = arg(&args, "--peer", "")
        .split(',')
        .filter(|v| !v.is_empty())
        .map(str::to_string)
        .collect();
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (big, small) = (35.0, 15.0);
    let mut rng = Rng(2026);
    let mut f = std::io::BufWriter::new(std::fs::File::create(d.join("scan.xyz")).unwrap());
    // The same points with their exact normals, for the peer.
    let mut g = std::io::BufWriter::new(std::fs::File::create(d.join("normals.xyz")).unwrap());
    let mut made = 0;
    while made < n {
        let (u, v) = (rng.uniform(), rng.uniform());
        // Area element ∝ R + r cos θ: rejection keeps the sample uniform over the surface.
        if rng.uniform() * (big + small) > big + small * (2.0 * PI * v).cos() {
            continue;
        }
        let (phi, theta) = (2.0 * PI * u, 2.0 * PI * v);
        let nrm = [
            theta.cos() * phi.cos(),
            theta.cos() * phi.sin(),
            theta.sin(),
        ];
        let r = small + (rng.uniform() - 0.5) * 0.04;
        let p = [
            big * phi.cos() + r * nrm[0],
            big * phi.sin() + r * nrm[1],
            r * nrm[2],
        ];
        writeln!(f, "{:.4} {:.4} {:.4}", p[0], p[1], p[2]).unwrap();
        if !peer.is_empty() {
            writeln!(
                g,
                "{:.4} {:.4} {:.4} {:.6} {:.6} {:.6}",
                p[0], p[1], p[2], nrm[0], nrm[1], nrm[2]
            )
            .unwrap();
        }
        made += 1;
    }
    drop((f, g));
    let exact = 2.0 * PI * PI * big * small * small;
    println!(
        "fgm: torus scan of {n} points, 100 mm across; VDB + mesh + PNG stack 600x300 dpi, {layer} mm layers; median of {runs} run(s)"
    );
    println!(
        "{:>7} {:>9} {:>9} {:>11} {:>8} {:>9} {:>9} {:>9} {:>9} {:>9} {:>10}",
        "voxel",
        "wall s",
        "peak MB",
        "band vox",
        "sdf MB",
        "sdf s",
        "mesh s",
        "mat s",
        "write s",
        "stack s",
        "vol err %"
    );
    for v in &voxels {
        let (mut secs, mut mem) = (Vec::new(), Vec::new());
        for _ in 0..runs {
            let r = run_measured(&mut latvox(
                d,
                &[
                    "fgm",
                    "--points",
                    "scan.xyz",
                    "--voxel",
                    v,
                    "--feature",
                    "skin",
                    "--law",
                    "step:0:5",
                    "--vdb",
                    "part.vdb",
                    "--png-stack",
                    "stack",
                    "--layer",
                    &layer,
                    "-o",
                    "part.stl",
                    "--verify",
                    "fast",
                    "--report",
                    "r.json",
                    "-q",
                ],
            ));
            assert_eq!(r.code, 0, "voxel {v} failed");
            secs.push(r.seconds);
            mem.push(r.peak_rss_mb());
        }
        let rep: serde_json::Value =
            serde_json::from_slice(&std::fs::read(d.join("r.json")).unwrap()).unwrap();
        let t = &rep["timings"];
        let g = &rep["geometry"];
        let secs_of = |k: &str| t[k].as_f64().unwrap_or(f64::NAN);
        println!(
            "{:>7} {:>9.1} {:>9.0} {:>11} {:>8.1} {:>9.1} {:>9.1} {:>9.1} {:>9.1} {:>9.1} {:>10.3}",
            v,
            median(secs),
            median(mem),
            g["band_voxels"],
            g["grid_bytes"].as_f64().unwrap_or(f64::NAN) / 1e6,
            secs_of("signed distance"),
            secs_of("mesh and verify"),
            secs_of("material distance"),
            secs_of("write"),
            secs_of("png stack"),
            100.0 * (rep["volume"].as_f64().unwrap_or(f64::NAN) / exact - 1.0)
        );
    }
    if !peer.is_empty() {
        compare_with_peer(d, &peer, big, small);
    }
}

/// The signed distance alone, latvox beside libigl's fast winding numbers (see the module
/// documentation).
fn compare_with_peer(d: &std::path::Path, voxels: &[String], big: f64, small: f64) {
    let peers = concat!(env!("CARGO_MANIFEST_DIR"), "/benches/peers");
    println!("signed distance alone: latvox (normals estimated) beside libigl fast winding numbers (exact normals) + nearest point");
    println!(
        "{:>7} {:>9} {:>9} {:>9} {:>9}   {:>26}   {:>26}   {:>13}",
        "voxel",
        "lv sdf s",
        "lv wall s",
        "lv MB",
        "peer s",
        "band err lv mean/p99/max",
        "band err peer mean/p99/max",
        "wrong sign lv/peer"
    );
    for v in voxels {
        let r = run_measured(&mut latvox(
            d,
            &[
                "fgm",
                "--points",
                "scan.xyz",
                "--voxel",
                v,
                "--vdb",
                "peer.vdb",
                "-o",
                "peer.stl",
                "--verify",
                "none",
                "--report",
                "peer.json",
                "-q",
            ],
        ));
        assert_eq!(r.code, 0, "voxel {v} failed");
        let rep: serde_json::Value =
            serde_json::from_slice(&std::fs::read(d.join("peer.json")).unwrap()).unwrap();
        let dense = std::process::Command::new("/usr/bin/python3")
            .arg(format!("{peers}/vdb_dense.py"))
            .args(["peer.vdb", "sdf", "dense.npz"])
            .current_dir(d)
            .status()
            .unwrap();
        assert!(dense.success(), "vdb_dense.py failed");
        let out = std::process::Command::new("python3")
            .arg(format!("{peers}/igl_winding.py"))
            .args([
                "normals.xyz",
                "dense.npz",
                &big.to_string(),
                &small.to_string(),
            ])
            .current_dir(d)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "igl_winding.py: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let p: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let errs = |k: &str| {
            let m = &p[k];
            format!(
                "{:.4}/{:.4}/{:.4}",
                m["band_mean"].as_f64().unwrap(),
                m["band_p99"].as_f64().unwrap(),
                m["band_max"].as_f64().unwrap()
            )
        };
        println!(
            "{:>7} {:>9.1} {:>9.1} {:>9.0} {:>9.1}   {:>26}   {:>26}   {:>6}/{:<6}",
            v,
            rep["timings"]["signed distance"]
                .as_f64()
                .unwrap_or(f64::NAN),
            r.seconds,
            r.peak_rss_mb(),
            p["peer_seconds"]["total"].as_f64().unwrap(),
            errs("latvox"),
            errs("peer"),
            p["latvox"]["wrong_sign"],
            p["peer"]["wrong_sign"]
        );
        println!("        {p}");
    }
}
