//! Meshes sized by a tolerance (`--tolerance MM`): checked against the published TPMS formulas
//! (the test's own sampling of the written triangles), CGAL's verdict, the enclosed volume and
//! the uniform mesh of the same part.

use crate::common::*;
use crate::meshkit;
use std::path::Path;

/// The largest distance from points sampled on `tris` ([`worst_on`]'s barycentric grid) to the
/// surface of the TPMS part in `bounds`: the level set `F = t` (a net) or `|F| = t` (a sheet),
/// to first order `|F − t| / |∇F|`, or the box's face where that is nearer (the part is cut by
/// its box).
fn deviation(
    tris: &[Tri],
    ty: &str,
    sheet: bool,
    t: f64,
    cell: f64,
    bounds: ([f64; 3], [f64; 3]),
) -> f64 {
    worst_on(tris, |p| {
        let local = [0, 1, 2].map(|k| p[k] - bounds.0[k]);
        let (f, g) = tpms(ty, local, cell);
        let gl = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
        let surface = if sheet {
            (f.abs() - t).abs() / gl
        } else {
            (f - t).abs() / gl
        };
        let face = (0..3)
            .map(|k| (p[k] - bounds.0[k]).min(bounds.1[k] - p[k]))
            .fold(f64::INFINITY, f64::min);
        surface.min(face.max(0.0))
    })
}

/// Makes a TPMS part with `args` (a uniform one beside it) and checks the simplified one:
/// CGAL finds it a closed, outward solid without self-intersections, one piece, at its density
/// (the test's own volume of the written triangles), in its box, within the tolerance of the
/// exact surface, with at least `fewer` times fewer triangles than the uniform mesh.
fn check_tpms(
    dir: &Path,
    ty: &str,
    sheet: bool,
    density: f64,
    args: &[&str],
    tolerance: f64,
    fewer: f64,
) {
    let tol = tolerance.to_string();
    let d = density.to_string();
    let structure = if sheet { "sheet" } else { "net" };
    let common = [
        &[
            "tpms",
            "--type",
            ty,
            "--structure",
            structure,
            "--density",
            &d,
        ][..],
        args,
    ]
    .concat();
    let uniform = dir.join("uniform.stl");
    ok(
        &[&common[..], &["-o", uniform.to_str().unwrap()]].concat(),
        dir,
    );
    let (stl, report) = (dir.join("simplified.stl"), dir.join("simplified.json"));
    let run_args = [
        &common[..],
        &[
            "--tolerance",
            &tol,
            "--verify",
            "cgal",
            "-o",
            stl.to_str().unwrap(),
        ],
        &["--report", report.to_str().unwrap()],
    ]
    .concat();
    ok(&run_args, dir);
    let r = json(&report);
    let what = format!("{ty} {structure} {args:?} at {tolerance} mm");
    let checks = &r["checks"];
    for key in ["closed", "manifold", "outward"] {
        assert_eq!(checks[key], true, "{what}: {key}");
    }
    assert_eq!(checks["self_intersecting"], false, "{what}");
    assert_eq!(checks["checked_by"], "CGAL", "{what}");
    let tris = read_stl(&stl);
    let topo = meshkit::topo(&tris);
    assert_eq!(topo.boundary, 0, "{what}");
    assert_eq!(pieces(&tris), 1, "{what}");
    let b = &r["box"];
    let lo = [0, 1, 2].map(|k| b["min"][k].as_f64().unwrap());
    let hi = [0, 1, 2].map(|k| b["max"][k].as_f64().unwrap());
    let box_volume: f64 = (0..3).map(|k| hi[k] - lo[k]).product();
    let achieved = volume(&tris) / box_volume;
    assert!(
        (achieved - density).abs() <= 0.002,
        "{what}: density {achieved}"
    );
    let (blo, bhi) = bounds(&tris);
    for k in 0..3 {
        assert!(
            (blo[k] - lo[k]).abs() <= tolerance && (bhi[k] - hi[k]).abs() <= tolerance,
            "{what}: bounds"
        );
    }
    let cell = r["cell_size"][0].as_f64().unwrap();
    let t = r["level"].as_f64().unwrap();
    let dev = deviation(&tris, ty, sheet, t, cell, (lo, hi));
    assert!(dev <= tolerance, "{what}: deviation {dev} mm");
    let reported = r["simplified"]["deviation"].as_f64().unwrap();
    assert!(
        reported <= tolerance && reported >= 0.5 * dev,
        "{what}: reported {reported}, measured {dev}"
    );
    let before = read_stl(&uniform).len() as f64;
    let ratio = before / tris.len() as f64;
    assert!(ratio >= fewer, "{what}: {ratio:.1}× fewer triangles");
    assert_eq!(
        r["simplified"]["uniform_triangles"].as_f64().unwrap(),
        before,
        "{what}"
    );
}

/// At half a voxel (5 mm cells at 32 voxels: 0.078 mm, about the deviation the uniform mesh has
/// at the box's cut edges) a gyroid net and a Schwarz D sheet keep every promise with over ten
/// times fewer triangles.
#[test]
fn tpms_at_half_a_voxel_are_valid_exact_and_ten_times_smaller() {
    let dir = tempdir();
    check_tpms(
        dir.path(),
        "gyroid",
        false,
        0.3,
        &["--cells", "3"],
        0.078,
        10.0,
    );
    check_tpms(dir.path(), "d", true, 0.3, &["--cells", "2"], 0.078, 10.0);
}

/// A strut lattice at half a voxel: valid by CGAL, one piece, its density kept, its triangles a
/// fifth of the uniform mesh's or fewer; the deviation reported within the tolerance.
#[test]
fn struts_at_half_a_voxel_are_valid_and_exact() {
    let dir = tempdir();
    let d = dir.path();
    let common = [
        "strut",
        "--cell",
        "kelvin",
        "--density",
        "0.15",
        "--cells",
        "2",
    ];
    ok(&[&common[..], &["-o", "u.stl"]].concat(), d);
    let args = [
        &common[..],
        &[
            "--tolerance",
            "0.078",
            "--verify",
            "cgal",
            "-o",
            "s.stl",
            "--report",
            "s.json",
        ],
    ]
    .concat();
    ok(&args, d);
    let r = json(&d.join("s.json"));
    assert_eq!(r["checks"]["checked_by"], "CGAL");
    for key in ["closed", "manifold", "outward"] {
        assert_eq!(r["checks"][key], true, "{key}");
    }
    assert_eq!(r["checks"]["self_intersecting"], false);
    let tris = read_stl(&d.join("s.stl"));
    assert_eq!(pieces(&tris), 1);
    let achieved = volume(&tris) / 1000.0;
    assert!((achieved - 0.15).abs() <= 0.002, "density {achieved}");
    assert!(r["simplified"]["deviation"].as_f64().unwrap() <= 0.078);
    let ratio = read_stl(&d.join("u.stl")).len() as f64 / tris.len() as f64;
    assert!(ratio >= 5.0, "{ratio:.1}× fewer");
}

/// For random types, structures, densities, tolerances, boxes that are not whole cells, and
/// origins: never an invalid mesh, never beyond the tolerance, the density kept.
#[test]
fn random_settings_never_break_a_promise() {
    let mut rng = Rng(45);
    let dir = tempdir();
    for _ in 0..3 {
        let ty = ["gyroid", "d", "p", "iwp"][rng.below(4) as usize];
        let sheet = rng.below(2) == 1;
        let density = rng.uniform(0.3, 0.45);
        let cell = rng.uniform(3.0, 6.0);
        let resolution = 16 + rng.below(12);
        let voxel = cell / resolution as f64;
        let tolerance = voxel * rng.uniform(0.45, 1.2);
        let size = [0, 1, 2].map(|_| cell * rng.uniform(1.3, 2.4));
        let origin = [0, 1, 2].map(|_| rng.uniform(-7.0, 7.0));
        let size = format!("{:.3},{:.3},{:.3}", size[0], size[1], size[2]);
        let origin = format!("{:.3},{:.3},{:.3}", origin[0], origin[1], origin[2]);
        let line = format!("--cell-size {cell:.3} --size {size} --origin {origin} -r {resolution}");
        let args: Vec<&str> = line.split_whitespace().collect();
        check_tpms(
            dir.path(),
            ty,
            sheet,
            (density * 1000.0f64).round() / 1000.0,
            &args,
            tolerance,
            2.0,
        );
    }
}

/// A tolerance that is not a positive length is refused: one line, exit 2, nothing written.
#[test]
fn tolerance_must_be_a_positive_length() {
    let dir = tempdir();
    for bad in ["0", "-0.1", "nan", "mm"] {
        let args = ["tpms", "--cells", "1", "--tolerance", bad, "-o", "x.stl"];
        let before = files_in(dir.path());
        let out = run(&args, dir.path());
        assert_refusal(dir.path(), &before, &out, &args, "tolerance");
    }
}

/// `--adaptivity`, once OpenVDB's adaptive meshing (a 4×4×4-cell gyroid net at 0.3 came out
/// self-intersecting at 0.1 and 0.3), is now a tolerance of that many voxels: valid by CGAL, its
/// density kept, fewer triangles than the uniform mesh.
#[test]
fn adaptivity_is_a_tolerance_in_voxels() {
    let dir = tempdir();
    let d = dir.path();
    let line = "tpms --type gyroid --density 0.3 --cells 3 --adaptivity 0.3 --verify cgal";
    let args: Vec<&str> = line
        .split(' ')
        .chain(["-o", "a.stl", "--report", "a.json"])
        .collect();
    ok(&args, d);
    let r = json(&d.join("a.json"));
    assert_eq!(r["checks"]["checked_by"], "CGAL");
    assert_eq!(r["checks"]["self_intersecting"], false);
    assert_eq!(r["checks"]["closed"], true);
    let s = &r["simplified"];
    let voxel = r["voxel_size"].as_f64().unwrap();
    assert!((s["tolerance"].as_f64().unwrap() - 0.3 * voxel).abs() < 1e-12);
    let tris = read_stl(&d.join("a.stl"));
    assert!((volume(&tris) / 3375.0 - 0.3).abs() <= 0.002);
    assert!(tris.len() * 5 < s["uniform_triangles"].as_u64().unwrap() as usize);
}
