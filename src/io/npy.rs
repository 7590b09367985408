//! NumPy's `.npy` format (versions 1–3): what optimisers in the field write. Reads float, integer
//! and boolean arrays of either byte order, C or Fortran order; writes little-endian `f8`.

use crate::error::{Error, Result};
use std::io::Write;

/// An n-dimensional array in C order.
#[derive(Debug, Clone, PartialEq)]
pub struct Array {
    /// Length along each axis.
    pub shape: Vec<usize>,
    /// The values, C order (last axis fastest).
    pub data: Vec<f64>,
}

/// Parses `.npy` bytes.
pub fn parse(bytes: &[u8]) -> Result<Array> {
    if bytes.len() < 10 || &bytes[..6] != b"\x93NUMPY" {
        return Err(Error::parse(
            "not a .npy file (missing the \\x93NUMPY magic)",
        ));
    }
    let major = bytes[6];
    let (hlen, start) = match major {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10),
        2 | 3 => {
            if bytes.len() < 12 {
                return Err(Error::parse("truncated .npy header"));
            }
            (
                u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize,
                12,
            )
        }
        v => return Err(Error::parse(format!("unsupported .npy version {v}"))),
    };
    let header = bytes
        .get(start..start + hlen)
        .ok_or_else(|| Error::parse("truncated .npy header"))?;
    let header =
        std::str::from_utf8(header).map_err(|_| Error::parse(".npy header is not text"))?;
    let descr =
        dict_value(header, "descr").ok_or_else(|| Error::parse(".npy header has no 'descr'"))?;
    let descr = descr.trim_matches(|c| c == '\'' || c == '"');
    let fortran = dict_value(header, "fortran_order")
        .ok_or_else(|| Error::parse(".npy header has no 'fortran_order'"))?
        .starts_with("True");
    let shape_txt =
        dict_value(header, "shape").ok_or_else(|| Error::parse(".npy header has no 'shape'"))?;
    let shape: Vec<usize> = shape_txt
        .trim_start_matches('(')
        .split([',', ')'])
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| {
            s.parse::<usize>()
                .map_err(|_| Error::parse(format!("bad shape {shape_txt}")))
        })
        .collect::<Result<_, _>>()?;
    let n: usize = shape.iter().product();
    let body = &bytes[start + hlen..];
    let (order, kind, size) = {
        let b = descr.as_bytes();
        if b.len() < 3 {
            return Err(Error::parse(format!("unsupported dtype '{descr}'")));
        }
        let size: usize = descr[2..]
            .parse()
            .map_err(|_| Error::parse(format!("unsupported dtype '{descr}'")))?;
        (b[0], b[1], size)
    };
    if body.len() < n * size {
        return Err(Error::parse(format!(
            "data holds {} bytes, shape {shape:?} of {descr} needs {}",
            body.len(),
            n * size
        )));
    }
    let big = order == b'>';
    let get = |i: usize| -> Result<f64> {
        let mut raw = [0u8; 8];
        raw[..size].copy_from_slice(&body[i * size..(i + 1) * size]);
        if big {
            raw[..size].reverse();
        }
        Ok(match (kind, size) {
            (b'f', 8) => f64::from_le_bytes(raw),
            (b'f', 4) => f32::from_le_bytes(raw[..4].try_into().unwrap()) as f64,
            (b'i', 8) => i64::from_le_bytes(raw) as f64,
            (b'i', 4) => i32::from_le_bytes(raw[..4].try_into().unwrap()) as f64,
            (b'i', 2) => i16::from_le_bytes(raw[..2].try_into().unwrap()) as f64,
            (b'i', 1) => raw[0] as i8 as f64,
            (b'u', 8) => u64::from_le_bytes(raw) as f64,
            (b'u', 4) => u32::from_le_bytes(raw[..4].try_into().unwrap()) as f64,
            (b'u', 2) => u16::from_le_bytes(raw[..2].try_into().unwrap()) as f64,
            (b'u' | b'b', 1) => raw[0] as f64,
            _ => return Err(Error::parse(format!("unsupported dtype '{descr}'"))),
        })
    };
    let flat: Vec<f64> = (0..n).map(get).collect::<Result<_, _>>()?;
    let data = if fortran && shape.len() > 1 {
        // Fortran order: the first index varies fastest. Reorder to C order.
        let mut out = vec![0.0; n];
        let mut idx = vec![0usize; shape.len()];
        for v in flat {
            let mut c = 0;
            for (a, &i) in idx.iter().enumerate() {
                c = c * shape[a] + i;
            }
            out[c] = v;
            for a in 0..shape.len() {
                idx[a] += 1;
                if idx[a] < shape[a] {
                    break;
                }
                idx[a] = 0;
            }
        }
        out
    } else {
        flat
    };
    Ok(Array { shape, data })
}

fn dict_value<'a>(header: &'a str, key: &str) -> Option<&'a str> {
    let at = header
        .find(&format!("'{key}'"))
        .or_else(|| header.find(&format!("\"{key}\"")))?;
    let rest = &header[at + key.len() + 2..];
    let rest = rest.trim_start().strip_prefix(':')?.trim_start();
    if rest.starts_with('(') {
        let end = rest.find(')')?;
        Some(&rest[..=end])
    } else {
        let end = rest.find([',', '}']).unwrap_or(rest.len());
        Some(rest[..end].trim())
    }
}

/// Writes `data` (C order) with `shape` as a version-1.0 little-endian `f8` array.
pub fn write(w: &mut dyn Write, shape: &[usize], data: &[f64]) -> std::io::Result<()> {
    let dims: Vec<String> = shape.iter().map(|s| s.to_string()).collect();
    let shape_txt = if dims.len() == 1 {
        format!("({},)", dims[0])
    } else {
        format!("({})", dims.join(", "))
    };
    let mut header = format!("{{'descr': '<f8', 'fortran_order': False, 'shape': {shape_txt}, }}");
    // Pad so the data starts on a 64-byte boundary, ending in a newline.
    let total = 10 + header.len() + 1;
    header.push_str(&" ".repeat((64 - total % 64) % 64));
    header.push('\n');
    w.write_all(b"\x93NUMPY\x01\x00")?;
    w.write_all(&(header.len() as u16).to_le_bytes())?;
    w.write_all(header.as_bytes())?;
    for v in data {
        w.write_all(&v.to_le_bytes())?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_fortran_order() {
        let mut buf = Vec::new();
        write(&mut buf, &[2, 3], &[0., 1., 2., 3., 4., 5.]).unwrap();
        assert_eq!(buf.len() % 64, 48);
        let a = parse(&buf).unwrap();
        assert_eq!(a.shape, vec![2, 3]);
        assert_eq!(a.data, vec![0., 1., 2., 3., 4., 5.]);
        let at = buf.windows(5).position(|w| w == b"False").unwrap();
        let mut f = buf.clone();
        f[at..at + 5].copy_from_slice(b"True ");
        let b = parse(&f).unwrap();
        // Fortran data 0..6 of shape (2, 3) is [[0, 2, 4], [1, 3, 5]].
        assert_eq!(b.data, vec![0., 2., 4., 1., 3., 5.]);
        assert!(parse(b"hello").is_err());
    }
}
