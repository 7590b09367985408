//! SVG layer stacks: one file with a `<g>` per layer, or a folder with a file per layer. Each
//! polygon (outer loop and its holes) is one `<path>` filled even–odd; open chains (only from an
//! invalid mesh) are red strokes. The SVG's y axis points down, so v is written negated: the
//! picture is the layer seen from `+d`. Lengths in mm (the root's width and height say so).

use super::{Section, Stack, StackWriter};
use crate::error::Result;
use crate::io::atomic::AtomicFile;
use std::fmt::Write as _;
use std::path::Path;

/// The root element's opening, sized to the part's in-layer bounds.
fn open_svg(stack: &Stack) -> String {
    let b = stack.bounds;
    let m = 0.02 * (b[2] - b[0]).max(b[3] - b[1]).max(1e-3);
    let (x, y, w, h) = (
        b[0] - m,
        -b[3] - m,
        b[2] - b[0] + 2.0 * m,
        b[3] - b[1] + 2.0 * m,
    );
    format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" \
         width=\"{w:.4}mm\" height=\"{h:.4}mm\" viewBox=\"{x:.5} {y:.5} {w:.5} {h:.5}\">\n\
         <!-- {} sliced by latvox: {} layers; one group per layer, data-z its mid-height (mm) -->\n",
        xml_text(&stack.name),
        stack.layers.len()
    )
}

/// Layer `index` as a `<g>` element.
fn group(stack: &Stack, index: usize, section: &Section) -> String {
    let l = stack.layers[index];
    let mut s = format!(
        "<g id=\"layer{index:05}\" data-z=\"{:.6}\" data-thickness=\"{:.6}\" fill=\"black\" \
         fill-rule=\"evenodd\">\n",
        l.z, l.thickness
    );
    let ring = |s: &mut String, pts: &[[f64; 2]]| {
        for (k, p) in pts.iter().enumerate() {
            let _ = write!(
                s,
                "{}{:.5} {:.5}",
                if k == 0 { "M" } else { " " },
                p[0],
                -p[1]
            );
        }
        s.push('Z');
    };
    for poly in section.polygons() {
        s.push_str("<path d=\"");
        ring(&mut s, &section.loops[poly.outer]);
        for &h in &poly.holes {
            ring(&mut s, &section.loops[h]);
        }
        s.push_str("\"/>\n");
    }
    for pts in &section.open {
        s.push_str("<polyline fill=\"none\" stroke=\"red\" stroke-width=\"0.05\" points=\"");
        for p in pts {
            let _ = write!(s, "{:.5},{:.5} ", p[0], -p[1]);
        }
        s.push_str("\"/>\n");
    }
    s.push_str("</g>\n");
    s
}

fn xml_text(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace("--", "- -")
}

/// One SVG file holding every layer.
pub struct SvgWriter {
    file: AtomicFile,
    stack: Stack,
}

impl SvgWriter {
    /// Starts `path`.
    pub fn create(path: &Path, stack: &Stack) -> Result<SvgWriter> {
        let mut file = AtomicFile::create(path)?;
        file.write(open_svg(stack).as_bytes())?;
        Ok(SvgWriter {
            file,
            stack: stack.clone(),
        })
    }
}

impl StackWriter for SvgWriter {
    fn encode(&self, index: usize, section: &Section) -> Result<Vec<u8>> {
        Ok(group(&self.stack, index, section).into_bytes())
    }

    fn put(&mut self, _index: usize, encoded: Vec<u8>) -> Result<()> {
        self.file.write(&encoded)
    }

    fn finish(mut self: Box<Self>) -> Result<()> {
        self.file.write(b"</svg>\n")?;
        self.file.commit()
    }
}

/// A folder of SVG files, `layer00000.svg` …, one per layer, and `stack.json`.
pub struct SvgDirWriter {
    dir: super::masks::LayerDir,
    stack: Stack,
}

impl SvgDirWriter {
    /// Starts the folder `path` (a shard writes its files into it; otherwise it is replaced
    /// whole on finishing).
    pub fn create(path: &Path, stack: &Stack, sharded: bool) -> Result<SvgDirWriter> {
        let dir = super::masks::LayerDir::create(path, sharded)?;
        super::masks::write_manifest(&dir, stack, None, "svg")?;
        Ok(SvgDirWriter {
            dir,
            stack: stack.clone(),
        })
    }
}

impl StackWriter for SvgDirWriter {
    fn encode(&self, index: usize, section: &Section) -> Result<Vec<u8>> {
        let mut s = open_svg(&self.stack);
        s.push_str(&group(&self.stack, index, section));
        s.push_str("</svg>\n");
        Ok(s.into_bytes())
    }

    fn put(&mut self, index: usize, encoded: Vec<u8>) -> Result<()> {
        self.dir.put(&format!("layer{index:05}.svg"), &encoded)
    }

    fn finish(self: Box<Self>) -> Result<()> {
        self.dir.finish()
    }
}
