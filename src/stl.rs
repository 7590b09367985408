//! STL, binary and ASCII. Writing computes facet normals from the winding (right-hand rule).
//! Reading tells binary from ASCII by size and content — never by the word "solid", which binary
//! headers may start with — and welds identical vertices.

use crate::error::{Error, Result};
use crate::mesh::{cross, norm, sub, Mesh};
use std::collections::HashMap;
use std::io::Write;
use std::path::Path;

/// STL flavour.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum StlFormat {
    Binary,
    Ascii,
}

fn unit_normal(m: &Mesh, t: usize) -> [f32; 3] {
    let [a, b, c] = m.triangle(t);
    let n = cross(sub(b, a), sub(c, a));
    let l = norm(n);
    if l > 0.0 {
        [(n[0] / l) as f32, (n[1] / l) as f32, (n[2] / l) as f32]
    } else {
        [0.0; 3]
    }
}

/// Writes `mesh` as STL to `w`.
pub fn write(mesh: &Mesh, format: StlFormat, w: &mut dyn Write) -> std::io::Result<()> {
    match format {
        StlFormat::Binary => write_binary(mesh, w),
        StlFormat::Ascii => write_ascii(mesh, w),
    }
}

fn write_binary(mesh: &Mesh, w: &mut dyn Write) -> std::io::Result<()> {
    use rayon::prelude::*;
    let n = mesh.triangle_count();
    let count = u32::try_from(n).map_err(|_| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "more than 2^32 triangles for binary STL",
        )
    })?;
    let mut header = [b' '; 80];
    let tag = b"binary STL written by latvox";
    header[..tag.len()].copy_from_slice(tag);
    w.write_all(&header)?;
    w.write_all(&count.to_le_bytes())?;
    // Records are encoded in parallel, a chunk at a time, so memory stays bounded.
    const CHUNK: usize = 1 << 16;
    let mut buf = vec![0u8; CHUNK * 50];
    for start in (0..n).step_by(CHUNK) {
        let end = (start + CHUNK).min(n);
        let out = &mut buf[..(end - start) * 50];
        out.par_chunks_mut(50).enumerate().for_each(|(k, rec)| {
            let t = start + k;
            let nrm = unit_normal(mesh, t);
            let idx = &mesh.indices[3 * t..3 * t + 3];
            let mut o = 0;
            for v in nrm {
                rec[o..o + 4].copy_from_slice(&v.to_le_bytes());
                o += 4;
            }
            for &i in idx {
                let p = &mesh.positions[3 * i as usize..3 * i as usize + 3];
                for v in p {
                    rec[o..o + 4].copy_from_slice(&v.to_le_bytes());
                    o += 4;
                }
            }
            rec[48] = 0;
            rec[49] = 0;
        });
        w.write_all(out)?;
    }
    Ok(())
}

fn write_ascii(mesh: &Mesh, w: &mut dyn Write) -> std::io::Result<()> {
    writeln!(w, "solid latvox")?;
    for t in 0..mesh.triangle_count() {
        let n = unit_normal(mesh, t);
        writeln!(w, "  facet normal {:e} {:e} {:e}", n[0], n[1], n[2])?;
        writeln!(w, "    outer loop")?;
        for &i in &mesh.indices[3 * t..3 * t + 3] {
            let p = &mesh.positions[3 * i as usize..3 * i as usize + 3];
            writeln!(w, "      vertex {:e} {:e} {:e}", p[0], p[1], p[2])?;
        }
        writeln!(w, "    endloop")?;
        writeln!(w, "  endfacet")?;
    }
    writeln!(w, "endsolid latvox")
}

/// Reads an STL file (binary or ASCII), welding bit-identical vertices.
pub fn read(path: &Path) -> Result<Mesh> {
    let data = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    parse(&data).map_err(|message| Error::Format {
        path: path.to_path_buf(),
        message,
    })
}

/// Parses STL bytes.
pub fn parse(data: &[u8]) -> std::result::Result<Mesh, String> {
    if data.len() >= 84 {
        let n = u32::from_le_bytes([data[80], data[81], data[82], data[83]]) as u64;
        if 84 + 50 * n == data.len() as u64 {
            return parse_binary(data, n as usize);
        }
    }
    let looks_ascii = data
        .iter()
        .take(512)
        .position(|b| !b.is_ascii_whitespace())
        .is_some_and(|i| data[i..].len() >= 5 && data[i..i + 5].eq_ignore_ascii_case(b"solid"));
    if looks_ascii {
        return parse_ascii(data);
    }
    if data.len() < 84 {
        return Err(format!("too short for STL ({} bytes)", data.len()));
    }
    let n = u32::from_le_bytes([data[80], data[81], data[82], data[83]]) as u64;
    Err(format!(
        "binary STL header says {n} facets ({} bytes) but the file has {} bytes",
        84 + 50 * n,
        data.len()
    ))
}

struct Welder {
    map: HashMap<[u32; 3], u32>,
    mesh: Mesh,
}

impl Welder {
    fn new(capacity: usize) -> Self {
        Welder {
            map: HashMap::with_capacity(capacity),
            mesh: Mesh::default(),
        }
    }

    fn vertex(&mut self, p: [f32; 3]) -> std::result::Result<u32, String> {
        if !p.iter().all(|v| v.is_finite()) {
            return Err(format!("non-finite vertex coordinate {p:?}"));
        }
        // +0.0 and -0.0 are the same point.
        let key = p.map(|v| if v == 0.0 { 0 } else { v.to_bits() });
        let next = self.map.len() as u32;
        let id = *self.map.entry(key).or_insert(next);
        if id == next {
            self.mesh.positions.extend_from_slice(&p);
        }
        Ok(id)
    }
}

fn parse_binary(data: &[u8], n: usize) -> std::result::Result<Mesh, String> {
    if n == 0 {
        return Err("binary STL with zero facets".into());
    }
    let mut w = Welder::new(n / 2 + 16);
    w.mesh.indices.reserve(3 * n);
    for rec in data[84..].chunks_exact(50) {
        for k in 0..3 {
            let o = 12 + 12 * k;
            let f = |j: usize| f32::from_le_bytes(rec[o + j..o + j + 4].try_into().unwrap());
            let id = w.vertex([f(0), f(4), f(8)])?;
            w.mesh.indices.push(id);
        }
    }
    Ok(w.mesh)
}

fn parse_ascii(data: &[u8]) -> std::result::Result<Mesh, String> {
    let text = String::from_utf8_lossy(data);
    let mut w = Welder::new(1024);
    let mut corners = 0usize;
    for (lineno, line) in text.lines().enumerate() {
        let mut it = line.split_whitespace();
        let Some(word) = it.next() else { continue };
        if word.eq_ignore_ascii_case("vertex") {
            let mut p = [0f32; 3];
            for v in p.iter_mut() {
                *v = it
                    .next()
                    .and_then(|s| s.parse::<f32>().ok())
                    .ok_or_else(|| format!("line {}: bad vertex", lineno + 1))?;
            }
            let id = w
                .vertex(p)
                .map_err(|e| format!("line {}: {e}", lineno + 1))?;
            w.mesh.indices.push(id);
            corners += 1;
        } else if word.eq_ignore_ascii_case("endloop") && !corners.is_multiple_of(3) {
            return Err(format!(
                "line {}: facet without exactly three vertices",
                lineno + 1
            ));
        }
    }
    if corners == 0 {
        return Err("ASCII STL with no facets".into());
    }
    if !corners.is_multiple_of(3) {
        return Err("ASCII STL ends inside a facet".into());
    }
    Ok(w.mesh)
}

/// Writes `mesh` to `path` atomically.
pub fn save(mesh: &Mesh, format: StlFormat, path: &Path) -> Result<()> {
    crate::output::write_atomic(path, |w| write(mesh, format, w))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tetra() -> Mesh {
        Mesh {
            positions: vec![0., 0., 0., 1., 0., 0., 0., 1., 0., 0., 0., 1.],
            indices: vec![0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3],
        }
    }

    #[test]
    fn binary_and_ascii_round_trip() {
        for f in [StlFormat::Binary, StlFormat::Ascii] {
            let mut buf = Vec::new();
            write(&tetra(), f, &mut buf).unwrap();
            let back = parse(&buf).unwrap();
            assert_eq!(back.triangle_count(), 4);
            assert_eq!(back.vertex_count(), 4);
            assert!((back.volume() - 1.0 / 6.0).abs() < 1e-7);
        }
    }

    #[test]
    fn binary_header_starting_with_solid_is_still_binary() {
        let mut buf = Vec::new();
        write(&tetra(), StlFormat::Binary, &mut buf).unwrap();
        buf[..5].copy_from_slice(b"solid");
        assert_eq!(parse(&buf).unwrap().triangle_count(), 4);
    }

    #[test]
    fn truncated_binary_is_an_error() {
        let mut buf = Vec::new();
        write(&tetra(), StlFormat::Binary, &mut buf).unwrap();
        buf.truncate(buf.len() - 7);
        assert!(parse(&buf).unwrap_err().contains("header says 4 facets"));
    }
}
