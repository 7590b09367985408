//! `latvox render`, run as a user runs it: parts made by `tpms`, `strut` and `fill` and saved as
//! part files are rendered straight from their implicit solids, and their meshes ray cast from
//! the same camera; the two pictures must agree pixel by pixel. Sphere tracing is checked
//! against dense ray marching on random rays through thin struts and sheets (no tunnelling),
//! and bad input is refused.

use crate::common::*;
use crate::meshkit;
use latvox::render::camera::Ray;
use latvox::render::trace::{Implicit, Tolerance};
use latvox::render::Model;
use std::path::Path;
use std::sync::Arc;

/// The depth image a render wrote as .npy: (height, width) distances, inf where missed.
fn depth(path: &Path) -> (Vec<f64>, usize, usize) {
    let a = latvox::io::npy::parse(&std::fs::read(path).unwrap()).unwrap();
    assert_eq!(a.shape.len(), 2);
    (a.data, a.shape[0], a.shape[1])
}

/// Pixels whose 3 × 3 neighbourhood holds a jump in depth of more than `jump`, or a miss
/// beside a hit: silhouettes and occlusion edges, where a sub-pixel shift changes which surface
/// a pixel sees.
fn edges(d: &[f64], h: usize, w: usize, jump: f64) -> Vec<bool> {
    let mut out = vec![false; d.len()];
    for y in 0..h {
        for x in 0..w {
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            for dy in -1i64..=1 {
                for dx in -1i64..=1 {
                    let (yy, xx) = (y as i64 + dy, x as i64 + dx);
                    if yy < 0 || xx < 0 || yy >= h as i64 || xx >= w as i64 {
                        continue;
                    }
                    let v = d[yy as usize * w + xx as usize];
                    let v = if v.is_finite() { v } else { 1e9 };
                    lo = lo.min(v);
                    hi = hi.max(v);
                }
            }
            out[y * w + x] = hi - lo > jump;
        }
    }
    out
}

/// Renders `part.toml` and `part.stl` in `dir` from `view` (with `extra` options) and compares
/// them: the share of pixels where both hit or both miss, and the share of pixels away from
/// edges in both where both hit and the depths agree within `voxel`.
fn compare(dir: &Path, view: &str, extra: &[&str], distance: f64, voxel: f64) -> (f64, f64, usize) {
    for (input, out) in [("part.toml", "implicit.npy"), ("part.stl", "mesh.npy")] {
        let mut args = vec![
            "render",
            input,
            "-o",
            "view.png",
            "--depth",
            out,
            "--view",
            view,
            "--width",
            "400",
            "--height",
            "300",
            "--distance",
        ];
        let distance = distance.to_string();
        args.push(&distance);
        args.extend_from_slice(extra);
        ok(&args, dir);
    }
    let (a, h, w) = depth(&dir.join("implicit.npy"));
    let (b, _, _) = depth(&dir.join("mesh.npy"));
    let same = a
        .iter()
        .zip(&b)
        .filter(|(x, y)| x.is_finite() == y.is_finite())
        .count();
    let (ea, eb) = (edges(&a, h, w, 2.0 * voxel), edges(&b, h, w, 2.0 * voxel));
    let smooth: Vec<usize> = (0..a.len())
        .filter(|&i| a[i].is_finite() && b[i].is_finite() && !ea[i] && !eb[i])
        .collect();
    let close = smooth
        .iter()
        .filter(|&&i| (a[i] - b[i]).abs() <= voxel)
        .count();
    (
        same as f64 / a.len() as f64,
        close as f64 / smooth.len() as f64,
        smooth.len(),
    )
}

/// The implicit part and its mesh, from the same camera: the silhouettes agree on ≥ 99.5 % of
/// pixels, and where both pictures see a surface away from an edge, the depths agree within
/// one voxel on ≥ 99.9 % of those pixels (the rest: slivers thinner than a voxel where the
/// lattice grazes a face of its box, which the implicit shows and the mesh cannot). A TPMS
/// block, a strut block at an odd origin, a filled torus, and Voronoi foams — a random net
/// whose box cuts struts loose (the fragments its mesh drops are not drawn either) and a sheet
/// (its depths within a voxel on ≥ 99.5 %: walls two voxels thick show their sharp cut edges
/// where they meet the box's faces edge on, which the mesh rounds; a pore's rim is such a
/// crease too, so pores are drawn in `tests/it/view.rs`).
#[test]
fn a_part_renders_as_its_mesh_does() {
    let cases: [(&str, Vec<&str>, f64, f64, &str); 5] = [
        (
            "tpms",
            vec![
                "tpms",
                "--type",
                "gyroid",
                "--density",
                "0.3",
                "--cells",
                "3",
            ],
            5.0 / 32.0,
            50.0,
            "z=7.3",
        ),
        (
            "strut",
            vec![
                "strut",
                "--cell",
                "octet",
                "--density",
                "0.15",
                "--cells",
                "3,3,2",
                "--cell-size",
                "4",
                "--origin",
                "-3.5,2,1.25",
            ],
            4.0 / 32.0,
            45.0,
            "z=5.1",
        ),
        (
            "fill",
            vec![
                "fill",
                "torus.stl",
                "--lattice",
                "bcc",
                "--cell-size",
                "4",
                "--density",
                "0.2",
                "--skin",
                "0.8",
                "--resolution",
                "16",
                "--drain",
                "2",
                "--keep",
                "boss.stl",
            ],
            4.0 / 16.0,
            90.0,
            "z=0.6",
        ),
        (
            "voronoi net",
            vec![
                "voronoi",
                "--spacing",
                "3",
                "--density",
                "0.15",
                "--size",
                "10,9,8",
                "--origin",
                "1.3,-2,0.7",
                "-r",
                "32",
            ],
            3.0 / 32.0,
            35.0,
            "z=4.1",
        ),
        (
            "voronoi sheet",
            vec![
                "voronoi",
                "--structure",
                "sheet",
                "--spacing",
                "3",
                "--density",
                "0.2",
                "--size",
                "10,9,8",
                "-r",
                "32",
            ],
            3.0 / 32.0,
            35.0,
            "z=4.1",
        ),
    ];
    for (name, args, voxel, distance, cut) in cases {
        let dir = tempdir();
        let d = dir.path();
        meshkit::write_stl(&d.join("torus.stl"), &meshkit::torus(12.0, 4.0, 192, 96));
        meshkit::write_stl(
            &d.join("boss.stl"),
            &meshkit::cuboid([9.0, -3.0, -6.0], [17.0, 3.0, 6.0]),
        );
        make_part(d, &args);
        // Cut open, the implicit's caps are where the mesh (not capped) shows its inside: the
        // silhouettes still agree, the depths only away from the cut.
        let (silhouette, _, _) = compare(d, "top", &["--section", cut], distance, voxel);
        let (cut_depth, _, _) = depth(&d.join("implicit.npy"));
        let seen = cut_depth.iter().filter(|v| v.is_finite()).count();
        assert!(
            seen * 10 > cut_depth.len(),
            "{name} cut: part on {seen} pixels"
        );
        eprintln!(
            "{name} cut: silhouettes agree on {:.3} %",
            100.0 * silhouette
        );
        assert!(
            silhouette >= 0.995,
            "{name} cut: silhouettes agree on {:.3} % of pixels",
            100.0 * silhouette
        );
        for view in ["iso", "top", "front"] {
            let (silhouette, depth, n) = compare(d, view, &[], distance, voxel);
            eprintln!(
                "{name} {view}: silhouettes agree on {:.3} %, depth within a voxel on {:.3} % of {n}",
                100.0 * silhouette,
                100.0 * depth
            );
            assert!(
                silhouette >= 0.995,
                "{name} {view}: silhouettes agree on {:.3} % of pixels",
                100.0 * silhouette
            );
            assert!(n > 3_500, "{name} {view}: only {n} pixels to compare");
            // A sheet's walls, a couple of voxels thick, show their sharp cut edges where they
            // meet the box's faces edge on; its mesh rounds them off.
            let bar = if name == "voronoi sheet" {
                0.995
            } else {
                0.999
            };
            assert!(
                depth >= bar,
                "{name} {view}: depth within a voxel on {:.3} % of {n} pixels",
                100.0 * depth
            );
        }
    }
}

/// Sphere tracing finds the first surface a ray meets, as dense ray marching at a tenth of a
/// voxel does, on 10⁴ random rays through thin struts (capsules, cones, blended joints) and thin
/// TPMS sheets: it never meets the solid later than the march (nothing tunnelled), and where it
/// meets it earlier than the march could, or where the march saw nothing, the point it stopped
/// at is on the surface (a graze thinner than the march's step).
#[test]
fn sphere_tracing_never_tunnels() {
    use latvox::strut::{StrutLattice, UnitCell};
    use latvox::tpms::{Lattice, Structure, Surface};
    let b = |lo: [f64; 3], hi: [f64; 3]| latvox::field::Aabb { min: lo, max: hi };
    let strut = |name: &str, radius: f64, blend: f64| -> latvox::render::Lattice {
        let bounds = b([0.3, -1.0, 0.0], [12.3, 11.0, 12.0]);
        latvox::render::Lattice::Struts(StrutLattice {
            cell: Arc::new(UnitCell::built_in(name).unwrap()),
            size: [4.0; 3],
            radius,
            blend,
            bounds,
            phase: bounds.min,
        })
    };
    let sheet = |surface: Surface, level: f64| -> latvox::render::Lattice {
        let bounds = b([0.0; 3], [15.0, 15.0, 10.0]);
        latvox::render::Lattice::Tpms(Lattice {
            surface,
            structure: Structure::Sheet,
            level,
            cell: [5.0; 3],
            bounds,
            phase: [0.7, 0.1, -0.4],
        })
    };
    // Struts 2–3 voxels across at 32 voxels a cell; sheets a few voxels thick.
    let voxel = 4.0 / 32.0;
    let models = [
        strut("bcc", 0.15, 0.0),
        strut("octet", 0.12, 0.0),
        strut("kelvin", 0.14, 0.3),
        sheet(Surface::Gyroid, 0.08),
        sheet(Surface::D, 0.1),
    ];
    let mut rng = Rng(0x5eed_2718);
    let (mut hits, mut grazes) = (0, 0);
    for lattice in models {
        let model = Model {
            lattice,
            level: 0.0,
            voxel,
            cell: 4.0,
            target: None,
            loose: Default::default(),
        };
        let field = model.field();
        let bounds = model.bounds();
        let scene = Implicit::new(&*field, bounds, None, voxel, model.cell);
        let tol = Tolerance {
            absolute: voxel / 100.0,
            per_distance: 0.0,
        };
        let dt = voxel / 10.0;
        for _ in 0..2000 {
            let outside = bounds.grown(6.0);
            let origin = [0, 1, 2].map(|a| rng.uniform(outside.min[a], outside.max[a]));
            let target = [0, 1, 2].map(|a| rng.uniform(bounds.min[a], bounds.max[a]));
            let dir = [0, 1, 2].map(|a| target[a] - origin[a]);
            let len = (dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]).sqrt();
            let ray = Ray {
                origin,
                dir: dir.map(|x| x / len),
            };
            let traced = scene.first_hit(&ray, tol);
            let marched = ray.clip(&bounds).and_then(|(t0, t1)| {
                let mut t = t0;
                while t <= t1 {
                    if scene.value(ray.at(t)) <= 0.0 {
                        return Some(t);
                    }
                    t += dt;
                }
                None
            });
            let on_surface = |t: f64| scene.value(ray.at(t)).abs() < 1e-3 * voxel;
            match (traced, marched) {
                (Some(ts), Some(tm)) => {
                    hits += 1;
                    assert!(
                        ts <= tm + 1e-9,
                        "{ray:?}: traced {ts}, marched {tm}: tunnelled"
                    );
                    if ts < tm - dt {
                        assert!(on_surface(ts), "{ray:?}: stopped off the surface at {ts}");
                        grazes += 1;
                    }
                }
                (None, Some(tm)) => {
                    panic!("{ray:?}: the march meets the solid at {tm}, the trace never")
                }
                (Some(ts), None) => {
                    assert!(on_surface(ts), "{ray:?}: stopped off the surface at {ts}");
                    grazes += 1;
                }
                (None, None) => {}
            }
        }
    }
    eprintln!("{hits} of 10⁴ rays met a solid, {grazes} of them grazes");
    assert!(hits > 4000, "only {hits} of 10⁴ rays met a solid");
    assert!(grazes < hits / 50, "{grazes} grazes of {hits} hits");
}

/// A section cuts the part open: from above, the cap of a gyroid net cut at mid-height covers
/// about the net's density of the cut (the exact share measured on the plane by this test), and
/// every hit is at or below the plane; a turntable puts its views side by side.
#[test]
fn sections_and_turntables() {
    let dir = tempdir();
    let d = dir.path();
    make_part(
        d,
        &[
            "tpms",
            "--type",
            "gyroid",
            "--density",
            "0.3",
            "--cells",
            "2",
            "--cell-size",
            "10",
        ],
    );
    ok(
        &[
            "render",
            "part.toml",
            "-o",
            "cut.png",
            "--view",
            "top",
            "--section",
            "z=10.3",
            "--width",
            "300",
            "--height",
            "300",
            "--depth",
            "cut.npy",
        ],
        d,
    );
    let img = read_png(&d.join("cut.png"));
    // The cap's colour: red well above blue.
    let caps = img
        .2
        .chunks(3)
        .filter(|c| c[0] as i32 > c[2] as i32 + 60)
        .count();
    let (z, _, _) = depth(&d.join("cut.npy"));
    // Looking straight down from the default distance: the plane is nearest possible surface.
    let nearest = z.iter().cloned().fold(f64::INFINITY, f64::min);
    assert!(caps > 0, "no cap");
    // The share of the plane z = 10.3 inside the net, sampled on a fine grid of the box.
    let (mut inside, n) = (0, 400);
    let level = latvox::tpms::calibrate::analytic_level(
        latvox::tpms::Surface::Gyroid,
        latvox::tpms::Structure::Net,
        0.3,
    );
    for i in 0..n {
        for j in 0..n {
            let (x, y) = (
                20.0 * (i as f64 + 0.5) / n as f64,
                20.0 * (j as f64 + 0.5) / n as f64,
            );
            let (f, _) = tpms("gyroid", [x, y, 10.3], 10.0);
            inside += (f <= level) as usize;
        }
    }
    let share = inside as f64 / (n * n) as f64;
    // Seen from straight above, the plane's square in the box is a square in the picture,
    // spanned by the cap (the net touches the box's sides all round): the cap's share of that
    // square is the plane's solid share.
    let w = 300;
    let cap_px: Vec<(usize, usize)> = img
        .2
        .chunks(3)
        .enumerate()
        .filter(|(_, c)| c[0] as i32 > c[2] as i32 + 60)
        .map(|(i, _)| (i % w, i / w))
        .collect();
    let (x0, x1) = (
        cap_px.iter().map(|p| p.0).min().unwrap(),
        cap_px.iter().map(|p| p.0).max().unwrap(),
    );
    let (y0, y1) = (
        cap_px.iter().map(|p| p.1).min().unwrap(),
        cap_px.iter().map(|p| p.1).max().unwrap(),
    );
    let seen = caps as f64 / ((x1 - x0 + 1) * (y1 - y0 + 1)) as f64;
    eprintln!("cap on {seen:.4} of the plane's square, the plane is {share:.4} solid");
    assert!(
        (seen - share).abs() < 0.02,
        "cap on {seen:.3} of the plane's square, the plane is {share:.3} solid"
    );
    assert!(nearest.is_finite());
    ok(
        &[
            "render",
            "part.toml",
            "-o",
            "turn.png",
            "--turntable",
            "4",
            "--width",
            "120",
            "--height",
            "90",
        ],
        d,
    );
    let (w, h, _) = read_png(&d.join("turn.png"));
    assert_eq!((w, h), (480, 90));
    // As an animation: one frame a view, each a picture of its own size.
    ok(
        &[
            "render",
            "part.toml",
            "-o",
            "spin.png",
            "--turntable",
            "3",
            "--animate",
            "--width",
            "60",
            "--height",
            "40",
        ],
        d,
    );
    let file = std::fs::File::open(d.join("spin.png")).unwrap();
    let mut reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .unwrap();
    let control = reader.info().animation_control.expect("an animated PNG");
    assert_eq!(control.num_frames, 3);
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let mut frames = Vec::new();
    while let Ok(info) = reader.next_frame(&mut buf) {
        assert_eq!((info.width, info.height), (60, 40));
        frames.push(buf[..info.buffer_size()].to_vec());
    }
    assert_eq!(frames.len(), 3);
    assert_ne!(frames[0], frames[1], "the views turn");
}

/// Unknown views, empty pictures, outputs that are not PNG, part files whose mesh is gone, and
/// files that are not part files: exit 2, one line, nothing written.
#[test]
fn bad_input_is_refused() {
    let dir = tempdir();
    let d = dir.path();
    meshkit::write_stl(&d.join("torus.stl"), &meshkit::torus(12.0, 4.0, 48, 24));
    ok(
        &[
            "fill",
            "torus.stl",
            "-q",
            "--lattice",
            "bcc",
            "--cell-size",
            "4",
            "-o",
            "f.stl",
            "--resolution",
            "8",
            "--save-part",
            "f.toml",
        ],
        d,
    );
    std::fs::rename(d.join("torus.stl"), d.join("moved.stl")).unwrap();
    std::fs::write(d.join("junk.toml"), "command = \"paint\"\n").unwrap();
    std::fs::write(d.join("broken.toml"), "command = [\n").unwrap();
    std::fs::write(d.join("dense.toml"), "command = \"tpms\"\ndensity = 1.5\n").unwrap();
    let before = files_in(d);
    let cases: [(&[&str], &str); 10] = [
        (
            &["render", "f.stl", "--view", "sideways", "-o", "x.png"],
            "sideways",
        ),
        (&["render", "f.stl", "--width", "0", "-o", "x.png"], "0"),
        (&["render", "f.stl", "--height", "-3", "-o", "x.png"], "-3"),
        (&["render", "f.stl", "-o", "x.jpg"], "PNG"),
        (&["render", "f.toml", "-o", "x.png"], "torus.stl"),
        (&["render", "junk.toml", "-o", "x.png"], "command"),
        (&["render", "broken.toml", "-o", "x.png"], "part file"),
        (
            &["render", "f.stl", "--section", "w=3", "-o", "x.png"],
            "section",
        ),
        (
            &["render", "dense.toml", "-o", "x.png"],
            "dense.toml: invalid value '1.5'",
        ),
        (
            &[
                "render", "f.stl", "--width", "12000", "--height", "9000", "-o", "x.png",
            ],
            "million pixels",
        ),
    ];
    for (args, what) in cases {
        let out = run(args, d);
        assert_refusal(d, &before, &out, args, what);
    }
}

/// README's pictures (docs/src/images) are what `latvox render` makes of the part files in
/// docs/examples, run from another folder (a part file names its mesh relative to itself): the
/// same picture at ≥ 99 % of pixels (within 8 levels per channel).
#[test]
fn readme_pictures_are_what_render_makes() {
    let docs = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs");
    let (examples, images) = (docs.join("examples"), docs.join("src/images"));
    let dir = tempdir();
    let d = dir.path();
    let size = ["--width", "400", "--height", "300"];
    let cases: [(&str, &[&str]); 3] = [
        ("gyroid", &[]),
        ("octet", &[]),
        (
            "filled",
            &["--section", "z=2", "--distance", "70", "--elevation", "40"],
        ),
    ];
    for (name, extra) in cases {
        let part = examples.join(format!("{name}.toml"));
        let part = part.to_str().unwrap();
        let mut args = vec!["render", part, "-o", "new.png"];
        args.extend_from_slice(&size);
        args.extend_from_slice(extra);
        ok(&args, d);
        let (w, h, new) = read_png(&d.join("new.png"));
        let (w0, h0, old) = read_png(&images.join(format!("{name}.png")));
        assert_eq!((w, h), (w0, h0));
        let same = new
            .chunks(3)
            .zip(old.chunks(3))
            .filter(|(a, b)| a.iter().zip(b.iter()).all(|(x, y)| x.abs_diff(*y) <= 8))
            .count();
        assert!(
            same * 100 >= 99 * (w * h) as usize,
            "{name}: {same} of {} pixels as in README",
            w * h
        );
    }
}
