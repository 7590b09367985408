//! Point clouds as scanners and CMMs write them: text (`.xyz`, `.txt`, `.csv`, `.asc`, `.pts`)
//! and PLY (a `vertex` element, ASCII or binary).
//!
//! Text: one point a line, numbers separated by spaces, tabs, commas or semicolons; lines that
//! are empty or start with `#` or `//` are comments; a first line holding one whole number (the
//! count Leica's `.pts` begins with) is read past, as is a header line of words (`x,y,z`).
//! Columns 4–6 are read as a normal when every such row holds a unit vector (the `x y z nx ny nz`
//! of CloudCompare and MeshLab), and ignored otherwise (intensity and colour, as in `.pts`).
//! PLY: `x y z`, and `nx ny nz` when the vertex element has them. Coordinates must be finite:
//! a NaN or infinite value is refused with the line (or point) it is on.

use crate::error::{Error, Result};
use std::path::Path;

/// Points, in millimetres, with their outward normals when the file gives them.
#[derive(Debug, Clone, Default)]
pub struct PointCloud {
    /// The points.
    pub points: Vec<[f64; 3]>,
    /// A unit normal per point, when the file has them.
    pub normals: Option<Vec<[f64; 3]>>,
}

/// Reads a point cloud file, choosing the format by its extension (`.ply`, else text).
pub fn read(path: &Path) -> Result<PointCloud> {
    let data = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let ply = is_ply(path, &data);
    let cloud = if ply {
        parse_ply(&data)
    } else {
        parse_text(&data)
    };
    cloud.map_err(|e| e.in_file(path))
}

/// Whether a file is PLY: by its extension or its first bytes.
fn is_ply(path: &Path, data: &[u8]) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("ply"))
        || data.starts_with(b"ply")
}

/// Reads a plane contour: a text file of `x y` per line (columns 3–4 a normal `nx ny` when every
/// such row holds a unit vector; a third column alone — the `z` of a section — is ignored), or
/// a PLY whose vertices' `x y` are taken. The points come back at `z = 0`.
pub fn read_plane(path: &Path) -> Result<PointCloud> {
    let data = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let ply = is_ply(path, &data);
    let cloud = if ply {
        parse_ply(&data).map(|c| PointCloud {
            points: c.points.iter().map(|p| [p[0], p[1], 0.0]).collect(),
            normals: c
                .normals
                .and_then(|n| unit_normals(n.iter().map(|n| [n[0], n[1], 0.0]).collect())),
        })
    } else {
        parse_text_plane(&data)
    };
    cloud.map_err(|e| e.in_file(path))
}

/// Parses a text plane contour (see [`read_plane`]).
pub fn parse_text_plane(data: &[u8]) -> Result<PointCloud> {
    let mut cloud = PointCloud::default();
    let mut extra = Vec::new();
    let mut all_have_extra = true;
    each_row(data, 2, "a point of a contour needs x and y", |numbers| {
        cloud.points.push([numbers[0], numbers[1], 0.0]);
        if numbers.len() >= 4 {
            extra.push([numbers[2], numbers[3], 0.0]);
        } else {
            all_have_extra = false;
        }
    })?;
    if all_have_extra && !cloud.points.is_empty() {
        cloud.normals = unit_normals(extra);
    }
    Ok(cloud)
}

/// Parses a PLY point cloud (its vertex element; faces, if any, are ignored).
pub fn parse_ply(data: &[u8]) -> Result<PointCloud> {
    const WANTED: [&str; 6] = ["x", "y", "z", "nx", "ny", "nz"];
    let (rows, found) = super::ply::vertex_properties(data, &WANTED)?;
    if !found[..3].iter().all(|&f| f) {
        return Err(Error::parse("vertex element without x, y, z"));
    }
    let with_normals = found[3..].iter().all(|&f| f);
    let mut cloud = PointCloud::default();
    let mut normals = Vec::new();
    for (i, r) in rows.chunks_exact(6).enumerate() {
        let p = [r[0], r[1], r[2]];
        if !p.iter().all(|x| x.is_finite()) {
            return Err(Error::parse(format!(
                "point {i} has a coordinate that is not a number"
            )));
        }
        cloud.points.push(p);
        normals.push([r[3], r[4], r[5]]);
    }
    if with_normals {
        cloud.normals = unit_normals(normals);
    }
    Ok(cloud)
}

/// Parses a text point cloud.
pub fn parse_text(data: &[u8]) -> Result<PointCloud> {
    let mut cloud = PointCloud::default();
    let mut extra = Vec::new();
    let mut all_have_extra = true;
    each_row(
        data,
        3,
        "a point needs three coordinates (x y alone: a plane contour, for --2d)",
        |numbers| {
            cloud.points.push([numbers[0], numbers[1], numbers[2]]);
            if numbers.len() >= 6 {
                extra.push([numbers[3], numbers[4], numbers[5]]);
            } else {
                all_have_extra = false;
            }
        },
    )?;
    if all_have_extra && !cloud.points.is_empty() {
        cloud.normals = unit_normals(extra);
    }
    Ok(cloud)
}

/// The rows of a text table (a law's table, a curve's vertices) with at least `columns`
/// numbers each, the first `columns` kept.
pub fn read_columns(path: &Path, columns: usize) -> Result<Vec<Vec<f64>>> {
    let data = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let mut rows = Vec::new();
    each_row(&data, columns, "too few numbers", |n| {
        rows.push(n[..columns].to_vec())
    })
    .map_err(|e| e.in_file(path))?;
    Ok(rows)
}

/// Calls `row` with the numbers of every data line of a text table (the rules of the module
/// documentation); a line with fewer than `min` numbers is refused with `short`.
fn each_row(data: &[u8], min: usize, short: &str, mut row: impl FnMut(&[f64])) -> Result<()> {
    let text = std::str::from_utf8(data)
        .map_err(|_| Error::parse("not a text point cloud (bytes that are not UTF-8)"))?;
    let mut first = true;
    let mut fields = Vec::with_capacity(8);
    let mut numbers = Vec::with_capacity(8);
    for (n, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') || line.starts_with("//") {
            continue;
        }
        fields.clear();
        fields.extend(
            line.split(|c: char| c.is_whitespace() || c == ',' || c == ';')
                .filter(|w| !w.is_empty()),
        );
        let was_first = std::mem::replace(&mut first, false);
        if was_first && fields.len() == 1 && fields[0].parse::<u64>().is_ok() {
            continue; // the point count of a .pts file
        }
        numbers.clear();
        let parsed = fields.iter().try_for_each(|w| {
            numbers.push(w.parse::<f64>()?);
            Ok::<(), std::num::ParseFloatError>(())
        });
        match parsed {
            Ok(()) => {}
            Err(_) if was_first => continue, // a header of column names
            Err(_) => {
                return Err(Error::parse(format!(
                    "line {}: '{}' is not a list of numbers",
                    n + 1,
                    line.chars().take(40).collect::<String>()
                )))
            }
        }
        if numbers.len() < min {
            return Err(Error::parse(format!(
                "line {}: {short}, found {} number{}",
                n + 1,
                numbers.len(),
                if numbers.len() == 1 { "" } else { "s" }
            )));
        }
        if !numbers.iter().all(|x| x.is_finite()) {
            return Err(Error::parse(format!(
                "line {}: a value that is not a finite number",
                n + 1
            )));
        }
        row(&numbers);
    }
    Ok(())
}

/// The vectors as unit normals, when every one is a unit vector (within 2 %, as files written
/// with a few decimals give them); `None` when the columns are something else.
fn unit_normals(v: Vec<[f64; 3]>) -> Option<Vec<[f64; 3]>> {
    let unit = |n: &[f64; 3]| ((n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt() - 1.0).abs() < 0.02;
    if !v.iter().all(unit) {
        return None;
    }
    Some(
        v.into_iter()
            .map(|n| {
                let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                n.map(|x| x / l)
            })
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_columns_counts_and_headers() {
        let c = parse_text(b"3\n0 0 0 10 200 30 40\n1,0,0,1,2,3,4\n0;1;0;5;6;7;8\n").unwrap();
        assert_eq!(c.points.len(), 3);
        assert!(c.normals.is_none(), "intensity and colour are not normals");
        let c = parse_text(b"x y z nx ny nz\n# a comment\n0 0 0 0 0 1\n1 0 0 1 0 0\n").unwrap();
        assert_eq!(c.normals.unwrap(), vec![[0., 0., 1.], [1., 0., 0.]]);
        let e = parse_text(b"0 0 0\n1 nan 0\n").unwrap_err().to_string();
        assert!(e.contains("line 2"), "{e}");
        let e = parse_text(b"0 0 0\n1 0\n").unwrap_err().to_string();
        assert!(e.contains("three coordinates"), "{e}");
        assert!(parse_text(b"").unwrap().points.is_empty());
    }

    #[test]
    fn plane_contours_with_and_without_normals() {
        let c = parse_text_plane(b"x,y\n0,0\n1,0\n").unwrap();
        assert_eq!(c.points, vec![[0., 0., 0.], [1., 0., 0.]]);
        assert!(c.normals.is_none());
        let c = parse_text_plane(b"0 0 0 -1\n1 0 1 0\n").unwrap();
        assert_eq!(c.normals.unwrap(), vec![[0., -1., 0.], [1., 0., 0.]]);
        let c = parse_text_plane(b"0 0 5\n1 0 5\n").unwrap();
        assert!(c.normals.is_none(), "a section's z is not a normal");
        let e = parse_text_plane(b"0 0\n1\n").unwrap_err().to_string();
        assert!(e.contains("line 2") && e.contains("x and y"), "{e}");
    }

    #[test]
    fn ply_points_with_and_without_normals() {
        let mut b = b"ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nend_header\n".to_vec();
        for v in [0f32, 0., 0., 0., 0., 1., 1., 2., 3., 1., 0., 0.] {
            b.extend_from_slice(&v.to_le_bytes());
        }
        let c = parse_ply(&b).unwrap();
        assert_eq!(c.points, vec![[0., 0., 0.], [1., 2., 3.]]);
        assert_eq!(c.normals.unwrap()[1], [1., 0., 0.]);
        let a = b"ply\nformat ascii 1.0\nelement vertex 2\nproperty double x\nproperty double y\nproperty double z\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 1 nan\n";
        assert!(parse_ply(a).unwrap_err().to_string().contains("point 1"));
    }
}
