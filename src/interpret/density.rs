//! Element density fields: the input of the `topo` pipeline, read from `.npy`, CSV (2D) or
//! whitespace-separated text with a dimension header.
//!
//! Layout conventions (those of the 88-line code and top3d as NumPy sees their `xPhys`):
//! a 2D array has shape `(ny, nx)` with row 0 at the **top**; a 3D array `(ny, nx, nz)`.
//! In memory a [`Density`] is stored x fastest, then y **upwards**, then z.

use crate::error::{Error, Result};
use crate::io::npy;
use std::path::Path;

/// A regular grid of element densities in [0, 1].
#[derive(Debug, Clone, PartialEq)]
pub struct Density {
    /// Elements along x.
    pub nx: usize,
    /// Elements along y.
    pub ny: usize,
    /// 1 for a 2D field.
    pub nz: usize,
    /// Whether the input array was 3D.
    pub is_3d: bool,
    /// `data[(iz·ny + iy)·nx + ix]`, `iy` from the bottom.
    pub data: Vec<f64>,
    /// Element edge length, mm.
    pub element_size: f64,
}

impl Density {
    /// Density of element `(ix, iy, iz)`, `iy` from the bottom.
    pub fn at(&self, ix: usize, iy: usize, iz: usize) -> f64 {
        self.data[(iz * self.ny + iy) * self.nx + ix]
    }

    /// From an array in the file layout (see the module doc).
    pub fn from_array(shape: &[usize], data: &[f64], element_size: f64) -> Result<Density> {
        let (ny, nx, nz, is_3d) = match *shape {
            [ny, nx] => (ny, nx, 1, false),
            [ny, nx, nz] => (ny, nx, nz, true),
            _ => {
                return Err(Error::invalid(format!(
                    "a density field must be 2D (ny, nx) or 3D (ny, nx, nz); got shape {shape:?}"
                )))
            }
        };
        if nx < 2 || ny < 2 || (is_3d && nz < 2) {
            return Err(Error::invalid(format!(
                "density field of shape {shape:?} is too small (at least 2 elements per axis)"
            )));
        }
        if data.len() != nx * ny * nz {
            return Err(Error::invalid(format!(
                "shape {shape:?} needs {} values, got {}",
                nx * ny * nz,
                data.len()
            )));
        }
        if !(element_size > 0.0 && element_size.is_finite()) {
            return Err(Error::invalid(
                "element size must be a positive length in mm",
            ));
        }
        for (i, &v) in data.iter().enumerate() {
            if v.is_nan() {
                return Err(Error::invalid(format!(
                    "density is NaN at {}",
                    index_text(shape, i)
                )));
            }
            if !(-1e-9..=1.0 + 1e-9).contains(&v) {
                return Err(Error::invalid(format!(
                    "density {v} at {} is outside [0, 1]",
                    index_text(shape, i)
                )));
            }
        }
        let mut out = vec![0.0; data.len()];
        for row in 0..ny {
            for ix in 0..nx {
                for iz in 0..nz {
                    let v = data[(row * nx + ix) * nz + iz].clamp(0.0, 1.0);
                    out[(iz * ny + (ny - 1 - row)) * nx + ix] = v;
                }
            }
        }
        Ok(Density {
            nx,
            ny,
            nz,
            is_3d,
            data: out,
            element_size,
        })
    }

    /// Back to the file layout: `(shape, data)`.
    pub fn to_array(&self) -> (Vec<usize>, Vec<f64>) {
        let mut v = Vec::with_capacity(self.data.len());
        for row in 0..self.ny {
            for ix in 0..self.nx {
                for iz in 0..self.nz {
                    v.push(self.at(ix, self.ny - 1 - row, iz));
                }
            }
        }
        let shape = if self.is_3d {
            vec![self.ny, self.nx, self.nz]
        } else {
            vec![self.ny, self.nx]
        };
        (shape, v)
    }

    /// Reads `.npy`, `.csv` or text (`.txt`, `.dat`, anything else) by extension.
    pub fn read(path: &Path, element_size: f64) -> Result<Density> {
        let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .unwrap_or("")
            .to_ascii_lowercase();
        let parsed = if ext == "npy" || bytes.starts_with(b"\x93NUMPY") {
            npy::parse(&bytes).map(|a| (a.shape, a.data))
        } else {
            match String::from_utf8(bytes) {
                Err(_) => Err(Error::parse("not UTF-8 text")),
                Ok(text) if ext == "csv" => parse_csv(&text),
                Ok(text) => parse_text(&text),
            }
        };
        let (shape, data) = parsed.map_err(|e| e.in_file(path))?;
        Density::from_array(&shape, &data, element_size).map_err(|e| match e {
            Error::Invalid(m) => Error::parse(m).in_file(path),
            other => other,
        })
    }
}

fn index_text(shape: &[usize], mut i: usize) -> String {
    let mut idx = vec![0; shape.len()];
    for a in (0..shape.len()).rev() {
        idx[a] = i % shape[a];
        i /= shape[a];
    }
    format!("index {idx:?}")
}

/// CSV: one row of the 2D field per line, comma- (or semicolon-) separated.
pub fn parse_csv(text: &str) -> Result<(Vec<usize>, Vec<f64>)> {
    let mut data = Vec::new();
    let mut cols = None;
    let mut rows = 0;
    for (n, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let vals: Vec<f64> = line
            .split([',', ';'])
            .map(|s| {
                s.trim().parse::<f64>().map_err(|_| {
                    Error::parse(format!("line {}: '{}' is not a number", n + 1, s.trim()))
                })
            })
            .collect::<Result<_, _>>()?;
        match cols {
            None => cols = Some(vals.len()),
            Some(c) if c != vals.len() => {
                return Err(Error::parse(format!(
                    "line {}: {} values, but the first row has {c}",
                    n + 1,
                    vals.len()
                )))
            }
            _ => {}
        }
        rows += 1;
        data.extend(vals);
    }
    let cols = cols.ok_or_else(|| Error::parse("no data rows"))?;
    Ok((vec![rows, cols], data))
}

/// Text: a header line `ny nx` or `ny nx nz`, then the values, whitespace-separated, in C order
/// of that shape (for 3D: all `nz` values of an element column together, as `numpy.savetxt` of
/// the array reshaped to `(ny, nx·nz)` writes them).
pub fn parse_text(text: &str) -> Result<(Vec<usize>, Vec<f64>)> {
    let mut lines = text
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#'));
    let head = lines.next().ok_or_else(|| Error::parse("empty file"))?;
    let shape: Vec<usize> = head
        .split_whitespace()
        .map(|s| {
            s.parse::<usize>().map_err(|_| {
                Error::parse(format!(
                    "first line must give the dimensions (ny nx [nz]); got '{head}'"
                ))
            })
        })
        .collect::<Result<_, _>>()?;
    if !(2..=3).contains(&shape.len()) {
        return Err(Error::parse(format!(
            "first line must give 2 or 3 dimensions (ny nx [nz]); got '{head}'"
        )));
    }
    let mut data = Vec::new();
    for l in lines {
        for s in l.split_whitespace() {
            data.push(
                s.parse::<f64>()
                    .map_err(|_| Error::parse(format!("'{s}' is not a number")))?,
            );
        }
    }
    let n: usize = shape.iter().product();
    if data.len() != n {
        return Err(Error::parse(format!(
            "header says {shape:?} ({n} values) but the file holds {}",
            data.len()
        )));
    }
    Ok((shape, data))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layouts_agree_and_bad_values_are_named() {
        let (s, d) = parse_csv("0,0.5,1\n1,1,0\n").unwrap();
        let a = Density::from_array(&s, &d, 2.0).unwrap();
        assert_eq!((a.nx, a.ny), (3, 2));
        // Row 0 is the top: (ix 1, iy 1) is 0.5.
        assert_eq!(a.at(1, 1, 0), 0.5);
        assert_eq!(a.at(0, 0, 0), 1.0);
        let (s2, d2) = parse_text("2 3\n0 0.5 1\n1 1 0\n").unwrap();
        assert_eq!(Density::from_array(&s2, &d2, 2.0).unwrap(), a);
        assert_eq!(a.to_array(), (s, d));
        let e = Density::from_array(&[2, 2], &[0.0, f64::NAN, 0.0, 0.0], 1.0).unwrap_err();
        assert!(e.to_string().contains("NaN at index [0, 1]"), "{e}");
        let e = Density::from_array(&[2, 2], &[0.0, 1.5, 0.0, 0.0], 1.0).unwrap_err();
        assert!(e.to_string().contains("outside [0, 1]"), "{e}");
        assert!(Density::from_array(&[4], &[0.0; 4], 1.0).is_err());
        assert!(parse_csv("1,2\n3\n").is_err());
        assert!(parse_text("2 2\n1 1 1\n").is_err());
    }
}
