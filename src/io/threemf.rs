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
use crate::geom::Mesh;
use quick_xml::events::{BytesStart, Event};
use std::collections::HashMap;
use std::io::{Cursor, Read, Write};

/// How a beam end is closed (the Beam Lattice extension's cap modes).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Cap {
    /// A sphere of the end's radius around the end point.
    #[default]
    Sphere,
    /// The half of that sphere beyond the end.
    Hemisphere,
    /// A flat end.
    Butt,
}

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
    /// The object's beam lattice (Beam Lattice extension), in the object's coordinates.
    lattice: Option<LatticeDef>,
}

/// A beam: a conical frustum between two vertices, a radius at each end, each end capped.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Beam {
    /// Vertex indices of the two ends.
    pub ends: [u32; 2],
    /// Radius at each end, mm.
    pub radii: [f64; 2],
    /// How each end is closed.
    pub caps: [Cap; 2],
}

/// Which side of the clipping mesh a lattice keeps.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Clipping {
    /// The lattice inside the clipping mesh.
    Inside,
    /// The lattice outside it.
    Outside,
}

/// A beam lattice of the 3MF Beam Lattice extension (v1.2) as placed by the build, in mm:
/// beams (frustums with capped ends) and balls (spheres) between vertices, clipped by a mesh,
/// and the triangles of the object that holds it, which the solid unites with the lattice.
#[derive(Debug, Clone, Default)]
pub struct BeamLattice {
    /// Vertex positions, mm.
    pub vertices: Vec<[f64; 3]>,
    /// The beams no shorter than the lattice's `minlength`.
    pub beams: Vec<Beam>,
    /// Balls: vertex index and radius, mm.
    pub balls: Vec<(u32, f64)>,
    /// The clipping mesh and the side kept.
    pub clip: Option<(Clipping, Mesh)>,
    /// The triangles of the object that holds the lattice (often none).
    pub mesh: Mesh,
    /// Beams dropped as shorter than `minlength`.
    pub short_beams: u64,
}

/// A `<beamlattice>` as read, in the object's coordinates (mm).
#[derive(Default)]
struct LatticeDef {
    radius: f64,
    min_length: f64,
    cap: Cap,
    /// `ballmode`: 0 none, 1 mixed, 2 all.
    ball_mode: u8,
    ball_radius: Option<f64>,
    clip: Option<(Clipping, u64)>,
    beams: Vec<Beam>,
    /// Balls given: vertex and radius (`None`: the lattice's `ballradius`).
    balls: Vec<(u32, Option<f64>)>,
    short_beams: u64,
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
    let mut stored_beams = 0u64;
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
            &mut stored_beams,
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
        let beams = o
            .lattice
            .as_ref()
            .map_or(0, |l| (l.beams.len() + l.balls.len()) as u64);
        let mut n = ((o.triangles.len() / 3) as u64, beams, 1u64);
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
    let beam_cap = 10_000_000 + 16 * stored_beams;
    if beams > beam_cap {
        return Err(Error::parse(format!(
            "build expands {stored_beams} stored beams and balls to {beams}, over the limit of {beam_cap}"
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
        lattices: &mut Vec<BeamLattice>,
    ) -> Result<()> {
        let o = &objects[key];
        if let Some(l) = &o.lattice {
            lattices.push(place_lattice(objects, key, l, m)?);
            for (c, t) in &o.components {
                emit(objects, c, &compose(t, m), sink, lattices)?;
            }
            return Ok(());
        }
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
            emit(objects, c, &compose(t, m), sink, lattices)?;
        }
        Ok(())
    }
    let mut sink = PolygonSink::new();
    let mut lattices = Vec::new();
    for (key, t) in &items {
        emit(&objects, key, t, &mut sink, &mut lattices)?;
    }
    let mut parsed = sink.finish_or_empty(!lattices.is_empty())?;
    parsed.lattices = lattices;
    Ok(parsed)
}

/// The triangles of object `key` placed by `m` (mm).
fn placed_mesh(o: &Object, m: &Transform) -> Result<Mesh> {
    let positions: Vec<f32> = o
        .positions
        .chunks_exact(3)
        .flat_map(|p| apply(m, [p[0], p[1], p[2]]))
        .collect();
    if o.triangles.is_empty() {
        return Ok(Mesh::default());
    }
    super::weld::weld_indexed(&positions, &o.triangles)
}

/// The lattice `l` of object `key` placed by `m`: vertices moved, radii scaled. A beam stays a
/// frustum only under a similarity (rotation, mirror, uniform scale, translation): any other
/// transform of a lattice is refused.
fn place_lattice(
    objects: &HashMap<Key, Object>,
    key: &Key,
    l: &LatticeDef,
    m: &Transform,
) -> Result<BeamLattice> {
    // Rows of the linear part: a similarity's are orthogonal and of one length.
    let row = |r: usize| [m[3 * r], m[3 * r + 1], m[3 * r + 2]];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let s2 = (0..3).map(|r| dot(row(r), row(r))).sum::<f64>() / 3.0;
    let similar = s2 > 0.0
        && (0..3).all(|r| {
            (0..3).all(|c| {
                let want = if r == c { s2 } else { 0.0 };
                (dot(row(r), row(c)) - want).abs() <= 1e-6 * s2
            })
        });
    if !similar {
        return Err(Error::parse(format!(
            "object {} holds a beam lattice placed by a transform that shears or scales unevenly (its beams would not stay round): not supported",
            key.1
        )));
    }
    let s = s2.sqrt();
    let o = &objects[key];
    let vertices: Vec<[f64; 3]> = o
        .positions
        .chunks_exact(3)
        .map(|p| {
            let [x, y, z] = [p[0], p[1], p[2]].map(|v| v as f64);
            [0, 1, 2].map(|c| x * m[c] + y * m[3 + c] + z * m[6 + c] + m[9 + c])
        })
        .collect();
    let beams = l
        .beams
        .iter()
        .map(|b| Beam {
            radii: b.radii.map(|r| r * s),
            ..*b
        })
        .collect();
    let ball = |r: Option<f64>| -> Result<f64> {
        r.or(l.ball_radius).map(|r| r * s).ok_or_else(|| {
            Error::parse(format!(
                "object {}: a ball without a radius in a lattice without ballradius",
                key.1
            ))
        })
    };
    let mut balls = Vec::new();
    match l.ball_mode {
        1 => {
            for &(v, r) in &l.balls {
                balls.push((v, ball(r)?));
            }
        }
        2 => {
            let given: HashMap<u32, Option<f64>> = l.balls.iter().copied().collect();
            let mut ends: Vec<u32> = l.beams.iter().flat_map(|b| b.ends).collect();
            ends.sort_unstable();
            ends.dedup();
            for v in ends {
                balls.push((v, ball(given.get(&v).copied().flatten())?));
            }
        }
        _ => {}
    }
    let clip = match l.clip {
        None => None,
        Some((side, id)) => {
            let k = (key.0.clone(), id);
            let c = objects.get(&k).ok_or_else(|| {
                Error::parse(format!(
                    "object {}: clipping mesh {id} is not defined in /{}",
                    key.1, key.0
                ))
            })?;
            if c.lattice.is_some() || c.triangles.is_empty() || k == *key {
                return Err(Error::parse(format!(
                    "object {}: clipping mesh {id} must be another object of triangles without a lattice",
                    key.1
                )));
            }
            Some((side, placed_mesh(c, m)?))
        }
    };
    Ok(BeamLattice {
        vertices,
        beams,
        balls,
        clip,
        mesh: placed_mesh(o, m)?,
        short_beams: l.short_beams,
    })
}

/// A positive finite length attribute, converted to mm.
fn length(e: &BytesStart, name: &str, scale: f64) -> Result<f64> {
    let v: f64 = num(e, name)?;
    if !(v.is_finite() && v > 0.0) {
        return Err(Error::parse(format!(
            "{name} must be a positive length, not {v}"
        )));
    }
    Ok(v * scale)
}

/// A cap mode attribute, `default` when absent.
fn cap(e: &BytesStart, name: &str, default: Cap) -> Result<Cap> {
    Ok(match attr(e, name)?.as_deref().map(str::trim) {
        None => default,
        Some("sphere") => Cap::Sphere,
        Some("hemisphere") => Cap::Hemisphere,
        Some("butt") => Cap::Butt,
        Some(c) => {
            return Err(Error::parse(format!(
                "unknown {name} '{}'",
                c.chars().take(24).collect::<String>()
            )))
        }
    })
}

/// A `<beamlattice>` element's settings.
fn lattice_def(e: &BytesStart, scale: f64) -> Result<LatticeDef> {
    let ball_mode = match attr(e, "ballmode")?.as_deref().map(str::trim) {
        None | Some("none") => 0,
        Some("mixed") => 1,
        Some("all") => 2,
        Some(m) => {
            return Err(Error::parse(format!(
                "unknown ballmode '{}'",
                m.chars().take(24).collect::<String>()
            )))
        }
    };
    let ball_radius = match attr(e, "ballradius")? {
        Some(_) => Some(length(e, "ballradius", scale)?),
        None => None,
    };
    let clip = match attr(e, "clippingmode")?.as_deref().map(str::trim) {
        None | Some("none") => None,
        Some(m @ ("inside" | "outside")) => {
            let side = if m == "inside" {
                Clipping::Inside
            } else {
                Clipping::Outside
            };
            Some((side, num(e, "clippingmesh")?))
        }
        Some(m) => {
            return Err(Error::parse(format!(
                "unknown clippingmode '{}'",
                m.chars().take(24).collect::<String>()
            )))
        }
    };
    let min_length: f64 = match attr(e, "minlength")? {
        Some(_) => num(e, "minlength")?,
        None => 0.0,
    };
    Ok(LatticeDef {
        radius: length(e, "radius", scale)?,
        min_length: if min_length.is_finite() {
            min_length.max(0.0) * scale
        } else {
            0.0
        },
        cap: cap(e, "cap", Cap::Sphere)?,
        ball_mode,
        ball_radius,
        clip,
        ..LatticeDef::default()
    })
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

/// The vertices and the open `<beamlattice>` of the object `current`, for its `<element>`.
fn open_lattice<'a>(
    objects: &'a mut HashMap<Key, Object>,
    current: &Option<Key>,
    element: &str,
) -> Result<(&'a [f32], &'a mut LatticeDef)> {
    let o = open(objects, current, element)?;
    let l = o
        .lattice
        .as_mut()
        .ok_or_else(|| Error::parse(format!("<{element}> outside a <beamlattice>")))?;
    Ok((&o.positions, l))
}

/// Reads the objects of the model part `part` into `objects`, and its build items into `items`
/// (the root part only). Returns the other parts its items and components name (`p:path`).
fn parse_part(
    xml: &[u8],
    part: &str,
    mut items: Option<&mut Vec<(Key, Transform)>>,
    objects: &mut HashMap<Key, Object>,
    stored_triangles: &mut u64,
    stored_beams: &mut u64,
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
            "beamlattice" => {
                let o = open(objects, &current, "beamlattice")?;
                if o.lattice.is_some() {
                    return Err(Error::parse("two <beamlattice>s in one object"));
                }
                o.lattice = Some(lattice_def(&e, scale)?);
            }
            "beam" => {
                let (positions, l) = open_lattice(objects, &current, "beam")?;
                let nv = positions.len() / 3;
                let ends: [u32; 2] = [num(&e, "v1")?, num(&e, "v2")?];
                if ends.iter().any(|&i| i as usize >= nv) {
                    return Err(Error::parse(format!(
                        "beam {ends:?} names a vertex past the {nv} vertices"
                    )));
                }
                let r1 = match attr(&e, "r1")? {
                    Some(_) => length(&e, "r1", scale)?,
                    None => l.radius,
                };
                let r2 = match attr(&e, "r2")? {
                    Some(_) => length(&e, "r2", scale)?,
                    None => r1,
                };
                let caps = [cap(&e, "cap1", l.cap)?, cap(&e, "cap2", l.cap)?];
                let p = |i: u32| {
                    let i = 3 * i as usize;
                    [0, 1, 2].map(|a| positions[i + a] as f64)
                };
                let (a, b) = (p(ends[0]), p(ends[1]));
                let len = (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt();
                // The extension's consumers ignore beams shorter than minlength (and a beam
                // from a vertex to itself).
                if ends[0] == ends[1] || len < l.min_length {
                    l.short_beams += 1;
                } else {
                    l.beams.push(Beam {
                        ends,
                        radii: [r1, r2],
                        caps,
                    });
                }
                *stored_beams += 1;
            }
            "ball" => {
                let (positions, l) = open_lattice(objects, &current, "ball")?;
                let nv = positions.len() / 3;
                let v: u32 = num(&e, "vindex")?;
                if v as usize >= nv {
                    return Err(Error::parse(format!(
                        "ball at vertex {v} past the {nv} vertices"
                    )));
                }
                let r = match attr(&e, "r")? {
                    Some(_) => Some(length(&e, "r", scale)?),
                    None => None,
                };
                l.balls.push((v, r));
                *stored_beams += 1;
            }
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
    pub clip: Option<crate::geom::Aabb>,
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
