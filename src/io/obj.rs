//! Wavefront OBJ: `v x y z [w]` vertices and `f` faces (`i`, `i/t`, `i//n`, `i/t/n`; negative
//! indices count back from the last vertex). Everything else (normals, texture coordinates,
//! groups, materials, lines) is ignored. Written as `v` and `f` lines, 1-based.

use super::{Parsed, PolygonSink};
use crate::error::{Error, Result};
use crate::geom::Mesh;
use std::io::Write;

/// Parses OBJ bytes (any line ends; non-UTF-8 bytes in ignored lines are harmless).
pub fn parse(data: &[u8]) -> Result<Parsed> {
    let mut sink = PolygonSink::new();
    // Faces are kept until the end: a face may name vertices defined after it.
    let mut faces: Vec<u32> = Vec::new();
    let mut face_len: Vec<u32> = Vec::new();
    for (lineno, line) in data.split(|&b| b == b'\n' || b == b'\r').enumerate() {
        let lineno = lineno + 1;
        let mut it = line
            .split(|b| b.is_ascii_whitespace())
            .filter(|w| !w.is_empty());
        let Some(kw) = it.next() else { continue };
        match kw {
            b"v" => {
                let mut p = [0f32; 3];
                for v in p.iter_mut() {
                    *v = it
                        .next()
                        .and_then(|w| std::str::from_utf8(w).ok())
                        .and_then(|s| s.parse::<f32>().ok())
                        .ok_or_else(|| Error::parse(format!("line {lineno}: bad vertex")))?;
                }
                sink.push_vertex(p)
                    .map_err(|e| Error::parse(format!("line {lineno}: {e}")))?;
            }
            b"f" | b"fo" => {
                let nv = sink.vertex_count() as i64;
                let mut n = 0u32;
                for w in it {
                    let first = w.split(|&b| b == b'/').next().unwrap_or(w);
                    let i: i64 = std::str::from_utf8(first)
                        .ok()
                        .and_then(|s| s.parse().ok())
                        .ok_or_else(|| Error::parse(format!("line {lineno}: bad face index")))?;
                    let abs = match i {
                        0 => {
                            return Err(Error::parse(format!(
                                "line {lineno}: face index 0 (OBJ counts from 1)"
                            )))
                        }
                        i if i > 0 => i - 1,
                        i => nv + i,
                    };
                    if !(0..u32::MAX as i64).contains(&abs) {
                        return Err(Error::parse(format!(
                            "line {lineno}: face index {i} out of range"
                        )));
                    }
                    faces.push(abs as u32);
                    n += 1;
                }
                face_len.push(n);
            }
            _ => {}
        }
    }
    let mut k = 0usize;
    for (f, &n) in face_len.iter().enumerate() {
        for &i in &faces[k..k + n as usize] {
            sink.corner(i);
        }
        k += n as usize;
        sink.end_face()
            .map_err(|e| Error::parse(format!("face {}: {e}", f + 1)))?;
    }
    sink.finish()
}

/// Writes OBJ text.
pub fn write(mesh: &Mesh, w: &mut dyn Write) -> std::io::Result<()> {
    writeln!(w, "# written by latvox")?;
    for p in mesh.positions.chunks_exact(3) {
        writeln!(w, "v {} {} {}", p[0], p[1], p[2])?;
    }
    for t in mesh.indices.chunks_exact(3) {
        writeln!(w, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quads_negative_indices_and_slashes() {
        let text =
            b"v 0 0 0\r\nv 1 0 0\r\nv 1 1 0\r\nv 0 1 0\r\nf 1/1/1 2/2/2 3//3 4\r\nf -4 -2 -1\n";
        let p = parse(text).unwrap();
        assert_eq!(p.mesh.triangle_count(), 3);
        assert_eq!(p.polygons_split, 1);
        assert!(parse(b"v 0 0 0\nf 1 2 3\n")
            .unwrap_err()
            .to_string()
            .contains("past"));
        assert!(parse(b"v 0 0 0\nf 0 1 1\n").is_err());
    }
}
