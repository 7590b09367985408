//! Every part command writes every format its output's extension names: STL, 3MF, OBJ and PLY
//! read back by independent libraries (trimesh; lib3mf, the 3MF Consortium's reference) with the
//! triangle count and volume the command reported, and `.vdb` read by OpenVDB's own Python
//! module as a level set of the part's voxels enclosing the reported volume (voids kept: a
//! filled part with a skin encloses some).

use crate::common::*;
use crate::meshkit::{cuboid, write_stl};
use serde_json::Value;
use std::path::Path;

const MESHES: [&str; 4] = ["stl", "3mf", "obj", "ply"];

/// What a command reported about the part it wrote: triangles, volume, voxel size.
struct Reported {
    triangles: u64,
    volume: f64,
    voxel: f64,
}

fn python(interpreter: &str, script: &str, args: &[&Path]) -> Value {
    let script = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/checkers")
        .join(script);
    let o = std::process::Command::new(interpreter)
        .arg(script)
        .args(args)
        .output()
        .expect("python (scripts/install-deps.sh installs the readers)");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap()
}

/// Runs `args` with `-o part.EXT --report EXT.json` for every format; checks each file. The
/// level set must enclose the part's volume within a tenth of a voxel over its area.
fn every_format(dir: &Path, args: &[&str], reported: impl Fn(&Value) -> Reported) {
    let mut meshes = Vec::new();
    let mut reports = Vec::new();
    for ext in MESHES {
        let (out, report) = (format!("part.{ext}"), format!("{ext}.json"));
        let mut all = args.to_vec();
        all.extend(["-q", "-o", &out, "--report", &report]);
        ok(&all, dir);
        meshes.push(dir.join(&out));
        reports.push(reported(&json(&dir.join(&report))));
    }
    let paths: Vec<&Path> = meshes.iter().map(|p| p.as_path()).collect();
    let read = python("python3", "mesh_file.py", &paths);
    for (p, r) in meshes.iter().zip(&reports) {
        let m = &read[p.to_str().unwrap()];
        assert_eq!(
            m["triangles"].as_u64(),
            Some(r.triangles),
            "{}: {m}",
            p.display()
        );
        let volume = m["volume"].as_f64().unwrap();
        assert!(
            (volume - r.volume).abs() < 1e-5 * r.volume,
            "{}: read {volume} mm³, reported {} mm³",
            p.display(),
            r.volume
        );
    }
    let area = read[meshes[0].to_str().unwrap()]["area"].as_f64().unwrap();
    let mut all = args.to_vec();
    all.extend(["-q", "-o", "part.vdb", "--report", "vdb.json"]);
    ok(&all, dir);
    let r = reported(&json(&dir.join("vdb.json")));
    let v = python(
        "/usr/bin/python3",
        "vdb_level_set.py",
        &[&dir.join("part.vdb")],
    );
    assert_eq!(v["grids"][0]["name"], "sdf", "{args:?}: {v}");
    assert_eq!(v["grids"][0]["class"], "level set", "{args:?}: {v}");
    let voxel = v["voxel"][0].as_f64().unwrap();
    assert!(
        (voxel - r.voxel).abs() < 1e-9,
        "{args:?}: voxel {voxel} ≠ {}",
        r.voxel
    );
    let volume = v["volume"].as_f64().unwrap();
    assert!(
        (volume - r.volume).abs() < 0.1 * voxel * area,
        "{args:?}: the level set encloses {volume} mm³, the part {} mm³ (area {area} mm²)",
        r.volume
    );
}

fn lattice(r: &Value) -> Reported {
    // A fill's report holds the part under `part`; tpms and strut reports are the part's.
    let p = if r["part"].is_object() { &r["part"] } else { r };
    Reported {
        triangles: p["triangles"].as_u64().unwrap(),
        volume: p["volume"].as_f64().unwrap(),
        voxel: p["meshing"]["voxel_size"].as_f64().unwrap(),
    }
}

/// A closed box, 12 × 10 × 8 mm.
fn write_box(path: &Path) {
    write_stl(path, &cuboid([0.0; 3], [12.0, 10.0, 8.0]));
}

/// `fgm` grading a box from its skin, at 0.5 mm voxels.
const FGM: [&str; 9] = [
    "fgm",
    "--mesh",
    "box.stl",
    "--voxel",
    "0.5",
    "--feature",
    "skin",
    "--materials",
    "A,B",
];

#[test]
fn lattice_commands_write_every_format() {
    let dir = tempdir();
    let d = dir.path();
    every_format(
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
            "5",
        ],
        lattice,
    );
    every_format(
        d,
        &[
            "strut",
            "--cell",
            "bcc",
            "--density",
            "0.2",
            "--cells",
            "2",
            "--cell-size",
            "4",
        ],
        lattice,
    );
    // Gyroid infill behind a 1 mm skin: the part encloses voids, which the level set keeps.
    write_box(&d.join("box.stl"));
    every_format(
        d,
        &[
            "fill",
            "box.stl",
            "--lattice",
            "gyroid",
            "--density",
            "0.3",
            "--cell-size",
            "4",
        ],
        lattice,
    );
}

#[test]
fn interpret_and_fgm_write_every_format() {
    let dir = tempdir();
    let d = dir.path();
    // A ring of elements (2D, extruded 3 mm).
    let (nx, ny) = (24usize, 12usize);
    let data: Vec<f64> = (0..nx * ny)
        .map(|i| {
            let (x, y) = ((i / ny) as f64 - 12.0, (i % ny) as f64 - 6.0);
            let r2 = x * x + y * y;
            f64::from(u8::from((6.0..30.0).contains(&r2)))
        })
        .collect();
    let mut bytes = Vec::new();
    latvox::io::npy::write(&mut bytes, &[nx, ny], &data).unwrap();
    std::fs::write(d.join("ring.npy"), bytes).unwrap();
    every_format(
        d,
        &[
            "interpret",
            "ring.npy",
            "--element-size",
            "1",
            "--thickness",
            "3",
        ],
        |r| Reported {
            triangles: r["triangles"].as_u64().unwrap(),
            volume: r["mesh_volume"].as_f64().unwrap(),
            voxel: r["pixel_size"].as_f64().unwrap(),
        },
    );
    write_box(&d.join("box.stl"));
    every_format(d, &FGM, |r| Reported {
        triangles: r["triangles"].as_u64().unwrap(),
        volume: r["volume"].as_f64().unwrap(),
        voxel: 0.5,
    });
}

#[test]
fn an_unknown_extension_or_a_vdb_repair_is_refused_before_any_work() {
    let dir = tempdir();
    let d = dir.path();
    write_box(&d.join("box.stl"));
    let fgm: Vec<&str> = FGM.iter().copied().chain(["-o", "part.step"]).collect();
    for (args, what) in [
        (
            &["tpms", "--cells", "1", "-o", "part.step"][..],
            "unknown output extension",
        ),
        (&fgm[..], "unknown output extension"),
        (
            &["repair", "box.stl", "-o", "fixed.vdb"][..],
            "writes a mesh",
        ),
    ] {
        let before = files_in(d);
        let out = run(args, d);
        assert_refusal(d, &before, &out, args, what);
    }
}
