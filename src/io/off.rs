//! OFF (Object File Format, as CGAL and Geomview write it): an `OFF` keyword (optionally with the
//! `ST`, `C`, `N`, `4` prefixes, whose extra per-vertex values are skipped), the counts
//! `V F E`, then one vertex per line and one face per line (`n i₁ … iₙ [colour]`). `#` starts a
//! comment. Counts bound the loops only; a file shorter than its counts is an error.

use super::{Parsed, PolygonSink};
use crate::error::{Error, Result};
use crate::geom::Mesh;
use std::io::Write;

/// Whether `head` (the first bytes of a file) starts with an OFF keyword.
pub fn has_off_keyword(head: &[u8]) -> bool {
    let word: Vec<u8> = head
        .iter()
        .take_while(|b| b.is_ascii_alphanumeric())
        .copied()
        .collect();
    keyword_ok(&word)
}

fn keyword_ok(w: &[u8]) -> bool {
    let Some(rest) = w.strip_suffix(b"OFF") else {
        return false;
    };
    let rest = rest.strip_prefix(b"ST").unwrap_or(rest);
    let rest = rest.strip_prefix(b"C").unwrap_or(rest);
    let rest = rest.strip_prefix(b"N").unwrap_or(rest);
    let rest = rest.strip_prefix(b"4").unwrap_or(rest);
    rest.is_empty()
}

/// Parses OFF text.
pub fn parse(data: &[u8]) -> Result<Parsed> {
    // Lines without comments, blank lines dropped, with their line numbers.
    let mut lines = data
        .split(|&b| b == b'\n' || b == b'\r')
        .enumerate()
        .map(|(i, l)| {
            let l = match l.iter().position(|&b| b == b'#') {
                Some(k) => &l[..k],
                None => l,
            };
            (i + 1, l)
        })
        .filter(|(_, l)| l.iter().any(|b| !b.is_ascii_whitespace()));
    let words = |l: &'_ [u8]| {
        l.split(|b| b.is_ascii_whitespace())
            .filter(|w| !w.is_empty())
            .map(|w| std::str::from_utf8(w).unwrap_or("\u{fffd}").to_string())
            .collect::<Vec<String>>()
    };
    let (_, first) = lines.next().ok_or_else(|| Error::parse("empty file"))?;
    let mut head = words(first);
    if !keyword_ok(head[0].as_bytes()) {
        return Err(Error::parse(format!(
            "expected the OFF keyword, found '{}'",
            trunc(&head[0])
        )));
    }
    let four_d = head[0].contains('4');
    if head
        .get(1)
        .is_some_and(|w| w.eq_ignore_ascii_case("BINARY"))
    {
        return Err(Error::parse("binary OFF is not supported"));
    }
    head.remove(0);
    if head.is_empty() {
        let (_, l) = lines
            .next()
            .ok_or_else(|| Error::parse("file ends before the vertex and face counts"))?;
        head = words(l);
    }
    let count = |i: usize, what: &str| -> Result<u64> {
        head.get(i)
            .and_then(|w| w.parse::<u64>().ok())
            .ok_or_else(|| Error::parse(format!("bad {what} count in the OFF header")))
    };
    let (nv, nf) = (count(0, "vertex")?, count(1, "face")?);
    let mut sink = PolygonSink::new();
    sink.positions
        .reserve(3 * super::bounded(nv, data.len(), 6));
    for k in 0..nv {
        let (ln, l) = lines
            .next()
            .ok_or_else(|| Error::parse(format!("file ends after {k} of {nv} vertices")))?;
        let w = words(l);
        let c = |a: usize| -> Result<f32> {
            w.get(a)
                .and_then(|s| s.parse::<f32>().ok())
                .ok_or_else(|| Error::parse(format!("line {ln}: bad vertex")))
        };
        let mut p = [c(0)?, c(1)?, c(2)?];
        if four_d {
            let h = c(3)?;
            p = p.map(|x| x / h);
        }
        sink.push_vertex(p)
            .map_err(|e| Error::parse(format!("line {ln}: {e}")))?;
    }
    for k in 0..nf {
        let (ln, l) = lines
            .next()
            .ok_or_else(|| Error::parse(format!("file ends after {k} of {nf} faces")))?;
        let w = words(l);
        let n: usize = w
            .first()
            .and_then(|s| s.parse().ok())
            .ok_or_else(|| Error::parse(format!("line {ln}: bad face")))?;
        if n >= w.len() {
            return Err(Error::parse(format!(
                "line {ln}: face says {n} corners but lists fewer"
            )));
        }
        for s in &w[1..=n] {
            let i: u32 = s
                .parse()
                .map_err(|_| Error::parse(format!("line {ln}: bad vertex index '{}'", trunc(s))))?;
            sink.corner(i);
        }
        sink.end_face()
            .map_err(|e| Error::parse(format!("line {ln}: {e}")))?;
    }
    sink.finish()
}

fn trunc(s: &str) -> String {
    s.chars().take(24).collect()
}

/// Writes OFF text.
pub fn write(mesh: &Mesh, w: &mut dyn Write) -> std::io::Result<()> {
    writeln!(w, "OFF")?;
    writeln!(w, "{} {} 0", mesh.vertex_count(), mesh.triangle_count())?;
    for p in mesh.positions.chunks_exact(3) {
        writeln!(w, "{} {} {}", p[0], p[1], p[2])?;
    }
    for t in mesh.indices.chunks_exact(3) {
        writeln!(w, "3 {} {} {}", t[0], t[1], t[2])?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_on_the_keyword_line_comments_and_colours() {
        let text =
            b"OFF 4 2 0\n# a comment\n0 0 0\n1 0 0\n1 1 0 # c\n0 1 0\n3 0 1 2 255 0 0\n3 0 2 3\n";
        let p = parse(text).unwrap();
        assert_eq!(p.mesh.triangle_count(), 2);
        assert!(parse(b"OFF\n4000000000 1 0\n0 0 0\n")
            .unwrap_err()
            .to_string()
            .contains("ends after 1"));
        assert!(
            parse(b"COFF\n3 1 0\n0 0 0 1 1 1 1\n1 0 0 1 1 1 1\n0 1 0 1 1 1 1\n3 0 1 5\n").is_err()
        );
    }
}
