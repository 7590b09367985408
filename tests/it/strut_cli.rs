//! The `latvox strut` command, run as a user runs it: parts checked with this test's own
//! computations (an STL reader, volume by the divergence theorem, edges by hash map, pieces by
//! shared corners, and the simple cubic lattice's volume in closed form), refusals checked for
//! one line, exit code 2 and no file, and a seeded property test over random settings.

use crate::common;
use crate::common::*;
use std::f64::consts::PI;
use std::path::Path;

/// Runs `latvox strut` with `args` in `dir`, writing `part.json` and `part.stl` (unless `args`
/// name the output).
fn strut(dir: &Path, args: &[&str]) -> std::process::Output {
    let mut all = vec!["strut", "-q", "--report", "part.json"];
    if !args.contains(&"-o") {
        all.extend_from_slice(&["-o", "part.stl"]);
    }
    all.extend_from_slice(args);
    run(&all, dir)
}

/// Asserts a refusal: exit 2, one line on stderr, naming `what`, no file left behind.
fn assert_refused(dir: &Path, args: &[&str], what: &str) {
    let before = files_in(dir);
    let out = strut(dir, args);
    assert_refusal(dir, &before, &out, args, what);
}

/// The volume fraction of a simple cubic lattice of struts of radius `r` along the edges of
/// cubes of side `a`: per cell, three cylinders of length `a`, less the three two-cylinder
/// overlaps at the node (16r³/3 each) plus the three-cylinder one (8(2 − √2)r³). The capsules'
/// end spheres lie inside the cylinders' union, and a box of whole cells holds whole periods.
fn simple_cubic_fraction(r: f64, a: f64) -> f64 {
    (3.0 * PI * r * r * a - 16.0 * r.powi(3) + 8.0 * (2.0 - 2f64.sqrt()) * r.powi(3)) / a.powi(3)
}

#[test]
fn simple_cubic_struts_of_a_given_radius_have_the_volume_in_closed_form() {
    let dir = tempdir();
    for (r, res) in [("0.5", "32"), ("1.1", "24")] {
        let out = strut(
            dir.path(),
            &[
                "--cell",
                "sc",
                "--radius",
                r,
                "--cells",
                "3",
                "--cell-size",
                "5",
                "-r",
                res,
            ],
        );
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "{err}");
        let tris = read_stl(&dir.path().join("part.stl"));
        let got = volume(&tris) / 15f64.powi(3);
        let want = simple_cubic_fraction(r.parse().unwrap(), 5.0);
        assert!(
            (got - want).abs() < 0.002,
            "radius {r}: {got:.5}, in closed form {want:.5}"
        );
        assert_eq!(edges(&tris), Edges::default(), "radius {r}");
        assert_eq!(pieces(&tris), 1, "radius {r}");
        let rep = json(&dir.path().join("part.json"));
        assert_eq!(rep["radius"].as_f64(), Some(r.parse().unwrap()));
        assert!(rep["target_density"].is_null());
        assert!((rep["achieved_density"].as_f64().unwrap() - got).abs() < 1e-4);
    }
}

#[test]
fn an_octet_part_that_is_not_whole_cells_meets_its_density_with_blended_joints() {
    let dir = tempdir();
    let out = strut(
        dir.path(),
        &[
            "--cell",
            "octet",
            "--density",
            "0.2",
            "--blend",
            "0.3",
            "--size",
            "13,9.5,7.25",
            "--cell-size",
            "4",
            "--origin",
            "-3.3,2,100",
        ],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    let tris = read_stl(&dir.path().join("part.stl"));
    let box_volume = 13.0 * 9.5 * 7.25;
    let got = volume(&tris) / box_volume;
    assert!((got - 0.2).abs() <= 0.002, "density {got:.5}");
    assert_eq!(edges(&tris), Edges::default());
    assert_eq!(pieces(&tris), 1);
    let (lo, hi) = bounds(&tris);
    let rep = json(&dir.path().join("part.json"));
    let h = rep["voxel_size"].as_f64().unwrap();
    for (a, (min, max)) in [(-3.3, 9.7), (2.0, 11.5), (100.0, 107.25)]
        .iter()
        .enumerate()
    {
        assert!((lo[a] - min).abs() <= h / 2.0 && (hi[a] - max).abs() <= h / 2.0);
    }
    let c = &rep["checks"];
    for key in ["closed", "outward", "manifold", "self_intersection_checked"] {
        assert_eq!(c[key], true, "{key}: {c}");
    }
    assert_eq!(c["self_intersecting"], false);
    assert_eq!(rep["cell"], "octet");
    assert_eq!(rep["blend"], 0.3);
}

/// A cell file with tapered struts (radius factors per node) that cross the cell's faces, edges
/// and corners.
#[test]
fn a_cell_file_with_tapered_struts_makes_a_closed_part() {
    let dir = tempdir();
    std::fs::write(
        dir.path().join("cell.json"),
        r#"{"nodes": [[0.5,0.5,0.5],[1,1,1],[0,0,0],[1,0,0],[0,1,1],[1.5,0.5,0.5],[1.5,1.5,0.5]],
            "struts": [[0,1],[0,2],[0,3],[0,4],[0,5],[0,6]],
            "radii": [1.5, 0.8, 0.8, 0.8, 0.8, 1.5, 1.5]}"#,
    )
    .unwrap();
    let out = strut(
        dir.path(),
        &[
            "--cell",
            "cell.json",
            "--density",
            "0.15",
            "--cells",
            "3",
            "--cell-size",
            "4",
        ],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    let tris = read_stl(&dir.path().join("part.stl"));
    assert!((volume(&tris) / 12f64.powi(3) - 0.15).abs() <= 0.002);
    assert_eq!(edges(&tris), Edges::default());
    let rep = json(&dir.path().join("part.json"));
    assert_eq!(rep["cell"], "cell.json");
    assert_eq!(rep["cell_struts"], 6);
}

#[test]
fn bad_input_is_refused_in_one_line_with_no_file() {
    let dir = tempdir();
    let d = dir.path();
    std::fs::write(d.join("empty.json"), "").unwrap();
    std::fs::write(
        d.join("nostruts.json"),
        r#"{"nodes": [[0,0,0]], "struts": []}"#,
    )
    .unwrap();
    std::fs::write(
        d.join("badindex.json"),
        r#"{"nodes": [[0,0,0]], "struts": [[0,3]]}"#,
    )
    .unwrap();
    std::fs::write(
        d.join("layers.json"),
        r#"{"nodes": [[0.5,0.5,0.5],[1.5,0.5,0.5],[0.5,1.5,1.5],[1.5,1.5,1.5]], "struts": [[0,1],[0,2],[0,3]]}"#,
    )
    .unwrap();
    std::fs::write(
        d.join("typo.json"),
        r#"{"nodes": [[0,0,0],[1,1,1]], "strut": [[0,1]]}"#,
    )
    .unwrap();
    for (args, what) in [
        (&["--cell", "missing.json"][..], "missing.json"),
        (&["--cell", "empty.json"], "empty.json"),
        (&["--cell", "nostruts.json"], "no struts"),
        (&["--cell", "badindex.json"], "node 3"),
        (&["--cell", "typo.json"], "strut"),
        (&["--cell", "layers.json"], "one lattice"),
        (&["--cell", "hexagonal"], "unknown cell"),
        (&["--cell-size", "0"], "positive"),
        (&["--cell-size", "-2"], "positive"),
        (&["--density", "1.2"], "density"),
        (&["--radius", "0"], "positive"),
        (
            &["--density", "0.2", "--radius", "1"],
            "cannot be used with",
        ),
        (&["--blend", "-0.1"], "≥ 0"),
        // Pores close: simple cubic struts fill the faces at half a cell.
        (&["--cell", "sc", "--radius", "2.6"], "closes up"),
        (&["--cell", "sc", "--density", "0.97"], "closes up"),
        // Too thin for the voxels, the resolution fixed: the refusal names the one that works.
        (
            &["--cell", "octet", "--radius", "0.05", "--fixed-resolution"],
            "--resolution",
        ),
        // Too thin for any resolution searched.
        (&["--cell", "octet", "--radius", "0.005"], "--resolution"),
    ] {
        assert_refused(d, args, what);
    }
}

/// A refusal of a thin strut names a resolution; that resolution works, the one below does not.
#[test]
fn the_resolution_a_refusal_names_works() {
    let dir = tempdir();
    let at = |res: &[&str]| {
        let mut args = vec!["--cell", "bcc", "--radius", "0.08", "--cells", "2"];
        args.push("--fixed-resolution");
        args.extend_from_slice(res);
        strut(dir.path(), &args)
    };
    let out = at(&[]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    let named: String = err
        .split("--resolution ")
        .nth(1)
        .expect("a resolution named")
        .chars()
        .take_while(char::is_ascii_digit)
        .collect();
    let below = (named.parse::<u32>().unwrap() - 1).to_string();
    let out = at(&["-r", &named]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    let rep = json(&dir.path().join("part.json"));
    assert!(rep["thinnest_strut_voxels"].as_f64().unwrap() >= 2.0);
    assert_eq!(at(&["-r", &below]).status.code(), Some(2));
}

#[test]
fn a_batch_job_makes_a_strut_part() {
    let dir = tempdir();
    std::fs::write(
        dir.path().join("jobs.toml"),
        "[[sweep]]\ncommand = 'strut'\ncell = ['bcc', 'kelvin']\ndensity = 0.15\ncells = 2\noutput = 'out/{cell}.stl'\n",
    )
    .unwrap();
    let out = run(&["batch", "jobs.toml", "-q"], dir.path());
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for cell in ["bcc", "kelvin"] {
        let tris = read_stl(&dir.path().join(format!("out/{cell}.stl")));
        assert!((volume(&tris) / 1000.0 - 0.15).abs() <= 0.002, "{cell}");
    }
}

/// Random settings — cell, density or radius, blend, cell size per axis, boxes that are not
/// whole cells, any origin, resolution — each run as a user runs it: exit 0 with the density
/// met (or the radius's part) closed, consistently wound and in one piece, or exit 2 with one
/// line and no file.
#[test]
fn random_settings_meet_their_density_or_are_refused() {
    const CELLS: [&str; 9] = [
        "sc", "bcc", "bccz", "fcc", "fccz", "octet", "kelvin", "diamond", "rhombic",
    ];
    let dir = tempdir();
    let d = dir.path();
    let mut rng = Rng(0x5EED_0012);
    let (mut built, mut refused) = (0, 0);
    for case in 0..14 {
        let cell = CELLS[rng.below(CELLS.len() as u64) as usize];
        let sizes = [0, 1, 2].map(|_| rng.uniform(3.0, 6.0));
        let counts = [0, 1, 2].map(|_| rng.uniform(1.3, 2.6));
        let size: Vec<String> = (0..3)
            .map(|a| format!("{:.3}", sizes[a] * counts[a]))
            .collect();
        let cell_size: Vec<String> = sizes.iter().map(|s| format!("{s:.3}")).collect();
        let origin: Vec<String> = (0..3)
            .map(|_| format!("{:.3}", rng.uniform(-20.0, 20.0)))
            .collect();
        let density = format!("{:.3}", rng.uniform(0.05, 0.4));
        let blend = format!(
            "{:.2}",
            if rng.below(2) == 0 {
                0.0
            } else {
                rng.uniform(0.05, 0.5)
            }
        );
        let res = (12 + rng.below(20)).to_string();
        let (size, cell_size, origin) = (size.join(","), cell_size.join(","), origin.join(","));
        let args = [
            "--cell",
            cell,
            "--density",
            &density,
            "--blend",
            &blend,
            "--size",
            &size,
            "--cell-size",
            &cell_size,
            "--origin",
            &origin,
            "-r",
            &res,
            "--verify",
            "fast",
        ];
        let ctx = format!("case {case}: {}", args.join(" "));
        let out = strut(d, &args);
        let err = String::from_utf8_lossy(&out.stderr);
        match out.status.code() {
            Some(0) => {
                built += 1;
                let tris = read_stl(&d.join("part.stl"));
                let box_volume: f64 = size.split(',').map(|x| x.parse::<f64>().unwrap()).product();
                let got = volume(&tris) / box_volume;
                let target: f64 = density.parse().unwrap();
                assert!((got - target).abs() <= 0.002, "{ctx}: density {got:.5}");
                assert_eq!(edges(&tris), Edges::default(), "{ctx}");
                assert_eq!(pieces(&tris), 1, "{ctx}");
            }
            Some(2) => {
                refused += 1;
                assert_eq!(err.trim_end().lines().count(), 1, "{ctx}: {err}");
            }
            code => panic!("{ctx}: exit {code:?}: {err}"),
        }
        std::fs::remove_file(d.join("part.stl")).ok();
        std::fs::remove_file(d.join("part.json")).ok();
    }
    // The settings are drawn where the cells can be built: most must be.
    assert!(built >= 10, "{built} built, {refused} refused");
}

/// Reads a 3MF with lib3mf (the 3MF Consortium's reference library, from PyPI): per mesh
/// object, its name, triangles, beams, clipping mode and the distinct beam radii.
fn lib3mf_read(path: &Path) -> serde_json::Value {
    const SCRIPT: &str = r#"
import json, sys, lib3mf
w = lib3mf.get_wrapper()
m = w.CreateModel()
m.QueryReader("3mf").ReadFromFile(sys.argv[1])
out = []
it = m.GetMeshObjects()
while it.MoveNext():
    o = it.GetCurrentMeshObject()
    bl = o.BeamLattice()
    radii = set()
    caps = set()
    for i in range(bl.GetBeamCount()):
        b = bl.GetBeam(i)
        radii.update(round(r, 9) for r in b.Radii)
        caps.update(int(c) for c in b.CapModes)
    out.append({"name": o.GetName(), "triangles": o.GetTriangleCount(),
                "beams": bl.GetBeamCount(), "clipping": int(bl.GetClipping()[0]),
                "sets": bl.GetBeamSetCount(), "radii": sorted(radii), "caps": sorted(caps)})
print(json.dumps(out))
"#;
    serde_json::from_slice(&common::python(SCRIPT, path)).unwrap()
}

#[test]
fn beams_are_read_back_by_lib3mf_as_written() {
    let dir = tempdir();
    let d = dir.path();
    // Simple cubic, 3×3×3 whole cells: (N + 1)² lines of nodes per axis, each with N beams
    // inside and one poking in at each end (clipped by the box): 3 · 16 · 5 beams.
    let out = run(
        &[
            "strut", "-q", "--cell", "sc", "--radius", "0.5", "--cells", "3", "--beams", "-o",
            "sc.3mf", "--report", "sc.json",
        ],
        d,
    );
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let objects = lib3mf_read(&d.join("sc.3mf"));
    let lattice = &objects[1];
    assert_eq!(lattice["beams"], 240);
    assert_eq!(lattice["triangles"], 0);
    assert_eq!(lattice["radii"], serde_json::json!([0.5]));
    // Sphere caps (capsules); clipped inside the box, which is the other object.
    assert_eq!(lattice["caps"], serde_json::json!([0]));
    assert_eq!(lattice["clipping"], 1);
    assert_eq!(objects[0]["triangles"], 12);
    assert_eq!(json(&d.join("sc.json"))["beams"], 240);

    // An octet truss to a density: the beams carry the radius found on the meshed part (lib3mf
    // holds radii in single precision).
    let out = run(
        &[
            "strut",
            "-q",
            "--cell",
            "octet",
            "--density",
            "0.2",
            "--cells",
            "4",
            "--beams",
            "-o",
            "octet.3mf",
            "--report",
            "octet.json",
        ],
        d,
    );
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rep = json(&d.join("octet.json"));
    assert!((rep["meshed_density"].as_f64().unwrap() - 0.2).abs() <= 0.002);
    let lattice = &lib3mf_read(&d.join("octet.3mf"))[1];
    assert_eq!(lattice["beams"], rep["beams"]);
    let r = rep["radius"].as_f64().unwrap();
    let radii: Vec<f64> = serde_json::from_value(lattice["radii"].clone()).unwrap();
    assert!(
        radii.len() == 1 && (radii[0] - r).abs() < 1e-6 * r,
        "{radii:?} vs {r}"
    );
    assert_eq!(lattice["sets"], 24);

    for (args, what) in [
        (&["--beams"][..], "3MF"),
        (&["--beams", "--blend", "0.2", "-o", "b.3mf"], "blend"),
    ] {
        assert_refused(d, args, what);
    }
}
