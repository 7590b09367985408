//! Common Layer Interface (CLI) files, version 2.0: the vector layer format of powder-bed and
//! stereolithography machines (Brite-EuRam project BE-2051, "Common Layer Interface (CLI) version
//! 2.0", 1994). ASCII: a header between `$$HEADERSTART` and `$$HEADEREND`, then the geometry,
//! `$$LAYER/z` and `$$POLYLINE/id,dir,n,x1,y1,…`. Binary: the same header (with `$$BINARY`),
//! then little-endian commands: a uint16 command index and its parameters — long layer (127,
//! real32 z), long polyline (130, int32 id, dir, n, then n real32 pairs).
//!
//! Coordinates are in the layer's frame (x and y for the default +Z build), `$$UNITS` 1 (mm),
//! `z` the layer's top. A closed polyline repeats its first point at the end; `dir` is 1 for a
//! counter-clockwise (outer) loop, 0 for a clockwise one (a hole), 2 for an open chain.

use super::{Section, Stack, StackWriter};
use crate::error::Result;
use crate::io::atomic::AtomicFile;
use std::path::Path;

/// Writes a CLI file, ASCII or binary.
pub struct CliWriter {
    file: AtomicFile,
    binary: bool,
    stack: Stack,
}

impl CliWriter {
    /// Starts `path`: writes the header.
    pub fn create(path: &Path, stack: &Stack, binary: bool) -> Result<CliWriter> {
        let mut file = AtomicFile::create(path)?;
        let b = stack.bounds;
        let h = stack.heights;
        let top = stack.layers.last().map_or(h[1], |l| l.top());
        let header = format!(
            "$$HEADERSTART\n{}\n$$UNITS/00000001.000000\n$$VERSION/200\n$$LABEL/1,{}\n$$DATE/{}\n\
             $$DIMENSION/{:.6},{:.6},{:.6},{:.6},{:.6},{:.6}\n$$LAYERS/{:06}\n$$HEADEREND",
            if binary { "$$BINARY" } else { "$$ASCII" },
            label(&stack.name),
            date_ddmmyy(),
            b[0],
            b[1],
            h[0],
            b[2],
            b[3],
            top,
            stack.layers.len()
        );
        file.write(header.as_bytes())?;
        if !binary {
            file.write(b"\n$$GEOMETRYSTART\n")?;
        }
        Ok(CliWriter {
            file,
            binary,
            stack: stack.clone(),
        })
    }
}

/// Loop direction code: 1 counter-clockwise, 0 clockwise, 2 open.
fn direction(l: &[[f64; 2]]) -> i32 {
    if crate::geom::contour::signed_area(l) > 0.0 {
        1
    } else {
        0
    }
}

impl StackWriter for CliWriter {
    fn put(&mut self, _index: usize, encoded: Vec<u8>) -> Result<()> {
        self.file.write(&encoded)
    }

    fn encode(&self, index: usize, section: &Section) -> Result<Vec<u8>> {
        let z = self.stack.layers[index].top();
        let polylines = section
            .loops
            .iter()
            .map(|l| (direction(l), l.as_slice(), true))
            .chain(section.open.iter().map(|l| (2, l.as_slice(), false)));
        if self.binary {
            let mut buf = Vec::with_capacity(64);
            buf.extend(127u16.to_le_bytes());
            buf.extend((z as f32).to_le_bytes());
            for (dir, pts, closed) in polylines {
                let n = pts.len() + closed as usize;
                buf.extend(130u16.to_le_bytes());
                buf.extend(1i32.to_le_bytes());
                buf.extend(dir.to_le_bytes());
                buf.extend((n as i32).to_le_bytes());
                for p in pts.iter().chain(pts.first().filter(|_| closed)) {
                    buf.extend((p[0] as f32).to_le_bytes());
                    buf.extend((p[1] as f32).to_le_bytes());
                }
            }
            Ok(buf)
        } else {
            let mut s = format!("$$LAYER/{z:.6}\n");
            for (dir, pts, closed) in polylines {
                use std::fmt::Write as _;
                let n = pts.len() + closed as usize;
                let _ = write!(s, "$$POLYLINE/1,{dir},{n}");
                for p in pts.iter().chain(pts.first().filter(|_| closed)) {
                    let _ = write!(s, ",{:.6},{:.6}", p[0], p[1]);
                }
                s.push('\n');
            }
            Ok(s.into_bytes())
        }
    }

    fn finish(mut self: Box<Self>) -> Result<()> {
        if !self.binary {
            self.file.write(b"$$GEOMETRYEND\n")?;
        }
        self.file.commit()
    }
}

/// A label for `$$LABEL`: the part's name without commas or line breaks.
fn label(name: &str) -> String {
    let l: String = name
        .chars()
        .map(|c| if c == ',' || c.is_control() { '_' } else { c })
        .collect();
    if l.is_empty() {
        "part".into()
    } else {
        l
    }
}

/// Today's date as the CLI header writes it (ddmmyy).
fn date_ddmmyy() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs())
        .unwrap_or(0);
    let ts = humantime::format_rfc3339_seconds(
        std::time::UNIX_EPOCH + std::time::Duration::from_secs(secs),
    )
    .to_string();
    // "YYYY-MM-DDThh:mm:ssZ"
    format!("{}{}{}", &ts[8..10], &ts[5..7], &ts[2..4])
}
