//! Slices made straight from a part file are the part its mesh is, checked as a user would check
//! them, by this test's own computations:
//!
//! - a randomised property test over TPMS types and structures and strut cells, densities,
//!   boxes that are not whole cells, odd origins and resolutions: the part is made (`-o m.stl
//!   --save-part p.toml`), then `latvox slice p.toml` and `latvox slice m.stl` cut the same
//!   layers (a whole number of them across the box, about half a voxel or a 96th of a cell
//!   thick, whichever is thinner). The implicit
//!   slices' volume (Σ area × thickness) is within 0.3 % of the mesh's (the STL's own
//!   divergence-theorem volume, computed here), the density `slice` reports is within 0.002 of
//!   the target, and it exits 0. At 40 voxels a cell and finer, every TPMS layer more than two
//!   voxels from the box's faces holds within 1 % of the mesh's layer area. (At 32, the layers
//!   through the thinnest necks differ by up to 3.4 % — a P net at 0.3, near where it falls
//!   apart: the implicit level moves by the mesh's mean loss to its chords, which a saddle-shaped
//!   neck's mesh does not have. Strut lattices are held to the volume only: their meshes fill
//!   the sharp concave creases where struts meet, by up to 8 % of a node plane's section at 32
//!   voxels a cell, where the implicit section keeps them sharp.)
//! - the fragments the box cuts loose: the mesh made with `--keep-fragments` is split into its
//!   shells here (the largest is the part, the others the fragments), and no loop of the
//!   implicit slices has a point inside a fragment (generalised winding number, computed here);
//!   a part file that keeps its fragments does have such loops, so the check can fail.
//!
//!   Voronoi foams the same way (their own property: nets and sheets, random and periodic, with
//!   pores or none), nets' layers at 32 voxels a spacing and finer; sheets are held to the
//!   volume, as strut lattices are (their meshes fill the sharp creases where walls meet, and
//!   round a pore's rim).
//!
//! Seeded: a failure names its case N, and `LATVOX_CASE=N` runs that case alone. The main tier
//! runs the first 4 cases (and 2 foams); the long tier (`cargo test --release -- --ignored
//! implicit_slices`) the next 18 (and 8 foams).

use crate::common::*;
use crate::density_property::{round, FEASIBLE};
use crate::slice::csv_rows;
use std::path::Path;

/// Built-in strut cells drawn, with the densities they are drawn at.
const CELLS: [(&str, f64, f64); 7] = [
    ("bcc", 0.12, 0.3),
    ("bccz", 0.15, 0.3),
    ("fcc", 0.15, 0.35),
    ("octet", 0.15, 0.35),
    ("kelvin", 0.12, 0.3),
    ("diamond", 0.12, 0.3),
    ("sc", 0.12, 0.3),
];

#[derive(Debug, Clone)]
struct Case {
    /// `tpms -t TYPE --structure S`, `strut --cell CELL` or `voronoi --spacing S …`.
    part: Vec<String>,
    /// Whether each layer is checked (at `layers_from` voxels a cell or finer).
    layers_from: Option<u64>,
    density: f64,
    /// The cell size (a foam's spacing: it is not given as `--cell-size`).
    cell: f64,
    size: [f64; 3],
    origin: [f64; 3],
    resolution: u32,
}

fn draw(rng: &mut Rng) -> Case {
    let tpms = rng.below(3) != 0;
    let (part, density) = if tpms {
        let (ty, st, lo, hi) = FEASIBLE[rng.below(FEASIBLE.len() as u64) as usize];
        let (lo, hi) = if st == "sheet" {
            (0.2, hi.min(0.8))
        } else {
            (lo + 0.03, 0.9)
        };
        let part = ["tpms", "--type", ty, "--structure", st];
        (part.map(String::from).to_vec(), rng.uniform(lo, hi))
    } else {
        let (cell, lo, hi) = CELLS[rng.below(CELLS.len() as u64) as usize];
        let part = ["strut", "--cell", cell];
        (part.map(String::from).to_vec(), rng.uniform(lo, hi))
    };
    let cell = round(rng.uniform(3.0, 6.0), 2);
    Case {
        part,
        layers_from: tpms.then_some(40),
        density: round(density, 3),
        cell,
        size: [0; 3].map(|_| round(cell * rng.uniform(1.1, 2.8), 2)),
        origin: [0; 3].map(|_| round(rng.uniform(-5.0, 5.0), 2)),
        resolution: [12, 16, 24, 32, 40, 48][rng.below(6) as usize],
    }
}

/// A Voronoi foam: a net or a sheet (one sheet in three with pores), random through its box or
/// periodic (one in three), at a density within its range, in a box of a few spacings.
fn draw_foam(rng: &mut Rng) -> Case {
    let sheet = rng.below(2) == 0;
    let spacing = round(rng.uniform(2.5, 3.5), 2);
    let mut part: Vec<String> = ["voronoi", "--spacing"].map(String::from).to_vec();
    part.push(spacing.to_string());
    part.extend(["--seed".into(), (1 + rng.below(1000)).to_string()]);
    let mut pores = false;
    if sheet {
        part.extend(["--structure", "sheet"].map(String::from));
        if rng.below(3) == 0 {
            pores = true;
            part.extend([
                "--pores".into(),
                round(rng.uniform(0.3, 0.6), 2).to_string(),
            ]);
        }
    }
    if rng.below(3) == 0 {
        part.extend([
            "--periodic".into(),
            round(spacing * rng.uniform(2.2, 3.0), 2).to_string(),
        ]);
    }
    let density = if sheet {
        rng.uniform(0.12, 0.35)
    } else {
        rng.uniform(0.08, 0.3)
    };
    let resolution = [16, 20, 24, 32][rng.below(4) as usize];
    Case {
        part,
        // A sheet's mesh fills the sharp concave creases where its walls meet, and rounds a
        // pore's rim: sheets are held to the volume, as strut lattices are.
        layers_from: (!sheet && !pores).then_some(32),
        density: round(density, 3),
        cell: spacing,
        size: [0; 3].map(|_| round(spacing * rng.uniform(2.2, 3.4), 2)),
        origin: [0; 3].map(|_| round(rng.uniform(-5.0, 5.0), 2)),
        resolution,
    }
}

fn list(v: [f64; 3]) -> String {
    format!("{},{},{}", v[0], v[1], v[2])
}

/// Makes the case's part and slices it both ways; panics naming the case where a promise is
/// broken. Returns the implicit slices' volume against the mesh's, and the worst layer checked.
fn check(n: usize, c: &Case, dir: &Path) -> Option<(f64, f64)> {
    let mut args: Vec<String> = c.part.clone();
    if c.part[0] != "voronoi" {
        args.extend(["--cell-size".into(), c.cell.to_string()]);
    }
    args.extend(
        [
            "--density".into(),
            c.density.to_string(),
            "--size".into(),
            list(c.size),
            "--origin".into(),
            list(c.origin),
            "--resolution".into(),
            c.resolution.to_string(),
        ]
        .into_iter()
        .chain(
            [
                "-o",
                "m.stl",
                "--save-part",
                "p.toml",
                "--report",
                "m.json",
                "-q",
            ]
            .map(String::from),
        ),
    );
    let argv: Vec<&str> = args.iter().map(String::as_str).collect();
    let out = run(&argv, dir);
    if out.status.code() == Some(2) {
        // Refused (members too thin, or pores closed, at this setting): nothing to slice.
        return None;
    }
    assert!(
        out.status.success(),
        "case {n} {c:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let made = json(&dir.join("m.json"));
    let voxel = made["voxel_size"].as_f64().unwrap();
    let resolution = made["resolution"].as_u64().unwrap();
    let mesh_volume = volume(&read_stl(&dir.join("m.stl")));
    // A whole number of layers across the box, about half a voxel thick (and thin enough for
    // the members of coarse voxels: a 96th of a cell at most).
    let height = c.size[2];
    let count = (height / (0.5 * voxel).min(c.cell / 96.0)).ceil();
    let layer = format!("{:.9}", height / count);
    let sliced = run(
        &[
            "slice", "p.toml", "--layer", &layer, "--csv", "i.csv", "--json", "-q",
        ],
        dir,
    );
    assert!(
        sliced.status.success(),
        "case {n} {c:?}: slice p.toml exit {:?}: {}{}",
        sliced.status.code(),
        String::from_utf8_lossy(&sliced.stderr),
        String::from_utf8_lossy(&sliced.stdout)
    );
    let r: serde_json::Value = serde_json::from_slice(&sliced.stdout).unwrap();
    let density = r["density"].as_f64().unwrap();
    assert!(
        (density - c.density).abs() <= 0.002,
        "case {n} {c:?}: sliced density {density}"
    );
    assert_eq!(r["target_density"].as_f64(), Some(c.density), "case {n}");
    let layer_volume = r["layer_volume"].as_f64().unwrap();
    let rel = layer_volume / mesh_volume - 1.0;
    assert!(
        rel.abs() < 0.003,
        "case {n} {c:?}: implicit slices hold {layer_volume} mm³, the mesh {mesh_volume} mm³"
    );
    let mut worst: f64 = 0.0;
    if c.layers_from.is_some_and(|r| resolution >= r) {
        ok(
            &["slice", "m.stl", "--layer", &layer, "--csv", "m.csv", "-q"],
            dir,
        );
        let (a, b) = (csv_rows(&dir.join("i.csv")), csv_rows(&dir.join("m.csv")));
        // The mesh's layers start where its vertices do (in single precision, as STL stores
        // them): layers are paired by height.
        let (z0, z1) = (c.origin[2], c.origin[2] + height);
        let mut paired = 0;
        for x in &a {
            let Some(y) = b.iter().find(|y| (x[0] - y[0]).abs() < 1e-4) else {
                continue;
            };
            paired += 1;
            if x[0] - z0 < 2.0 * voxel || z1 - x[0] < 2.0 * voxel || y[2] < 1e-6 {
                continue;
            }
            let d = (x[2] - y[2]).abs() / y[2];
            worst = worst.max(d);
            assert!(
                d < 0.01,
                "case {n} {c:?}: layer z={} holds {} mm² implicit, {} mm² meshed",
                x[0],
                x[2],
                y[2]
            );
        }
        assert!(
            paired * 10 >= a.len() * 9,
            "case {n}: {paired} of {} layers paired",
            a.len()
        );
    }
    Some((rel, worst))
}

fn property(cases: std::ops::Range<usize>) {
    property_of(cases, 0x005e_ed48, draw)
}

/// The cases `cases` of the sequence `draw` makes from `seed`.
fn property_of(cases: std::ops::Range<usize>, seed: u64, draw: fn(&mut Rng) -> Case) {
    let mut rng = Rng(seed);
    let (mut done, mut refused) = (0, 0);
    let (mut volume_worst, mut layer_worst): (f64, f64) = (0.0, 0.0);
    let tier = cases.len();
    let cases = Cases::new(cases);
    for n in 0..cases.end() {
        let c = draw(&mut rng);
        if !cases.runs(n) {
            continue;
        }
        let dir = tempdir();
        match check(n, &c, dir.path()) {
            Some((v, l)) => {
                done += 1;
                volume_worst = volume_worst.max(v.abs());
                layer_worst = layer_worst.max(l);
            }
            None => refused += 1,
        }
    }
    eprintln!(
        "{done} parts sliced ({refused} settings refused): volume within {:.3} %, layers within {:.3} %",
        100.0 * volume_worst,
        100.0 * layer_worst
    );
    assert!(
        cases.only.is_some() || done * 4 >= tier * 3,
        "too few cases ran"
    );
}

#[test]
fn implicit_slices_hold_the_mesh_at_random_settings() {
    property(0..4);
}

/// The next eighteen settings of the main tier's sequence.
#[test]
#[ignore = "long: eighteen more random parts sliced both ways"]
fn implicit_slices_hold_the_mesh_at_eighteen_more_random_settings() {
    property(4..22);
}

/// Voronoi foams, nets and sheets, random and periodic, with and without pores.
#[test]
fn implicit_slices_of_voronoi_foams_hold_the_mesh() {
    property_of(0..2, 0x0f0a_3546, draw_foam);
}

/// The next eight foams of the main tier's sequence.
#[test]
#[ignore = "long: eight more random Voronoi foams sliced both ways"]
fn implicit_slices_of_voronoi_foams_hold_the_mesh_at_eight_more_settings() {
    property_of(2..10, 0x0f0a_3546, draw_foam);
}

/// Each layer's loops from an ASCII CLI file: the layer's top height and its loops.
fn cli_loops(path: &Path) -> Vec<(f64, Vec<Vec<[f64; 2]>>)> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut layers: Vec<(f64, Vec<Vec<[f64; 2]>>)> = Vec::new();
    for line in text.lines() {
        if let Some(z) = line.strip_prefix("$$LAYER/") {
            layers.push((z.parse().unwrap(), Vec::new()));
        } else if let Some(p) = line.strip_prefix("$$POLYLINE/") {
            let v: Vec<f64> = p.split(',').map(|t| t.parse().unwrap()).collect();
            let n = v[2] as usize;
            let pts: Vec<[f64; 2]> = (0..n).map(|k| [v[3 + 2 * k], v[4 + 2 * k]]).collect();
            layers.last_mut().unwrap().1.push(pts);
        }
    }
    layers
}

/// Twice the signed area of a loop.
fn twice_area(l: &[[f64; 2]]) -> f64 {
    (0..l.len())
        .map(|i| {
            let (a, b) = (l[i], l[(i + 1) % l.len()]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum()
}

/// A point inside the region an outer loop bounds, among all the layer's loops: on a line across
/// the loop's middle, between its first crossing and the next crossing of any loop.
fn point_in(l: &[[f64; 2]], all: &[Vec<[f64; 2]>]) -> [f64; 2] {
    let (lo, hi) = l
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p[1]), b.max(p[1]))
        });
    let y = lo + (hi - lo) * 0.500_013_7;
    let crossings = |l: &[[f64; 2]]| -> Vec<f64> {
        (0..l.len())
            .filter_map(|i| {
                let (a, b) = (l[i], l[(i + 1) % l.len()]);
                ((a[1] - y) * (b[1] - y) < 0.0)
                    .then(|| a[0] + (y - a[1]) / (b[1] - a[1]) * (b[0] - a[0]))
            })
            .collect()
    };
    let first = crossings(l).into_iter().fold(f64::INFINITY, f64::min);
    let next = all
        .iter()
        .flat_map(|m| crossings(m))
        .filter(|&x| x > first)
        .fold(f64::INFINITY, f64::min);
    [0.5 * (first + next), y]
}

/// The generalised winding number of a closed shell about `p` (Van Oosterom and Strackee's
/// solid angle of each triangle).
fn winding(shell: &[Tri], p: [f64; 3]) -> f64 {
    let sub = |a: [f64; 3]| [a[0] - p[0], a[1] - p[1], a[2] - p[2]];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let norm = |a: [f64; 3]| dot(a, a).sqrt();
    let omega: f64 = shell
        .iter()
        .map(|t| {
            let (a, b, c) = (sub(t[0]), sub(t[1]), sub(t[2]));
            let det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0]);
            let (la, lb, lc) = (norm(a), norm(b), norm(c));
            let den = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
            2.0 * det.atan2(den)
        })
        .sum();
    omega / (4.0 * std::f64::consts::PI)
}

/// Loops of the implicit slices of `part` (a part file in `dir`) with a point inside one of
/// `fragments`, over the layers of `layer` mm.
fn loops_in_fragments(dir: &Path, part: &str, layer: f64, fragments: &[Vec<Tri>]) -> usize {
    ok(
        &[
            "slice",
            part,
            "-o",
            "l.cli",
            "--layer",
            &layer.to_string(),
            "-q",
        ],
        dir,
    );
    let mut found = 0;
    for (top, loops) in cli_loops(&dir.join("l.cli")) {
        let z = top - 0.5 * layer;
        for l in loops.iter().filter(|l| twice_area(l) > 0.0) {
            let q = point_in(l, &loops);
            let p = [q[0], q[1], z];
            let near = |f: &Vec<Tri>| {
                let (lo, hi) = bounds(f);
                (0..3).all(|a| p[a] >= lo[a] - 1e-6 && p[a] <= hi[a] + 1e-6)
            };
            if fragments
                .iter()
                .any(|f| near(f) && winding(f, p).abs() > 0.5)
            {
                found += 1;
            }
        }
    }
    found
}

/// The shells of an STL that keeps its fragments: the part (the largest) and the fragments (the
/// other outer shells).
fn part_and_fragments(stl: &Path) -> (Vec<Tri>, Vec<Vec<Tri>>) {
    let mut shells = shells(&read_stl(stl));
    shells.sort_by(|a, b| volume(b).total_cmp(&volume(a)));
    let fragments = shells.split_off(1);
    let part = shells.pop().expect("a part");
    (
        part,
        fragments.into_iter().filter(|s| volume(s) > 0.0).collect(),
    )
}

#[test]
fn the_fragments_the_mesh_drops_are_in_no_layer() {
    // A gyroid net at 0.15 in boxes of partial cells, which cut fragments loose: measured whole,
    // and on a template of its cells (whose fragments stand for every copy along x).
    for (size, measured_on) in [("11,6,9", "part"), ("27,11,9.3", "template")] {
        let dir = tempdir();
        let d = dir.path();
        ok(
            &[
                "tpms",
                "--type",
                "gyroid",
                "--density",
                "0.15",
                "--size",
                size,
                "--cell-size",
                "5",
                "-o",
                "p.stl",
                "--save-part",
                "p.toml",
                "--report",
                "p.json",
                "-q",
            ],
            d,
        );
        assert_eq!(
            json(&d.join("p.json"))["level_search"]["measured_on"],
            measured_on
        );
        ok(
            &[
                "tpms",
                "--part",
                "p.toml",
                "--keep-fragments",
                "-o",
                "k.stl",
                "--save-part",
                "k.toml",
                "-q",
            ],
            d,
        );
        let (_, fragments) = part_and_fragments(&d.join("k.stl"));
        assert!(
            !fragments.is_empty(),
            "{size}: the box cuts no fragment loose"
        );
        assert_eq!(pieces(&read_stl(&d.join("p.stl"))), 1);
        let layer = 0.05;
        let kept = loops_in_fragments(d, "k.toml", layer, &fragments);
        assert!(
            kept > 0,
            "{size}: no loop in a fragment where they are kept"
        );
        let dropped = loops_in_fragments(d, "p.toml", layer, &fragments);
        assert_eq!(
            dropped,
            0,
            "{size}: {dropped} loops of the implicit slices lie in the {} fragments the mesh drops ({kept} where they are kept)",
            fragments.len()
        );
    }
}

/// A part measured tile by tile holds no mesh: its fragments are meshed again where they lie.
/// The implicit model finds the same fragments (points inside each, from the mesh made with
/// `--keep-fragments`), the same level and the same volume fraction, whether the part is
/// measured whole or in tiles of 64 samples.
#[test]
fn fragments_found_tile_by_tile_are_the_whole_parts() {
    use latvox::field::Domain;
    use latvox::tpms::{Structure, Surface, TpmsJob};
    let dir = tempdir();
    let d = dir.path();
    ok(
        &[
            "tpms",
            "--type",
            "gyroid",
            "--density",
            "0.15",
            "--size",
            "11,6,9",
            "--cell-size",
            "5",
            "--keep-fragments",
            "-o",
            "k.stl",
            "-q",
        ],
        d,
    );
    let (part, fragments) = part_and_fragments(&d.join("k.stl"));
    let inside = |shell: &[Tri]| {
        // A point deep in the shell: the centre of its bounds, moved along a line through it
        // to the middle of the first stretch the shell holds.
        let (lo, hi) = bounds(shell);
        let c = [0, 1, 2].map(|a| 0.5 * (lo[a] + hi[a]));
        (0..400)
            .map(|k| {
                let t = k as f64 / 400.0;
                [lo[0] + t * (hi[0] - lo[0]), c[1], c[2]]
            })
            .filter(|p| winding(shell, *p) > 0.5)
            .nth(3)
    };
    let points: Vec<[f64; 3]> = fragments.iter().filter_map(|f| inside(f)).collect();
    assert!(!points.is_empty(), "no point found inside a fragment");
    let outside: Vec<[f64; 3]> = (0..50)
        .filter_map(|k| {
            let (lo, hi) = bounds(&part);
            let t = (k as f64 + 0.5) / 50.0;
            let p = [0, 1, 2].map(|a| lo[a] + t * (hi[a] - lo[a]));
            (winding(&part, p) > 0.5).then_some(p)
        })
        .collect();
    let job = |tile| TpmsJob {
        surface: Surface::Gyroid,
        structure: Structure::Net,
        density: 0.15,
        domain: Domain::from_size_and_cell([11.0, 6.0, 9.0], [5.0; 3], [0.0; 3]).unwrap(),
        resolution: 32,
        adaptivity: 0.0,
        tolerance: None,
        allow_islands: false,
        auto_resolution: true,
        verify: latvox::verify::Verify::Fast,
        instancing: true,
        tile,
        memory: None,
        keep_fragments: false,
        grading: None,
        blend: None,
        cell_map: None,
    };
    let volume = latvox::render::Fidelity::Volume;
    let whole = job(None).model(volume).unwrap();
    let tiled = job(Some(64)).model(volume).unwrap();
    for m in [&whole, &tiled] {
        for p in &points {
            assert!(m.loose.contains(*p), "{p:?} lies in a fragment");
        }
        for p in &outside {
            assert!(!m.loose.contains(*p), "{p:?} lies in the part");
        }
    }
    assert!(
        (whole.level - tiled.level).abs() < 1e-3,
        "levels {} and {}",
        whole.level,
        tiled.level
    );
    eprintln!(
        "{} points in fragments, {} in the part; levels {} whole, {} tiled",
        points.len(),
        outside.len(),
        whole.level,
        tiled.level
    );
}
