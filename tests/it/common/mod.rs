//! Test helpers that do not use latvox's own code: an STL reader, edge counting by hash map,
//! volume by the divergence theorem, the TPMS formulas written out directly, a seeded generator,
//! a PNG reader.
#![allow(dead_code)]

pub mod child;

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

pub fn latvox() -> Command {
    Command::new(env!("CARGO_BIN_EXE_latvox"))
}

pub fn run(args: &[&str], dir: &Path) -> Output {
    latvox()
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run latvox")
}

/// Runs latvox with `args` in `dir`, asserting success.
pub fn ok(args: &[&str], dir: &Path) {
    let r = run(args, dir);
    assert_eq!(
        r.status.code(),
        Some(0),
        "{args:?}: {}",
        String::from_utf8_lossy(&r.stderr)
    );
}

/// Makes a part with `args` (a meshing command and its settings) in `dir`: `part.stl` and its
/// part file `part.toml`.
pub fn make_part(dir: &Path, args: &[&str]) {
    let mut all = args.to_vec();
    all.extend(["-q", "-o", "part.stl", "--save-part", "part.toml"]);
    ok(&all, dir);
}

/// Triangles as three corner positions each.
pub type Tri = [[f64; 3]; 3];

/// Reads a binary STL (checked against its size) or an ASCII STL.
pub fn read_stl(path: &Path) -> Vec<Tri> {
    let data = std::fs::read(path).unwrap();
    if data.len() >= 84 {
        let n = u32::from_le_bytes(data[80..84].try_into().unwrap()) as usize;
        if data.len() == 84 + 50 * n {
            return (0..n)
                .map(|i| {
                    let r = &data[84 + 50 * i..84 + 50 * (i + 1)];
                    let f = |o: usize| f32::from_le_bytes(r[o..o + 4].try_into().unwrap()) as f64;
                    [0, 1, 2].map(|k| [f(12 + 12 * k), f(16 + 12 * k), f(20 + 12 * k)])
                })
                .collect();
        }
    }
    let text = String::from_utf8(data).expect("ASCII STL");
    let verts: Vec<[f64; 3]> = text
        .lines()
        .filter_map(|l| {
            let mut it = l.split_whitespace();
            (it.next()? == "vertex").then(|| {
                let v: Vec<f64> = it.map(|s| s.parse().unwrap()).collect();
                [v[0], v[1], v[2]]
            })
        })
        .collect();
    verts.chunks(3).map(|c| [c[0], c[1], c[2]]).collect()
}

#[derive(Debug, Default, PartialEq, Eq)]
pub struct Edges {
    pub boundary: usize,
    pub non_manifold: usize,
    /// Edges used twice in the same direction (neighbours wound inconsistently).
    pub same_direction: usize,
}

/// Edge incidences by exact vertex position (what a slicer sees).
pub fn edges(tris: &[Tri]) -> Edges {
    let key = |p: [f64; 3]| p.map(|x| (x as f32).to_bits());
    let mut directed: HashMap<([u32; 3], [u32; 3]), usize> = HashMap::new();
    for t in tris {
        for k in 0..3 {
            *directed
                .entry((key(t[k]), key(t[(k + 1) % 3])))
                .or_default() += 1;
        }
    }
    let mut e = Edges::default();
    let mut seen = std::collections::HashSet::new();
    for (&(a, b), &n) in &directed {
        let (lo, hi) = if a < b { (a, b) } else { (b, a) };
        if !seen.insert((lo, hi)) {
            continue;
        }
        let back = directed.get(&(b, a)).copied().unwrap_or(0);
        let total = n + back;
        if total == 1 {
            e.boundary += 1;
        } else if total > 2 {
            e.non_manifold += 1;
        } else if n == 2 || back == 2 {
            e.same_direction += 1;
        }
    }
    e
}

/// Signed volume by the divergence theorem.
pub fn volume(tris: &[Tri]) -> f64 {
    tris.iter()
        .map(|[a, b, c]| {
            (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0]))
                / 6.0
        })
        .sum()
}

/// Shells with positive volume (outer surfaces of separate pieces), found by joining triangles
/// that share a corner.
pub fn pieces(tris: &[Tri]) -> usize {
    shell_volumes(tris).iter().filter(|&&v| v > 0.0).count()
}

/// Signed volume of each shell (triangles joined through shared corners): positive for the
/// outside of a piece, negative for a void it encloses.
#[allow(dead_code)]
pub fn shell_volumes(tris: &[Tri]) -> Vec<f64> {
    shells(tris).iter().map(|s| volume(s)).collect()
}

/// The shells of a triangle soup: triangles joined through shared corners.
#[allow(dead_code)]
pub fn shells(tris: &[Tri]) -> Vec<Vec<Tri>> {
    let key = |p: [f64; 3]| p.map(|x| (x as f32).to_bits());
    let mut id: HashMap<[u32; 3], usize> = HashMap::new();
    let corners: Vec<[usize; 3]> = tris
        .iter()
        .map(|t| {
            t.map(|p| {
                let n = id.len();
                *id.entry(key(p)).or_insert(n)
            })
        })
        .collect();
    let mut parent: Vec<usize> = (0..id.len()).collect();
    fn find(p: &mut [usize], mut x: usize) -> usize {
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    for c in &corners {
        for k in 1..3 {
            let (a, b) = (find(&mut parent, c[0]), find(&mut parent, c[k]));
            parent[a.max(b)] = a.min(b);
        }
    }
    let mut shell: HashMap<usize, Vec<Tri>> = HashMap::new();
    for (t, c) in tris.iter().zip(&corners) {
        let r = find(&mut parent, c[0]);
        shell.entry(r).or_default().push(*t);
    }
    shell.into_values().collect()
}

pub fn bounds(tris: &[Tri]) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for t in tris {
        for p in t {
            for a in 0..3 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
    }
    (lo, hi)
}

/// The largest `f` over points sampled on `tris`: a barycentric grid of 6 steps a side
/// (corners, edges and inside).
pub fn worst_on(tris: &[Tri], f: impl Fn([f64; 3]) -> f64) -> f64 {
    let n = 6;
    let mut worst: f64 = 0.0;
    for t in tris {
        for i in 0..=n {
            for j in 0..=n - i {
                let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                let w = 1.0 - u - v;
                let p = [0, 1, 2].map(|k| u * t[0][k] + v * t[1][k] + w * t[2][k]);
                worst = worst.max(f(p));
            }
        }
    }
    worst
}

/// The seed's formulas, with X = 2πx / a; returns F and its gradient in mm⁻¹.
pub fn tpms(name: &str, p: [f64; 3], a: f64) -> (f64, [f64; 3]) {
    let w = 2.0 * std::f64::consts::PI / a;
    let f = |q: [f64; 3]| {
        let (x, y, z) = (w * q[0], w * q[1], w * q[2]);
        let (c, s) = (f64::cos, f64::sin);
        match name {
            "p" => -(c(x) + c(y) + c(z)),
            "gyroid" => c(x) * s(y) + c(y) * s(z) + c(z) * s(x),
            "d" => {
                s(x) * s(y) * s(z) + s(x) * c(y) * c(z) + c(x) * s(y) * c(z) + c(x) * c(y) * s(z)
            }
            "iwp" => {
                2.0 * (c(x) * c(y) + c(y) * c(z) + c(z) * c(x))
                    - (c(2. * x) + c(2. * y) + c(2. * z))
            }
            "s" => c(2. * x) * s(y) * c(z) + c(x) * c(2. * y) * s(z) + s(x) * c(y) * c(2. * z),
            "frd" => {
                -(4.0 * c(x) * c(y) * c(z)
                    - (c(2. * x) * c(2. * y) + c(2. * y) * c(2. * z) + c(2. * z) * c(2. * x)))
            }
            "neovius" => 3.0 * (c(x) + c(y) + c(z)) + 4.0 * c(x) * c(y) * c(z),
            // Lidin and Larsson (2002); Schoen's split P as tabulated by Wohlgemuth et al. (2001).
            "lidinoid" => {
                0.5 * (s(2. * x) * c(y) * s(z) + s(2. * y) * c(z) * s(x) + s(2. * z) * c(x) * s(y))
                    - 0.5 * (c(2. * x) * c(2. * y) + c(2. * y) * c(2. * z) + c(2. * z) * c(2. * x))
                    + 0.15
            }
            "split-p" => {
                1.1 * (s(2. * x) * s(z) * c(y) + s(2. * y) * s(x) * c(z) + s(2. * z) * s(y) * c(x))
                    - 0.2 * (c(2. * x) * c(2. * y) + c(2. * y) * c(2. * z) + c(2. * z) * c(2. * x))
                    - 0.4 * (c(2. * x) + c(2. * y) + c(2. * z))
            }
            _ => panic!("unknown {name}"),
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

/// Asserts that `out` (a run with `args` in `dir`, whose files were `before`) is a refusal:
/// exit 2, one line on stderr naming `what`, no file left behind.
pub fn assert_refusal(dir: &Path, before: &[PathBuf], out: &Output, args: &[&str], what: &str) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
    assert!(
        err.contains(what),
        "{args:?}: '{err}' does not say '{what}'"
    );
    assert_eq!(files_in(dir), before, "{args:?} left a file");
}

/// Runs a Python `script` (the independent checkers: lib3mf, trimesh, manifold3d) on `path`;
/// its standard output.
pub fn python(script: &str, path: &Path) -> Vec<u8> {
    let o = Command::new("python3")
        .args(["-c", script])
        .arg(path)
        .output()
        .expect("python3 with the checkers (scripts/install-deps.sh installs them)");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    o.stdout
}

pub fn tempdir() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

pub fn json(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
}

pub fn files_in(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    v.sort();
    v
}

/// splitmix64: a small, well-mixed generator, enough to draw cases reproducibly.
pub struct Rng(pub u64);

impl Rng {
    pub fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
}

/// An 8-bit RGB PNG: width, height and the pixels row by row from the top.
pub fn read_png(path: &Path) -> (u32, u32, Vec<u8>) {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb);
    buf.truncate(info.buffer_size());
    (info.width, info.height, buf)
}

/// The cases of a seeded sweep this run makes: the tier's `range`, or the one case
/// `LATVOX_CASE=N` names (a failure names its N), past the range too.
pub struct Cases {
    range: std::ops::Range<usize>,
    pub only: Option<usize>,
}

impl Cases {
    pub fn new(range: std::ops::Range<usize>) -> Cases {
        let only = std::env::var("LATVOX_CASE")
            .ok()
            .and_then(|v| v.parse().ok());
        Cases { range, only }
    }

    /// How far the sequence is drawn.
    pub fn end(&self) -> usize {
        self.only.map_or(self.range.end, |n| n + 1)
    }

    /// Whether case `i` runs.
    pub fn runs(&self, i: usize) -> bool {
        match self.only {
            Some(n) => n == i,
            None => self.range.contains(&i),
        }
    }
}
