//! The `latvox fill` command, run as a user runs it: parts the test writes itself (a box and a
//! torus, whose inner offsets — the skin's inside — are known in closed form), a real part from
//! CGAL's data (Debian's libcgal-demo), solids kept whole, refusals, and a seeded property test
//! over random lattices, skins, cell sizes and boxes at odd origins. Every written mesh is read
//! back by this test's own STL reader: volume by the divergence theorem, edges by hash map,
//! pieces by shared corners; CGAL's verdict comes from the report.

use crate::common::*;
use crate::meshkit::{torus as torus_tris, write_stl};
use crate::{common, meshkit};
use std::f64::consts::PI;
use std::path::Path;

/// A box `[lo, lo + size]`.
fn box_tris(lo: [f64; 3], size: [f64; 3]) -> Vec<Tri> {
    meshkit::cuboid(lo, [0, 1, 2].map(|a| lo[a] + size[a]))
}

fn torus_volume(big: f64, small: f64) -> f64 {
    2.0 * PI * PI * big * small * small
}

/// Runs `latvox fill` in `dir`, writing `part.stl` and `part.json`.
fn fill(dir: &Path, args: &[&str]) -> std::process::Output {
    let mut all = vec!["fill", "-q", "--report", "part.json", "-o", "part.stl"];
    all.extend_from_slice(args);
    run(&all, dir)
}

/// What the written part is, by this test's reckoning and by the report.
struct Filled {
    report: serde_json::Value,
    volume: f64,
}

/// Fills, asserts success, a closed, one-piece mesh that CGAL finds sound, and the report's
/// volume equal to the one this test measures; returns both.
fn filled(dir: &Path, args: &[&str]) -> Filled {
    let out = fill(dir, args);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report = json(&dir.join("part.json"));
    let tris = read_stl(&dir.join("part.stl"));
    let e = edges(&tris);
    assert_eq!(
        e.boundary + e.non_manifold,
        0,
        "{args:?}: open or non-manifold"
    );
    assert_eq!(pieces(&tris), 1, "{args:?}: not one piece");
    let c = &report["checks"];
    for key in ["closed", "manifold", "outward"] {
        assert_eq!(c[key], true, "{args:?}: CGAL says not {key}");
    }
    assert_eq!(c["self_intersecting"], false, "{args:?}: self-intersecting");
    let volume = common::volume(&tris);
    let reported = report["volume"].as_f64().unwrap();
    assert!(
        (volume - reported).abs() <= 1e-6 * volume.abs().max(1.0),
        "{args:?}: volume {volume} read back, {reported} reported"
    );
    Filled { report, volume }
}

fn f(v: &serde_json::Value, key: &str) -> f64 {
    v[key]
        .as_f64()
        .unwrap_or_else(|| panic!("{key} missing in {v}"))
}

/// A box and a torus with a 1 mm skin and the lattice at 0.2: the part's volume is the skin's
/// (the part less its inner offset, in closed form) plus 0.2 of the core's, within 0.005 of the
/// core's volume. The torus is written with 256 × 128 facets: its volume is within 0.03 % of
/// the smooth torus', far inside the tolerance.
#[test]
fn a_box_and_a_torus_hold_their_skin_and_a_fifth_of_their_core() {
    let dir = tempdir();
    let d = dir.path();
    write_stl(&d.join("box.stl"), &box_tris([0.0; 3], [20.0; 3]));
    write_stl(&d.join("torus.stl"), &torus_tris(15.0, 5.0, 256, 128));
    let cases = [
        ("box.stl", "gyroid", 20f64.powi(3), 18f64.powi(3)),
        ("box.stl", "octet", 20f64.powi(3), 18f64.powi(3)),
        (
            "torus.stl",
            "bcc",
            torus_volume(15.0, 5.0),
            torus_volume(15.0, 4.0),
        ),
    ];
    for (part, lattice, whole, core) in cases {
        let args = [
            part,
            "--skin",
            "1",
            "--lattice",
            lattice,
            "--cell-size",
            "4",
            "--density",
            "0.2",
            "--resolution",
            "16",
        ];
        let p = filled(d, &args);
        let want = (whole - core) + 0.2 * core;
        assert!(
            (p.volume - want).abs() <= 0.005 * core,
            "{part} with {lattice}: volume {:.2}, skin + 0.2 core {want:.2} (±{:.2})",
            p.volume,
            0.005 * core
        );
        assert!((f(&p.report, "achieved_density") - 0.2).abs() <= 0.002);
        assert!((f(&p.report, "fill_volume") - core).abs() <= 0.005 * core);
    }
}

/// A mechanical part from CGAL's data (1 mm across), filled with an octet truss: sound, one
/// piece, the density of its fill as asked.
#[test]
fn a_real_part_is_filled_and_sound() {
    let dir = tempdir();
    let part = meshkit::cgal_data().join("couplingdown.off");
    let part = part.to_str().unwrap();
    let args = [
        part,
        "--skin",
        "0.03",
        "--lattice",
        "octet",
        "--cell-size",
        "0.12",
        "--density",
        "0.2",
        "--resolution",
        "16",
    ];
    let p = filled(dir.path(), &args);
    assert!((f(&p.report, "achieved_density") - 0.2).abs() <= 0.002);
    // The part as read: its volume, by this test, against the report's solid part.
    let whole = common::volume(&meshkit::read_off(std::path::Path::new(part)));
    assert!(
        (f(&p.report, "part_volume") / whole - 1.0).abs() < 0.01,
        "part {} against {whole}",
        f(&p.report, "part_volume")
    );
}

/// A skin closes the lattice's void: the part encloses it (reported, with a warning, and found
/// here as a shell of negative volume in the file). Drain holes (`--drain 2`) open it — no
/// enclosed void left in the file — and keep the part sound, one piece, at its density; the
/// holes' axes cross the skin at the lowest and highest facets.
#[test]
fn drain_holes_open_the_void_a_skin_encloses() {
    let dir = tempdir();
    let d = dir.path();
    write_stl(&d.join("box.stl"), &box_tris([0.0; 3], [20.0; 3]));
    let voids = |d: &Path| {
        shell_volumes(&read_stl(&d.join("part.stl")))
            .iter()
            .filter(|&&v| v < 0.0)
            .count()
    };
    let args = ["box.stl", "--cell-size", "5", "--resolution", "12"];
    let closed = filled(d, &args);
    assert_eq!(voids(d), 1, "a skinned part encloses the lattice's void");
    assert_eq!(closed.report["fragments"]["cavities"], 1);
    let warned = closed.report["warnings"].as_array().unwrap();
    assert!(
        warned
            .iter()
            .any(|w| w.as_str().unwrap().contains("--drain")),
        "{warned:?}"
    );
    let mut drained_args = args.to_vec();
    drained_args.extend(["--drain", "2"]);
    let drained = filled(d, &drained_args);
    assert_eq!(voids(d), 0, "the drain holes leave an enclosed void");
    let r = &drained.report;
    assert_eq!(r["fragments"]["cavities"], 0);
    assert!((f(r, "achieved_density") - 0.2).abs() <= 0.002);
    let holes = r["drains"].as_array().unwrap();
    assert_eq!(holes.len(), 2);
    for (h, z) in holes.iter().zip([0.0, 20.0]) {
        assert!((h["from"][2].as_f64().unwrap() - z).abs() < 1e-9, "{h}");
        assert_eq!(h["radius"], 1.0);
    }
    // Less material than the closed part by about the two holes through the skin.
    let hole = PI * 1.0 * 1.0 * 1.0;
    assert!(
        closed.volume - drained.volume > hole,
        "{} against {}",
        drained.volume,
        closed.volume
    );
}

/// `torus.stl` without a skin, cut from a sheet gyroid at 0.3 in 4 mm cells: an open-cell part
/// whose surface cuts fragments loose.
const OPEN_TORUS: [&str; 10] = [
    "torus.stl",
    "--no-skin",
    "--lattice",
    "gyroid",
    "--structure",
    "sheet",
    "--cell-size",
    "4",
    "--density",
    "0.3",
];

/// A part meshed in tiles finds its pieces across them: the fragments that a torus's surface
/// cuts loose from an open-cell lattice are dropped from the tiles as from the whole part — the
/// same triangles (as sorted records of the two files), the same fragments counted — at small
/// tiles (many seams) and large ones, and what is written is one piece by this test's count.
#[test]
fn tiles_drop_the_fragments_the_whole_part_drops() {
    let dir = tempdir();
    let d = dir.path();
    write_stl(&d.join("torus.stl"), &torus_tris(12.0, 4.0, 192, 96));
    let mut common = OPEN_TORUS.to_vec();
    common.extend(["--resolution", "12"]);
    let records = |p: &Path| {
        let mut r: Vec<[u64; 9]> = read_stl(p)
            .iter()
            .map(|t| {
                let c = t.concat();
                std::array::from_fn(|i| c[i].to_bits())
            })
            .collect();
        r.sort_unstable();
        r
    };
    let whole = filled(d, &common);
    let whole_records = records(&d.join("part.stl"));
    let fragments = &whole.report["fragments"];
    assert!(
        fragments["count"].as_u64().unwrap() > 0,
        "the case must cut fragments loose: {fragments}"
    );
    for tile in ["16", "48"] {
        let mut args = common.to_vec();
        args.extend(["--tile", tile]);
        let tiled = filled(d, &args);
        let r = &tiled.report;
        assert!(r["tiling"]["tiles"].as_u64().unwrap() > 4, "tile {tile}");
        let g = &r["fragments"];
        assert_eq!(g["count"], fragments["count"], "tile {tile}: fragments");
        assert_eq!(g["removed"], true, "tile {tile}: fragments");
        assert!(
            (f(g, "volume") - f(fragments, "volume")).abs() <= 1e-9 * whole.volume,
            "tile {tile}: fragments' volume {g} against {fragments}"
        );
        assert_eq!(r["one_piece"], true, "tile {tile}");
        assert_eq!(r["vertices"], whole.report["vertices"], "tile {tile}");
        assert!(
            records(&d.join("part.stl")) == whole_records,
            "tile {tile}: the tiled part's triangles differ from the whole part's"
        );
    }
}

/// Without a skin the part is the lattice cut by its surface (fragments it cuts loose
/// removed); a kept solid stays whole inside a skinned part, and the density is the lattice's
/// share of the rest of the core.
#[test]
fn no_skin_and_kept_solids() {
    let dir = tempdir();
    let d = dir.path();
    write_stl(&d.join("torus.stl"), &torus_tris(15.0, 5.0, 256, 128));
    let mut args = OPEN_TORUS.to_vec();
    args.extend(["--resolution", "16"]);
    let p = filled(d, &args);
    let whole = torus_volume(15.0, 5.0);
    assert_eq!(f(&p.report, "skin_volume"), 0.0);
    assert!(
        (p.volume - 0.3 * whole).abs() <= 0.005 * whole,
        "{} against {}",
        p.volume,
        0.3 * whole
    );

    write_stl(&d.join("box.stl"), &box_tris([0.0; 3], [20.0; 3]));
    write_stl(&d.join("boss.stl"), &box_tris([7.0; 3], [6.0; 3]));
    let p = filled(
        d,
        &[
            "box.stl",
            "--keep",
            "boss.stl",
            "--lattice",
            "bcc",
            "--cell-size",
            "4",
            "--resolution",
            "16",
        ],
    );
    let (skin, core, boss) = (8000.0 - 5832.0, 5832.0, 216.0);
    let want = skin + boss + 0.2 * (core - boss);
    assert!(
        (p.volume - want).abs() <= 0.005 * core,
        "{} against {want}",
        p.volume
    );
    // The boss is solid: its centre and points near its corners lie inside the written part.
    let tris = read_stl(&d.join("part.stl"));
    for q in [[10.0; 3], [7.3, 7.3, 7.3], [12.7, 7.3, 12.7]] {
        assert!(inside(&tris, q), "{q:?} is not solid");
    }
}

/// Whether `q` lies inside the closed mesh `tris` (the parity of crossings of a ray along a
/// direction no facet of these parts is parallel to).
fn inside(tris: &[Tri], q: [f64; 3]) -> bool {
    let dir = [0.5773, 0.5774, 0.5775];
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let mut n = 0;
    for t in tris {
        // Möller–Trumbore.
        let (e1, e2) = (sub(t[1], t[0]), sub(t[2], t[0]));
        let p = cross(dir, e2);
        let det = dot(e1, p);
        if det.abs() < 1e-12 {
            continue;
        }
        let s = sub(q, t[0]);
        let u = dot(s, p) / det;
        let qv = cross(s, e1);
        let v = dot(dir, qv) / det;
        let w = dot(e2, qv) / det;
        if u >= 0.0 && v >= 0.0 && u + v <= 1.0 && w > 0.0 {
            n += 1;
        }
    }
    n % 2 == 1
}

/// Asserts a refusal: exit 2, one line on stderr, naming `what`, no file left behind.
fn assert_refused(dir: &Path, args: &[&str], what: &str) {
    let before = files_in(dir);
    let out = fill(dir, args);
    assert_refusal(dir, &before, &out, args, what);
}

#[test]
fn bad_input_is_refused_in_one_line() {
    let dir = tempdir();
    let d = dir.path();
    write_stl(&d.join("box.stl"), &box_tris([0.0; 3], [20.0; 3]));
    write_stl(&d.join("slab.stl"), &box_tris([0.0; 3], [3.0, 20.0, 20.0]));
    write_stl(
        &d.join("triangle.stl"),
        &[[[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [0.0, 10.0, 0.0]]],
    );
    std::fs::write(d.join("empty.stl"), b"").unwrap();
    std::fs::write(d.join("nofacets.stl"), b"solid x\nendsolid x\n").unwrap();
    std::fs::create_dir(d.join("folder.stl")).unwrap();
    std::fs::write(
        d.join("cell.json"),
        br#"{"nodes": [[0,0,0]], "struts": [[0, 5]]}"#,
    )
    .unwrap();
    std::fs::write(d.join("broken.json"), b"{\"nodes\": [[0,0").unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&[], "<PART>"),
        (&["missing.stl"], "missing.stl"),
        (&["empty.stl"], "empty.stl"),
        (&["nofacets.stl"], "no facets"),
        (&["folder.stl"], "folder.stl"),
        (&["triangle.stl"], "repair could not close it"),
        (&["slab.stl", "--skin", "2"], "leaves no room"),
        (&["box.stl", "--cell-size", "0"], "cell-size"),
        (&["box.stl", "--cell-size", "-2"], "cell-size"),
        (&["box.stl", "--lattice", "cell.json"], "cell.json"),
        (&["box.stl", "--lattice", "broken.json"], "broken.json"),
        (&["box.stl", "--lattice", "nosuch"], "unknown lattice"),
        (&["box.stl", "--keep", "missing.stl"], "missing.stl"),
        (&["box.stl", "--density", "1.2"], "density"),
        (&["box.stl", "--skin", "-1"], "skin"),
        (&["box.stl", "--skin", "1", "--no-skin"], "--no-skin"),
        (&["box.stl", "--no-skin", "--drain", "2"], "--no-skin"),
        (&["box.stl", "--drain", "0"], "drain"),
        (&["box.stl", "--drain", "11"], "too wide"),
        (&["box.stl", "--spacing", "2"], "--lattice voronoi"),
        (
            &["box.stl", "--lattice", "octet", "--seed", "3"],
            "--lattice voronoi",
        ),
        (
            &["box.stl", "--lattice", "voronoi", "--structure", "sheet"],
            "Voronoi net",
        ),
        (
            &["box.stl", "--lattice", "voronoi", "--spacing", "3"],
            "under 2 spacings",
        ),
    ];
    for (args, what) in cases {
        assert_refused(d, args, what);
    }
}

/// For random lattices, skins, cell sizes, densities and boxes that are not whole cells, at
/// odd origins, whole or in tiles of random size: the part is sound and one piece, the fill's density within 0.002 of the target,
/// and the regions latvox measured agree with the box's (its skin: the box less the box shrunk
/// by the skin on every side) — up to the rounding of the box's edges: the distance field is
/// sampled on voxels, so each edge loses a sliver of about half a voxel squared per mm of edge
/// (measured 0.4–0.5 v²), which is allowed for here.
#[test]
fn every_setting_gives_a_sound_part_at_its_density() {
    let dir = tempdir();
    let d = dir.path();
    let mut rng = Rng(0x5eed_f111);
    let lattices = ["gyroid", "d", "p", "bcc", "octet", "kelvin", "fccz"];
    for case in 0..6 {
        let size = [0, 1, 2].map(|_| rng.uniform(9.0, 16.0));
        let lo = [0, 1, 2].map(|_| rng.uniform(-40.0, 40.0));
        write_stl(&d.join("part.in.stl"), &box_tris(lo, size));
        let lattice = lattices[rng.below(lattices.len() as u64) as usize];
        let cell = rng.uniform(2.5, 4.0);
        let density = rng.uniform(0.15, 0.35);
        let skin = if rng.below(4) == 0 {
            0.0
        } else {
            rng.uniform(0.6, 1.5)
        };
        // Every other part in tiles (found in pieces across them, fragments dropped).
        let tile = ["16", "24", "32", "40"][rng.below(4) as usize];
        let tiled = case % 2 == 1;
        let (cell_s, density_s, skin_s) = (
            format!("{cell:.3}"),
            format!("{density:.3}"),
            format!("{skin:.3}"),
        );
        let mut args = vec![
            "part.in.stl",
            "--lattice",
            lattice,
            "--cell-size",
            &cell_s,
            "--density",
            &density_s,
            "--resolution",
            "12",
        ];
        if skin == 0.0 {
            args.push("--no-skin");
        } else {
            args.extend_from_slice(&["--skin", &skin_s]);
        }
        if tiled {
            args.extend_from_slice(&["--tile", tile]);
        }
        let p = filled(d, &args);
        // The target is what the command line said.
        let density: f64 = density_s.parse().unwrap();
        if tiled {
            assert!(p.report["tiling"]["tiles"].as_u64().unwrap() > 1);
            assert_eq!(p.report["one_piece"], true, "case {case}: {args:?}");
        }
        let r = &p.report;
        let what = format!("case {case}: {args:?}");
        assert!(
            (f(r, "achieved_density") - density).abs() <= 0.002,
            "{what}: density {}",
            f(r, "achieved_density")
        );
        let whole = size[0] * size[1] * size[2];
        let core: f64 = size.iter().map(|s| s - 2.0 * skin).product();
        let v = f(r, "voxel_size");
        let edges = 0.6 * v * v * 4.0 * size.iter().sum::<f64>();
        assert!(
            (f(r, "part_volume") - whole).abs() <= 0.005 * core + edges,
            "{what}: part {} against {whole}",
            f(r, "part_volume")
        );
        assert!(
            (f(r, "fill_volume") - core).abs() <= 0.005 * core + edges,
            "{what}: fill {} against {core}",
            f(r, "fill_volume")
        );
        let b = bounds(&read_stl(&d.join("part.stl")));
        for a in 0..3 {
            assert!(
                b.0[a] >= lo[a] - v && b.1[a] <= lo[a] + size[a] + v,
                "{what}: bounds {b:?}"
            );
        }
    }
}

/// A fill run's settings saved as a part file make the same part again, byte for byte, from
/// another folder (the part's mesh and the kept solids are saved by absolute path); options on
/// the command line override the file's; a batch job can name the part file.
#[test]
fn part_files_make_the_same_filled_part_again() {
    let dir = tempdir();
    let d = dir.path();
    write_stl(&d.join("box.stl"), &box_tris([0.0; 3], [12.0; 3]));
    write_stl(&d.join("boss.stl"), &box_tris([4.0; 3], [4.0; 3]));
    let args = [
        "fill",
        "-q",
        "box.stl",
        "--keep",
        "boss.stl",
        "--lattice",
        "kelvin",
        "--cell-size",
        "4",
        "--resolution",
        "12",
        "-o",
        "first.stl",
        "--save-part",
        "box.toml",
    ];
    assert_eq!(run(&args, d).status.code(), Some(0));
    let sub = d.join("elsewhere");
    std::fs::create_dir(&sub).unwrap();
    let again = run(
        &["fill", "-q", "--part", "../box.toml", "-o", "again.stl"],
        &sub,
    );
    assert_eq!(again.status.code(), Some(0), "{:?}", again);
    assert!(
        std::fs::read(d.join("first.stl")).unwrap()
            == std::fs::read(sub.join("again.stl")).unwrap(),
        "the part file made another part"
    );
    let finer = run(
        &[
            "fill",
            "-q",
            "--part",
            "../box.toml",
            "-r",
            "16",
            "-o",
            "finer.stl",
            "--report",
            "finer.json",
        ],
        &sub,
    );
    assert_eq!(finer.status.code(), Some(0));
    assert_eq!(json(&sub.join("finer.json"))["resolution"], 16);
    std::fs::write(
        d.join("jobs.toml"),
        "[[job]]\ncommand = \"fill\"\npart = \"box.toml\"\noutput = \"batch.stl\"\n",
    )
    .unwrap();
    let batch = run(&["batch", "-q", "jobs.toml"], d);
    assert_eq!(batch.status.code(), Some(0), "{:?}", batch);
    assert!(
        std::fs::read(d.join("first.stl")).unwrap() == std::fs::read(d.join("batch.stl")).unwrap(),
        "the batch job made another part"
    );
}

/// A skin under two voxels raises the resolution (with a warning saying why), or is refused
/// with `--fixed-resolution`, naming the resolution that works.
#[test]
fn a_thin_skin_raises_the_resolution() {
    let dir = tempdir();
    let d = dir.path();
    write_stl(&d.join("box.stl"), &box_tris([0.0; 3], [8.0; 3]));
    let args = [
        "box.stl",
        "--skin",
        "0.3",
        "--lattice",
        "gyroid",
        "--cell-size",
        "4",
        "--resolution",
        "12",
    ];
    let p = filled(d, &args);
    // 0.3 mm at 12 voxels per 4 mm cell is 0.9 voxels: 2 voxels need 27 per cell, raised to
    // whole 8-voxel blocks.
    assert_eq!(p.report["resolution"], 32);
    let warnings = p.report["warnings"].to_string();
    assert!(
        warnings.contains("the skin was 0.90 voxels thick"),
        "{warnings}"
    );
    let mut fixed = args.to_vec();
    fixed.push("--fixed-resolution");
    assert_refused(d, &fixed, "--resolution 27");
}
