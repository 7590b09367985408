//! `latvox fgm`: scans to signed distance grids and graded materials, checked against analytic
//! shapes and independent readers — OpenVDB's Python module and `vdb_print` for the grids, the
//! analytic distance for the PNG stack's layers.

use crate::common;

use crate::common::{assert_refusal, files_in, json, ok, run, tempdir, Rng};
use latvox::fgm::material::{Composition, Feature, Features, Law};
use latvox::fgm::{FgmJob, Geometry, Sign};
use latvox::io::points::PointCloud;
use latvox::progress::Progress;
use std::f64::consts::PI;
use std::path::Path;

/// A shape the test knows exactly: its signed distance, and a way to sample its surface.
#[derive(Clone, Copy)]
enum Shape {
    /// Radius 10 mm about (5, −3, 2).
    Sphere,
    /// Ring radius 10 mm, tube radius 4 mm, about the z axis through (−2, 1, 3).
    Torus,
}

const SPHERE_C: [f64; 3] = [5.0, -3.0, 2.0];
const TORUS_C: [f64; 3] = [-2.0, 1.0, 3.0];

impl Shape {
    fn distance(self, p: [f64; 3]) -> f64 {
        match self {
            Shape::Sphere => norm(sub(p, SPHERE_C)) - 10.0,
            Shape::Torus => {
                let q = sub(p, TORUS_C);
                let ring = (q[0] * q[0] + q[1] * q[1]).sqrt() - 10.0;
                (ring * ring + q[2] * q[2]).sqrt() - 4.0
            }
        }
    }

    /// The surface point at parameters (u, v) ∈ [0, 1)², its normal, and whether it lies in
    /// the patch a 10 % hole removes.
    fn at(self, u: f64, v: f64) -> ([f64; 3], [f64; 3], bool) {
        match self {
            Shape::Sphere => {
                // Area-uniform: z uniform in [−1, 1]; the hole is the cap z > 0.8 (10 % of the area).
                let z = 1.0 - 2.0 * u;
                let r = (1.0 - z * z).sqrt();
                let n = [r * (2.0 * PI * v).cos(), r * (2.0 * PI * v).sin(), z];
                (add(SPHERE_C, n.map(|x| 10.0 * x)), n, z > 0.8)
            }
            Shape::Torus => {
                let (phi, theta) = (2.0 * PI * u, 2.0 * PI * v);
                let n = [
                    theta.cos() * phi.cos(),
                    theta.cos() * phi.sin(),
                    theta.sin(),
                ];
                let ring = [10.0 * phi.cos(), 10.0 * phi.sin(), 0.0];
                let p = add(TORUS_C, add(ring, n.map(|x| 4.0 * x)));
                // The hole: a fifth of the ring, the upper half of the tube (about 10 %).
                (p, n, u < 0.2 && v < 0.5)
            }
        }
    }

    /// Whether `p` is near the hole's patch, where the scan says nothing (excluded from the
    /// distance and sign checks; the rest of the part must be right despite the hole).
    fn near_hole(self, p: [f64; 3]) -> bool {
        match self {
            Shape::Sphere => p[2] - SPHERE_C[2] > 7.0,
            Shape::Torus => {
                let q = sub(p, TORUS_C);
                let phi = q[1].atan2(q[0]).rem_euclid(2.0 * PI) / (2.0 * PI);
                !(0.3..=0.9).contains(&phi)
            }
        }
    }

    /// Samples `n` surface points (area-uniform), moved along the normal by up to `noise` mm,
    /// less the hole's patch when `hole`.
    fn scan(self, n: usize, noise: f64, hole: bool, seed: u64) -> Vec<[f64; 3]> {
        let mut rng = Rng(seed);
        let mut out = Vec::new();
        while out.len() < n {
            let (u, v) = (rng.uniform(0.0, 1.0), rng.uniform(0.0, 1.0));
            if let Shape::Torus = self {
                // Area element ∝ 10 + 4 cos θ: rejection keeps the sample uniform.
                if rng.uniform(0.0, 14.0) > 10.0 + 4.0 * (2.0 * PI * v).cos() {
                    continue;
                }
            }
            let (p, nrm, in_hole) = self.at(u, v);
            if hole && in_hole {
                continue;
            }
            let e = rng.uniform(-noise, noise);
            out.push(add(p, nrm.map(|x| e * x)));
        }
        out
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn norm(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

fn write_xyz(path: &Path, points: &[[f64; 3]]) {
    let text: String = points
        .iter()
        .map(|p| format!("{:.5} {:.5} {:.5}\n", p[0], p[1], p[2]))
        .collect();
    std::fs::write(path, text).unwrap();
}

fn skin_job(points: Vec<[f64; 3]>, voxel: f64) -> FgmJob {
    FgmJob {
        geometry: Geometry::Points(PointCloud {
            points,
            normals: None,
        }),
        input_name: "scan".into(),
        voxel,
        sign: Sign::Winding,
        features: Features {
            list: vec![Feature::Skin],
            weights: None,
        },
        composition: Composition::new(vec!["A".into(), "B".into()], vec![Law::Power { p: 1.0 }])
            .unwrap(),
        dmax: None,
        tolerance: None,
        verify: latvox::verify::Verify::Full,
    }
}

/// Sphere and torus scans — clean, with 1 % noise, with a 10 % hole — at 0.4 mm voxels: the
/// signed distance within half a voxel of the analytic one near the surface (within a voxel of
/// it; noise: within half a voxel of the noise band), the right sign across the band and deep
/// inside, the mesh closed and free of self-intersections, its volume the shape's (less what a
/// hole's film cuts off).
#[test]
fn scans_give_the_analytic_distance_and_keep_their_inside() {
    let voxel = 0.4;
    for shape in [Shape::Sphere, Shape::Torus] {
        let size: f64 = match shape {
            Shape::Sphere => 20.0,
            Shape::Torus => 28.0,
        };
        for (noise, hole) in [(0.0, false), (0.01 * size / 2.0, false), (0.0, true)] {
            let what = format!(
                "{} noise {noise} hole {hole}",
                match shape {
                    Shape::Sphere => "sphere",
                    Shape::Torus => "torus",
                }
            );
            let fgm = skin_job(shape.scan(30_000, noise, hole, 7), voxel)
                .run(&Progress::hidden())
                .unwrap();
            assert!(
                fgm.checks.closed && fgm.checks.outward && fgm.checks.manifold,
                "{what}"
            );
            assert!(!fgm.checks.self_intersecting, "{what}");
            let mut rng = Rng(11);
            let (mut worst, mut checked, mut deep) = (0.0f64, 0, 0);
            let b = 16.0;
            let c = match shape {
                Shape::Sphere => SPHERE_C,
                Shape::Torus => TORUS_C,
            };
            for _ in 0..60_000 {
                let p = add(c, [0, 1, 2].map(|_| rng.uniform(-b, b)));
                if hole && shape.near_hole(p) {
                    continue;
                }
                let exact = shape.distance(p);
                let v = fgm.sdf.value_at(p);
                if exact.abs() < voxel {
                    worst = worst.max((v - exact).abs());
                    checked += 1;
                } else if exact.abs() > noise + 0.5 * voxel {
                    assert_eq!(
                        v < 0.0,
                        exact < 0.0,
                        "{what}: value {v} at {p:?}, exact distance {exact}"
                    );
                    deep += (exact < -3.0 * voxel) as usize;
                }
            }
            assert!(checked > 200 && deep > 1000, "{what}: {checked} {deep}");
            assert!(
                worst < 0.5 * voxel + noise,
                "{what}: worst distance error {worst} mm"
            );
            let exact_volume = match shape {
                Shape::Sphere => 4.0 / 3.0 * PI * 1000.0,
                Shape::Torus => 2.0 * PI * PI * 10.0 * 16.0,
            };
            let v = fgm.checks.volume.unwrap();
            let tolerance = if hole { 0.05 } else { 0.01 };
            assert!(
                (v / exact_volume - 1.0).abs() < tolerance,
                "{what}: volume {v} vs {exact_volume}"
            );
        }
    }
}

/// The inside told by line scans (the literature's method) on a clean scan agrees with the
/// analytic sign; given normals are used as given (and flipped when they point inward).
#[test]
fn line_scans_and_given_normals() {
    let dir = tempdir();
    let points = Shape::Sphere.scan(20_000, 0.0, false, 3);
    // x y z nx ny nz, normals pointing inward: latvox flips them.
    let text: String = points
        .iter()
        .map(|p| {
            let n = sub(SPHERE_C, *p).map(|x| x / 10.0);
            format!("{} {} {} {} {} {}\n", p[0], p[1], p[2], n[0], n[1], n[2])
        })
        .collect();
    std::fs::write(dir.path().join("s.xyz"), text).unwrap();
    ok(
        &[
            "fgm", "--points", "s.xyz", "--voxel", "0.5", "--sign", "scan", "-o", "s.stl",
            "--report", "r.json", "-q",
        ],
        dir.path(),
    );
    let r = json(&dir.path().join("r.json"));
    assert_eq!(r["geometry"]["normals_estimated"], false);
    assert_eq!(r["geometry"]["normals_flipped"], true);
    assert_eq!(r["geometry"]["sign"], "scan");
    let v = r["volume"].as_f64().unwrap();
    assert!((v / (4.0 / 3.0 * PI * 1000.0) - 1.0).abs() < 0.01, "{v}");
}

/// Runs the Python reader on `vdb` with `materials`.
fn read_vdb(dir: &Path, vdb: &str, materials: &str) -> serde_json::Value {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/reference/fgm_vdb.py");
    let out = std::process::Command::new("/usr/bin/python3")
        .arg(script)
        .args([vdb, materials])
        .current_dir(dir)
        .output()
        .expect("run /usr/bin/python3 (python3-openvdb)");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

/// Three materials graded from the skin, read back with OpenVDB's Python module: the grids
/// named and sized as asked (and as `vdb_print` lists them), fractions in [0, 1] summing to 1
/// at every voxel, each the law applied to that voxel's distance (so every iso-surface of the
/// distance has one composition), the distance the sphere's analytic depth; and a linear law's
/// profile linear from the surface inward.
#[test]
fn composition_sums_to_one_and_follows_the_distance() {
    let dir = tempdir();
    write_xyz(
        &dir.path().join("s.xyz"),
        &Shape::Sphere.scan(30_000, 0.0, false, 5),
    );
    // Hard deep inside (a smooth step from 4 to 8 mm), Mid near the skin (a table: 0.6 up to
    // 3 mm, nothing from 5 mm), Soft the rest.
    std::fs::write(
        dir.path().join("mid.csv"),
        "d,fraction\n0,0.6\n3,0.6\n5,0\n",
    )
    .unwrap();
    ok(
        &[
            "fgm",
            "--points",
            "s.xyz",
            "--voxel",
            "0.5",
            "--materials",
            "Hard,Mid,Soft",
            "--law",
            "step:4:8",
            "--law",
            "table:mid.csv",
            "--vdb",
            "g.vdb",
            "-o",
            "g.ply",
            "-q",
            "--report",
            "r.json",
        ],
        dir.path(),
    );
    let listing = std::process::Command::new("vdb_print")
        .args(["-l", "g.vdb"])
        .current_dir(dir.path())
        .output()
        .expect("vdb_print (libopenvdb-tools)");
    let listing = String::from_utf8_lossy(&listing.stdout);
    for name in ["sdf", "distance", "Hard", "Mid", "Soft"] {
        assert!(
            listing.contains(&format!("Name: {name}\n")),
            "{name} not in {listing}"
        );
    }
    assert_eq!(listing.matches("voxel size: 0.5\n").count(), 5, "{listing}");
    let v = read_vdb(dir.path(), "g.vdb", "Hard,Mid,Soft");
    let classes: Vec<(String, String)> = v["grids"]
        .as_array()
        .unwrap()
        .iter()
        .map(|g| {
            (
                g["name"].as_str().unwrap().into(),
                g["class"].as_str().unwrap().into(),
            )
        })
        .collect();
    for (name, class) in [
        ("sdf", "level set"),
        ("Hard", "fog volume"),
        ("Soft", "fog volume"),
    ] {
        assert!(
            classes.contains(&(name.into(), class.into())),
            "{classes:?}"
        );
    }
    let dmax = json(&dir.path().join("r.json"))["dmax"].as_f64().unwrap();
    assert!((dmax - 10.0).abs() < 0.5, "d_max {dmax}");
    let voxels = v["voxels"].as_array().unwrap();
    assert!(voxels.len() > 20_000, "{}", voxels.len());
    let (mut sum_err, mut law_err, mut depth_err) = (0.0f64, 0.0f64, 0.0f64);
    for x in voxels {
        let p: Vec<f64> = numbers(&x[0]);
        let d = x[1].as_f64().unwrap();
        let f: Vec<f64> = numbers(&x[2]);
        assert!(f.iter().all(|x| (-1e-6..=1.0 + 1e-6).contains(x)), "{f:?}");
        sum_err = sum_err.max((f.iter().sum::<f64>() - 1.0).abs());
        // The laws, written out here.
        let t = ((d - 4.0) / 4.0).clamp(0.0, 1.0);
        let mid = if d <= 3.0 {
            0.6
        } else {
            (0.6 * (5.0 - d) / 2.0).max(0.0)
        };
        let want = [t * t * (3.0 - 2.0 * t), mid];
        law_err = law_err
            .max((f[0] - want[0]).abs())
            .max((f[1] - want[1]).abs());
        let depth = -Shape::Sphere.distance([p[0], p[1], p[2]]);
        if depth > 0.0 {
            depth_err = depth_err.max((d - depth).abs());
        }
    }
    assert!(sum_err < 1e-6, "fractions sum to 1 within {sum_err}");
    assert!(law_err < 1e-5, "fractions follow the laws within {law_err}");
    assert!(
        depth_err < 0.5,
        "distance to the skin within {depth_err} mm of the depth"
    );

    // Linear (p = 1) from the surface inward: along the x axis through the centre.
    write_xyz(
        &dir.path().join("s.xyz"),
        &Shape::Sphere.scan(30_000, 0.0, false, 5),
    );
    ok(
        &[
            "fgm", "--points", "s.xyz", "--voxel", "0.5", "--dmax", "10", "--vdb", "l.vdb", "-o",
            "l.stl", "-q",
        ],
        dir.path(),
    );
    let v = read_vdb(dir.path(), "l.vdb", "A,B");
    let mut line: Vec<(f64, f64)> = v["voxels"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|x| {
            let p: Vec<f64> = numbers(&x[0]);
            let on_axis = (p[1] - SPHERE_C[1]).abs() < 0.26 && (p[2] - SPHERE_C[2]).abs() < 0.26;
            (on_axis && p[0] > SPHERE_C[0])
                .then(|| (10.0 - (p[0] - SPHERE_C[0]), x[2][0].as_f64().unwrap()))
        })
        .collect();
    line.sort_by(|a, b| a.0.total_cmp(&b.0));
    assert!(line.len() >= 15, "{line:?}");
    for (depth, a) in &line {
        // A = d / 10 with d the depth: linear, within the distance's half-voxel accuracy.
        assert!((a - depth / 10.0).abs() < 0.03, "at depth {depth}: A = {a}");
    }
}

/// A JSON array of numbers.
fn numbers(v: &serde_json::Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

/// Reads an RGBA PNG (the stack's layers): width, height, pixels.
fn read_rgba(path: &Path) -> (usize, usize, Vec<u8>) {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgba);
    buf.truncate(info.buffer_size());
    (info.width as usize, info.height as usize, buf)
}

/// A PNG stack of a sphere graded from its skin: every layer the same size, each part pixel
/// one of the palette's colours, outside transparent; per layer, each material's share of the
/// pixels within 1 % of its mean fraction over them, the fraction computed here from the
/// analytic depth of each pixel.
#[test]
fn png_stack_layers_match_the_field() {
    let dir = tempdir();
    write_xyz(
        &dir.path().join("s.xyz"),
        &Shape::Sphere.scan(30_000, 0.0, false, 9),
    );
    ok(
        &[
            "fgm",
            "--points",
            "s.xyz",
            "--voxel",
            "0.4",
            "--law",
            "step:0.5:3",
            "--png-stack",
            "stack",
            "--dpi",
            "150x120",
            "--layer",
            "0.8",
            "--palette",
            "#ff0000,#0000ff",
            "-o",
            "s.stl",
            "-q",
        ],
        dir.path(),
    );
    let manifest = json(&dir.path().join("stack/stack.json"));
    let s = &manifest["stack"];
    let (layers, width, height) = (
        s["layers"].as_u64().unwrap() as usize,
        s["width"].as_u64().unwrap() as usize,
        s["height"].as_u64().unwrap() as usize,
    );
    let px = [25.4 / 150.0, 25.4 / 120.0];
    let origin: Vec<f64> = s["origin"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_f64().unwrap())
        .collect();
    assert_eq!(layers, 25);
    let mut checked = 0;
    for l in 0..layers {
        let (w, h, rgba) = read_rgba(&dir.path().join(format!("stack/layer_{l:05}.png")));
        assert_eq!((w, h), (width, height));
        let z = origin[2] + (l as f64 + 0.5) * 0.8;
        let (mut red, mut part, mut want) = (0usize, 0usize, 0.0f64);
        for r in 0..h {
            for c in 0..w {
                let p = &rgba[4 * (r * w + c)..4 * (r * w + c) + 4];
                match p {
                    [_, _, _, 0] => continue,
                    [255, 0, 0, 255] => red += 1,
                    [0, 0, 255, 255] => {}
                    _ => panic!("layer {l}: pixel {p:?} is neither material nor transparent"),
                }
                part += 1;
                let x = origin[0] + (c as f64 + 0.5) * px[0];
                let y = origin[1] + height as f64 * px[1] - (r as f64 + 0.5) * px[1];
                let depth = (-Shape::Sphere.distance([x, y, z])).max(0.0);
                let t = ((depth - 0.5) / 2.5).clamp(0.0, 1.0);
                want += t * t * (3.0 - 2.0 * t);
            }
        }
        if part >= 500 {
            let got = red as f64 / part as f64;
            let expect = want / part as f64;
            assert!(
                (got - expect).abs() < 0.01,
                "layer {l}: share {got} vs field {expect} over {part} pixels"
            );
            checked += 1;
        }
    }
    assert!(checked >= 20, "{checked} layers checked");
}

/// Bad input is refused: exit 2, one line, no file written.
#[test]
fn bad_input_is_refused() {
    let dir = tempdir();
    let d = dir.path();
    std::fs::write(d.join("empty.xyz"), "").unwrap();
    std::fs::write(d.join("nan.xyz"), "0 0 0\n1 nan 2\n").unwrap();
    std::fs::write(d.join("binary.xyz"), [0u8, 159, 146, 150, 255]).unwrap();
    let few: String = (0..10).map(|i| format!("{i} {} 0\n", i * i)).collect();
    std::fs::write(d.join("few.xyz"), few).unwrap();
    write_xyz(&d.join("ok.xyz"), &Shape::Sphere.scan(5_000, 0.0, false, 1));
    let before = files_in(d);
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["--points", "empty.xyz"], "no points"),
        (vec!["--points", "missing.xyz"], "missing.xyz"),
        (vec!["--points", "nan.xyz"], "line 2"),
        (vec!["--points", "binary.xyz"], "binary.xyz"),
        (vec!["--points", "few.xyz"], "at least 32"),
        (
            vec!["--points", "ok.xyz", "--feature", "plane:0,0,1"],
            "unknown feature",
        ),
        (
            vec!["--points", "ok.xyz", "--law", "linear", "--law", "linear"],
            "sum to",
        ),
        (
            vec![
                "--points",
                "ok.xyz",
                "--materials",
                "A,B,C",
                "--law",
                "power:1",
                "--law",
                "step:0:1",
            ],
            "fraction",
        ),
        (
            vec!["--points", "ok.xyz", "--palette", "red,blue"],
            "palette",
        ),
        (vec!["--points", "ok.xyz", "--law", "cubic"], "law 'cubic'"),
    ];
    for (args, what) in cases {
        let mut all = vec![
            "fgm",
            "--voxel",
            "1",
            "-o",
            "out.ply",
            "--vdb",
            "out.vdb",
            "--png-stack",
            "st",
        ];
        all.extend(args);
        let out = run(&all, d);
        assert_refusal(d, &before, &out, &all, what);
    }
    // Refused once the part is known, still before any file is made.
    let late: Vec<(Vec<&str>, &str)> = vec![
        (vec!["--png-stack", "no/such/folder"], "does not exist"),
        (vec!["--png-stack", "st", "--dpi", "100000"], "lower --dpi"),
        (
            vec!["--preview", "p.png", "--preview-z", "1000"],
            "outside the part",
        ),
    ];
    for (args, what) in late {
        let mut all = vec![
            "fgm", "--points", "ok.xyz", "--voxel", "1", "-o", "out.ply", "--vdb", "out.vdb",
        ];
        all.extend(args);
        let out = run(&all, d);
        assert_refusal(d, &before, &out, &all, what);
    }
}

/// The part's meshes carry the composition: the 3MF read by lib3mf has the named base materials
/// and a composite group whose mix at each corner is the law at that vertex (graded from a
/// point: the fraction is the vertex's distance to it over d_max, computed here); the PLY's
/// vertex colours, read by trimesh, are the palette mixed by the same fractions.
#[test]
fn meshes_carry_the_composition() {
    let dir = tempdir();
    write_xyz(
        &dir.path().join("s.xyz"),
        &Shape::Sphere.scan(20_000, 0.0, false, 4),
    );
    let feature = "point:5,-3,12"; // the sphere's top
    for out in ["m.3mf", "m.ply"] {
        ok(
            &[
                "fgm",
                "--points",
                "s.xyz",
                "--voxel",
                "0.5",
                "--feature",
                feature,
                "--dmax",
                "20",
                "--materials",
                "Stiff,Soft",
                "--palette",
                "#ff0000,#0000ff",
                "-o",
                out,
                "-q",
            ],
            dir.path(),
        );
    }
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/reference/fgm_mesh.py");
    let out = std::process::Command::new("python3")
        .arg(script)
        .args(["m.3mf", "m.ply"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["bases"], serde_json::json!(["Stiff", "Soft"]));
    assert!(
        v["composites"].as_u64().unwrap() > 100,
        "{}",
        v["composites"]
    );
    let fraction = |p: &[f64]| norm(sub([p[0], p[1], p[2]], [5.0, -3.0, 12.0])) / 20.0;
    let corners = v["corners"].as_array().unwrap();
    assert!(corners.len() > 1000);
    for c in corners {
        let p: Vec<f64> = numbers(&c[0]);
        let mix: Vec<f64> = numbers(&c[1]);
        let f = fraction(&p);
        assert!(
            (mix[0] - f).abs() < 1e-3 && (mix[1] - (1.0 - f)).abs() < 1e-3,
            "{p:?}: {mix:?} vs {f}"
        );
    }
    let verts = v["ply_vertices"].as_array().unwrap();
    for (p, c) in verts.iter().zip(v["ply_colours"].as_array().unwrap()) {
        let p: Vec<f64> = numbers(p);
        let f = fraction(&p);
        let (r, b) = (c[0].as_f64().unwrap(), c[2].as_f64().unwrap());
        assert!(
            (r - 255.0 * f).abs() <= 1.0 && (b - 255.0 * (1.0 - f)).abs() <= 1.0,
            "{p:?}: {c} vs {f}"
        );
    }
}

/// `--tolerance`: the part's mesh simplified within it of the part's surface, for a torus given
/// as a fine mesh (within 0.003 mm of the analytic torus) and for a sphere's scan (where the
/// surface is the one meshed from the scan's distance). Checked by the test: closed, one piece,
/// free of self-intersections (its own search, and CGAL's verdict), the uniform mesh's volume,
/// every sampled point within the tolerance of the analytic surface (plus the uniform mesh's
/// own deviation, for the scan), and at least 5× fewer triangles.
#[test]
fn meshes_simplified_within_a_tolerance_stay_on_the_surface() {
    let dir = tempdir();
    let d = dir.path();
    crate::meshkit::write_stl(
        &d.join("torus.stl"),
        &crate::meshkit::torus(10.0, 4.0, 256, 128),
    );
    write_xyz(&d.join("s.xyz"), &Shape::Sphere.scan(20_000, 0.0, false, 4));
    let torus = |p: [f64; 3]| {
        let ring = (p[0] * p[0] + p[1] * p[1]).sqrt() - 10.0;
        (ring * ring + p[2] * p[2]).sqrt() - 4.0
    };
    let sphere = |p: [f64; 3]| Shape::Sphere.distance(p);
    type Distance<'a> = &'a dyn Fn([f64; 3]) -> f64;
    let cases: [(&str, &str, Distance, &str, f64); 2] = [
        ("--mesh", "torus.stl", &torus, "0.25", 0.1),
        ("--points", "s.xyz", &sphere, "0.4", 0.15),
    ];
    for (flag, input, distance, voxel, tolerance) in cases {
        let tol = tolerance.to_string();
        let base = ["fgm", flag, input, "--voxel", voxel, "-q"];
        ok(&[&base[..], &["-o", "uniform.stl"]].concat(), d);
        let args = [
            &base[..],
            &["--tolerance", &tol, "--verify", "cgal"],
            &["-o", "simple.stl", "--report", "r.json"],
        ]
        .concat();
        ok(&args, d);
        let (u, s) = (
            common::read_stl(&d.join("uniform.stl")),
            common::read_stl(&d.join("simple.stl")),
        );
        let r = json(&d.join("r.json"));
        assert_eq!(r["checks"]["checked_by"], "CGAL", "{input}");
        assert_eq!(r["checks"]["self_intersecting"], false, "{input}");
        assert_eq!(common::edges(&s), common::Edges::default(), "{input}");
        assert_eq!(common::pieces(&s), 1, "{input}");
        assert_eq!(crate::meshkit::intersecting_pairs(&s), 0, "{input}");
        let (vu, vs) = (common::volume(&u), common::volume(&s));
        assert!((vs / vu - 1.0).abs() < 2e-3, "{input}: {vs} vs {vu} mm³");
        let worst = |tris: &[common::Tri]| common::worst_on(tris, |p| distance(p).abs());
        let (du, ds) = (worst(&u), worst(&s));
        let bound = match flag {
            "--mesh" => tolerance.max(du) + 0.003,
            _ => tolerance + du,
        };
        let ratio = u.len() as f64 / s.len() as f64;
        eprintln!(
            "{input}: {} → {} triangles ({ratio:.1}×), deviation {du:.4} → {ds:.4} mm (bound {bound:.4})",
            u.len(),
            s.len()
        );
        assert!(ds <= bound, "{input}: deviation {ds} > {bound}");
        assert!(ratio >= 5.0, "{input}: {ratio:.1}× fewer");
        let reported = &r["simplified"];
        assert_eq!(reported["uniform_triangles"], u.len(), "{input}");
        assert!(
            reported["deviation"].as_f64().unwrap() <= tolerance.max(du) + 0.003,
            "{input}: {reported:#}"
        );
    }
}

/// An fgm run saved as a part file (its scan and law table by absolute paths) makes the same
/// part from another folder, and as a `latvox batch` job naming the part file.
#[test]
fn part_files_and_batch_jobs_make_the_same_part() {
    let dir = tempdir();
    let d = dir.path();
    write_xyz(&d.join("s.xyz"), &Shape::Sphere.scan(8_000, 0.0, false, 2));
    std::fs::write(d.join("law.csv"), "0,0.2\n5,0.9\n").unwrap();
    let first = [
        "fgm",
        "--points",
        "s.xyz",
        "--voxel",
        "0.8",
        "--feature",
        "skin",
        "--feature",
        "point:5,-3,2",
        "--law",
        "table:law.csv",
        "-o",
        "a.stl",
        "--report",
        "a.json",
        "-q",
        "--save-part",
        "a.toml",
    ];
    let r = run(&first, d);
    assert_eq!(
        r.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&r.stderr)
    );
    let part = std::fs::read_to_string(d.join("a.toml")).unwrap();
    assert!(
        part.contains("command = \"fgm\"") && part.contains("feature = ["),
        "{part}"
    );
    std::fs::create_dir(d.join("other")).unwrap();
    ok(
        &[
            "fgm",
            "--part",
            "../a.toml",
            "-o",
            "b.stl",
            "--report",
            "b.json",
            "-q",
        ],
        &d.join("other"),
    );
    std::fs::write(
        d.join("jobs.toml"),
        "[[job]]\ncommand = \"fgm\"\npart = \"a.toml\"\noutput = \"c.stl\"\nreport = \"c.json\"\n",
    )
    .unwrap();
    ok(&["batch", "jobs.toml", "-q"], d);
    let a = json(&d.join("a.json"));
    for other in ["other/b.json", "c.json"] {
        let b = json(&d.join(other));
        for key in ["triangles", "volume", "dmax", "shares"] {
            assert_eq!(a[key], b[key], "{other}: {key}");
        }
    }
}

/// A part from a mesh (a closed STL sphere written here) graded from a polyline, a surface and
/// its skin combined by weights: the distance grid is the weighted mean of the three distances
/// computed here; the preview is a picture of the section with the part's colours in it.
#[test]
fn meshes_curves_surfaces_weights_and_the_preview() {
    let dir = tempdir();
    let d = dir.path();
    // A UV sphere of radius 10 about SPHERE_C, 64 × 32 facets, outward.
    let (nu, nv) = (64, 32);
    let at = |i: usize, j: usize| {
        let (u, v) = (2.0 * PI * i as f64 / nu as f64, PI * j as f64 / nv as f64);
        add(
            SPHERE_C,
            [
                10.0 * v.sin() * u.cos(),
                10.0 * v.sin() * u.sin(),
                10.0 * v.cos(),
            ],
        )
    };
    let mut stl = String::from("solid s\n");
    for i in 0..nu {
        for j in 0..nv {
            let (a, b, c, e) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            for t in [[a, c, b], [a, e, c]] {
                if norm(sub(t[0], t[1])) < 1e-9
                    || norm(sub(t[1], t[2])) < 1e-9
                    || norm(sub(t[0], t[2])) < 1e-9
                {
                    continue;
                }
                stl += "facet normal 0 0 0\nouter loop\n";
                for p in t {
                    stl += &format!("vertex {} {} {}\n", p[0], p[1], p[2]);
                }
                stl += "endloop\nendfacet\n";
            }
        }
    }
    stl += "endsolid s\n";
    std::fs::write(d.join("ball.stl"), stl).unwrap();
    std::fs::write(d.join("axis.csv"), "5,-3,-20\n5,-3,20\n").unwrap();
    // A plane at z = 2 (two triangles, 100 mm square).
    std::fs::write(
        d.join("plane.stl"),
        "solid p\nfacet normal 0 0 1\nouter loop\nvertex -50 -50 2\nvertex 50 -50 2\nvertex 50 50 2\nendloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex -50 -50 2\nvertex 50 50 2\nvertex -50 50 2\nendloop\nendfacet\nendsolid p\n",
    )
    .unwrap();
    ok(
        &[
            "fgm",
            "--mesh",
            "ball.stl",
            "--voxel",
            "0.5",
            "--feature",
            "curve:axis.csv",
            "--feature",
            "surface:plane.stl",
            "--feature",
            "skin",
            "--weights",
            "1,2,1",
            "--vdb",
            "w.vdb",
            "-o",
            "w.stl",
            "--preview",
            "w.png",
            "--report",
            "w.json",
            "-q",
        ],
        d,
    );
    let rep = json(&d.join("w.json"));
    assert_eq!(rep["geometry"]["source"], "mesh");
    let v = read_vdb(d, "w.vdb", "A,B");
    let mut worst = 0.0f64;
    let mut n = 0;
    for x in v["voxels"].as_array().unwrap() {
        let p: Vec<f64> = numbers(&x[0]);
        let depth = -Shape::Sphere.distance([p[0], p[1], p[2]]);
        if depth < 1.0 {
            continue; // the faceted skin's distance differs from the sphere's there
        }
        let axis = ((p[0] - 5.0).powi(2) + (p[1] + 3.0).powi(2)).sqrt();
        let plane = (p[2] - 2.0).abs();
        let want = (axis + 2.0 * plane + depth) / 4.0;
        worst = worst.max((x[1].as_f64().unwrap() - want).abs());
        n += 1;
    }
    assert!(n > 10_000, "{n}");
    // The skin term is the faceted sphere's distance (its chords lie up to 0.05 mm inside).
    assert!(worst < 0.1, "weighted distance off by {worst} mm");
    let (w, h, rgb) = common::read_png(&d.join("w.png"));
    assert!(w >= 460 && h > 560, "{w} × {h}");
    let coloured = rgb
        .chunks_exact(3)
        .filter(|p| p[0] != p[1] || p[1] != p[2])
        .count();
    assert!(coloured > 100_000, "{coloured} coloured pixels");
}

/// A plane contour: the cam of the implicit FGM literature's example (a base circle of 20 mm
/// with a lobe, `r(θ) = 20 + 8 max(0, cos θ)²`) about (3.1, −4.7), with a 6 mm bore; or a
/// circle of 10 mm. Signed distances computed here: the circle's exactly, the cam's from a
/// polygon of 7200 vertices (distance to its edges, sign by containment).
struct Contour {
    bore: bool,
    cam: Vec<[f64; 2]>,
}

const CAM_C: [f64; 2] = [3.1, -4.7];

impl Contour {
    fn new(bore: bool) -> Contour {
        let cam = (0..7200)
            .map(|k| {
                let [x, y, _] = Contour::cam_at(k as f64 / 7200.0);
                [x, y]
            })
            .collect();
        Contour { bore, cam }
    }

    /// The cam's profile at parameter `t` ∈ [0, 1) and its outward normal (x, y, 0 / 2D).
    fn cam_at(t: f64) -> [f64; 3] {
        let a = 2.0 * PI * t;
        let r = 20.0 + 8.0 * a.cos().max(0.0).powi(2);
        [CAM_C[0] + r * a.cos(), CAM_C[1] + r * a.sin(), 0.0]
    }

    /// Signed distance to the part (negative inside).
    fn distance(&self, p: [f64; 2]) -> f64 {
        let n = self.cam.len();
        let mut d = f64::INFINITY;
        let mut inside = false;
        for k in 0..n {
            let (a, b) = (self.cam[k], self.cam[(k + 1) % n]);
            let ab = [b[0] - a[0], b[1] - a[1]];
            let t = (((p[0] - a[0]) * ab[0] + (p[1] - a[1]) * ab[1])
                / (ab[0] * ab[0] + ab[1] * ab[1]))
                .clamp(0.0, 1.0);
            d = d.min(
                ((p[0] - a[0] - t * ab[0]).powi(2) + (p[1] - a[1] - t * ab[1]).powi(2)).sqrt(),
            );
            if (a[1] > p[1]) != (b[1] > p[1]) && p[0] < a[0] + (p[1] - a[1]) / (b[1] - a[1]) * ab[0]
            {
                inside = !inside;
            }
        }
        let cam = if inside { -d } else { d };
        if !self.bore {
            return cam;
        }
        let bore = ((p[0] - CAM_C[0]).powi(2) + (p[1] - CAM_C[1]).powi(2)).sqrt() - 6.0;
        cam.max(-bore)
    }

    fn area(&self) -> f64 {
        let n = self.cam.len();
        let cam: f64 = (0..n)
            .map(|k| {
                let (a, b) = (self.cam[k], self.cam[(k + 1) % n]);
                a[0] * b[1] - b[0] * a[1]
            })
            .sum::<f64>()
            / 2.0;
        cam - if self.bore { PI * 36.0 } else { 0.0 }
    }

    /// `n` points of the profile (and a sixth as many on the bore), moved along the normal by up
    /// to `noise`, less the arc `gap` (a fraction of the profile) from the top.
    fn scan(&self, n: usize, noise: f64, gap: f64, seed: u64) -> Vec<[f64; 2]> {
        let mut rng = Rng(seed);
        let mut out = Vec::new();
        for k in 0..n {
            let t = (k as f64 + 0.5) / n as f64;
            if (t - 0.25).abs() < gap / 2.0 {
                continue;
            }
            let (p, q) = (Contour::cam_at(t), Contour::cam_at(t + 1e-6));
            let tangent = [q[0] - p[0], q[1] - p[1]];
            let l = (tangent[0] * tangent[0] + tangent[1] * tangent[1]).sqrt();
            let e = rng.uniform(-noise, noise);
            out.push([p[0] + e * tangent[1] / l, p[1] - e * tangent[0] / l]);
        }
        if self.bore {
            for k in 0..n / 6 {
                let a = 2.0 * PI * k as f64 / (n / 6) as f64;
                out.push([CAM_C[0] + 6.0 * a.cos(), CAM_C[1] + 6.0 * a.sin()]);
            }
        }
        out
    }
}

/// The signed distance image a run wrote: the grid (x0, y0, h) and the rows.
fn read_image(path: &Path) -> ([f64; 3], Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let header = text.lines().find(|l| l.contains("x0 =")).unwrap();
    let value = |name: &str| -> f64 {
        header
            .trim_start_matches('#')
            .split(',')
            .find_map(|kv| {
                let (k, v) = kv.split_once('=')?;
                (k.trim() == name).then(|| v.trim().parse().unwrap())
            })
            .unwrap()
    };
    let rows: Vec<Vec<f64>> = text
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), value("rows") as usize);
    assert!(rows.iter().all(|r| r.len() == value("columns") as usize));
    ([value("x0"), value("y0"), value("h")], rows)
}

/// `fgm --2d`: a cam's profile (clean, with 1 % noise, with a 10 % gap; with a bore, a second
/// loop whose orientation must be found) and its signed distance image: within half a node
/// spacing of the distance computed here near the outline, the right sign everywhere else (by
/// winding numbers and by line scans), the outline's area and loops, the composition's area
/// shares (graded linearly from the skin: the mean depth over d_max, computed here from the
/// analytic distance), the SVG's loops and the preview's colours.
#[test]
fn plane_contours_give_a_signed_distance_image() {
    let dir = tempdir();
    let d = dir.path();
    let cases = [
        (true, 0.0, 0.0, "winding", 0.5),
        (true, 0.0, 0.0, "scan", 0.35),
        (false, 0.2, 0.0, "winding", 0.5),
        (true, 0.0, 0.1, "winding", 0.5),
    ];
    for (bore, noise, gap, sign, h) in cases {
        let c = Contour::new(bore);
        let label = format!("bore {bore} noise {noise} gap {gap} sign {sign} h {h}");
        let text: String = c
            .scan(900, noise, gap, 3)
            .iter()
            .map(|p| format!("{:.5} {:.5}\n", p[0], p[1]))
            .collect();
        std::fs::write(d.join("cam.xy"), text).unwrap();
        ok(
            &[
                "fgm",
                "--2d",
                "--points",
                "cam.xy",
                "--voxel",
                &h.to_string(),
                "--sign",
                sign,
                "-o",
                "cam.csv",
                "--svg",
                "cam.svg",
                "--preview",
                "cam.png",
                "--report",
                "cam.json",
            ],
            d,
        );
        let ([x0, y0, hh], rows) = read_image(&d.join("cam.csv"));
        assert_eq!(hh, h);
        let (mut worst, mut wrong, mut depth_sum, mut inside) = (0.0f64, 0, 0.0, 0usize);
        let in_gap =
            |p: [f64; 2]| gap > 0.0 && p[1] - CAM_C[1] > 10.0 && (p[0] - CAM_C[0]).abs() < 12.0;
        for (j, row) in rows.iter().enumerate() {
            for (i, v) in row.iter().enumerate() {
                let p = [x0 + i as f64 * h, y0 + j as f64 * h];
                let exact = c.distance(p);
                if exact < 0.0 {
                    depth_sum += -exact;
                    inside += 1;
                }
                if in_gap(p) {
                    continue;
                }
                if exact.abs() < 1.5 * h {
                    worst = worst.max((v - exact).abs());
                } else if v.signum() != exact.signum() {
                    wrong += 1;
                }
            }
        }
        let tol = 0.5 * h + noise;
        assert!(worst < tol, "{label}: worst {worst} near the outline");
        assert_eq!(wrong, 0, "{label}: {wrong} nodes of the wrong sign");
        let r = json(&d.join("cam.json"));
        let area = r["area"].as_f64().unwrap();
        let gap_area = if gap > 0.0 { 0.02 * c.area() } else { 0.0 };
        assert!(
            (area - c.area()).abs() < 0.01 * c.area() + gap_area,
            "{label}: area {area} against {}",
            c.area()
        );
        assert_eq!(r["loops"], if bore { 2 } else { 1 }, "{label}");
        let svg = std::fs::read_to_string(d.join("cam.svg")).unwrap();
        assert_eq!(
            svg.matches('M').count(),
            if bore { 2 } else { 1 },
            "{label}"
        );
        // Linear from the skin: material A's share is the mean depth over d_max.
        let dmax = r["dmax"].as_f64().unwrap();
        let share = numbers(&r["shares"])[0];
        let expect = depth_sum / inside as f64 / dmax;
        assert!(
            (share - expect).abs() < 0.01,
            "{label}: share {share} against {expect}"
        );
        // The preview: white in the bore, the part coloured (neither white nor black).
        let (w, _, px) = common::read_png(&d.join("cam.png"));
        let centre_px = |p: [f64; 2]| {
            let span_x = (rows[0].len() - 1) as f64 * h;
            let span_y = (rows.len() - 1) as f64 * h;
            let scale = 560.0 / span_x.max(span_y);
            let col = 20 + ((p[0] - x0) * scale) as usize;
            let row = 20 + ((y0 + span_y - p[1]) * scale) as usize;
            let k = 3 * (row * w as usize + col);
            [px[k], px[k + 1], px[k + 2]]
        };
        if bore {
            assert_eq!(centre_px(CAM_C), [255; 3], "{label}");
        }
        let material = centre_px([CAM_C[0] - 13.0, CAM_C[1]]);
        assert!(
            material != [255; 3] && material != [0; 3],
            "{label}: {material:?}"
        );
    }
    // A part file makes the same image again, and so does a batch job naming it.
    ok(
        &[
            "fgm",
            "--2d",
            "--points",
            "cam.xy",
            "--voxel",
            "0.6",
            "-o",
            "a.csv",
            "--save-part",
            "a.toml",
        ],
        d,
    );
    assert!(std::fs::read_to_string(d.join("a.toml"))
        .unwrap()
        .contains("2d = true"));
    ok(&["fgm", "--part", "a.toml", "-o", "b.csv"], d);
    std::fs::write(
        d.join("jobs.toml"),
        "[[job]]\ncommand = \"fgm\"\npart = \"a.toml\"\noutput = \"c.csv\"\n",
    )
    .unwrap();
    ok(&["batch", "jobs.toml", "-q"], d);
    let a = std::fs::read(d.join("a.csv")).unwrap();
    assert_eq!(a, std::fs::read(d.join("b.csv")).unwrap());
    assert_eq!(a, std::fs::read(d.join("c.csv")).unwrap());
    // Refused in the plane, before any file is made.
    let before = files_in(d);
    for (args, what) in [
        (vec!["--vdb", "x.vdb"], "--vdb"),
        (vec!["--feature", "surface:x.stl"], "plane contour"),
        (vec!["--feature", "point:1,2,3"], "point:X,Y"),
        (vec!["-o", "x.ply"], ".csv"),
    ] {
        let mut all = vec!["fgm", "--2d", "--points", "cam.xy", "--voxel", "1"];
        all.extend(args);
        let out = run(&all, d);
        assert_refusal(d, &before, &out, &all, what);
    }
    let all = ["fgm", "--points", "cam.xy", "--voxel", "1", "-o", "x.ply"];
    assert_refusal(d, &before, &run(&all, d), &all, "--2d");
}
