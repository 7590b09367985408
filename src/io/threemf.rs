//! 3MF (3D Manufacturing Format, core specification): a zip package holding
//! `[Content_Types].xml`, `_rels/.rels` and the model XML (`3D/3dmodel.model`), whose `<object>`s
//! carry `<mesh>`es (`<vertex x y z>`, `<triangle v1 v2 v3>`) or `<components>` referring to other
//! objects, placed by the `<build>` `<item>`s with affine transforms. Units are converted to mm.
//!
//! Reading guards against hostile packages: the model is decompressed with a size cap, component
//! nesting is bounded (no cycles), and the triangle count after instancing is computed before any
//! copy is made and capped relative to what the file stores.

use super::{Parsed, PolygonSink};
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use quick_xml::events::{BytesStart, Event};
use std::collections::HashMap;
use std::io::{Cursor, Read, Write};

const MODEL_NS: &str = "http://schemas.microsoft.com/3dmanufacturing/core/2015/02";
const REL_3DMODEL: &str = "http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel";
/// Decompressed model XML larger than this is refused.
const MAX_MODEL_BYTES: u64 = 4 << 30;
/// Component nesting deeper than this is refused (the spec forbids cycles).
const MAX_DEPTH: usize = 16;

/// An affine map in 3MF's layout: `p' = (x, y, z, 1) · M`, M 4×3, stored row by row.
type Transform = [f64; 12];
const IDENTITY: Transform = [1., 0., 0., 0., 1., 0., 0., 0., 1., 0., 0., 0.];

fn compose(a: &Transform, b: &Transform) -> Transform {
    // Apply a, then b.
    let mut m = [0.0; 12];
    for r in 0..4 {
        for c in 0..3 {
            let mut v = if r == 3 { b[9 + c] } else { 0.0 };
            for k in 0..3 {
                v += a[3 * r + k] * b[3 * k + c];
            }
            m[3 * r + c] = v;
        }
    }
    m
}

fn apply(m: &Transform, p: [f32; 3]) -> [f32; 3] {
    let [x, y, z] = p.map(|v| v as f64);
    [0, 1, 2].map(|c| (x * m[c] + y * m[3 + c] + z * m[6 + c] + m[9 + c]) as f32)
}

/// An object's key: the model part that holds it (its path in the package, no leading slash) and
/// its id there.
type Key = (String, u64);

#[derive(Default)]
struct Object {
    positions: Vec<f32>,
    triangles: Vec<u32>,
    components: Vec<(Key, Transform)>,
    /// Beams of the Beam Lattice extension (not read as geometry).
    beams: u64,
}

/// Most model parts a package may reference (Production extension).
const MAX_PARTS: usize = 100_000;

fn attr(e: &BytesStart, name: &str) -> Result<Option<String>> {
    for a in e.attributes() {
        let a = a.map_err(|e| Error::parse(format!("bad XML attribute: {e}")))?;
        if a.key.local_name().as_ref() == name {
            return Ok(Some(a.value.to_string()));
        }
    }
    Ok(None)
}

fn num<T: std::str::FromStr>(e: &BytesStart, name: &str) -> Result<T> {
    let v = attr(e, name)?
        .ok_or_else(|| Error::parse(format!("<{}> without {}", e.local_name().as_ref(), name)))?;
    v.trim().parse().map_err(|_| {
        Error::parse(format!(
            "bad {} '{}'",
            name,
            v.chars().take(24).collect::<String>()
        ))
    })
}

/// A `transform` attribute, its translation converted from model units to mm.
fn transform(e: &BytesStart, scale: f64) -> Result<Transform> {
    let Some(t) = attr(e, "transform")? else {
        return Ok(IDENTITY);
    };
    let v: Vec<f64> = t
        .split_whitespace()
        .map(|s| s.parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| Error::parse("bad transform"))?;
    if v.len() != 12 || !v.iter().all(|x| x.is_finite()) {
        return Err(Error::parse("a transform needs 12 finite numbers"));
    }
    let mut m: Transform = v.try_into().expect("12 values");
    for t in &mut m[9..] {
        *t *= scale;
    }
    Ok(m)
}

fn read_entry(zip: &mut zip::ZipArchive<Cursor<&[u8]>>, name: &str) -> Result<Vec<u8>> {
    let f = zip
        .by_name(name)
        .map_err(|e| Error::parse(format!("package has no readable {name}: {e}")))?;
    if f.size() > MAX_MODEL_BYTES {
        return Err(Error::parse(format!("{name} is larger than 4 GiB")));
    }
    let mut out = Vec::new();
    f.take(MAX_MODEL_BYTES + 1)
        .read_to_end(&mut out)
        .map_err(|e| Error::parse(format!("{name}: {e}")))?;
    if out.len() as u64 > MAX_MODEL_BYTES {
        return Err(Error::parse(format!("{name} is larger than 4 GiB")));
    }
    Ok(out)
}

fn model_path(zip: &mut zip::ZipArchive<Cursor<&[u8]>>) -> String {
    let fallback = "3D/3dmodel.model".to_string();
    let Ok(rels) = read_entry(zip, "_rels/.rels") else {
        return fallback;
    };
    let Ok(text) = std::str::from_utf8(&rels) else {
        return fallback;
    };
    let mut r = quick_xml::Reader::from_str(text);
    while let Ok(ev) = r.read_event() {
        match ev {
            Event::Empty(e) | Event::Start(e)
                if e.local_name().as_ref() == "Relationship"
                    && attr(&e, "Type").ok().flatten().as_deref() == Some(REL_3DMODEL) =>
            {
                if let Ok(Some(t)) = attr(&e, "Target") {
                    return t.trim_start_matches('/').to_string();
                }
            }
            Event::Eof => break,
            _ => {}
        }
    }
    fallback
}

/// A part's path as a key: `p:path` values are absolute within the package.
fn part_key(path: &str) -> String {
    path.trim_start_matches('/').to_string()
}

/// Parses a 3MF package: the root model part, and the model parts its build items and components
/// name by the Production extension's `p:path`, each in its own unit.
pub fn parse(data: &[u8]) -> Result<Parsed> {
    let mut zip = zip::ZipArchive::new(Cursor::new(data))
        .map_err(|e| Error::parse(format!("not a zip package: {e}")))?;
    let root = part_key(&model_path(&mut zip));
    let mut objects: HashMap<Key, Object> = HashMap::new();
    let mut items: Vec<(Key, Transform)> = Vec::new();
    let mut stored_triangles = 0u64;
    let mut todo = vec![root.clone()];
    let mut seen: std::collections::HashSet<String> = todo.iter().cloned().collect();
    let mut bytes = 0u64;
    while let Some(part) = todo.pop() {
        let xml = read_entry(&mut zip, &part)?;
        bytes += xml.len() as u64;
        if bytes > MAX_MODEL_BYTES {
            return Err(Error::parse("model parts larger than 4 GiB in all"));
        }
        let named = parse_part(
            &xml,
            &part,
            (part == root).then_some(&mut items),
            &mut objects,
            &mut stored_triangles,
        )?;
        for p in named {
            if seen.len() >= MAX_PARTS {
                return Err(Error::parse(format!(
                    "more than {MAX_PARTS} model parts referenced"
                )));
            }
            if seen.insert(p.clone()) {
                todo.push(p);
            }
        }
    }
    if items.is_empty() {
        return Err(Error::parse("no <build> <item>"));
    }
    // Triangles, beams and object instances after instancing, computed before copying anything
    // (once per object: components that share objects cost nothing more).
    type Counts = (u64, u64, u64);
    fn count(
        objects: &HashMap<Key, Object>,
        key: &Key,
        depth: usize,
        memo: &mut HashMap<Key, Counts>,
    ) -> Result<Counts> {
        if depth > MAX_DEPTH {
            return Err(Error::parse("components nested too deeply (or in a cycle)"));
        }
        if let Some(c) = memo.get(key) {
            return Ok(*c);
        }
        let o = objects.get(key).ok_or_else(|| {
            Error::parse(format!(
                "reference to undefined object {} in /{}",
                key.1, key.0
            ))
        })?;
        let mut n = ((o.triangles.len() / 3) as u64, o.beams, 1u64);
        for (c, _) in &o.components {
            let (cn, cb, ci) = count(objects, c, depth + 1, memo)?;
            n = (
                n.0.saturating_add(cn),
                n.1.saturating_add(cb),
                n.2.saturating_add(ci),
            );
        }
        memo.insert(key.clone(), n);
        Ok(n)
    }
    let (mut total, mut beams, mut instances) = (0u64, 0u64, 0u64);
    let mut memo = HashMap::new();
    for (key, _) in &items {
        let (n, b, i) = count(&objects, key, 0, &mut memo)?;
        total = total.saturating_add(n);
        beams = beams.saturating_add(b);
        instances = instances.saturating_add(i);
    }
    if beams > 0 {
        return Err(Error::parse(format!(
            "{beams} beams of the 3MF Beam Lattice extension: beam lattices are not read as solids yet (export the lattice as a mesh)"
        )));
    }
    let placed = 1_000_000 + 16 * objects.len() as u64;
    if instances > placed {
        return Err(Error::parse(format!(
            "build places {} objects {instances} times, over the limit of {placed}",
            objects.len()
        )));
    }
    let cap = 20_000_000 + 16 * stored_triangles;
    if total > cap {
        return Err(Error::parse(format!(
            "build expands {stored_triangles} stored triangles to {total}, over the limit of {cap}"
        )));
    }
    fn emit(
        objects: &HashMap<Key, Object>,
        key: &Key,
        m: &Transform,
        sink: &mut PolygonSink,
    ) -> Result<()> {
        let o = &objects[key];
        let base = sink.vertex_count() as u32;
        for p in o.positions.chunks_exact(3) {
            sink.push_vertex(apply(m, [p[0], p[1], p[2]]))?;
        }
        for t in o.triangles.chunks_exact(3) {
            for &i in t {
                sink.corner(base + i);
            }
            sink.end_face()?;
        }
        for (c, t) in &o.components {
            emit(objects, c, &compose(t, m), sink)?;
        }
        Ok(())
    }
    let mut sink = PolygonSink::new();
    for (key, t) in &items {
        emit(&objects, key, t, &mut sink)?;
    }
    sink.finish()
}

/// The object being read, for an `element` that belongs inside one.
fn open<'a>(
    objects: &'a mut HashMap<Key, Object>,
    current: &Option<Key>,
    element: &str,
) -> Result<&'a mut Object> {
    current
        .as_ref()
        .and_then(|k| objects.get_mut(k))
        .ok_or_else(|| Error::parse(format!("<{element}> outside an <object>")))
}

/// Reads the objects of the model part `part` into `objects`, and its build items into `items`
/// (the root part only). Returns the other parts its items and components name (`p:path`).
fn parse_part(
    xml: &[u8],
    part: &str,
    mut items: Option<&mut Vec<(Key, Transform)>>,
    objects: &mut HashMap<Key, Object>,
    stored_triangles: &mut u64,
) -> Result<Vec<String>> {
    let text = std::str::from_utf8(xml)
        .map_err(|_| Error::parse(format!("model part /{part} is not UTF-8")))?;
    let mut r = quick_xml::Reader::from_str(text);
    let mut named = Vec::new();
    let mut current: Option<Key> = None;
    let mut scale = 1.0f64;
    // The part an item or component names: its own unless `p:path` says otherwise.
    let target = |e: &BytesStart, named: &mut Vec<String>| -> Result<Key> {
        let id: u64 = num(e, "objectid")?;
        Ok(match attr(e, "path")? {
            Some(p) if part_key(&p) != part => {
                let p = part_key(&p);
                named.push(p.clone());
                (p, id)
            }
            _ => (part.to_string(), id),
        })
    };
    loop {
        let ev = r.read_event().map_err(|e| {
            Error::parse(format!(
                "model XML /{part}: {e} (at byte {})",
                r.buffer_position()
            ))
        })?;
        let (e, empty) = match ev {
            Event::Start(e) => (e, false),
            Event::Empty(e) => (e, true),
            Event::End(e) => {
                if e.local_name().as_ref() == "object" {
                    current = None;
                }
                continue;
            }
            Event::Eof => break,
            _ => continue,
        };
        match e.local_name().as_ref() {
            "model" => {
                scale = match attr(&e, "unit")?.as_deref().unwrap_or("millimeter") {
                    "micron" => 0.001,
                    "millimeter" => 1.0,
                    "centimeter" => 10.0,
                    "inch" => 25.4,
                    "foot" => 304.8,
                    "meter" => 1000.0,
                    u => {
                        return Err(Error::parse(format!(
                            "unknown unit '{}'",
                            u.chars().take(24).collect::<String>()
                        )))
                    }
                };
            }
            "object" => {
                let key = (part.to_string(), num(&e, "id")?);
                if objects.contains_key(&key) {
                    return Err(Error::parse(format!(
                        "object id {} defined twice in /{part}",
                        key.1
                    )));
                }
                objects.insert(key.clone(), Object::default());
                current = (!empty).then_some(key);
            }
            "vertex" => {
                let p: [f32; 3] = [num(&e, "x")?, num(&e, "y")?, num(&e, "z")?];
                if !p.iter().all(|v| v.is_finite()) {
                    return Err(Error::parse(format!("non-finite vertex coordinate {p:?}")));
                }
                open(objects, &current, "vertex")?
                    .positions
                    .extend(p.map(|v| (v as f64 * scale) as f32));
            }
            "triangle" => {
                let t: [u32; 3] = [num(&e, "v1")?, num(&e, "v2")?, num(&e, "v3")?];
                let o = open(objects, &current, "triangle")?;
                let nv = o.positions.len() / 3;
                if t.iter().any(|&i| i as usize >= nv) {
                    return Err(Error::parse(format!(
                        "triangle {t:?} names a vertex past the {nv} vertices"
                    )));
                }
                o.triangles.extend_from_slice(&t);
                *stored_triangles += 1;
            }
            "beam" => open(objects, &current, "beam")?.beams += 1,
            "component" => {
                let key = target(&e, &mut named)?;
                let t = transform(&e, scale)?;
                open(objects, &current, "component")?
                    .components
                    .push((key, t));
            }
            "item" => {
                let key = target(&e, &mut named)?;
                let t = transform(&e, scale)?;
                if let Some(items) = items.as_deref_mut() {
                    items.push((key, t));
                }
            }
            _ => {}
        }
    }
    Ok(named)
}

/// The package's fixed parts, and the model XML up to its first vertex / after its last triangle.
pub(crate) const CONTENT_TYPES: &[u8] = br#"<?xml version="1.0" encoding="UTF-8"?>
<Types xmlns="http://schemas.openxmlformats.org/package/2006/content-types"><Default Extension="rels" ContentType="application/vnd.openxmlformats-package.relationships+xml"/><Default Extension="model" ContentType="application/vnd.ms-package.3dmanufacturing-3dmodel+xml"/></Types>
"#;

pub(crate) fn rels() -> String {
    format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships"><Relationship Target="/3D/3dmodel.model" Id="rel0" Type="{REL_3DMODEL}"/></Relationships>
"#
    )
}

pub(crate) fn model_head() -> String {
    format!("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<model unit=\"millimeter\" xml:lang=\"en-US\" xmlns=\"{MODEL_NS}\">\n<metadata name=\"Application\">latvox</metadata>\n<resources>\n<object id=\"1\" type=\"model\">\n<mesh>\n<vertices>\n")
}

pub(crate) const MODEL_MIDDLE: &str = "</vertices>\n<triangles>\n";
pub(crate) const MODEL_TAIL: &str =
    "</triangles>\n</mesh>\n</object>\n</resources>\n<build>\n<item objectid=\"1\"/>\n</build>\n</model>\n";

pub(crate) fn vertex_line(w: &mut dyn Write, p: &[f32]) -> std::io::Result<()> {
    writeln!(w, "<vertex x=\"{}\" y=\"{}\" z=\"{}\"/>", p[0], p[1], p[2])
}

pub(crate) fn triangle_line(w: &mut dyn Write, t: &[u32]) -> std::io::Result<()> {
    writeln!(
        w,
        "<triangle v1=\"{}\" v2=\"{}\" v3=\"{}\"/>",
        t[0], t[1], t[2]
    )
}

/// Writes a 3MF package to `w`: the content types, the relationship to the model, and the
/// model XML that `model` writes.
fn package(
    w: &mut dyn Write,
    model: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let mut zip = zip::ZipWriter::new(Cursor::new(Vec::new()));
    let opts = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated);
    let z = |e: zip::result::ZipError| std::io::Error::other(e);
    zip.start_file("[Content_Types].xml", opts).map_err(z)?;
    zip.write_all(CONTENT_TYPES)?;
    zip.start_file("_rels/.rels", opts).map_err(z)?;
    zip.write_all(rels().as_bytes())?;
    zip.start_file("3D/3dmodel.model", opts).map_err(z)?;
    {
        let mut x = std::io::BufWriter::with_capacity(1 << 16, &mut zip);
        model(&mut x)?;
        x.flush()?;
    }
    let buf = zip.finish().map_err(z)?.into_inner();
    w.write_all(&buf)
}

/// 3MF forbids a triangle that repeats a vertex: the first one is refused.
fn refuse_degenerate(mesh: &Mesh) -> std::io::Result<()> {
    match mesh
        .indices
        .chunks_exact(3)
        .position(|t| t[0] == t[1] || t[1] == t[2] || t[0] == t[2])
    {
        Some(t) => Err(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("3MF forbids degenerate triangles and triangle {t} repeats a vertex (run `latvox repair`)"),
        )),
        None => Ok(()),
    }
}

/// Writes a 3MF package with one mesh object and one build item.
pub fn write(mesh: &Mesh, w: &mut dyn Write) -> std::io::Result<()> {
    refuse_degenerate(mesh)?;
    package(w, |x| {
        x.write_all(model_head().as_bytes())?;
        for p in mesh.positions.chunks_exact(3) {
            vertex_line(x, p)?;
        }
        x.write_all(MODEL_MIDDLE.as_bytes())?;
        for t in mesh.indices.chunks_exact(3) {
            triangle_line(x, t)?;
        }
        x.write_all(MODEL_TAIL.as_bytes())?;
        Ok(())
    })
}

const MATERIAL_NS: &str = "http://schemas.microsoft.com/3dmanufacturing/material/2015/02";

/// Materials mixed per vertex, for the 3MF Materials and Properties extension: base materials
/// (a name and a colour each) and, per vertex, the fractions of each (summing to 1).
#[derive(Debug, Clone)]
pub struct Composites<'a> {
    /// The base materials' names.
    pub names: &'a [String],
    /// Their display colours (RGB).
    pub colours: &'a [[u8; 3]],
    /// Per vertex, one fraction per base material.
    pub fractions: &'a [Vec<f64>],
}

/// Writes `mesh` as a 3MF package whose vertices carry compositions: a `basematerials` group
/// of the named materials, a `compositematerials` group over it holding each distinct
/// composition (fractions rounded to 1/10000), and every triangle's corners pointing at their
/// vertices' compositions (`p1 p2 p3`), so that a slicer that reads the Materials extension
/// mixes the materials as graded.
pub fn write_composites(mesh: &Mesh, c: &Composites, w: &mut dyn Write) -> std::io::Result<()> {
    refuse_degenerate(mesh)?;
    let mut index = std::collections::HashMap::new();
    let mut composites: Vec<Vec<u32>> = Vec::new();
    let per_vertex: Vec<u32> = c
        .fractions
        .iter()
        .map(|f| {
            let q: Vec<u32> = f
                .iter()
                .map(|x| (x.clamp(0.0, 1.0) * 1e4).round() as u32)
                .collect();
            *index.entry(q.clone()).or_insert_with(|| {
                composites.push(q);
                composites.len() as u32 - 1
            })
        })
        .collect();
    package(w, |x| {
        write!(
            x,
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<model unit=\"millimeter\" xml:lang=\"en-US\" xmlns=\"{MODEL_NS}\" xmlns:m=\"{MATERIAL_NS}\">\n<metadata name=\"Application\">latvox</metadata>\n<resources>\n<basematerials id=\"1\">\n"
        )?;
        for (name, col) in c.names.iter().zip(c.colours) {
            writeln!(
                x,
                "<base name=\"{name}\" displaycolor=\"#{:02X}{:02X}{:02X}FF\"/>",
                col[0], col[1], col[2]
            )?;
        }
        let indices: Vec<String> = (0..c.names.len()).map(|i| i.to_string()).collect();
        writeln!(
            x,
            "</basematerials>\n<m:compositematerials id=\"2\" matid=\"1\" matindices=\"{}\">",
            indices.join(" ")
        )?;
        for q in &composites {
            let v: Vec<String> = q.iter().map(|v| format!("{}", *v as f64 / 1e4)).collect();
            writeln!(x, "<m:composite values=\"{}\"/>", v.join(" "))?;
        }
        x.write_all(b"</m:compositematerials>\n<object id=\"3\" type=\"model\" pid=\"2\" pindex=\"0\">\n<mesh>\n<vertices>\n")?;
        for p in mesh.positions.chunks_exact(3) {
            vertex_line(x, p)?;
        }
        x.write_all(MODEL_MIDDLE.as_bytes())?;
        for t in mesh.indices.chunks_exact(3) {
            let p = [0, 1, 2].map(|k| per_vertex[t[k] as usize]);
            writeln!(
                x,
                "<triangle v1=\"{}\" v2=\"{}\" v3=\"{}\" pid=\"2\" p1=\"{}\" p2=\"{}\" p3=\"{}\"/>",
                t[0], t[1], t[2], p[0], p[1], p[2]
            )?;
        }
        x.write_all(b"</triangles>\n</mesh>\n</object>\n</resources>\n<build>\n<item objectid=\"3\"/>\n</build>\n</model>\n")?;
        Ok(())
    })
}

const BEAM_NS: &str = "http://schemas.microsoft.com/3dmanufacturing/beamlattice/2017/02";

/// A lattice of beams for the 3MF Beam Lattice extension (v1.2): vertices, beams between them
/// with a radius at each end (capped by spheres: capsules, or cones with rounded ends), grouped
/// in named sets, clipped by a box (a clipping mesh, `clippingmode="inside"`).
#[derive(Debug, Clone, Default)]
pub struct BeamModel {
    /// Vertex positions, mm.
    pub vertices: Vec<[f64; 3]>,
    /// Beams: vertex indices and the radius at each end, mm.
    pub beams: Vec<([u32; 2], [f64; 2])>,
    /// The lattice's default radius, mm.
    pub radius: f64,
    /// Beams shorter than this are not written (the extension's `minlength`), mm.
    pub min_length: f64,
    /// The box that clips the beams, if any.
    pub clip: Option<crate::field::Aabb>,
    /// Per beam, the index of its set in `set_names`.
    pub sets: Vec<u32>,
    /// The names of the beam sets.
    pub set_names: Vec<String>,
}

/// Writes `m` as a 3MF package: a lattice-only mesh object (no triangles) holding the beams,
/// and, when the beams are clipped, the box as a mesh object it names as its clipping mesh.
pub fn write_beams(m: &BeamModel, w: &mut dyn Write) -> std::io::Result<()> {
    package(w, |x| {
        write!(
            x,
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<model unit=\"millimeter\" xml:lang=\"en-US\" xmlns=\"{MODEL_NS}\" xmlns:b=\"{BEAM_NS}\" requiredextensions=\"b\">\n<metadata name=\"Application\">latvox</metadata>\n<resources>\n"
        )?;
        let lattice_id = if let Some(b) = m.clip {
            x.write_all(
                b"<object id=\"1\" type=\"model\" name=\"clipping box\">\n<mesh>\n<vertices>\n",
            )?;
            for i in 0..8 {
                let c = [i & 1, (i >> 1) & 1, (i >> 2) & 1];
                let p = [0, 1, 2].map(|a| if c[a] == 1 { b.max[a] } else { b.min[a] });
                writeln!(x, "<vertex x=\"{}\" y=\"{}\" z=\"{}\"/>", p[0], p[1], p[2])?;
            }
            x.write_all(b"</vertices>\n<triangles>\n")?;
            // The cube's faces, wound outward (corner i has bits x, y, z).
            for t in [
                [0, 2, 3],
                [0, 3, 1],
                [4, 5, 7],
                [4, 7, 6],
                [0, 1, 5],
                [0, 5, 4],
                [2, 6, 7],
                [2, 7, 3],
                [0, 4, 6],
                [0, 6, 2],
                [1, 3, 7],
                [1, 7, 5],
            ] {
                triangle_line(x, &t)?;
            }
            x.write_all(b"</triangles>\n</mesh>\n</object>\n")?;
            2
        } else {
            1
        };
        writeln!(
            x,
            "<object id=\"{lattice_id}\" type=\"model\" name=\"lattice\">\n<mesh>\n<vertices>"
        )?;
        for p in &m.vertices {
            writeln!(x, "<vertex x=\"{}\" y=\"{}\" z=\"{}\"/>", p[0], p[1], p[2])?;
        }
        write!(
            x,
            "</vertices>\n<b:beamlattice minlength=\"{}\" radius=\"{}\" cap=\"sphere\"",
            m.min_length, m.radius
        )?;
        if m.clip.is_some() {
            x.write_all(b" clippingmode=\"inside\" clippingmesh=\"1\"")?;
        }
        x.write_all(b">\n<b:beams>\n")?;
        let mut kept = Vec::with_capacity(m.beams.len());
        for (i, ([a, b], [ra, rb])) in m.beams.iter().enumerate() {
            let (p, q) = (m.vertices[*a as usize], m.vertices[*b as usize]);
            let len = (0..3).map(|k| (p[k] - q[k]).powi(2)).sum::<f64>().sqrt();
            if a == b || len < m.min_length {
                continue;
            }
            writeln!(x, "<b:beam v1=\"{a}\" v2=\"{b}\" r1=\"{ra}\" r2=\"{rb}\"/>")?;
            kept.push(i);
        }
        x.write_all(b"</b:beams>\n")?;
        if !m.set_names.is_empty() && m.sets.len() == m.beams.len() {
            let mut members: Vec<Vec<usize>> = vec![Vec::new(); m.set_names.len()];
            for (index, &i) in kept.iter().enumerate() {
                members[m.sets[i] as usize].push(index);
            }
            x.write_all(b"<b:beamsets>\n")?;
            for (name, refs) in m.set_names.iter().zip(&members) {
                writeln!(x, "<b:beamset name=\"{}\">", xml_escape(name))?;
                for r in refs {
                    writeln!(x, "<b:ref index=\"{r}\"/>")?;
                }
                x.write_all(b"</b:beamset>\n")?;
            }
            x.write_all(b"</b:beamsets>\n")?;
        }
        writeln!(
            x,
            "</b:beamlattice>\n</mesh>\n</object>\n</resources>\n<build>\n<item objectid=\"{lattice_id}\"/>\n</build>\n</model>"
        )?;
        Ok(())
    })
}

/// `s` with XML's special characters escaped, for an attribute.
fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_components_with_transforms() {
        let m = Mesh {
            positions: vec![0., 0., 0., 1., 0., 0., 0., 1., 0., 0., 0., 1.],
            indices: vec![0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3],
        };
        let mut b = Vec::new();
        write(&m, &mut b).unwrap();
        assert_eq!(parse(&b).unwrap().mesh, m);
        let degenerate = Mesh {
            positions: m.positions.clone(),
            indices: vec![0, 0, 1],
        };
        assert!(write(&degenerate, &mut Vec::new()).is_err());
    }

    /// Objects that each hold ten instances of the next, sixteen deep: 10¹⁵ instances from a
    /// few kilobytes. Refused at once (counting visits each object once), with or without
    /// triangles at the bottom.
    #[test]
    fn deep_shared_components_are_counted_once_and_refused() {
        for leaf in ["<mesh><vertices/><triangles/></mesh>", TETRA] {
            let mut model = String::from("<model unit=\"millimeter\"><resources>");
            model += &format!("<object id=\"16\">{leaf}</object>");
            for id in (0..16).rev() {
                model += &format!("<object id=\"{id}\"><components>");
                for _ in 0..10 {
                    model += &format!("<component objectid=\"{}\"/>", id + 1);
                }
                model += "</components></object>";
            }
            model += "</resources><build><item objectid=\"0\"/></build></model>";
            let mut b = Vec::new();
            package(&mut b, |w| w.write_all(model.as_bytes())).unwrap();
            let t = std::time::Instant::now();
            let e = parse(&b).map(|_| ()).unwrap_err().to_string();
            assert!(e.contains("over the limit"), "{e}");
            assert!(t.elapsed().as_secs() < 5, "{:?}", t.elapsed());
        }
    }

    const TETRA: &str = "<mesh><vertices><vertex x=\"0\" y=\"0\" z=\"0\"/><vertex x=\"1\" y=\"0\" z=\"0\"/>\
        <vertex x=\"0\" y=\"1\" z=\"0\"/><vertex x=\"0\" y=\"0\" z=\"1\"/></vertices><triangles>\
        <triangle v1=\"0\" v2=\"2\" v3=\"1\"/><triangle v1=\"0\" v2=\"1\" v3=\"3\"/>\
        <triangle v1=\"0\" v2=\"3\" v3=\"2\"/><triangle v1=\"1\" v2=\"2\" v3=\"3\"/></triangles></mesh>";

    #[test]
    fn units_components_and_build_transforms_compose() {
        // Centimetres; object 2 = tetra 1 twice, the second moved 5 cm along x; the build item
        // scales by 2 and lifts by 1 cm. Model path given by _rels/.rels (not the default).
        let data = include_bytes!("../../fuzz/corpus/threemf/components-transforms.3mf");
        let m = parse(data).unwrap().mesh;
        assert_eq!(m.triangle_count(), 8);
        let b = m.bounds().unwrap();
        assert!(
            (b.min[0] - 0.0).abs() < 1e-4 && (b.max[0] - 120.0).abs() < 1e-4,
            "{b:?}"
        );
        assert!(
            (b.min[2] - 10.0).abs() < 1e-4 && (b.max[2] - 30.0).abs() < 1e-4,
            "{b:?}"
        );
        assert!((m.volume() - 2.0 * 20.0f64.powi(3) / 6.0).abs() < 1e-3);
    }
}
