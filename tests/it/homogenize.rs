//! `latvox homogenize`: the published reference cell, the tensor of a solid cell, cubic
//! symmetry, an independent SciPy transcription (a direct sparse solve) on two cells, the Voigt
//! bound and definiteness over random settings, sheets stiffer than nets, refinement converging,
//! and refusals of bad input.

use crate::common::*;
use serde_json::Value;
use std::path::Path;

/// The report `latvox homogenize ARGS --json` prints.
fn homogenize(args: &[&str]) -> Value {
    let dir = tempdir();
    let mut all = vec!["homogenize"];
    all.extend(args);
    all.push("--json");
    let out = run(&all, dir.path());
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

fn tensor(v: &Value) -> [[f64; 6]; 6] {
    std::array::from_fn(|i| std::array::from_fn(|j| v["stiffness"][i][j].as_f64().unwrap()))
}

/// The isotropic elasticity matrix of Lamé constants λ, μ.
fn isotropic(l: f64, m: f64) -> [[f64; 6]; 6] {
    std::array::from_fn(|i| {
        std::array::from_fn(|j| match (i < 3, j < 3) {
            (true, true) => l + if i == j { 2.0 * m } else { 0.0 },
            (false, false) if i == j => m,
            _ => 0.0,
        })
    })
}

/// Dong, Tang & Zhao (2019), the example of their code: the grid cell (the cube's 12 edges),
/// radius 0.1, 40 voxels a side solid where their centres are, λ = 115.4, μ = 79.6: density
/// 8.5 %, C11 = 7.1876, C12 = 0.3875, C44 = 0.1489.
#[test]
fn the_published_grid_cell() {
    let r = homogenize(&[
        "--cell",
        "sc",
        "--radius",
        "0.1",
        "--voxels",
        "40",
        "--voxelization",
        "centres",
        "--lame",
        "115.4,79.6",
    ]);
    let c = tensor(&r);
    for (got, want) in [(c[0][0], 7.1876), (c[0][1], 0.3875), (c[3][3], 0.1489)] {
        assert!((got / want - 1.0).abs() < 0.005, "{got} against {want}");
    }
    let density = r["relative_density"].as_f64().unwrap();
    assert!((density - 0.085).abs() < 0.001, "{density}");
    assert!(r["solver"]["residual"].as_f64().unwrap() < 1e-7);
}

/// A cell the solid fills has the solid's own tensor: E and ν back, isotropic.
#[test]
fn a_solid_cell_is_the_solid() {
    let (e, nu) = (200.0, 0.25);
    let r = homogenize(&[
        "--cell",
        "sc",
        "--radius",
        "1",
        "--voxels",
        "8",
        "--young",
        "200",
        "--poisson",
        "0.25",
    ]);
    assert_eq!(r["relative_density"].as_f64(), Some(1.0));
    let (l, m) = (
        e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
        e / (2.0 * (1.0 + nu)),
    );
    let (c, want) = (tensor(&r), isotropic(l, m));
    for i in 0..6 {
        for j in 0..6 {
            assert!(
                (c[i][j] - want[i][j]).abs() < 1e-6 * e,
                "C{i}{j} {}",
                c[i][j]
            );
        }
    }
    let k = &r["constants"];
    assert!((k["young"][0].as_f64().unwrap() - e).abs() < 1e-6 * e);
    assert!((k["poisson"][0][1].as_f64().unwrap() - nu).abs() < 1e-6);
    assert!((k["zener"].as_f64().unwrap() - 1.0).abs() < 1e-6);
}

/// Cells with cubic symmetry give a cubic tensor: three equal C11, C12 and C44 each, nothing
/// coupling normal and shear strains or two shears.
#[test]
fn cubic_cells_have_cubic_tensors() {
    for args in [
        &["--type", "gyroid", "--density", "0.25"][..],
        &["--type", "d", "--structure", "sheet", "--density", "0.2"],
        &["--type", "p", "--density", "0.35"],
        &["--cell", "bcc", "--density", "0.15"],
        &["--cell", "octet", "--radius", "0.07"],
    ] {
        let mut a = args.to_vec();
        a.extend(["--voxels", "24"]);
        let c = tensor(&homogenize(&a));
        let scale = c[0][0];
        let near = |x: f64, y: f64| (x - y).abs() < 1e-6 * scale;
        for i in 0..3 {
            assert!(near(c[i][i], c[0][0]), "{args:?} C{i}{i}");
            assert!(
                near(c[i + 3][i + 3], c[3][3]),
                "{args:?} C{}{}",
                i + 3,
                i + 3
            );
            for j in 0..3 {
                if i != j {
                    assert!(near(c[i][j], c[0][1]), "{args:?} C{i}{j}");
                    assert!(near(c[i + 3][j + 3], 0.0), "{args:?}");
                }
                assert!(near(c[i][j + 3], 0.0), "{args:?}");
            }
        }
        assert!(c[0][0] > c[0][1] && c[3][3] > 0.0, "{args:?}");
    }
}

/// The same cells homogenised by an independent transcription in NumPy/SciPy (its own
/// voxelisation, element, sparse assembly and a direct solve): the tensors agree within 1 %.
#[test]
fn an_independent_scipy_transcription_agrees() {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/reference/homogenize.py");
    for (cell, radius) in [("sc", "0.15"), ("bcc", "0.12")] {
        let (l, m) = ("0.576923", "0.384615");
        let o = std::process::Command::new("python3")
            .arg(&script)
            .args([cell, radius, "20", l, m])
            .output()
            .expect("python3 with numpy and scipy (scripts/install-deps.sh --tests)");
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let reference: Value = serde_json::from_slice(&o.stdout).unwrap();
        let ours = homogenize(&[
            "--cell",
            cell,
            "--radius",
            radius,
            "--voxels",
            "20",
            "--voxelization",
            "centres",
            "--lame",
            &format!("{l},{m}"),
        ]);
        assert_eq!(
            ours["relative_density"].as_f64(),
            reference["density"].as_f64(),
            "{cell}"
        );
        let c = tensor(&ours);
        for i in 0..6 {
            for j in 0..6 {
                let want = reference["C"][i][j].as_f64().unwrap();
                assert!(
                    (c[i][j] - want).abs() <= 0.01 * want.abs() + 1e-9 * c[0][0],
                    "{cell} C{i}{j}: {} against {want}",
                    c[i][j]
                );
            }
        }
    }
}

/// Over random lattices, densities, cell shapes, solids and voxel counts: the density is met on
/// the voxels, the tensor is symmetric and positive definite, and no strain finds it stiffer
/// than the Voigt bound ρ·C_solid (the uniform strain's energy, an upper bound of the discrete
/// model too); a TPMS density outside its feasible range is refused, naming the range.
#[test]
fn every_setting_keeps_the_bounds() {
    let mut rng = Rng(0x4700_5eed);
    let types = ["gyroid", "d", "p", "iwp", "neovius"];
    let cells = ["bcc", "octet", "kelvin", "fccz", "diamond"];
    let mut refused = 0;
    for case in 0..8 {
        let density = rng.uniform(0.15, 0.5);
        let size: Vec<String> = (0..3)
            .map(|_| format!("{:.3}", rng.uniform(0.6, 2.0)))
            .collect();
        let (e, nu) = (rng.uniform(1.0, 300.0), rng.uniform(0.0, 0.45));
        let voxels = [8, 12, 16, 20][rng.below(4) as usize].to_string();
        let mut args: Vec<String> = if rng.below(2) == 0 {
            let structure = if rng.below(2) == 0 { "net" } else { "sheet" };
            [
                "--type",
                types[rng.below(5) as usize],
                "--structure",
                structure,
            ]
            .map(String::from)
            .to_vec()
        } else {
            vec!["--cell".into(), cells[rng.below(5) as usize].into()]
        };
        args.extend([
            "--density".into(),
            format!("{density:.4}"),
            "--cell-size".into(),
            size.join(","),
            "--voxels".into(),
            voxels,
            "--young".into(),
            format!("{e}"),
            "--poisson".into(),
            format!("{nu}"),
        ]);
        let a: Vec<&str> = args.iter().map(String::as_str).collect();
        let dir = tempdir();
        let mut all = vec!["homogenize", "--json"];
        all.extend(&a);
        let out = run(&all, dir.path());
        if out.status.code() == Some(2) {
            let err = String::from_utf8_lossy(&out.stderr);
            assert!(
                err.contains("holds together at densities from"),
                "{a:?}: {err}"
            );
            refused += 1;
            continue;
        }
        assert!(
            out.status.success(),
            "{a:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let r: Value = serde_json::from_slice(&out.stdout).unwrap();
        let rho = r["relative_density"].as_f64().unwrap();
        assert!(
            (rho - (density * 1e4).round() / 1e4).abs() < 2e-5,
            "case {case} {a:?}: {rho}"
        );
        let c = tensor(&r);
        let (l, m) = (
            e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
            e / (2.0 * (1.0 + nu)),
        );
        let d = isotropic(l, m);
        let energy = |c: &[[f64; 6]; 6], s: &[f64; 6]| -> f64 {
            (0..6)
                .map(|i| (0..6).map(|j| s[i] * c[i][j] * s[j]).sum::<f64>())
                .sum()
        };
        for i in 0..6 {
            for j in 0..6 {
                assert!(
                    (c[i][j] - c[j][i]).abs() <= 1e-9 * c[0][0],
                    "case {case} {a:?}: {c:?}"
                );
            }
        }
        for _ in 0..200 {
            let s: [f64; 6] = std::array::from_fn(|_| rng.uniform(-1.0, 1.0));
            let (w, bound) = (energy(&c, &s), rho * energy(&d, &s));
            assert!(w > 0.0, "case {case} {a:?}: not positive definite");
            assert!(
                w <= bound * (1.0 + 1e-9),
                "case {case} {a:?}: {w} above the Voigt bound {bound}"
            );
        }
    }
    assert!(refused <= 2, "{refused} of 8 settings refused");
}

/// At equal density (25 %) a TPMS sheet is stiffer than its net (Al-Ketan, Rowshan & Abu Al-Rub
/// 2018), by Young's modulus averaged over directions: a primitive net is the stiffer along the
/// axes, its struts' own direction, and far softer across them.
#[test]
fn sheets_are_stiffer_than_nets() {
    for t in ["gyroid", "d", "p"] {
        let young = |structure: &str| {
            homogenize(&[
                "--type",
                t,
                "--structure",
                structure,
                "--density",
                "0.25",
                "--voxels",
                "24",
            ])["constants"]["young_mean"]
                .as_f64()
                .unwrap()
        };
        let (net, sheet) = (young("net"), young("sheet"));
        assert!(sheet > net, "{t}: sheet {sheet}, net {net}");
    }
}

/// Finer voxels converge: the tensor's change from 24 to 48 voxels is larger than from 48 to 96.
#[test]
#[ignore = "long: 96³ voxels"]
fn long_refining_the_voxels_converges() {
    for args in [
        &["--type", "gyroid", "--density", "0.2"][..],
        &["--cell", "bcc", "--density", "0.2"],
    ] {
        let at = |n: &str| {
            let mut a = args.to_vec();
            a.extend(["--voxels", n]);
            tensor(&homogenize(&a))
        };
        let (c24, c48, c96) = (at("24"), at("48"), at("96"));
        let change = |a: &[[f64; 6]; 6], b: &[[f64; 6]; 6]| {
            [(0, 0), (0, 1), (3, 3)]
                .iter()
                .map(|&(i, j)| ((a[i][j] - b[i][j]) / b[i][j]).abs())
                .fold(0.0, f64::max)
        };
        let (coarse, fine) = (change(&c24, &c48), change(&c48, &c96));
        assert!(fine < coarse, "{args:?}: 24→48 {coarse}, 48→96 {fine}");
    }
}

/// Bad settings are refused with one line, exit 2, and no report written.
#[test]
fn bad_settings_are_refused() {
    let dir = tempdir();
    let before = files_in(dir.path());
    for (args, what) in [
        (&["--cell", "bcc", "--level", "0.3"][..], "--level"),
        (&["--type", "gyroid", "--radius", "0.1"], "--radius"),
        (&["--poisson", "0.5"], "ν"),
        (&["--density", "0"], "density"),
        (&["--voxels", "3"], "voxels"),
        (&["--lame", "1"], "λ,μ"),
        (&["--cell", "nosuch"], "unknown cell"),
        (
            &[
                "--cell",
                "sc",
                "--radius",
                "0.001",
                "--voxels",
                "8",
                "--voxelization",
                "centres",
            ],
            "no solid",
        ),
        (
            &["--type", "p", "--density", "0.05"],
            "holds together at densities from",
        ),
        (
            &["--type", "p", "--level", "-2.5"],
            "does not hold together",
        ),
        (&["--report", "missing/dir/r.json"], "missing"),
    ] {
        let mut a = vec!["homogenize"];
        a.extend(args);
        if !args.contains(&"--report") {
            a.extend(["--report", "r.json"]);
        }
        let out = run(&a, dir.path());
        assert_refusal(dir.path(), &before, &out, &a, what);
    }
}

/// `--densities` tabulates the cell over densities and fits Gibson and Ashby's law: every
/// density met, the moduli rising with it, each point within the fit's stated miss of the law,
/// and the law's exponent where bending- and stretching-dominated cells put it (between 1 and 3).
#[test]
fn a_density_curve_fits_a_power_law() {
    let r = homogenize(&[
        "--type",
        "gyroid",
        "--structure",
        "sheet",
        "--densities",
        "0.1:0.4:4",
        "--voxels",
        "16",
    ]);
    let points = r["points"].as_array().unwrap();
    assert_eq!(points.len(), 4);
    let law = &r["young"];
    let (c, n, miss) = (
        law["c"].as_f64().unwrap(),
        law["n"].as_f64().unwrap(),
        law["max_error"].as_f64().unwrap(),
    );
    assert!(n > 1.0 && n < 3.0 && miss < 0.2, "{law}");
    let mut last = 0.0;
    for (p, want) in points.iter().zip([0.1, 0.2, 0.3, 0.4]) {
        let rho = p["relative_density"].as_f64().unwrap();
        assert!((rho - want).abs() < 2e-5, "{rho}");
        let e: f64 = (0..3)
            .map(|a| p["constants"]["young"][a].as_f64().unwrap())
            .sum::<f64>()
            / 3.0;
        assert!(e > last);
        last = e;
        assert!((c * rho.powf(n) / e - 1.0).abs() <= miss + 1e-12);
    }
    let dir = tempdir();
    let before = files_in(dir.path());
    for bad in ["0.5", "0.1:0.5:1", "0:0.5:3", "a:b:c"] {
        let a = ["homogenize", "--densities", bad, "--report", "r.json"];
        let out = run(&a, dir.path());
        assert_refusal(dir.path(), &before, &out, &a, "densities");
    }
}

/// `--plot` draws the directional Young's modulus from three sides. A solid cell's surface is a
/// sphere: its silhouette in each view is a disc. The grid cell's is a cross of spikes along the
/// axes: in the front view the silhouette reaches along the image's axes more than three times
/// as far as along its diagonals.
#[test]
fn the_plot_shows_the_directional_modulus() {
    let dir = tempdir();
    let silhouette = |args: &[&str]| {
        let mut a = vec!["homogenize", "-q", "--plot", "e.png", "--voxels", "12"];
        a.extend(args);
        ok(&a, dir.path());
        let (w, h, rgb) = read_png(&dir.path().join("e.png"));
        assert_eq!((w, h), (1200, 400));
        // The renderer's background: a vertical gradient; anything else is the surface.
        let hit = |x: u32, y: u32| {
            let v = y as f64 / h as f64;
            let bg = [247.0, 248.0, 250.0]
                .iter()
                .zip([222.0, 226.0, 232.0])
                .map(|(t, b)| (t + (b - t) * v) as u8)
                .collect::<Vec<u8>>();
            let i = 3 * (y * w + x) as usize;
            rgb[i..i + 3]
                .iter()
                .zip(&bg)
                .any(|(a, b)| a.abs_diff(*b) > 3)
        };
        // The front view: the middle third; the reach of the silhouette from its centre along
        // the image's horizontal axis and along its diagonal.
        let (cx, cy) = (600i64, 200i64);
        let reach = |dx: i64, dy: i64| {
            (0..200)
                .take_while(|&k| hit((cx + k * dx) as u32, (cy + k * dy) as u32))
                .count() as f64
                * ((dx * dx + dy * dy) as f64).sqrt()
        };
        (reach(1, 0), reach(1, 1), reach(0, 1))
    };
    let (axis, diagonal, up) = silhouette(&["--cell", "sc", "--radius", "1"]);
    assert!(
        (axis - diagonal).abs() < 0.05 * axis && (axis - up).abs() < 0.05 * axis,
        "{axis} {diagonal} {up}"
    );
    let (axis, diagonal, _) = silhouette(&["--cell", "sc", "--radius", "0.12"]);
    assert!(axis > 3.0 * diagonal, "{axis} {diagonal}");
}

/// `--stiffness-field` grades a part by stiffness: each whole cell is made at the density whose
/// homogenised cell has the Young's modulus the field asks for at its centre. Checked by
/// homogenising each cell's density again, apart from the part: its modulus is the field's
/// within 3 % (the table interpolates between 9 densities).
#[test]
fn a_stiffness_field_grades_the_density() {
    let dir = tempdir();
    for (args, lattice, field) in [
        (
            &[
                "tpms",
                "--type",
                "gyroid",
                "--cells",
                "3,1,1",
                "--cell-size",
                "5",
            ][..],
            &["--type", "gyroid"][..],
            (0.01, 0.004),
        ),
        (
            &[
                "strut",
                "--cell",
                "octet",
                "--cells",
                "3,1,1",
                "--cell-size",
                "5",
            ],
            &["--cell", "octet"],
            (0.02, 0.002),
        ),
    ] {
        let expr = format!("{} + {}*x/5", field.0, field.1);
        let mut a = args.to_vec();
        a.extend([
            "-q",
            "-r",
            "24",
            "-o",
            "part.stl",
            "--report",
            "r.json",
            "--stiffness-field",
            &expr,
        ]);
        ok(&a, dir.path());
        let report = json(&dir.path().join("r.json"));
        let cells = report["grading"]["cells"].as_array().unwrap();
        assert_eq!(cells.len(), 3);
        for c in cells {
            let i = c["cell"][0].as_f64().unwrap();
            let want = field.0 + field.1 * (i + 0.5);
            let density = format!("{:.5}", c["target"].as_f64().unwrap());
            let mut h = lattice.to_vec();
            h.extend(["--density", &density, "--voxels", "24", "--cell-size", "5"]);
            let r = homogenize(&h);
            let e: f64 = (0..3)
                .map(|k| r["constants"]["young"][k].as_f64().unwrap())
                .sum::<f64>()
                / 3.0;
            assert!(
                (e / want - 1.0).abs() < 0.03,
                "{args:?} cell {i}: E/Es {e}, field {want}"
            );
        }
    }
    let before = files_in(dir.path());
    for (args, what) in [
        (
            &[
                "tpms",
                "--stiffness-field",
                "0.03",
                "--density-field",
                "0.2",
            ][..],
            "--density-field",
        ),
        (&["tpms", "--stiffness-field", "-0.1"], "density field"),
    ] {
        let mut a = args.to_vec();
        a.extend(["-o", "bad.stl"]);
        let out = run(&a, dir.path());
        assert_refusal(dir.path(), &before, &out, &a, what);
    }
}

/// `topopt --stiffness` writes the design's SIMP stiffness at its elements' nodes in the part's
/// coordinates: checked against the densities it wrote beside it (ρᵖ with Emin, averaged over
/// the elements around each node, the optimiser's rows flipped so that y is up), and read by a
/// stiffness-graded part of the same box.
#[test]
fn topopt_writes_the_stiffness_a_graded_part_reads() {
    let dir = tempdir();
    ok(
        &[
            "topopt",
            "-q",
            "--problem",
            "cantilever3d",
            "--nelx",
            "8",
            "--nely",
            "4",
            "--nelz",
            "2",
            "-o",
            "d.npy",
            "--stiffness",
            "s.npy",
        ],
        dir.path(),
    );
    let check = r#"
import sys, numpy as np
d = np.load(sys.argv[1] + "/d.npy")  # (nely, nelx, nelz), row 0 at the top
s = np.load(sys.argv[1] + "/s.npy")  # (nelx+1, nely+1, nelz+1), y up
ny, nx, nz = d.shape
e = 1e-9 + d ** 3 * (1 - 1e-9)
e = e[::-1].transpose(1, 0, 2)  # (nx, ny, nz), y up
want = np.zeros((nx + 1, ny + 1, nz + 1)); count = np.zeros_like(want)
for a in (0, 1):
    for b in (0, 1):
        for c in (0, 1):
            want[a:a + nx, b:b + ny, c:c + nz] += e
            count[a:a + nx, b:b + ny, c:c + nz] += 1
want /= count
assert s.shape == want.shape, (s.shape, want.shape)
print(float(np.abs(s - want).max()))
"#;
    let o = std::process::Command::new("python3")
        .args(["-c", check])
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let diff: f64 = String::from_utf8_lossy(&o.stdout).trim().parse().unwrap();
    assert!(diff < 1e-12, "{diff}");
    // The box the file spans: 8 × 4 × 2 elements of 1 mm; held to the sheet's range where the
    // design is void or solid.
    ok(
        &[
            "tpms",
            "-q",
            "--type",
            "gyroid",
            "--structure",
            "sheet",
            "--size",
            "8,4,2",
            "--cell-size",
            "2",
            "-r",
            "16",
            "--stiffness-field",
            "s.npy",
            "--clamp",
            "-o",
            "p.stl",
            "--report",
            "p.json",
        ],
        dir.path(),
    );
    let r = json(&dir.path().join("p.json"));
    assert!(r["grading"]["field"]
        .as_str()
        .unwrap()
        .contains("stiffness samples s.npy"));
}
