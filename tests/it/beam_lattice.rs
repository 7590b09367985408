//! 3MF Beam Lattice extension files read as solids by `check` and `repair`: packages written here
//! by the extension's text (v1.2: beams, cap modes, balls, clipping meshes, an object's own
//! triangles, build transforms), counted against lib3mf and measured against independent
//! solids — the analytic volume of a ball-and-beam lattice, and manifold3d's union of the
//! same frustums, caps and spheres (polygons of 256 sides) for everything else.

use crate::common::{json, python, run, tempdir};
use serde_json::{json, Value};
use std::f64::consts::PI;
use std::io::Write;
use std::path::Path;

const CORE: &str = "http://schemas.microsoft.com/3dmanufacturing/core/2015/02";
const BEAMS: &str = "http://schemas.microsoft.com/3dmanufacturing/beamlattice/2017/02";
const BALLS: &str = "http://schemas.microsoft.com/3dmanufacturing/beamlattice/balls/2020/07";

/// A package holding `model` as its 3D model.
fn package(path: &Path, model: &str) {
    let mut z = zip::ZipWriter::new(std::fs::File::create(path).unwrap());
    let opts = zip::write::SimpleFileOptions::default();
    for (name, text) in [
        (
            "[Content_Types].xml",
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<Types xmlns=\"http://schemas.openxmlformats.org/package/2006/content-types\"><Default Extension=\"rels\" ContentType=\"application/vnd.openxmlformats-package.relationships+xml\"/><Default Extension=\"model\" ContentType=\"application/vnd.ms-package.3dmanufacturing-3dmodel+xml\"/></Types>",
        ),
        (
            "_rels/.rels",
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<Relationships xmlns=\"http://schemas.openxmlformats.org/package/2006/relationships\"><Relationship Id=\"rel0\" Target=\"/3D/3dmodel.model\" Type=\"http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel\"/></Relationships>",
        ),
        ("3D/3dmodel.model", model),
    ] {
        z.start_file(name, opts).unwrap();
        z.write_all(text.as_bytes()).unwrap();
    }
    z.finish().unwrap();
}

fn vertices(v: &[[f64; 3]]) -> String {
    let mut s = String::from("<vertices>");
    for p in v {
        s += &format!("<vertex x=\"{}\" y=\"{}\" z=\"{}\"/>", p[0], p[1], p[2]);
    }
    s + "</vertices>"
}

fn triangles(t: &[[u32; 3]]) -> String {
    let mut s = String::from("<triangles>");
    for t in t {
        s += &format!(
            "<triangle v1=\"{}\" v2=\"{}\" v3=\"{}\"/>",
            t[0], t[1], t[2]
        );
    }
    s + "</triangles>"
}

/// A mesh object (the description's `{vertices, triangles}`).
fn mesh_object(id: u32, m: &Value) -> String {
    let v: Vec<[f64; 3]> = serde_json::from_value(m["vertices"].clone()).unwrap();
    let t: Vec<[u32; 3]> = serde_json::from_value(m["triangles"].clone()).unwrap();
    format!(
        "<object id=\"{id}\" type=\"model\"><mesh>{}{}</mesh></object>",
        vertices(&v),
        triangles(&t)
    )
}

/// A lattice object from its description: `vertices`, `beams` ([v1, v2, r1|null, r2|null,
/// cap1|null, cap2|null]), `balls` ([vindex, r|null]), lattice attributes `attrs`, and its own
/// `triangles` (over the same vertices).
fn lattice_object(id: u32, l: &Value) -> String {
    let v: Vec<[f64; 3]> = serde_json::from_value(l["vertices"].clone()).unwrap();
    let mut s = format!("<object id=\"{id}\" type=\"model\"><mesh>{}", vertices(&v));
    if let Some(t) = l.get("triangles") {
        let t: Vec<[u32; 3]> = serde_json::from_value(t.clone()).unwrap();
        s += &triangles(&t);
    }
    s += &format!("<b:beamlattice {}><b:beams>", l["attrs"].as_str().unwrap());
    for b in l["beams"].as_array().unwrap() {
        s += &format!("<b:beam v1=\"{}\" v2=\"{}\"", b[0], b[1]);
        for (k, name) in [(2, "r1"), (3, "r2")] {
            if let Some(r) = b[k].as_f64() {
                s += &format!(" {name}=\"{r}\"");
            }
        }
        for (k, name) in [(4, "cap1"), (5, "cap2")] {
            if let Some(c) = b[k].as_str() {
                s += &format!(" {name}=\"{c}\"");
            }
        }
        s += "/>";
    }
    s += "</b:beams>";
    if let Some(balls) = l.get("balls") {
        s += "<b2:balls>";
        for b in balls.as_array().unwrap() {
            s += &format!("<b2:ball vindex=\"{}\"", b[0]);
            if let Some(r) = b[1].as_f64() {
                s += &format!(" r=\"{r}\"");
            }
            s += "/>";
        }
        s += "</b2:balls>";
    }
    s + "</b:beamlattice></mesh></object>"
}

fn model(unit: &str, resources: &str, build: &str) -> String {
    format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<model unit=\"{unit}\" xml:lang=\"en-US\" xmlns=\"{CORE}\" xmlns:b=\"{BEAMS}\" xmlns:b2=\"{BALLS}\" requiredextensions=\"b b2\"><resources>{resources}</resources><build>{build}</build></model>"
    )
}

/// lib3mf's count of beams and balls over the package's mesh objects.
fn lib3mf_beams(path: &Path) -> (u64, u64) {
    const SCRIPT: &str = r#"
import sys, lib3mf
w = lib3mf.get_wrapper()
m = w.CreateModel()
m.QueryReader("3mf").ReadFromFile(sys.argv[1])
it = m.GetMeshObjects()
beams = balls = 0
while it.MoveNext():
    bl = it.GetCurrentMeshObject().BeamLattice()
    beams += bl.GetBeamCount()
    balls += bl.GetBallCount()
print(beams, balls)
"#;
    let out = String::from_utf8(python(SCRIPT, path)).unwrap();
    let v: Vec<u64> = out.split_whitespace().map(|s| s.parse().unwrap()).collect();
    (v[0], v[1])
}

/// The lattice of 3 × 3 × 3 nodes `spacing` apart, a beam between each pair of neighbours.
fn grid_lattice(spacing: f64) -> (Vec<[f64; 3]>, Vec<[u32; 2]>) {
    let id = |i: u32, j: u32, k: u32| (i * 3 + j) * 3 + k;
    let mut v = Vec::new();
    let mut beams = Vec::new();
    for i in 0..3 {
        for j in 0..3 {
            for k in 0..3 {
                v.push([i, j, k].map(|x| x as f64 * spacing));
                for d in [[1, 0, 0], [0, 1, 0], [0, 0, 1]] {
                    let n = [i + d[0], j + d[1], k + d[2]];
                    if n.iter().all(|&x| x < 3) {
                        beams.push([id(i, j, k), id(n[0], n[1], n[2])]);
                    }
                }
            }
        }
    }
    (v, beams)
}

fn check_json(file: &Path, extra: &[&str]) -> (i32, Value) {
    let dir = file.parent().unwrap();
    let mut args = vec!["check", "-q", "--json", file.to_str().unwrap()];
    args.extend_from_slice(extra);
    let out = run(&args, dir);
    let code = out.status.code().unwrap();
    assert!(
        code == 0 || code == 1,
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    (code, serde_json::from_slice(&out.stdout).unwrap())
}

/// Ball-and-beam: beams of radius r between nodes 4 mm apart, a ball of radius R > r·√2 at
/// every node (`ballmode="all"`), so that beams meet only inside balls. Its volume is
/// analytic: the balls, and each beam's cylinder less the two pieces inside its end balls
/// (a cylinder of height h = √(R² − r²) and a spherical cap of height R − h). lib3mf counts the
/// same beams and balls; the solid `check` reads is valid and within 1 % of the volume; `repair
/// --solid` writes it as an STL that trimesh finds watertight, of the same volume.
#[test]
fn ball_and_beam_lattice_has_the_analytic_volume() {
    let dir = tempdir();
    let d = dir.path();
    let (r, big_r, spacing): (f64, f64, f64) = (0.5, 0.8, 4.0);
    let (v, beams) = grid_lattice(spacing);
    let l = json!({
        "vertices": v,
        "beams": beams.iter().map(|b| json!([b[0], b[1], null, null, null, null])).collect::<Vec<_>>(),
        "attrs": format!("radius=\"{r}\" minlength=\"0.001\" b2:ballmode=\"all\" b2:ballradius=\"{big_r}\""),
    });
    let file = d.join("balls.3mf");
    package(
        &file,
        &model(
            "millimeter",
            &lattice_object(1, &l),
            "<item objectid=\"1\"/>",
        ),
    );
    // lib3mf lists a ball at every beam end in `all` mode.
    assert_eq!(lib3mf_beams(&file), (54, 27));
    let h = (big_r * big_r - r * r).sqrt();
    let inside = PI * r * r * h + PI * (big_r - h).powi(2) * (2.0 * big_r + h) / 3.0;
    let want = 27.0 * 4.0 / 3.0 * PI * big_r.powi(3) + 54.0 * (PI * r * r * spacing - 2.0 * inside);
    let (code, c) = check_json(&file, &[]);
    assert_eq!(code, 0, "{c:#}");
    let b = &c["reading"]["beam_lattices"];
    assert_eq!(
        (b["beams"].as_u64(), b["balls"].as_u64()),
        (Some(54), Some(27))
    );
    let got = c["cgal"]["volume"].as_f64().unwrap();
    eprintln!("volume {got:.4} mm³ against {want:.4} mm³");
    assert!((got / want - 1.0).abs() < 0.01, "{got} vs {want}");
    assert_eq!(c["check"]["shells"].as_array().map(Vec::len), Some(1));

    let out = run(
        &[
            "repair",
            "-q",
            "--solid",
            "balls.3mf",
            "-o",
            "balls.stl",
            "--report",
            "r.json",
        ],
        d,
    );
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    const TRIMESH: &str = r#"
import sys, trimesh
m = trimesh.load(sys.argv[1], process=True)
print(int(m.is_watertight), int(m.is_winding_consistent), m.volume)
"#;
    let t = String::from_utf8(python(TRIMESH, &d.join("balls.stl"))).unwrap();
    let t: Vec<f64> = t.split_whitespace().map(|s| s.parse().unwrap()).collect();
    assert_eq!((t[0], t[1]), (1.0, 1.0), "{t:?}");
    assert!((t[2] / want - 1.0).abs() < 0.01, "{} vs {want}", t[2]);
    assert_eq!(json(&d.join("r.json"))["valid_solid"], true);
}

/// latvox's own beam files (`strut --beams`: capsules clipped by the box) read back as the
/// lattice's solid: simple cubic, 3 × 3 × 3 cells of 5 mm, radius 0.5. Within the box the
/// lattice is 9 whole cylinders per axis (halves on the faces, quarters on the edges), less
/// the overlaps of three cylinders at each of the 27 nodes' worth of joints (inclusion and
/// exclusion: 3 · 16r³/3 − 8(2 − √2)r³ each).
#[test]
fn strut_beam_files_read_back_as_the_clipped_lattice() {
    let dir = tempdir();
    let d = dir.path();
    let out = run(
        &[
            "strut", "-q", "--cell", "sc", "--radius", "0.5", "--cells", "3", "--beams", "-o",
            "sc.3mf",
        ],
        d,
    );
    assert_eq!(out.status.code(), Some(0));
    let r: f64 = 0.5;
    let want = 3.0 * 9.0 * PI * r * r * 15.0
        - 27.0 * (16.0 * r.powi(3) - 8.0 * (2.0 - 2f64.sqrt()) * r.powi(3));
    let (code, c) = check_json(&d.join("sc.3mf"), &[]);
    assert_eq!(code, 0, "{c:#}");
    let got = c["cgal"]["volume"].as_f64().unwrap();
    eprintln!("volume {got:.4} mm³ against {want:.4} mm³");
    assert!((got / want - 1.0).abs() < 0.01, "{got} vs {want}");
    // A coarser voxel, given: still a valid solid, fewer triangles.
    let (code, coarse) = check_json(&d.join("sc.3mf"), &["--beam-voxel", "0.2"]);
    assert_eq!(code, 0, "{coarse:#}");
    assert_eq!(
        coarse["reading"]["beam_lattices"]["voxel_mm"].as_f64(),
        Some(0.2)
    );
    assert!(coarse["check"]["facets"].as_u64() < c["check"]["facets"].as_u64());
}

/// Everything else the extension has, against manifold3d's union of the same pieces: cones
/// (r1 ≠ r2), each cap mode at either end, balls given in `mixed` mode (with and without
/// their own radius), a clipping mesh that is not a box (an octahedron, `inside`), the whole
/// placed by a build item that rotates, scales and moves it, in centimetres; and beside it an
/// object whose own triangles (a plate) unite with its beams, clipped `outside` a box.
#[test]
fn caps_cones_balls_clipping_and_transforms_match_manifold3d() {
    let dir = tempdir();
    let d = dir.path();
    let (v, beams) = grid_lattice(0.5);
    let caps = [
        ["sphere", "sphere"],
        ["hemisphere", "butt"],
        ["butt", "butt"],
        ["sphere", "hemisphere"],
        ["butt", "sphere"],
    ];
    // In centimetres: radius 0.06 cm by default, every third beam a cone.
    let beam_list: Vec<Value> = beams
        .iter()
        .enumerate()
        .map(|(i, b)| {
            let c = caps[i % caps.len()];
            if i % 3 == 0 {
                json!([b[0], b[1], 0.09, 0.04, c[0], c[1]])
            } else {
                json!([b[0], b[1], null, null, c[0], c[1]])
            }
        })
        .collect();
    let lattice = json!({
        "vertices": v,
        "beams": beam_list,
        "balls": [[0, 0.13], [13, null], [26, 0.1]],
        "attrs": "radius=\"0.06\" minlength=\"0.0001\" cap=\"sphere\" b2:ballmode=\"mixed\" b2:ballradius=\"0.11\" clippingmode=\"inside\" clippingmesh=\"1\"",
    });
    let (c, e) = (0.5, 0.62);
    let octahedron = json!({
        "vertices": [[c + e, c, c], [c - e, c, c], [c, c + e, c], [c, c - e, c], [c, c, c + e], [c, c, c - e]],
        "triangles": [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]],
    });
    // The plate 0..1 × 0..1 × 0..0.1 cm with four posts and a top frame; clipped outside the
    // box [0.1, 0.3] × [-0.1, 1.1] × [0.4, 0.5], which cuts the two posts at x = 0.2.
    let plate_vertices = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 0.1],
        [1.0, 0.0, 0.1],
        [1.0, 1.0, 0.1],
        [0.0, 1.0, 0.1],
        [0.2, 0.2, 0.05],
        [0.8, 0.2, 0.05],
        [0.8, 0.8, 0.05],
        [0.2, 0.8, 0.05],
        [0.2, 0.2, 0.8],
        [0.8, 0.2, 0.8],
        [0.8, 0.8, 0.8],
        [0.2, 0.8, 0.8],
    ];
    let plate = json!({
        "vertices": plate_vertices,
        "triangles": [[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4],
                      [1, 2, 6], [1, 6, 5], [2, 3, 7], [2, 7, 6], [3, 0, 4], [3, 4, 7]],
        "beams": [[8, 12, null, null, null, null], [9, 13, null, null, null, null],
                  [10, 14, null, null, null, null], [11, 15, null, null, null, null],
                  [12, 13, null, null, null, null], [13, 14, null, null, null, null],
                  [14, 15, null, null, null, null], [15, 12, null, null, null, null]],
        "attrs": "radius=\"0.07\" minlength=\"0.0001\" clippingmode=\"outside\" clippingmesh=\"3\"",
    });
    let cut = json!({
        "vertices": [[0.1, -0.1, 0.4], [0.3, -0.1, 0.4], [0.3, 1.1, 0.4], [0.1, 1.1, 0.4],
                     [0.1, -0.1, 0.5], [0.3, -0.1, 0.5], [0.3, 1.1, 0.5], [0.1, 1.1, 0.5]],
        "triangles": [[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4],
                      [1, 2, 6], [1, 6, 5], [2, 3, 7], [2, 7, 6], [3, 0, 4], [3, 4, 7]],
    });
    // 3MF's transform rows: p' = (x, y, z, 1) · M. A rotation by 30° about z, scaled 1.5.
    let (s, a) = (1.5, 30f64.to_radians());
    let m = [
        s * a.cos(),
        s * a.sin(),
        0.0,
        -s * a.sin(),
        s * a.cos(),
        0.0,
        0.0,
        0.0,
        s,
        0.3,
        -0.2,
        0.7,
    ];
    let transform = m.map(|x| format!("{x}")).join(" ");
    let file = d.join("mixed.3mf");
    package(
        &file,
        &model(
            "centimeter",
            &(mesh_object(1, &octahedron)
                + &lattice_object(2, &lattice)
                + &mesh_object(3, &cut)
                + &lattice_object(4, &plate)),
            &format!(
                "<item objectid=\"2\" transform=\"{transform}\"/><item objectid=\"4\" transform=\"1 0 0 0 1 0 0 0 1 4 0 0\"/>"
            ),
        ),
    );
    assert_eq!(lib3mf_beams(&file), (54 + 8, 3));

    const MANIFOLD: &str = r#"
import json, sys, numpy as np, manifold3d as m3
d = json.load(open(sys.argv[1]))
N = 96
def solid(mesh):
    v = np.array(mesh["vertices"], dtype=np.float32)
    t = np.array(mesh["triangles"], dtype=np.uint32)
    s = m3.Manifold(m3.Mesh(vert_properties=v, tri_verts=t))
    if s.volume() < 0 or s.is_empty():
        s = m3.Manifold(m3.Mesh(vert_properties=v, tri_verts=t[:, ::-1].copy()))
    return s
def frame(a, b):
    z = (b - a) / np.linalg.norm(b - a)
    h = np.array([1.0, 0, 0]) if abs(z[0]) < 0.9 else np.array([0, 1.0, 0])
    x = np.cross(h, z); x /= np.linalg.norm(x)
    y = np.cross(z, x)
    return np.column_stack([x, y, z])
def lattice(l):
    v = np.array(l["vertices"], dtype=float)
    attrs = dict(kv.split("=") for kv in l["attrs"].split())
    attrs = {k.split(":")[-1]: val.strip('"') for k, val in attrs.items()}
    r0 = float(attrs["radius"]); cap0 = attrs.get("cap", "sphere")
    parts = []
    for v1, v2, r1, r2, c1, c2 in l["beams"]:
        a, b = v[v1], v[v2]
        r1 = r0 if r1 is None else r1
        r2 = r1 if r2 is None else r2
        L = np.linalg.norm(b - a); R = frame(a, b)
        cyl = m3.Manifold.cylinder(L, r1, r2, N).transform(np.column_stack([R, a]))
        parts.append(cyl)
        for end, other, r, c in [(a, b, r1, c1 or cap0), (b, a, r2, c2 or cap0)]:
            if c == "butt":
                continue
            sph = m3.Manifold.sphere(r, N).translate(tuple(end))
            if c == "hemisphere":
                n = (end - other) / np.linalg.norm(end - other)
                sph = sph.trim_by_plane(tuple(n), float(np.dot(n, end)))
            parts.append(sph)
    mode = attrs.get("ballmode", "none")
    for vi, r in l.get("balls", []):
        if mode != "none":
            r = float(attrs["ballradius"]) if r is None else r
            parts.append(m3.Manifold.sphere(r, N).translate(tuple(v[vi])))
    u = m3.Manifold.batch_boolean(parts, m3.OpType.Add)
    return u
out = 0.0
for item in d["items"]:
    u = lattice(item["lattice"])
    clip = item.get("clip")
    if clip:
        c = solid(clip["mesh"])
        u = (u ^ c) if clip["side"] == "inside" else (u - c)
    if "triangles" in item["lattice"]:
        u = u + solid(item["lattice"])
    M = np.array(item["transform"], dtype=float).reshape(4, 3)
    u = u.transform(np.column_stack([M[:3].T, M[3]]))
    out += u.volume() * d["unit"] ** 3
print(out)
"#;
    let desc = json!({
        "unit": 10.0,
        "items": [
            {"lattice": lattice, "clip": {"side": "inside", "mesh": octahedron}, "transform": m},
            {"lattice": plate, "clip": {"side": "outside", "mesh": cut},
             "transform": [1, 0, 0, 0, 1, 0, 0, 0, 1, 4, 0, 0]},
        ],
    });
    let desc_file = d.join("desc.json");
    std::fs::write(&desc_file, desc.to_string()).unwrap();
    let want: f64 = String::from_utf8(python(MANIFOLD, &desc_file))
        .unwrap()
        .trim()
        .parse()
        .unwrap();
    let (code, c) = check_json(&file, &[]);
    assert_eq!(code, 0, "{c:#}");
    let b = &c["reading"]["beam_lattices"];
    assert_eq!(
        (
            b["lattices"].as_u64(),
            b["beams"].as_u64(),
            b["balls"].as_u64()
        ),
        (Some(2), Some(62), Some(3)),
        "{b}"
    );
    let got = c["cgal"]["volume"].as_f64().unwrap();
    eprintln!("volume {got:.4} mm³ against {want:.4} mm³");
    assert!((got / want - 1.0).abs() < 0.01, "{got} vs {want}");
}

/// What the reader cannot make a solid of is refused in one line (exit 2), nothing written:
/// a lattice placed by a shearing transform, a ball without a radius, a beam past the
/// vertices, an unknown cap mode, a lattice clipped away entirely.
#[test]
fn lattices_that_cannot_be_solids_are_refused_in_one_line() {
    let dir = tempdir();
    let d = dir.path();
    let base = |attrs: &str, beam: &str, balls: &str, item: &str| {
        model(
            "millimeter",
            &format!(
                "<object id=\"1\" type=\"model\"><mesh>{}</mesh></object>\
                 <object id=\"2\" type=\"model\"><mesh>{}<b:beamlattice radius=\"0.5\" minlength=\"0.001\" {attrs}><b:beams>{beam}</b:beams>{balls}</b:beamlattice></mesh></object>",
                vertices(&[[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
                    + &triangles(&[[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]),
                vertices(&[[0.0, 0.0, 5.0], [10.0, 0.0, 5.0]]),
            ),
            item,
        )
    };
    let good = "<b:beam v1=\"0\" v2=\"1\"/>";
    for (name, text, says) in [
        (
            "shear",
            base(
                "",
                good,
                "",
                "<item objectid=\"2\" transform=\"1 0 0 0.5 1 0 0 0 1 0 0 0\"/>",
            ),
            "shears or scales unevenly",
        ),
        (
            "ball",
            base(
                "b2:ballmode=\"mixed\"",
                good,
                "<b2:balls><b2:ball vindex=\"0\"/></b2:balls>",
                "<item objectid=\"2\"/>",
            ),
            "ball without a radius",
        ),
        (
            "index",
            base(
                "",
                "<b:beam v1=\"0\" v2=\"7\"/>",
                "",
                "<item objectid=\"2\"/>",
            ),
            "past the 2 vertices",
        ),
        (
            "cap",
            base(
                "",
                "<b:beam v1=\"0\" v2=\"1\" cap1=\"round\"/>",
                "",
                "<item objectid=\"2\"/>",
            ),
            "unknown cap1",
        ),
        (
            "away",
            base(
                "clippingmode=\"inside\" clippingmesh=\"1\"",
                "<b:beam v1=\"0\" v2=\"1\" r1=\"0.01\"/>",
                "",
                "<item objectid=\"2\"/>",
            ),
            "leaves no solid",
        ),
    ] {
        let file = d.join(format!("{name}.3mf"));
        package(&file, &text);
        let out = run(
            &[
                "repair",
                "-q",
                "--solid",
                file.to_str().unwrap(),
                "-o",
                "out.stl",
            ],
            d,
        );
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{name}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{name}: {err}");
        assert!(err.contains(says), "{name}: {err}");
        assert!(!d.join("out.stl").exists(), "{name}");
    }
}
