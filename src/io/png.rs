//! PNG pictures: 8-bit RGB, written atomically.

use crate::error::Result;
use std::path::Path;

/// Writes `rgb` (row by row from the top, three bytes a pixel) as a `width × height` PNG.
pub fn write_rgb(path: &Path, width: u32, height: u32, rgb: &[u8]) -> Result<()> {
    write_colour(path, width, height, ::png::ColorType::Rgb, rgb)
}

/// Writes `rgba` (four bytes a pixel, alpha last: 0 transparent) as a `width × height` PNG.
pub fn write_rgba(path: &Path, width: u32, height: u32, rgba: &[u8]) -> Result<()> {
    write_colour(path, width, height, ::png::ColorType::Rgba, rgba)
}

fn write_colour(
    path: &Path,
    width: u32,
    height: u32,
    colour: ::png::ColorType,
    data: &[u8],
) -> Result<()> {
    crate::io::atomic::write_atomic(path, |w| {
        let mut e = ::png::Encoder::new(w, width, height);
        e.set_color(colour);
        e.set_depth(::png::BitDepth::Eight);
        let mut wr = e.write_header().map_err(std::io::Error::other)?;
        wr.write_image_data(data).map_err(std::io::Error::other)?;
        wr.finish().map_err(std::io::Error::other)
    })
}

/// Writes `frames` (each `rgb` as for [`write_rgb`], all `width × height`) as an animated PNG
/// (APNG) that loops forever, each frame shown `delay_ms` milliseconds; viewers without APNG
/// show the first frame.
pub fn write_animated(
    path: &Path,
    width: u32,
    height: u32,
    frames: &[&[u8]],
    delay_ms: u16,
) -> Result<()> {
    crate::io::atomic::write_atomic(path, |w| {
        let err = std::io::Error::other;
        let mut e = ::png::Encoder::new(w, width, height);
        e.set_color(::png::ColorType::Rgb);
        e.set_depth(::png::BitDepth::Eight);
        e.set_animated(frames.len() as u32, 0).map_err(err)?;
        e.set_frame_delay(delay_ms, 1000).map_err(err)?;
        let mut wr = e.write_header().map_err(err)?;
        for f in frames {
            wr.write_image_data(f).map_err(err)?;
        }
        wr.finish().map_err(err)
    })
}

/// `grey` (row by row from the top, a byte a pixel) as an 8-bit greyscale PNG, in memory.
pub fn encode_grey(width: u32, height: u32, grey: &[u8]) -> Result<Vec<u8>> {
    let mut out = Vec::new();
    {
        let mut e = ::png::Encoder::new(&mut out, width, height);
        e.set_color(::png::ColorType::Grayscale);
        e.set_depth(::png::BitDepth::Eight);
        e.set_compression(::png::Compression::Fast);
        let err = |e: ::png::EncodingError| {
            crate::error::Error::io(Path::new("PNG"), std::io::Error::other(e))
        };
        let mut wr = e.write_header().map_err(err)?;
        wr.write_image_data(grey).map_err(err)?;
        wr.finish().map_err(err)?;
    }
    Ok(out)
}
