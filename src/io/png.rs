//! PNG pictures: 8-bit RGB, written atomically.

use crate::error::Result;
use std::path::Path;

/// Writes `rgb` (row by row from the top, three bytes a pixel) as a `width × height` PNG.
pub fn write_rgb(path: &Path, width: u32, height: u32, rgb: &[u8]) -> Result<()> {
    crate::io::atomic::write_atomic(path, |w| {
        let mut e = ::png::Encoder::new(w, width, height);
        e.set_color(::png::ColorType::Rgb);
        e.set_depth(::png::BitDepth::Eight);
        let mut wr = e.write_header().map_err(std::io::Error::other)?;
        wr.write_image_data(rgb).map_err(std::io::Error::other)?;
        wr.finish().map_err(std::io::Error::other)
    })
}
