//! Independent mesh computations for the check/repair tests, written without latvox's code:
//! an OFF reader, STL writers, brute-force topology (hash maps, union-find, per-vertex walks),
//! brute-force T-junctions and triangle–triangle intersection, test shapes, and trimesh (PyPI)
//! run through python3.
#![allow(dead_code)]

use std::collections::{HashMap, HashSet};
use std::path::Path;

pub type P = [f64; 3];
pub type Tri = [P; 3];

pub fn cgal_data() -> std::path::PathBuf {
    // Debian's libcgal-demo ships CGAL's data archive; unpack it once per test process.
    let archive = Path::new("/usr/share/doc/libcgal-dev/data.tar.gz");
    assert!(
        archive.exists(),
        "{} missing: run scripts/install-deps.sh (libcgal-demo)",
        archive.display()
    );
    static ONCE: std::sync::Once = std::sync::Once::new();
    let dir = std::env::temp_dir().join(format!("latvox-cgal-data-{}", std::process::id()));
    ONCE.call_once(|| {
        std::fs::create_dir_all(&dir).unwrap();
        let ok = std::process::Command::new("tar")
            .args([
                "xzf",
                archive.to_str().unwrap(),
                "-C",
                dir.to_str().unwrap(),
                "data/meshes",
            ])
            .status()
            .unwrap()
            .success();
        assert!(ok, "unpacking {}", archive.display());
    });
    dir.join("data/meshes")
}

/// OFF as triangles (polygons fanned), vertices as f32 like every STL.
pub fn read_off(path: &Path) -> Vec<Tri> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut toks = text
        .lines()
        .map(|l| l.split('#').next().unwrap())
        .flat_map(|l| l.split_whitespace().map(str::to_string).collect::<Vec<_>>())
        .collect::<Vec<_>>()
        .into_iter();
    let kw = toks.next().unwrap();
    assert!(kw.ends_with("OFF"), "{kw}");
    let nv: usize = toks.next().unwrap().parse().unwrap();
    let nf: usize = toks.next().unwrap().parse().unwrap();
    let _ne = toks.next();
    let v: Vec<P> = (0..nv)
        .map(|_| [0, 1, 2].map(|_| toks.next().unwrap().parse::<f32>().unwrap() as f64))
        .collect();
    let mut tris = Vec::new();
    for _ in 0..nf {
        let n: usize = toks.next().unwrap().parse().unwrap();
        let idx: Vec<usize> = (0..n)
            .map(|_| toks.next().unwrap().parse().unwrap())
            .collect();
        for k in 1..n - 1 {
            tris.push([v[idx[0]], v[idx[k]], v[idx[k + 1]]]);
        }
    }
    tris
}

pub fn write_stl(path: &Path, tris: &[Tri]) {
    write_stl_with_normals(path, tris, &vec![[0.0; 3]; tris.len()]);
}

pub fn write_stl_with_normals(path: &Path, tris: &[Tri], normals: &[[f32; 3]]) {
    let mut b = vec![0u8; 80];
    b.extend_from_slice(&(tris.len() as u32).to_le_bytes());
    for (t, n) in tris.iter().zip(normals) {
        for x in n {
            b.extend_from_slice(&x.to_le_bytes());
        }
        for p in t {
            for x in p {
                b.extend_from_slice(&(*x as f32).to_le_bytes());
            }
        }
        b.extend_from_slice(&[0, 0]);
    }
    std::fs::write(path, b).unwrap();
}

fn key(p: P) -> [u32; 3] {
    p.map(|x| if x == 0.0 { 0 } else { (x as f32).to_bits() })
}

/// Brute-force topology by exact position.
#[derive(Debug, Default, Clone, PartialEq)]
pub struct Topo {
    pub facets: usize,
    pub vertices: usize,
    pub edges: usize,
    pub boundary: usize,
    pub non_manifold: usize,
    pub inconsistent: usize,
    pub non_manifold_vertices: usize,
    pub repeated_vertex: usize,
    pub duplicates: usize,
    /// Per shell (sorted by facet count, then volume): (F, V, E, signed volume).
    pub shells: Vec<(usize, usize, usize, f64)>,
}

pub fn topo(tris: &[Tri]) -> Topo {
    let mut id: HashMap<[u32; 3], usize> = HashMap::new();
    let mut faces: Vec<[usize; 3]> = Vec::new();
    let mut t = Topo {
        facets: tris.len(),
        ..Default::default()
    };
    for tri in tris {
        let f = tri.map(|p| {
            let n = id.len();
            *id.entry(key(p)).or_insert(n)
        });
        if f[0] == f[1] || f[1] == f[2] || f[0] == f[2] {
            t.repeated_vertex += 1;
        } else {
            faces.push(f);
        }
    }
    t.vertices = {
        let mut s = HashSet::new();
        for tri in tris {
            for p in tri {
                s.insert(key(*p));
            }
        }
        s.len()
    };
    let mut seen = HashSet::new();
    for f in &faces {
        let mut s = *f;
        s.sort();
        if !seen.insert(s) {
            t.duplicates += 1;
        }
    }
    // Undirected edge → list of (face, forward).
    let mut edges: HashMap<(usize, usize), Vec<(usize, bool)>> = HashMap::new();
    for (i, f) in faces.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            edges
                .entry((a.min(b), a.max(b)))
                .or_default()
                .push((i, a < b));
        }
    }
    t.edges = edges.len();
    let mut parent: Vec<usize> = (0..faces.len()).collect();
    fn find(p: &mut [usize], mut x: usize) -> usize {
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    for list in edges.values() {
        match list.len() {
            1 => t.boundary += 1,
            2 => {
                if list[0].1 == list[1].1 {
                    t.inconsistent += 1
                }
            }
            _ => t.non_manifold += 1,
        }
        for w in list.windows(2) {
            let (a, b) = (find(&mut parent, w[0].0), find(&mut parent, w[1].0));
            parent[a] = b;
        }
    }
    // Non-manifold vertices: walk each vertex's facets across edges with exactly two facets.
    let mut around: HashMap<usize, Vec<usize>> = HashMap::new();
    for (i, f) in faces.iter().enumerate() {
        for v in f {
            around.entry(*v).or_default().push(i);
        }
    }
    for (v, fs) in &around {
        let mut reached = HashSet::from([fs[0]]);
        let mut stack = vec![fs[0]];
        while let Some(f) = stack.pop() {
            for &w in &faces[f] {
                if w == *v {
                    continue;
                }
                let list = &edges[&((*v).min(w), (*v).max(w))];
                if list.len() == 2 {
                    for &(g, _) in list {
                        if reached.insert(g) {
                            stack.push(g);
                        }
                    }
                }
            }
        }
        if reached.len() != fs.len() {
            t.non_manifold_vertices += 1;
        }
    }
    let mut shells: HashMap<usize, Vec<usize>> = HashMap::new();
    for i in 0..faces.len() {
        shells.entry(find(&mut parent, i)).or_default().push(i);
    }
    let mut back = vec![[0.0; 3]; id.len()];
    for (k, &i) in &id {
        back[i] = k.map(|b| f32::from_bits(b) as f64);
    }
    for fs in shells.values() {
        let vs: HashSet<usize> = fs.iter().flat_map(|&f| faces[f]).collect();
        let es: HashSet<(usize, usize)> = fs
            .iter()
            .flat_map(|&f| {
                let x = faces[f];
                (0..3).map(move |k| (x[k].min(x[(k + 1) % 3]), x[k].max(x[(k + 1) % 3])))
            })
            .collect();
        let vol: f64 = fs
            .iter()
            .map(|&f| {
                let [a, b, c] = faces[f];
                det([back[a], back[b], back[c]])
            })
            .sum();
        t.shells.push((fs.len(), vs.len(), es.len(), vol));
    }
    t.shells.sort_by(|a, b| {
        (a.0, a.1, a.2)
            .cmp(&(b.0, b.1, b.2))
            .then(a.3.total_cmp(&b.3))
    });
    t
}

pub fn det(t: Tri) -> f64 {
    let [a, b, c] = t;
    (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
        + a[2] * (b[0] * c[1] - b[1] * c[0]))
        / 6.0
}

pub fn volume(tris: &[Tri]) -> f64 {
    tris.iter().map(|t| det(*t)).sum()
}

fn sub(a: P, b: P) -> P {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn cross(a: P, b: P) -> P {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn dot(a: P, b: P) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// T-junctions by brute force: (vertex, edge) pairs with the vertex strictly inside an edge used
/// by exactly one facet, within `eps`.
pub fn t_junctions(tris: &[Tri], eps: f64) -> usize {
    let mut count: HashMap<([u32; 3], [u32; 3]), usize> = HashMap::new();
    let mut pos: HashMap<[u32; 3], P> = HashMap::new();
    for t in tris {
        for k in 0..3 {
            let (a, b) = (key(t[k]), key(t[(k + 1) % 3]));
            pos.insert(a, t[k]);
            *count.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let boundary: Vec<(P, P)> = count
        .iter()
        .filter(|(_, n)| **n == 1)
        .map(|((a, b), _)| (pos[a], pos[b]))
        .collect();
    let verts: HashSet<[u32; 3]> = boundary
        .iter()
        .flat_map(|(a, b)| [key(*a), key(*b)])
        .collect();
    let mut n = 0;
    for (a, b) in &boundary {
        let d = sub(*b, *a);
        let len = dot(d, d).sqrt();
        for v in &verts {
            let p = pos[v];
            let t = dot(sub(p, *a), d) / (len * len);
            if t * len <= eps || (1.0 - t) * len <= eps {
                continue;
            }
            let q = [0, 1, 2].map(|i| a[i] + t * d[i]);
            if dot(sub(p, q), sub(p, q)).sqrt() <= eps {
                n += 1;
            }
        }
    }
    n
}

/// Whether segment pq crosses triangle t (proper crossing of the interior).
fn segment_hits(p: P, q: P, t: &Tri) -> bool {
    let o = |a: P, b: P, c: P, d: P| dot(sub(b, a), cross(sub(c, a), sub(d, a)));
    let (s1, s2) = (o(t[0], t[1], t[2], p), o(t[0], t[1], t[2], q));
    if s1 * s2 >= 0.0 {
        return false;
    }
    let e = [
        o(p, q, t[0], t[1]),
        o(p, q, t[1], t[2]),
        o(p, q, t[2], t[0]),
    ];
    (e[0] > 0.0 && e[1] > 0.0 && e[2] > 0.0) || (e[0] < 0.0 && e[1] < 0.0 && e[2] < 0.0)
}

/// Pairs of facets sharing no vertex whose interiors cross (general position), brute force.
pub fn intersecting_pairs(tris: &[Tri]) -> usize {
    let mut n = 0;
    for i in 0..tris.len() {
        for j in i + 1..tris.len() {
            let (a, b) = (&tris[i], &tris[j]);
            if a.iter().any(|p| b.iter().any(|q| key(*p) == key(*q))) {
                continue;
            }
            let hit = (0..3).any(|k| segment_hits(a[k], a[(k + 1) % 3], b))
                || (0..3).any(|k| segment_hits(b[k], b[(k + 1) % 3], a));
            n += hit as usize;
        }
    }
    n
}

/// A torus of radii `big` and `small` about the z axis, `nu × nv` planar quads, wound outward;
/// the seams share their vertices exactly (indices wrap, angles are never recomputed at 2π).
pub fn torus(big: f64, small: f64, nu: usize, nv: usize) -> Vec<Tri> {
    let p = |i: usize, j: usize| {
        let (u, v) = (
            2.0 * std::f64::consts::PI * (i % nu) as f64 / nu as f64,
            2.0 * std::f64::consts::PI * (j % nv) as f64 / nv as f64,
        );
        let r = big + small * v.cos();
        [r * u.cos(), r * u.sin(), small * v.sin()]
    };
    let mut t = Vec::new();
    for i in 0..nu {
        for j in 0..nv {
            let (a, b, c, d) = (p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1));
            t.push([a, b, c]);
            t.push([a, c, d]);
        }
    }
    t
}

/// An axis-aligned box, 12 facets wound outward.
pub fn cuboid(lo: P, hi: P) -> Vec<Tri> {
    let c = |i: usize| {
        [
            if i & 1 != 0 { hi[0] } else { lo[0] },
            if i & 2 != 0 { hi[1] } else { lo[1] },
            if i & 4 != 0 { hi[2] } else { lo[2] },
        ]
    };
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    quads
        .iter()
        .flat_map(|q| [[c(q[0]), c(q[1]), c(q[2])], [c(q[0]), c(q[2]), c(q[3])]])
        .collect()
}

/// A UV sphere of radius r with n rings and 2n segments, wound outward.
pub fn sphere(r: f64, n: usize) -> Vec<Tri> {
    let p = |i: usize, j: usize| {
        let j = j % (2 * n);
        let th = std::f64::consts::PI * i as f64 / n as f64;
        let ph = std::f64::consts::PI * j as f64 / n as f64;
        if i == 0 {
            return [0.0, 0.0, r];
        }
        if i == n {
            return [0.0, 0.0, -r];
        }
        [
            r * th.sin() * ph.cos(),
            r * th.sin() * ph.sin(),
            r * th.cos(),
        ]
    };
    let mut t = Vec::new();
    for i in 0..n {
        for j in 0..2 * n {
            let (a, b, c, d) = (p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1));
            if i != 0 {
                t.push([a, b, d]);
            }
            if i != n - 1 {
                t.push([b, c, d]);
            }
        }
    }
    t
}

/// trimesh's view of a mesh file (merging vertices as trimesh does on load). One python3
/// process serves the whole test binary (importing trimesh takes over a second).
pub fn trimesh(path: &Path) -> serde_json::Value {
    use std::io::{BufRead, BufReader, Write};
    use std::process::{Child, ChildStdout, Command, Stdio};
    use std::sync::{Mutex, OnceLock};
    const SCRIPT: &str = r#"
import json, sys, warnings
warnings.filterwarnings("ignore")
import trimesh
from trimesh import grouping
for line in sys.stdin:
    path = line.rstrip("\n")
    try:
        m = trimesh.load(path, force='mesh', process=True)
        edges = m.edges_sorted
        once = grouping.group_rows(edges, require_count=1)
        counts = {}
        for e in map(tuple, edges):
            counts[e] = counts.get(e, 0) + 1
        out = {
          "faces": int(len(m.faces)),
          "vertices": int(len(m.vertices)),
          "edges_unique": int(len(m.edges_unique)),
          "boundary_edges": int(len(once)),
          "non_manifold_edges": int(sum(1 for c in counts.values() if c > 2)),
          "watertight": bool(m.is_watertight),
          "winding_consistent": bool(m.is_winding_consistent),
          "volume": float(m.volume),
          "area": float(m.area),
          "euler": int(m.euler_number),
          "bodies": int(len(m.split(only_watertight=False))),
        }
    except Exception as e:
        out = {"error": repr(e)}
    print(json.dumps(out), flush=True)
"#;
    static WORKER: OnceLock<Mutex<(Child, BufReader<ChildStdout>)>> = OnceLock::new();
    let worker = WORKER.get_or_init(|| {
        let mut child = Command::new("python3")
            .args(["-c", SCRIPT])
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .expect("python3 with trimesh (run scripts/install-deps.sh)");
        let out = BufReader::new(child.stdout.take().unwrap());
        Mutex::new((child, out))
    });
    let mut w = worker.lock().unwrap_or_else(|e| e.into_inner());
    let (child, out) = &mut *w;
    writeln!(child.stdin.as_mut().unwrap(), "{}", path.display()).unwrap();
    let mut line = String::new();
    out.read_line(&mut line).unwrap();
    assert!(
        !line.is_empty(),
        "trimesh worker died (run scripts/install-deps.sh to install trimesh)"
    );
    let v: serde_json::Value = serde_json::from_str(&line).unwrap();
    assert!(
        v.get("error").is_none(),
        "trimesh on {}: {v}",
        path.display()
    );
    v
}

/// The meshes of Debian's cura and prusa-slicer packages (printer beds, platforms, shapes),
/// unpacked by scripts/install-deps.sh.
pub fn slicer_mesh(package: &str, name: &str) -> std::path::PathBuf {
    let p = Path::new("/usr/local/share/latvox/slicer-meshes")
        .join(package)
        .join(name);
    assert!(
        p.exists(),
        "{} missing: run scripts/install-deps.sh (unpacks the slicers' meshes)",
        p.display()
    );
    p
}
