//! STL, binary and ASCII. Writing computes facet normals from the winding (right-hand rule).
//! Reading tells binary from ASCII by size and content — never by the word "solid", which binary
//! headers may start with — welds identical vertices, and keeps the stored normals so `check` can
//! compare them with the winding.

use super::weld::ExactWelder;
use super::{Parsed, Words};
use crate::error::{Error, Result};
use crate::geom::{cross, norm, sub, Mesh};
use std::io::Write;
use std::path::Path;

/// STL flavour.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum StlFormat {
    /// Binary STL: an 80-byte header, a count, 50 bytes per facet.
    Binary,
    /// ASCII STL (`solid` … `endsolid`).
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
    parse(&data).map_err(|e| e.in_file(path))
}

/// Parses STL bytes.
pub fn parse(data: &[u8]) -> Result<Mesh> {
    parse_facets(data).map(|p| p.mesh)
}

/// Parses STL bytes, keeping each facet's stored normal (as written, possibly zero or NaN).
///
/// Binary if the size is exactly `84 + 50·n` for the header's facet count `n`; otherwise ASCII
/// if the first word is `solid` (any case) and the text parses; otherwise an error naming the
/// mismatch. No allocation is ever sized from the header alone.
pub fn parse_facets(data: &[u8]) -> Result<Parsed> {
    if data.len() >= 84 {
        let n = u32::from_le_bytes([data[80], data[81], data[82], data[83]]) as u64;
        if 84 + 50 * n == data.len() as u64 {
            return parse_binary(data, n as usize);
        }
    }
    let first_word = data
        .iter()
        .position(|b| !b.is_ascii_whitespace())
        .map(|i| &data[i..]);
    let looks_ascii =
        first_word.is_some_and(|w| w.len() >= 5 && w[..5].eq_ignore_ascii_case(b"solid"));
    if looks_ascii {
        return parse_ascii(data);
    }
    if data.len() < 84 {
        return Err(Error::parse(format!(
            "too short for STL ({} bytes)",
            data.len()
        )));
    }
    let n = u32::from_le_bytes([data[80], data[81], data[82], data[83]]) as u64;
    Err(Error::parse(format!(
        "binary STL header says {n} facets ({} bytes) but the file has {} bytes",
        84 + 50 * n,
        data.len()
    )))
}

fn parse_binary(data: &[u8], n: usize) -> Result<Parsed> {
    use rayon::prelude::*;
    if n == 0 {
        return Err(Error::parse("binary STL with zero facets"));
    }
    // n is bounded by the file size here (checked by the caller).
    let f = |rec: &[u8], o: usize| f32::from_le_bytes([rec[o], rec[o + 1], rec[o + 2], rec[o + 3]]);
    let records = &data[84..];
    let normals: Vec<[f32; 3]> = records
        .par_chunks_exact(50)
        .map(|r| [f(r, 0), f(r, 4), f(r, 8)])
        .collect();
    // Corners straight from the records: corner k of facet i at bytes 12 + 12k of record i.
    let facet = |i: usize| {
        let r = &records[50 * i + 12..50 * i + 48];
        [0, 12, 24].map(|o| [f(r, o), f(r, o + 4), f(r, o + 8)])
    };
    Ok(Parsed {
        mesh: super::weld::weld_facets_by(n, facet)?,
        normals: Some(normals),
        ..Parsed::default()
    })
}

/// ASCII STL as a stream of words; only `solid`/`endsolid` names are read to the end of their
/// line. Keywords in any case; CR, LF or CRLF line ends; several solids in one file; text after
/// the last `endsolid` ignored. Stored normals may be anything `f32` parses (`nan`, `+inf`).
fn parse_ascii(data: &[u8]) -> Result<Parsed> {
    let mut words = Words::new(data);
    let mut w = ExactWelder::new(1024);
    let mut normals = Vec::new();
    let num = |words: &mut Words, what: &str| -> Result<f32> {
        let line = words.line;
        let tok = words
            .next()
            .ok_or_else(|| Error::parse(format!("line {line}: file ends inside a facet")))?;
        std::str::from_utf8(tok)
            .ok()
            .and_then(|s| s.parse::<f32>().ok())
            .ok_or_else(|| {
                Error::parse(format!(
                    "line {line}: bad {what} '{}'",
                    String::from_utf8_lossy(&tok[..tok.len().min(24)])
                ))
            })
    };
    let expect = |words: &mut Words, kw: &str| -> Result<()> {
        let line = words.line;
        match words.next() {
            Some(t) if t.eq_ignore_ascii_case(kw.as_bytes()) => Ok(()),
            Some(t) => Err(Error::parse(format!(
                "line {line}: expected '{kw}', found '{}'",
                String::from_utf8_lossy(&t[..t.len().min(24)])
            ))),
            None => Err(Error::parse(format!(
                "line {line}: file ends where '{kw}' was expected"
            ))),
        }
    };
    let mut in_solid = false;
    let mut saw_solid = false;
    while let Some(tok) = words.next() {
        if tok.eq_ignore_ascii_case(b"solid") {
            if in_solid {
                return Err(Error::parse(format!(
                    "line {}: 'solid' inside a solid",
                    words.line
                )));
            }
            words.skip_line();
            in_solid = true;
            saw_solid = true;
        } else if tok.eq_ignore_ascii_case(b"endsolid") {
            words.skip_line();
            in_solid = false;
        } else if !in_solid && saw_solid {
            // Trailing text after the last endsolid.
            break;
        } else if tok.eq_ignore_ascii_case(b"facet") {
            let line = words.line;
            let mut n = [0f32; 3];
            match words.peek() {
                Some(t) if t.eq_ignore_ascii_case(b"normal") => {
                    words.next();
                    for v in n.iter_mut() {
                        *v = num(&mut words, "normal")?;
                    }
                }
                _ => n = [f32::NAN; 3],
            }
            expect(&mut words, "outer")?;
            expect(&mut words, "loop")?;
            for _ in 0..3 {
                expect(&mut words, "vertex")?;
                let p = [
                    num(&mut words, "vertex coordinate")?,
                    num(&mut words, "vertex coordinate")?,
                    num(&mut words, "vertex coordinate")?,
                ];
                w.corner(p)
                    .map_err(|e| Error::parse(format!("line {}: {e}", words.line)))?;
            }
            let l = words.line;
            match words.next() {
                Some(t) if t.eq_ignore_ascii_case(b"endloop") => {}
                Some(t) if t.eq_ignore_ascii_case(b"vertex") => {
                    return Err(Error::parse(format!(
                        "line {l}: facet starting on line {line} has more than three vertices"
                    )))
                }
                _ => return Err(Error::parse(format!("line {l}: expected 'endloop'"))),
            }
            expect(&mut words, "endfacet")?;
            normals.push(n);
        } else {
            return Err(Error::parse(format!(
                "line {}: unexpected '{}' in ASCII STL",
                words.line,
                String::from_utf8_lossy(&tok[..tok.len().min(24)])
            )));
        }
    }
    if normals.is_empty() {
        return Err(Error::parse("ASCII STL with no facets"));
    }
    Ok(Parsed {
        mesh: w.mesh,
        normals: Some(normals),
        ..Parsed::default()
    })
}

/// Writes `mesh` to `path` atomically.
pub fn save(mesh: &Mesh, format: StlFormat, path: &Path) -> Result<()> {
    crate::io::atomic::write_atomic(path, |w| write(mesh, format, w))
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
        assert!(parse(&buf)
            .unwrap_err()
            .to_string()
            .contains("header says 4 facets"));
    }
}
