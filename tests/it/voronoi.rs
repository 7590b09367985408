//! `latvox voronoi`: Voronoi foams, nets and sheets, random through the box or periodic, at
//! their density; checked against the
//! written mesh (volume, pieces and bounds measured here, CGAL's verdict), against SciPy's
//! Voronoi diagram of the same seeds, and against the spacing field's cell count.

use crate::common::*;
use std::path::Path;

/// One random setting: made to its density (closed, free of self-intersections by CGAL, one
/// piece, the box within half a voxel, the density within 0.002 measured here) or refused
/// naming the range the foam allows.
fn case(rng: &mut Rng, n: u64, dir: &Path) -> Option<String> {
    let structure = if rng.below(2) == 0 { "net" } else { "sheet" };
    let spacing = rng.uniform(2.5, 4.0);
    let density: f64 = match structure {
        "net" => rng.uniform(0.05, 0.6),
        _ => rng.uniform(0.08, 0.85),
    };
    let size = [0; 3].map(|_| rng.uniform(7.0, 13.0));
    let origin = [0; 3].map(|_| rng.uniform(-20.0, 20.0));
    let resolution = 10 + rng.below(6);
    let seed = rng.next() % 1000;
    // One foam in three repeats with a cell of two to three and a half spacings.
    let periodic = (rng.below(3) == 0).then(|| format!("{:.3}", spacing * rng.uniform(2.0, 3.5)));
    // One sheet in three has pores.
    let pores = (structure == "sheet" && rng.below(3) == 0)
        .then(|| format!("{:.2}", rng.uniform(0.3, 0.8)));
    let f = |v: [f64; 3]| format!("{:.3},{:.3},{:.3}", v[0], v[1], v[2]);
    let (size_s, origin_s) = (f(size), f(origin));
    let (spacing_s, density_s, res_s, seed_s) = (
        format!("{spacing:.3}"),
        format!("{density:.4}"),
        resolution.to_string(),
        seed.to_string(),
    );
    let mut args = vec![
        "voronoi",
        "--structure",
        structure,
        "--spacing",
        &spacing_s,
        "--density",
        &density_s,
        "--size",
        &size_s,
        "--origin",
        &origin_s,
        "--seed",
        &seed_s,
        "--resolution",
        &res_s,
        "--verify",
        "cgal",
        "-q",
        "-o",
        "p.stl",
        "--report",
        "p.json",
    ];
    if let Some(p) = &periodic {
        args.extend(["--periodic", p]);
    }
    if let Some(p) = &pores {
        args.extend(["--pores", p]);
    }
    let what = format!("case {n}: {}", args.join(" "));
    let out = run(&args, dir);
    let err = String::from_utf8_lossy(&out.stderr);
    match out.status.code() {
        Some(0) => {}
        Some(2) if err.contains("can be built at") => {
            eprintln!("{what}: refused ({})", err.trim_end());
            return None;
        }
        code => return Some(format!("{what}: exit {code:?}: {err}")),
    }
    let r = json(&dir.join("p.json"));
    let tris = read_stl(&dir.join("p.stl"));
    let boxv = size[0] * size[1] * size[2];
    let measured = volume(&tris) / boxv;
    let voxel = r["voxel_size"].as_f64().unwrap();
    let (lo, hi) = bounds(&tris);
    let checks = &r["checks"];
    let problems = [
        ((measured - density_s.parse::<f64>().unwrap()).abs() > 0.002)
            .then(|| format!("density {measured:.5}, asked {density_s}")),
        (checks["checked_by"] != "CGAL").then(|| "not checked by CGAL".into()),
        (checks["closed"] != true || checks["self_intersecting"] != false)
            .then(|| format!("checks {checks}")),
        (pieces(&tris) != 1).then(|| format!("{} pieces", pieces(&tris))),
        (0..3)
            .any(|k| {
                (lo[k] - origin[k]).abs() > 0.5 * voxel + 1e-3
                    || (hi[k] - origin[k] - size[k]).abs() > 0.5 * voxel + 1e-3
            })
            .then(|| format!("bounds {lo:?}–{hi:?}")),
    ];
    let problems: Vec<String> = problems.into_iter().flatten().collect();
    eprintln!(
        "{what}: density {measured:.4} {}",
        if problems.is_empty() { "ok" } else { "FAILED" }
    );
    (!problems.is_empty()).then(|| format!("{what}: {}", problems.join("; ")))
}

fn property(seed: u64, cases: u64) {
    let dir = tempdir();
    let mut rng = Rng(seed);
    let only: Option<u64> = std::env::var("LATVOX_CASE")
        .ok()
        .and_then(|v| v.parse().ok());
    let mut failures = Vec::new();
    for n in 0..cases {
        let mut case_rng = Rng(rng.next());
        if only.is_some_and(|o| o != n) {
            continue;
        }
        failures.extend(case(&mut case_rng, n, dir.path()));
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn random_foams_meet_their_density_closed_and_in_one_piece() {
    property(0x0f0a_2026, 3);
}

#[test]
#[ignore = "long: twelve random foams"]
fn long_random_foams_meet_their_density_closed_and_in_one_piece() {
    property(0x5eed_f0a5, 12);
}

/// Runs `tests/reference/voronoi.py` (SciPy's Voronoi diagram of the seeds, points classified
/// against the part by winding number) in `dir` with `args`; its JSON.
fn scipy_reference(dir: &Path, args: &[&str]) -> serde_json::Value {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/reference/voronoi.py");
    let o = std::process::Command::new("python3")
        .arg(&script)
        .args(args)
        .current_dir(dir)
        .output()
        .expect("python3 with numpy and scipy (scripts/install-deps.sh --tests)");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap()
}

/// The same seeds through SciPy's Voronoi diagram (Qhull): points on its edges (net) or faces
/// (sheet) inside the box lie inside the written solid, the seeds (far from every member)
/// outside it.
#[test]
fn scipy_voronoi_of_the_same_seeds_lies_inside_the_members() {
    let dir = tempdir();
    let d = dir.path();
    ok(
        &[
            "voronoi",
            "--spacing",
            "3",
            "--size",
            "12",
            "--radius",
            "0.3",
            "--resolution",
            "12",
            "-q",
            "--seeds-out",
            "seeds.csv",
            "-o",
            "gen.stl",
        ],
        d,
    );
    for (structure, flag, level) in [("net", "--radius", "0.3"), ("sheet", "--thickness", "0.4")] {
        let out = format!("{structure}.stl");
        ok(
            &[
                "voronoi",
                "--structure",
                structure,
                "--seeds-in",
                "seeds.csv",
                "--size",
                "12",
                flag,
                level,
                "--resolution",
                "12",
                "-q",
                "-o",
                &out,
            ],
            d,
        );
        let r = scipy_reference(
            d,
            &[
                "seeds.csv",
                &out,
                structure,
                level,
                "0.6",
                "0",
                "0",
                "0",
                "12",
                "12",
                "12",
            ],
        );
        eprintln!("{structure}: {r}");
        let n = r["member_points"].as_u64().unwrap();
        assert!(n >= 50, "{structure}: only {n} member points");
        assert_eq!(r["members_inside"], r["member_points"], "{structure}: {r}");
        assert!(r["seeds"].as_u64().unwrap() >= 20, "{structure}: {r}");
        assert_eq!(r["seeds_outside"], r["seeds"], "{structure}: {r}");
    }
}

/// `--pores`: a sheet's walls each get a round hole, so its cells drain (no enclosed void where
/// the closed sheet has one per cell) and the centroids of SciPy's faces of the same seeds lie
/// outside the solid (in the holes: faces whose pore, 0.6 of their inradius, is well over the
/// two voxels a pore needs), at the density asked, valid by CGAL, one piece.
#[test]
fn pores_open_a_sheets_cells() {
    let dir = tempdir();
    let d = dir.path();
    for pores in ["0", "0.6"] {
        let (out, rep) = (format!("p{pores}.stl"), format!("p{pores}.json"));
        ok(
            &[
                "voronoi",
                "--structure",
                "sheet",
                "--spacing",
                "3",
                "--size",
                "12",
                "--density",
                "0.25",
                "--pores",
                pores,
                "--resolution",
                "16",
                "--verify",
                "cgal",
                "-q",
                "--seeds-out",
                "seeds.csv",
                "-o",
                &out,
                "--report",
                &rep,
            ],
            d,
        );
        let r = json(&d.join(&rep));
        let tris = read_stl(&d.join(&out));
        let measured = volume(&tris) / 1728.0;
        assert!(
            (measured - 0.25).abs() <= 0.002,
            "pores {pores}: {measured}"
        );
        let checks = &r["checks"];
        assert!(
            checks["checked_by"] == "CGAL"
                && checks["closed"] == true
                && checks["self_intersecting"] == false,
            "pores {pores}: {checks}"
        );
        assert_eq!(pieces(&tris), 1, "pores {pores}");
        let voids = r["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .any(|w| w.as_str().unwrap().contains("voids"));
        assert_eq!(voids, pores == "0", "pores {pores}: {}", r["warnings"]);
        // Pores of 0.6 × 0.8 mm = 0.48 mm or more, against the least of 2 voxels, 0.375 mm.
        let s = scipy_reference(
            d,
            &[
                "seeds.csv",
                &out,
                "pores",
                "0.8",
                "0.6",
                "0",
                "0",
                "0",
                "12",
                "12",
                "12",
            ],
        );
        eprintln!("pores {pores}: {s}");
        let (n, inside) = (
            s["member_points"].as_u64().unwrap() as f64,
            s["members_inside"].as_u64().unwrap() as f64,
        );
        assert!(n >= 40.0, "{s}");
        if pores == "0" {
            assert_eq!(inside, n, "closed walls hold every centroid: {s}");
        } else {
            assert_eq!(inside, 0.0, "every centroid in a pore: {s}");
        }
    }
}

/// A spacing graded from 2 mm to 5 mm across x: the seeds per slab of the box follow
/// `∫ dV / s³` within 10 %; and the same seed makes the same file, byte for byte.
#[test]
fn a_graded_spacing_sets_the_cells_per_slab_and_a_seed_repeats_exactly() {
    let dir = tempdir();
    let d = dir.path();
    let args = [
        "voronoi",
        "--spacing-field",
        "2 + x/10",
        "--size",
        "30",
        "--density",
        "0.2",
        "--resolution",
        "8",
        "-q",
        "--seeds-out",
        "seeds.csv",
        "-o",
        "a.stl",
        "--report",
        "a.json",
    ];
    ok(&args, d);
    let text = std::fs::read_to_string(d.join("seeds.csv")).unwrap();
    let seeds: Vec<[f64; 3]> = text
        .lines()
        .skip(1)
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect();
    // ∫ dx / (2 + x/10)³ = −5 / (2 + x/10)², times the slab's 30 × 30 mm section.
    let prim = |x: f64| -5.0 / (2.0 + x / 10.0).powi(2);
    for slab in 0..5 {
        let (a, b) = (6.0 * slab as f64, 6.0 * (slab + 1) as f64);
        let expected = 900.0 * (prim(b) - prim(a));
        let count = seeds
            .iter()
            .filter(|p| {
                p[0] >= a && p[0] < b && (0..3).skip(1).all(|k| p[k] >= 0.0 && p[k] <= 30.0)
            })
            .count() as f64;
        eprintln!("slab {a}–{b} mm: {count} seeds, {expected:.1} expected");
        assert!(
            (count / expected - 1.0).abs() <= 0.1,
            "slab {a}–{b} mm: {count} seeds, {expected:.1} expected"
        );
    }
    let r = json(&d.join("a.json"));
    assert!((r["achieved_density"].as_f64().unwrap() - 0.2).abs() <= 0.002);
    // Byte for byte again with the same seed; another seed differs.
    let mut again = args.to_vec();
    let n = again.len();
    again[n - 5] = "seeds2.csv";
    again[n - 3] = "b.stl";
    ok(&again, d);
    assert!(std::fs::read(d.join("a.stl")).unwrap() == std::fs::read(d.join("b.stl")).unwrap());
    assert_eq!(text, std::fs::read_to_string(d.join("seeds2.csv")).unwrap());
    let mut other = again.clone();
    other.extend(["--seed", "2"]);
    ok(&other, d);
    assert!(std::fs::read(d.join("a.stl")).unwrap() != std::fs::read(d.join("b.stl")).unwrap());
}

/// Regularity 1: the seeds on the BCC lattice, every cell a Kelvin truncated octahedron of the
/// spacing's cube volume (equivalent diameter (6 s³/π)^⅓) with equal edges (a/(2√2) for the
/// lattice's cube edge a = 2^⅓ s).
#[test]
fn full_regularity_is_the_kelvin_foam() {
    let dir = tempdir();
    let d = dir.path();
    ok(
        &[
            "voronoi",
            "--spacing",
            "3",
            "--regularity",
            "1",
            "--size",
            "12",
            "--density",
            "0.12",
            "--resolution",
            "12",
            "-q",
            "-o",
            "k.stl",
            "--report",
            "k.json",
        ],
        d,
    );
    let r = json(&d.join("k.json"));
    let cell = &r["foam"]["cell_diameter"];
    let want = (6.0 * 27.0 / std::f64::consts::PI).cbrt();
    for k in ["p5", "p95", "mean"] {
        assert!((cell[k].as_f64().unwrap() - want).abs() < 1e-6, "{cell}");
    }
    let edge = &r["foam"]["edge_length"];
    let a = 2f64.cbrt() * 3.0;
    for k in ["min", "max"] {
        assert!(
            (edge[k].as_f64().unwrap() - a / 8f64.sqrt()).abs() < 1e-6,
            "{edge}"
        );
    }
    assert!((r["achieved_density"].as_f64().unwrap() - 0.12).abs() <= 0.002);
}

/// A net as 3MF beams: lib3mf reads as many beams as the report gives, each of the radius
/// found on the meshed part, which met the density.
#[test]
fn a_net_is_written_as_3mf_beams() {
    let dir = tempdir();
    let d = dir.path();
    ok(
        &[
            "voronoi",
            "--spacing",
            "3",
            "--density",
            "0.15",
            "--size",
            "12",
            "-r",
            "12",
            "--beams",
            "-q",
            "-o",
            "b.3mf",
            "--report",
            "b.json",
        ],
        d,
    );
    let r = json(&d.join("b.json"));
    assert!((r["meshed_density"].as_f64().unwrap() - 0.15).abs() <= 0.002);
    const SCRIPT: &str = r#"
import sys, lib3mf
w = lib3mf.get_wrapper()
m = w.CreateModel()
m.QueryReader("3mf").ReadFromFile(sys.argv[1])
it = m.GetMeshObjects()
beams, radii = 0, set()
while it.MoveNext():
    bl = it.GetCurrentMeshObject().BeamLattice()
    for b in bl.GetBeams():
        beams += 1
        radii.update([round(b.Radii[0], 6), round(b.Radii[1], 6)])
print(beams, len(radii), min(radii))
"#;
    let out = String::from_utf8(python(SCRIPT, &d.join("b.3mf"))).unwrap();
    let v: Vec<f64> = out.split_whitespace().map(|x| x.parse().unwrap()).collect();
    assert_eq!(v[0] as u64, r["beams"].as_u64().unwrap(), "{out}");
    assert!(v[0] > 500.0, "{out}");
    assert_eq!(v[1], 1.0, "{out}");
    assert!((v[2] - r["radius"].as_f64().unwrap()).abs() < 1e-5, "{out}");
}

/// Bad settings are refused in one line, exit 2, nothing written.
#[test]
fn bad_settings_are_refused() {
    let dir = tempdir();
    let d = dir.path();
    std::fs::write(d.join("few.csv"), "x,y,z\n1,2,3\n4,5,6\n").unwrap();
    std::fs::write(d.join("bad.csv"), "x,y,z\n1,2,3\n4,five,6\n").unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&["--density", "0.9"], "can be built at"),
        (&["--radius", "2.5"], "can be built at"),
        (&["--structure", "sheet", "--radius", "0.3"], "--thickness"),
        (&["--thickness", "0.3"], "--radius"),
        (&["--regularity", "1.5"], "regularity"),
        (&["--spacing", "0"], "spacing"),
        (&["--spacing-field", "x - 5"], "spacing"),
        (&["--seeds-in", "few.csv"], "at least 5 seeds"),
        (&["--seeds-in", "bad.csv"], "line 3"),
        (&["--seeds-in", "missing.csv"], "missing.csv"),
        (&["--spacing", "0.001"], "seeds"),
        (&["--structure", "sheet", "--beams"], "sheet's walls"),
        (&["--beams"], ".3mf"),
        (&["--periodic", "5"], "under 2 spacings"),
        (&["--spacing", "0.5", "--periodic", "9"], "more than 4000"),
        (
            &["--periodic", "9", "--spacing-field", "3"],
            "--spacing-field",
        ),
        (&["--cell-out", "c.json"], "--periodic"),
        (&["--density-grade", "z:0.1:0.3", "--beams"], "as a mesh"),
        (&["--stiffness-field", "0.02"], "repeating cell"),
        (
            &[
                "--periodic",
                "9",
                "--structure",
                "sheet",
                "--density-field",
                "0.2",
            ],
            "periodic sheet",
        ),
        (
            &[
                "--structure",
                "sheet",
                "--periodic",
                "9",
                "--cell-out",
                "c.json",
            ],
            "not a strut cell",
        ),
    ];
    for (extra, what) in cases {
        let mut args = vec![
            "voronoi",
            "--size",
            "10",
            "--resolution",
            "8",
            "-o",
            "x.stl",
        ];
        args.extend_from_slice(extra);
        let before = files_in(d);
        let out = run(&args, d);
        assert_refusal(d, &before, &out, &args, what);
    }
}

/// A periodic foam (`--periodic`): a part of 4×4×4 repeating cells is copied from a template
/// of 3×3×3, and SciPy's Voronoi diagram of the cell's seeds repeated through the box puts
/// its edges (net) and faces (sheet) inside the written solid, in every cell, and its seeds
/// outside; the net's cell, written with `--cell-out`, makes the same part through
/// `latvox strut --cell`.
#[test]
fn a_periodic_foam_is_copied_from_its_cell_and_is_scipys_foam_in_every_cell() {
    let dir = tempdir();
    let d = dir.path();
    for (structure, flag, level, res) in [
        ("net", "--radius", "0.45", "6"),
        ("sheet", "--thickness", "0.85", "6"),
    ] {
        let (out, rep, seeds) = (
            format!("{structure}.stl"),
            format!("{structure}.json"),
            format!("{structure}.csv"),
        );
        let mut args = vec![
            "voronoi",
            "--structure",
            structure,
            "--spacing",
            "3",
            "--periodic",
            "6.5",
            "--size",
            "26",
            "--origin",
            "-3,1.5,2",
            "--seed",
            "11",
            flag,
            level,
            "--resolution",
            res,
            "--verify",
            "cgal",
            "-q",
            "--seeds-out",
            &seeds,
            "-o",
            &out,
            "--report",
            &rep,
        ];
        if structure == "net" {
            args.extend(["--cell-out", "cell.json"]);
        }
        ok(&args, d);
        let r = json(&d.join(&rep));
        assert_eq!(r["period"], 6.5, "{structure}");
        assert_eq!(r["instancing"]["part_cells"], serde_json::json!([4, 4, 4]));
        assert_eq!(
            r["instancing"]["template_cells"],
            serde_json::json!([3, 3, 3])
        );
        let checks = &r["checks"];
        assert!(
            checks["closed"] == true && checks["self_intersecting"] == false,
            "{structure}: {checks}"
        );
        let tris = read_stl(&d.join(&out));
        assert_eq!(pieces(&tris), 1, "{structure}");
        let s = scipy_reference(
            d,
            &[
                &seeds, &out, structure, level, "0.6", "-3", "1.5", "2", "23", "27.5", "28", "6.5",
                "120",
            ],
        );
        eprintln!("{structure}: {s}");
        assert!(
            s["member_points"].as_u64().unwrap() >= 100,
            "{structure}: {s}"
        );
        assert_eq!(s["members_inside"], s["member_points"], "{structure}: {s}");
        assert!(s["seeds"].as_u64().unwrap() >= 50, "{structure}: {s}");
        assert_eq!(s["seeds_outside"], s["seeds"], "{structure}: {s}");
        if structure == "net" {
            // The same lattice from its cell file: the same volume.
            ok(
                &[
                    "strut",
                    "--cell",
                    "cell.json",
                    "--cell-size",
                    "6.5",
                    "--size",
                    "26",
                    "--origin",
                    "-3,1.5,2",
                    "--radius",
                    "0.45",
                    // 6 voxels per spacing, in whole OpenVDB leaves per cell.
                    "--resolution",
                    "16",
                    "-q",
                    "-o",
                    "strut.stl",
                ],
                d,
            );
            let (a, b) = (volume(&tris), volume(&read_stl(&d.join("strut.stl"))));
            assert!(
                (a - b).abs() < 1e-3 * a,
                "voronoi {a} mm³, strut --cell {b} mm³"
            );
        }
    }
}
