//! What the benchmarks share: the process's peak memory, a sink that makes STL records and
//! drops them (the writing of a part too large for this machine's disk, without the disk),
//! a torus mesh, latvox as a quiet child process, a command's time and peak memory, medians and
//! the `--runs` argument.
#![allow(dead_code)]

use latvox::geom::Mesh;
use latvox::io::sink::{MeshSink, Triangle};
use std::f64::consts::PI;

/// The process's peak resident memory, MB (`VmHWM`).
pub fn peak_rss_mb() -> f64 {
    peak_rss_mb_of("self")
}

/// The peak resident memory (MB, `VmHWM`) of the running process `pid` (`"self"` for this one).
pub fn peak_rss_mb_of(pid: &str) -> f64 {
    std::fs::read_to_string(format!("/proc/{pid}/status"))
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse::<f64>().ok())
        })
        .map_or(f64::NAN, |kb| kb / 1024.0)
}

/// Binary STL records made for every triangle (normal, corners, attribute: 50 bytes each) and
/// dropped: the writing of a part too large for this machine's disk, without the disk.
#[derive(Default)]
pub struct DiscardedStl {
    pub triangles: u64,
    buf: Vec<u8>,
}

impl MeshSink for DiscardedStl {
    fn begin(&mut self, _: Option<u64>) -> latvox::Result<()> {
        Ok(())
    }
    fn triangles(&mut self, batch: &[Triangle]) -> latvox::Result<()> {
        self.buf.clear();
        for t in batch {
            let u = [0, 1, 2].map(|a| t[1][a] - t[0][a]);
            let v = [0, 1, 2].map(|a| t[2][a] - t[0][a]);
            let n = [
                u[1] * v[2] - u[2] * v[1],
                u[2] * v[0] - u[0] * v[2],
                u[0] * v[1] - u[1] * v[0],
            ];
            for x in n.iter().chain(t.iter().flatten()) {
                self.buf.extend_from_slice(&x.to_le_bytes());
            }
            self.buf.extend_from_slice(&[0, 0]);
        }
        self.triangles += batch.len() as u64;
        std::hint::black_box(&self.buf);
        Ok(())
    }
    fn finish(&mut self) -> latvox::Result<()> {
        Ok(())
    }
}

/// A torus of radii `big` and `small` mm about the z axis, `nu × nv` quads, wound outward.
pub fn torus(big: f64, small: f64, nu: usize, nv: usize) -> Mesh {
    let mut positions = Vec::with_capacity(3 * nu * nv);
    for i in 0..nu {
        for j in 0..nv {
            let (u, v) = (
                2.0 * PI * i as f64 / nu as f64,
                2.0 * PI * j as f64 / nv as f64,
            );
            let r = big + small * v.cos();
            positions.extend([r * u.cos(), r * u.sin(), small * v.sin()].map(|x| x as f32));
        }
    }
    let id = |i: usize, j: usize| ((i % nu) * nv + j % nv) as u32;
    let mut indices = Vec::with_capacity(6 * nu * nv);
    for i in 0..nu {
        for j in 0..nv {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            indices.extend([a, b, c, a, c, d]);
        }
    }
    Mesh { positions, indices }
}

/// latvox run in `dir` with `args`, its output dropped.
pub fn latvox(dir: &std::path::Path, args: &[&str]) -> std::process::Command {
    use std::process::Stdio;
    let mut c = std::process::Command::new(env!("CARGO_BIN_EXE_latvox"));
    c.args(args)
        .current_dir(dir)
        .stdout(Stdio::null())
        .stderr(Stdio::null());
    c
}

/// Wall seconds and peak resident memory (MB) of `program` with `args` run in `dir` under
/// `/usr/bin/time`, its output dropped; panics when it fails.
pub fn time_and_peak(dir: &std::path::Path, program: &str, args: &[&str]) -> (f64, f64) {
    use std::process::Stdio;
    let out = dir.join("time.txt");
    let s = std::process::Command::new("/usr/bin/time")
        .args(["-f", "%e %M", "-o", out.to_str().unwrap()])
        .arg(program)
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .unwrap();
    assert!(s.success(), "{program} {args:?}");
    let t = std::fs::read_to_string(out).unwrap();
    let v: Vec<f64> = t.split_whitespace().map(|x| x.parse().unwrap()).collect();
    (v[0], v[1] / 1024.0)
}

/// The middle value of `v` (the upper one of an even count).
pub fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// `--runs N` from the bench's arguments (`default` without it).
pub fn runs_arg(args: &[String], default: usize) -> usize {
    args.iter()
        .position(|a| a == "--runs")
        .map_or(default, |i| args[i + 1].parse().expect("--runs N"))
}
