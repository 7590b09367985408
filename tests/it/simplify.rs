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

/// What `--tolerance auto` stands for in the report `r`: half a voxel, or the uniform mesh's
/// deviation where larger.
fn auto_tolerance(r: &serde_json::Value, what: &str) -> f64 {
    let s = &r["simplified"];
    assert_eq!(s["auto"], true, "{what}");
    let half = 0.5 * r["voxel_size"].as_f64().unwrap();
    let uniform = s["uniform_deviation"].as_f64().unwrap();
    half.max(uniform)
}

/// Makes a TPMS part with `args` (a uniform one beside it) and checks the simplified one:
/// CGAL finds it a closed, outward solid without self-intersections, one piece, at its density
/// (the test's own volume of the written triangles), in its box, within the tolerance of the
/// exact surface, with at least `fewer` times fewer triangles than the uniform mesh. A
/// tolerance of `None` is `--tolerance auto` ([`auto_tolerance`]).
fn check_tpms(
    dir: &Path,
    ty: &str,
    sheet: bool,
    density: f64,
    args: &[&str],
    tolerance: Option<f64>,
    fewer: f64,
) {
    let tol = tolerance.map_or("auto".to_string(), |t| t.to_string());
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
    let what = format!("{ty} {structure} {args:?} at {tol} mm");
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
    let cell = r["cell_size"][0].as_f64().unwrap();
    let t = r["level"].as_f64().unwrap();
    let tolerance = tolerance.unwrap_or_else(|| auto_tolerance(&r, &what));
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
    let dev = deviation(&tris, ty, sheet, t, cell, (lo, hi));
    assert!(
        dev <= tolerance,
        "{what}: deviation {dev} mm, at most {tolerance}"
    );
    let reported = r["simplified"]["deviation"].as_f64().unwrap();
    let asked = r["simplified"]["tolerance"].as_f64().unwrap();
    assert!(
        reported <= asked && reported >= 0.5 * dev,
        "{what}: reported {reported}, measured {dev}"
    );
    let before = read_stl(&uniform).len() as f64;
    let ratio = before / tris.len() as f64;
    eprintln!(
        "{what}: {before} → {} triangles ({ratio:.1}×), deviation {dev:.4} mm (test), {reported:.4} (latvox), tolerance {tolerance:.4}",
        tris.len()
    );
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
        Some(0.078),
        10.0,
    );
    check_tpms(
        dir.path(),
        "d",
        true,
        0.3,
        &["--cells", "2"],
        Some(0.078),
        10.0,
    );
}

/// The largest distance from points sampled on `tris` ([`worst_on`]) to the surface of the strut
/// lattice of built-in `cell` (capsules of `radius` on its struts, cells of `size` mm from the box's
/// lower corner) cut by the box `bounds`: the capsules' exact distance (outside them; inside, the
/// nearest capsule's, a lower bound), or the box's face where that is nearer.
fn strut_deviation(
    tris: &[Tri],
    cell: &str,
    radius: f64,
    size: f64,
    bounds: ([f64; 3], [f64; 3]),
) -> f64 {
    let unit = latvox::strut::UnitCell::built_in(cell).unwrap();
    let segments: Vec<([f64; 3], [f64; 3])> = unit
        .struts
        .iter()
        .map(|&[a, b]| {
            (
                unit.nodes[a].map(|x| x * size),
                unit.nodes[b].map(|x| x * size),
            )
        })
        .collect();
    worst_on(tris, |p| {
        let local = [0, 1, 2].map(|k| p[k] - bounds.0[k]);
        let home = local.map(|x| (x / size).floor());
        let mut nearest = f64::INFINITY;
        for o in 0..27 {
            let shift = [o % 3, o / 3 % 3, o / 9].map(|i| i as f64 - 1.0);
            let corner = [0, 1, 2].map(|k| (home[k] + shift[k]) * size);
            let q = [0, 1, 2].map(|k| local[k] - corner[k]);
            for (a, b) in &segments {
                let ab = [0, 1, 2].map(|k| b[k] - a[k]);
                let aq = [0, 1, 2].map(|k| q[k] - a[k]);
                let len2: f64 = ab.iter().map(|x| x * x).sum();
                let t = ((0..3).map(|k| aq[k] * ab[k]).sum::<f64>() / len2).clamp(0.0, 1.0);
                let d2: f64 = (0..3).map(|k| (aq[k] - t * ab[k]).powi(2)).sum();
                nearest = nearest.min(d2.sqrt() - radius);
            }
        }
        let face = (0..3)
            .map(|k| (p[k] - bounds.0[k]).min(bounds.1[k] - p[k]))
            .fold(f64::INFINITY, f64::min);
        nearest.abs().min(face.max(0.0))
    })
}

/// Makes a lattice of built-in strut `cell` at `density` with `args` (a uniform one beside it)
/// and checks the simplified one: valid by CGAL, one piece, its density kept (the test's own
/// volume), within the tolerance of the capsules ([`strut_deviation`]) as reported, and at least
/// `fewer` times fewer triangles than the uniform mesh. `None` is `--tolerance auto`: the
/// tolerance reported is [`auto_tolerance`]. Returns the report.
fn check_strut(
    dir: &Path,
    cell: &str,
    density: f64,
    args: &[&str],
    tolerance: Option<f64>,
    fewer: f64,
) -> serde_json::Value {
    let tol = tolerance.map_or("auto".to_string(), |t| t.to_string());
    let d = density.to_string();
    let common = [&["strut", "--cell", cell, "--density", &d][..], args].concat();
    ok(&[&common[..], &["-o", "u.stl"]].concat(), dir);
    let more = [
        "--tolerance",
        &tol,
        "--verify",
        "cgal",
        "-o",
        "s.stl",
        "--report",
        "s.json",
    ];
    ok(&[&common[..], &more[..]].concat(), dir);
    let r = json(&dir.join("s.json"));
    let what = format!("{cell} {args:?} at {tol}");
    assert_eq!(r["checks"]["checked_by"], "CGAL", "{what}");
    for key in ["closed", "manifold", "outward"] {
        assert_eq!(r["checks"][key], true, "{what}: {key}");
    }
    assert_eq!(r["checks"]["self_intersecting"], false, "{what}");
    let tris = read_stl(&dir.join("s.stl"));
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
    let s = &r["simplified"];
    let asked = s["tolerance"].as_f64().unwrap();
    match tolerance {
        Some(t) => assert_eq!(asked, t, "{what}"),
        None => assert_eq!(asked, auto_tolerance(&r, &what), "{what}"),
    }
    assert!(s["deviation"].as_f64().unwrap() <= asked, "{what}");
    let size = r["cell_size"][0].as_f64().unwrap();
    let radius = r["radius"].as_f64().unwrap();
    let dev = strut_deviation(&tris, cell, radius, size, (lo, hi));
    assert!(
        dev <= asked,
        "{what}: {dev} mm from the capsules, tolerance {asked}"
    );
    let before = read_stl(&dir.join("u.stl")).len();
    let ratio = before as f64 / tris.len() as f64;
    eprintln!(
        "{what}: {before} → {} triangles ({ratio:.1}×), deviation {dev:.4} mm (test), {:.4} (latvox), tolerance {asked:.4}",
        tris.len(),
        s["deviation"].as_f64().unwrap()
    );
    assert!(ratio >= fewer, "{what}: {ratio:.1}× fewer");
    r
}

/// A strut lattice at half a voxel: valid by CGAL, one piece, its density kept, within the
/// tolerance of its capsules, its triangles a fifth of the uniform mesh's or fewer.
#[test]
fn struts_at_half_a_voxel_are_valid_and_exact() {
    let dir = tempdir();
    check_strut(
        dir.path(),
        "kelvin",
        0.15,
        &["--cells", "2"],
        Some(0.078),
        5.0,
    );
}

/// `--tolerance auto` holds the mesh to the default mesh's deviation (half a voxel, or the
/// uniform mesh's where larger): a gyroid net within it of its formula with ten times fewer
/// triangles; a Kelvin lattice within it of its capsules. The setting is saved in a part file
/// and made again from it.
#[test]
fn auto_keeps_the_uniform_meshs_deviation() {
    let dir = tempdir();
    let d = dir.path();
    check_tpms(d, "gyroid", false, 0.3, &["--cells", "3"], None, 10.0);
    let r = check_strut(
        d,
        "kelvin",
        0.15,
        &["--cells", "2", "--save-part", "k.toml"],
        None,
        5.0,
    );
    let part = std::fs::read_to_string(d.join("k.toml")).unwrap();
    assert!(part.contains("tolerance = \"auto\""), "{part}");
    ok(&["strut", "--part", "k.toml", "-o", "again.stl"], d);
    assert_eq!(
        read_stl(&d.join("again.stl")).len() as u64,
        r["triangles"].as_u64().unwrap()
    );
}

/// For every TPMS type and structure and every built-in strut cell, 3×3×3 cells at
/// `--tolerance auto` (the default mesh's deviation): valid by CGAL, the density within 0.002,
/// within that tolerance of the exact surface (the test's own sampling), and at least five
/// times fewer triangles — except where it cannot simplify within it and writes the uniform
/// mesh, saying so (the FCC cell: latvox measures deviation to first order, the field over its
/// gradient, and where struts tie on the mirror planes of a joint the gradient is their mean,
/// so the uniform mesh's deviation comes out larger than its true one and the simplified
/// mesh's too).
#[test]
#[ignore = "long: 27 parts of 3×3×3 cells simplified and verified by CGAL"]
fn every_type_and_cell_keeps_its_uniform_deviation() {
    let dir = tempdir();
    let d = dir.path();
    for ty in [
        "p", "gyroid", "d", "iwp", "s", "frd", "neovius", "lidinoid", "split-p",
    ] {
        for sheet in [false, true] {
            // The F-RD and Neovius nets fall apart below about 0.34.
            let density = if !sheet && (ty == "frd" || ty == "neovius") {
                0.4
            } else {
                0.3
            };
            check_tpms(d, ty, sheet, density, &["--cells", "3"], None, 5.0);
        }
    }
    for cell in latvox::strut::cell::BUILT_IN {
        let fewer = if cell == "fcc" { 1.0 } else { 5.0 };
        let r = check_strut(d, cell, 0.15, &["--cells", "3"], None, fewer);
        assert_eq!(r["simplified"]["gave_up"], cell == "fcc", "{cell}");
    }
}

/// For random types, structures, densities, tolerances (`auto` among them), boxes that are not
/// whole cells, and origins: never an invalid mesh, never beyond the tolerance, the density
/// kept.
#[test]
fn random_settings_never_break_a_promise() {
    let mut rng = Rng(45);
    let dir = tempdir();
    for case in 0..3 {
        let ty = ["gyroid", "d", "p", "iwp"][rng.below(4) as usize];
        let sheet = rng.below(2) == 1;
        let density = rng.uniform(0.3, 0.45);
        let cell = rng.uniform(3.0, 6.0);
        let resolution = 16 + rng.below(12);
        let voxel = cell / resolution as f64;
        // The first setting asks for auto.
        let tolerance = (case > 0).then(|| voxel * rng.uniform(0.45, 1.2));
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
    for bad in ["0", "-0.1", "nan", "mm", "automatic"] {
        let args = ["tpms", "--cells", "1", "--tolerance", bad, "-o", "x.stl"];
        let before = files_in(dir.path());
        let out = run(&args, dir.path());
        assert_refusal(dir.path(), &before, &out, &args, "tolerance");
        let said = String::from_utf8_lossy(&out.stderr);
        assert!(said.contains("or auto"), "{said}");
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
