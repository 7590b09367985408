//! PLY (Stanford polygon format), ASCII and binary (little- and big-endian). The header declares
//! elements and their properties; `vertex` gives `x y z` (any numeric type), `face` gives a list
//! property (`vertex_indices` or `vertex_index`). Other elements and properties are read past.
//! Element counts only bound loops; the data must actually be there.
//! Written as binary little-endian (float coordinates, uchar/uint face lists) or ASCII.

use super::{Parsed, PolygonSink, Words};
use crate::error::{Error, Result};
use crate::geom::Mesh;
use std::io::Write;

#[derive(Debug, Clone, Copy, PartialEq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(s: &str) -> Option<Scalar> {
        Some(match s {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }
}

#[derive(Debug, Clone)]
enum Prop {
    Scalar(String, Scalar),
    List(String, Scalar, Scalar),
}

#[derive(Debug, Clone)]
struct Element {
    name: String,
    count: u64,
    props: Vec<Prop>,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Encoding {
    Ascii,
    Little,
    Big,
}

/// Reads values of a PLY body one at a time.
struct Body<'a> {
    data: &'a [u8],
    pos: usize,
    enc: Encoding,
}

impl Body<'_> {
    fn value(&mut self, t: Scalar) -> Result<f64> {
        if self.enc == Encoding::Ascii {
            let mut w = Words::new(self.data);
            w.pos = self.pos;
            let tok = w
                .next()
                .ok_or_else(|| Error::parse("file ends inside the data"))?;
            let start = self.pos;
            self.pos = w.pos;
            return std::str::from_utf8(tok)
                .ok()
                .and_then(|s| s.parse::<f64>().ok())
                .ok_or_else(|| Error::parse(format!("bad number at byte {start}")));
        }
        let n = t.size();
        let b = self
            .data
            .get(self.pos..self.pos + n)
            .ok_or_else(|| Error::parse("file ends inside the data"))?;
        self.pos += n;
        let mut a = [0u8; 8];
        a[..n].copy_from_slice(b);
        if self.enc == Encoding::Big {
            a[..n].reverse();
        }
        Ok(match t {
            Scalar::I8 => a[0] as i8 as f64,
            Scalar::U8 => a[0] as f64,
            Scalar::I16 => i16::from_le_bytes([a[0], a[1]]) as f64,
            Scalar::U16 => u16::from_le_bytes([a[0], a[1]]) as f64,
            Scalar::I32 => i32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Scalar::U32 => u32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Scalar::F32 => f32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Scalar::F64 => f64::from_le_bytes(a),
        })
    }

    fn left(&self) -> usize {
        self.data.len().saturating_sub(self.pos)
    }
}

fn header(data: &[u8]) -> Result<(Encoding, Vec<Element>, usize)> {
    let mut pos = 0usize;
    let mut elements: Vec<Element> = Vec::new();
    let mut enc = None;
    let mut first = true;
    loop {
        let rest = &data[pos..];
        let end = rest
            .iter()
            .position(|&b| b == b'\n' || b == b'\r')
            .ok_or_else(|| Error::parse("header has no end_header line"))?;
        let line = std::str::from_utf8(&rest[..end])
            .map_err(|_| Error::parse("non-text bytes in the header"))?;
        pos += end + 1;
        if rest[end] == b'\r' && data.get(pos) == Some(&b'\n') {
            pos += 1;
        }
        let w: Vec<&str> = line.split_whitespace().collect();
        if first {
            if w.first() != Some(&"ply") {
                return Err(Error::parse("does not start with 'ply'"));
            }
            first = false;
            continue;
        }
        match w.as_slice() {
            [] | ["comment", ..] | ["obj_info", ..] => {}
            ["format", f, _] => {
                enc = Some(match *f {
                    "ascii" => Encoding::Ascii,
                    "binary_little_endian" => Encoding::Little,
                    "binary_big_endian" => Encoding::Big,
                    _ => return Err(Error::parse(format!("unknown format '{f}'"))),
                })
            }
            ["element", name, n] => elements.push(Element {
                name: name.to_string(),
                count: n
                    .parse()
                    .map_err(|_| Error::parse(format!("bad count for element {name}")))?,
                props: Vec::new(),
            }),
            ["property", "list", c, i, name] => {
                let el = elements
                    .last_mut()
                    .ok_or_else(|| Error::parse("property before any element"))?;
                let (c, i) = (
                    Scalar::parse(c).ok_or_else(|| Error::parse(format!("unknown type '{c}'")))?,
                    Scalar::parse(i).ok_or_else(|| Error::parse(format!("unknown type '{i}'")))?,
                );
                el.props.push(Prop::List(name.to_string(), c, i));
            }
            ["property", t, name] => {
                let el = elements
                    .last_mut()
                    .ok_or_else(|| Error::parse("property before any element"))?;
                let t =
                    Scalar::parse(t).ok_or_else(|| Error::parse(format!("unknown type '{t}'")))?;
                el.props.push(Prop::Scalar(name.to_string(), t));
            }
            ["end_header"] => break,
            _ => {
                return Err(Error::parse(format!(
                    "unexpected header line '{}'",
                    line.chars().take(40).collect::<String>()
                )))
            }
        }
    }
    Ok((
        enc.ok_or_else(|| Error::parse("no format line"))?,
        elements,
        pos,
    ))
}

/// Parses PLY bytes.
pub fn parse(data: &[u8]) -> Result<Parsed> {
    let (enc, elements, start) = header(data)?;
    let mut body = Body {
        data,
        pos: start,
        enc,
    };
    let mut sink = PolygonSink::new();
    let mut saw_vertex = false;
    for el in &elements {
        let min_size: usize = el
            .props
            .iter()
            .map(|p| match (enc, p) {
                (Encoding::Ascii, _) => 2,
                (_, Prop::Scalar(_, t)) => t.size(),
                (_, Prop::List(_, c, _)) => c.size(),
            })
            .sum::<usize>()
            .max(1);
        if el.count > 0 && el.props.is_empty() {
            return Err(Error::parse(format!(
                "element {} has no properties",
                el.name
            )));
        }
        if el.count > (body.left() / min_size) as u64 {
            return Err(Error::parse(format!(
                "element {} says {} items but the file is too short",
                el.name, el.count
            )));
        }
        let is_vertex = el.name == "vertex";
        let is_face = el.name == "face";
        let (mut ix, mut iy, mut iz) = (None, None, None);
        let mut list_at = None;
        for (k, p) in el.props.iter().enumerate() {
            match p {
                Prop::Scalar(n, _) if n == "x" => ix = Some(k),
                Prop::Scalar(n, _) if n == "y" => iy = Some(k),
                Prop::Scalar(n, _) if n == "z" => iz = Some(k),
                Prop::List(n, _, _)
                    if list_at.is_none() || n == "vertex_indices" || n == "vertex_index" =>
                {
                    list_at = Some(k)
                }
                _ => {}
            }
        }
        if is_vertex {
            if ix.is_none() || iy.is_none() || iz.is_none() {
                return Err(Error::parse("vertex element without x, y, z"));
            }
            if is_face || saw_vertex {
                return Err(Error::parse("more than one vertex element"));
            }
            saw_vertex = true;
            sink.positions.reserve(3 * el.count as usize);
        }
        for item in 0..el.count {
            let mut p = [0f32; 3];
            for (k, prop) in el.props.iter().enumerate() {
                match prop {
                    Prop::Scalar(_, t) => {
                        let v = body.value(*t)?;
                        if is_vertex {
                            for (slot, idx) in [ix, iy, iz].iter().enumerate() {
                                if *idx == Some(k) {
                                    p[slot] = v as f32;
                                }
                            }
                        }
                    }
                    Prop::List(_, c, t) => {
                        let n = body.value(*c)?;
                        if !(n >= 0.0 && n.fract() == 0.0) {
                            return Err(Error::parse(format!(
                                "{} {item}: bad list length {n}",
                                el.name
                            )));
                        }
                        let n = n as u64;
                        let need = if enc == Encoding::Ascii { 2 } else { t.size() };
                        if n > (body.left() / need) as u64 + 1 {
                            return Err(Error::parse(format!(
                                "{} {item}: list of {n} values runs past the end of the file",
                                el.name
                            )));
                        }
                        let take = is_face && list_at == Some(k);
                        for _ in 0..n {
                            let v = body.value(*t)?;
                            if take {
                                if !(v >= 0.0 && v < u32::MAX as f64 && v.fract() == 0.0) {
                                    return Err(Error::parse(format!(
                                        "face {item}: bad vertex index {v}"
                                    )));
                                }
                                sink.corner(v as u32);
                            }
                        }
                        if take {
                            sink.end_face()
                                .map_err(|e| Error::parse(format!("face {item}: {e}")))?;
                        }
                    }
                }
            }
            if is_vertex {
                sink.push_vertex(p)?;
            }
        }
    }
    sink.finish()
}

/// The scalar properties `wanted` of every vertex of PLY bytes (a point cloud's `x y z` and its
/// normals `nx ny nz`, say), row after row; `None` for a property the vertex element lacks.
/// Other elements are read past.
pub fn vertex_properties(data: &[u8], wanted: &[&str]) -> Result<(Vec<f64>, Vec<bool>)> {
    let (enc, elements, start) = header(data)?;
    let mut body = Body {
        data,
        pos: start,
        enc,
    };
    let vertex = elements
        .iter()
        .find(|e| e.name == "vertex")
        .ok_or_else(|| Error::parse("no vertex element"))?;
    let at: Vec<Option<usize>> = wanted
        .iter()
        .map(|w| {
            vertex
                .props
                .iter()
                .position(|p| matches!(p, Prop::Scalar(n, _) if n == w))
        })
        .collect();
    let mut rows = Vec::new();
    for el in &elements {
        let is_vertex = el.name == "vertex";
        let min_size = if enc == Encoding::Ascii { 2 } else { 1 } * el.props.len().max(1);
        if el.count > (body.left() / min_size) as u64 {
            return Err(Error::parse(format!(
                "element {} says {} items but the file is too short",
                el.name, el.count
            )));
        }
        if is_vertex {
            rows.reserve(wanted.len() * el.count as usize);
        }
        let mut row = vec![0.0; el.props.len()];
        for _ in 0..el.count {
            for (k, prop) in el.props.iter().enumerate() {
                match prop {
                    Prop::Scalar(_, t) => row[k] = body.value(*t)?,
                    Prop::List(_, c, t) => {
                        let n = body.value(*c)?;
                        if !(n >= 0.0 && n.fract() == 0.0 && n <= body.left() as f64) {
                            return Err(Error::parse(format!("{}: bad list length {n}", el.name)));
                        }
                        for _ in 0..n as u64 {
                            body.value(*t)?;
                        }
                    }
                }
            }
            if is_vertex {
                rows.extend(at.iter().map(|a| a.map_or(0.0, |k| row[k])));
            }
        }
        if is_vertex {
            break;
        }
    }
    Ok((rows, at.iter().map(Option::is_some).collect()))
}

/// Writes a binary little-endian PLY whose vertices carry colours (`red green blue`, one byte
/// each, one triple per vertex): what MeshLab, CloudCompare and Blender show as vertex colours.
pub fn write_coloured(mesh: &Mesh, colours: &[[u8; 3]], w: &mut dyn Write) -> std::io::Result<()> {
    write!(
        w,
        "ply\nformat binary_little_endian 1.0\ncomment written by latvox\nelement vertex {}\n\
         property float x\nproperty float y\nproperty float z\nproperty uchar red\n\
         property uchar green\nproperty uchar blue\nelement face {}\n\
         property list uchar uint vertex_indices\nend_header\n",
        mesh.vertex_count(),
        mesh.triangle_count()
    )?;
    binary_body(mesh, Some(colours), w)
}

/// Writes PLY: binary little-endian, or ASCII.
pub fn write(mesh: &Mesh, ascii: bool, w: &mut dyn Write) -> std::io::Result<()> {
    let format = if ascii {
        "ascii"
    } else {
        "binary_little_endian"
    };
    write!(
        w,
        "ply\nformat {format} 1.0\ncomment written by latvox\nelement vertex {}\n\
         property float x\nproperty float y\nproperty float z\nelement face {}\n\
         property list uchar uint vertex_indices\nend_header\n",
        mesh.vertex_count(),
        mesh.triangle_count()
    )?;
    if ascii {
        for p in mesh.positions.chunks_exact(3) {
            writeln!(w, "{} {} {}", p[0], p[1], p[2])?;
        }
        for t in mesh.indices.chunks_exact(3) {
            writeln!(w, "3 {} {} {}", t[0], t[1], t[2])?;
        }
        return Ok(());
    }
    binary_body(mesh, None, w)
}

/// The vertices (with their colours, when given) and faces of a binary little-endian PLY.
fn binary_body(mesh: &Mesh, colours: Option<&[[u8; 3]]>, w: &mut dyn Write) -> std::io::Result<()> {
    let mut buf = Vec::with_capacity(1 << 16);
    for (i, p) in mesh.positions.chunks_exact(3).enumerate() {
        for v in p {
            buf.extend_from_slice(&v.to_le_bytes());
        }
        if let Some(c) = colours {
            buf.extend_from_slice(&c[i]);
        }
        if buf.len() > 60_000 {
            w.write_all(&buf)?;
            buf.clear();
        }
    }
    for t in mesh.indices.chunks_exact(3) {
        buf.push(3);
        for v in t {
            buf.extend_from_slice(&v.to_le_bytes());
        }
        if buf.len() > 60_000 {
            w.write_all(&buf)?;
            buf.clear();
        }
    }
    w.write_all(&buf)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad() -> Mesh {
        Mesh {
            positions: vec![0., 0., 0., 1., 0., 0., 1., 1., 0., 0., 1., 0.],
            indices: vec![0, 1, 2, 0, 2, 3],
        }
    }

    #[test]
    fn both_encodings_round_trip_and_big_endian_reads() {
        for ascii in [false, true] {
            let mut b = Vec::new();
            write(&quad(), ascii, &mut b).unwrap();
            assert_eq!(parse(&b).unwrap().mesh, quad());
        }
        let mut b = b"ply\r\nformat binary_big_endian 1.0\r\nelement vertex 3\r\nproperty double x\r\nproperty double y\r\nproperty double z\r\nproperty uchar red\r\nelement face 1\r\nproperty list uchar int vertex_indices\r\nend_header\r\n".to_vec();
        for p in [[0.0f64, 0., 0.], [1., 0., 0.], [0., 1., 0.]] {
            for v in p {
                b.extend_from_slice(&v.to_be_bytes());
            }
            b.push(7);
        }
        b.push(3);
        for i in [0i32, 1, 2] {
            b.extend_from_slice(&i.to_be_bytes());
        }
        let m = parse(&b).unwrap().mesh;
        assert_eq!(m.positions, vec![0., 0., 0., 1., 0., 0., 0., 1., 0.]);
        assert_eq!(m.indices, vec![0, 1, 2]);
    }

    #[test]
    fn header_counts_larger_than_the_file_are_refused() {
        let b = b"ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\nend_header\n\0\0\0\0";
        assert!(parse(b).unwrap_err().to_string().contains("too short"));
    }
}
