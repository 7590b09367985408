//! Mask stacks for DLP and SLA printers: every layer an 8-bit greyscale PNG at a pixel size,
//! anti-aliased (a pixel's grey is the fraction of it the section covers, [`super::raster`]).
//! Two forms: a folder of `layer00000.png` … with `stack.json` (pixel size, where pixel (0, 0)
//! lies, every layer's height), and a PrusaSlicer SL1 archive (`config.ini`, `prusaslicer.ini`,
//! the layers as `NAME00000.png` … at the Original Prusa SL1's 1440 × 2560 display, 0.046875 mm
//! pixels, the part centred; a thumbnail of the part's outline).

use super::raster::Mask;
use super::{Section, Stack, StackWriter};
use crate::error::{Error, Result};
use crate::io::atomic::AtomicDir;
use crate::io::png::encode_grey;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Where the pixels lie: pixel `(i, j)` (row `j` from the top) covers
/// `u ∈ [u0 + i·p, u0 + (i+1)·p]`, `v ∈ [v_top − (j+1)·p, v_top − j·p]`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct PixelGrid {
    /// Pixel size, mm.
    pub pixel: f64,
    /// Width, pixels.
    pub width: usize,
    /// Height, pixels.
    pub height: usize,
    /// `u` of the left edge, mm.
    pub u0: f64,
    /// `v` of the top edge, mm.
    pub v_top: f64,
}

/// Most pixels a layer image may have.
pub const MAX_PIXELS: usize = 200_000_000;

impl PixelGrid {
    /// A grid over the part's in-layer bounds with a pixel of margin, aligned to multiples of
    /// the pixel size (so two parts sliced at one pixel size share a grid).
    pub fn around(bounds: [f64; 4], pixel: f64) -> Result<PixelGrid> {
        let i0 = (bounds[0] / pixel).floor() - 1.0;
        let i1 = (bounds[2] / pixel).ceil() + 1.0;
        let j0 = (bounds[1] / pixel).floor() - 1.0;
        let j1 = (bounds[3] / pixel).ceil() + 1.0;
        let (w, h) = (i1 - i0, j1 - j0);
        if w * h > MAX_PIXELS as f64 || w.is_nan() || h.is_nan() {
            return Err(Error::invalid(format!(
                "{pixel} mm pixels make {w} × {h} pixel layers (more than {MAX_PIXELS} pixels): use larger pixels"
            )));
        }
        Ok(PixelGrid {
            pixel,
            width: w as usize,
            height: h as usize,
            u0: i0 * pixel,
            v_top: j1 * pixel,
        })
    }

    /// A printer's display of `width × height` pixels of size `pixel`, centred on the part;
    /// an error if the part does not fit.
    pub fn display(bounds: [f64; 4], pixel: f64, width: usize, height: usize) -> Result<PixelGrid> {
        let (w, h) = (width as f64 * pixel, height as f64 * pixel);
        if bounds[2] - bounds[0] > w || bounds[3] - bounds[1] > h {
            return Err(Error::invalid(format!(
                "the part's layers are {:.2} × {:.2} mm, larger than the printer's {w:.2} × {h:.2} mm display",
                bounds[2] - bounds[0],
                bounds[3] - bounds[1]
            )));
        }
        let c = [0.5 * (bounds[0] + bounds[2]), 0.5 * (bounds[1] + bounds[3])];
        Ok(PixelGrid {
            pixel,
            width,
            height,
            u0: c[0] - 0.5 * w,
            v_top: c[1] + 0.5 * h,
        })
    }

    /// The section's coverage mask on this grid.
    pub fn mask(&self, section: &Section) -> Mask {
        let mut m = Mask::new(self.width, self.height);
        let p = self.pixel;
        for l in &section.loops {
            m.add_loop(
                l.iter()
                    .map(|q| [(q[0] - self.u0) / p, (self.v_top - q[1]) / p]),
            );
        }
        m
    }
}

/// A folder of layer files: built aside and put in place whole, or — for one shard of a
/// stack — written file by file into a shared folder.
pub struct LayerDir {
    path: PathBuf,
    whole: Option<AtomicDir>,
}

impl LayerDir {
    /// Starts the folder `path`.
    pub fn create(path: &Path, sharded: bool) -> Result<LayerDir> {
        let whole = if sharded {
            std::fs::create_dir_all(path).map_err(|e| Error::io(path, e))?;
            None
        } else {
            Some(AtomicDir::create(path, "stack.json")?)
        };
        Ok(LayerDir {
            path: path.to_path_buf(),
            whole,
        })
    }

    /// Writes the file `name` in the folder.
    pub fn put(&self, name: &str, bytes: &[u8]) -> Result<()> {
        match &self.whole {
            Some(d) => {
                let f = d.file(name);
                std::fs::write(&f, bytes).map_err(|e| Error::io(self.path.join(name), e))
            }
            None => crate::io::atomic::write_atomic(&self.path.join(name), |w| w.write_all(bytes)),
        }
    }

    /// Puts the folder in place.
    pub fn finish(self) -> Result<()> {
        match self.whole {
            Some(d) => d.commit(),
            None => Ok(()),
        }
    }
}

/// What `stack.json` says of a folder of layer files.
#[derive(serde::Serialize)]
struct Manifest<'a> {
    part: &'a str,
    #[serde(skip_serializing_if = "Option::is_none")]
    grid: Option<PixelGrid>,
    direction: [f64; 3],
    u_axis: [f64; 3],
    v_axis: [f64; 3],
    layers: Vec<ManifestLayer>,
}

#[derive(serde::Serialize)]
struct ManifestLayer {
    file: String,
    z: f64,
    thickness: f64,
}

/// Writes `stack.json` into `dir`: the part, the frame, the pixel grid (for masks) and every
/// layer's file (`layer00000.EXT` …), mid-height and thickness.
pub(crate) fn write_manifest(
    dir: &LayerDir,
    stack: &Stack,
    grid: Option<PixelGrid>,
    ext: &str,
) -> Result<()> {
    let manifest = Manifest {
        part: &stack.name,
        grid,
        direction: stack.frame.d,
        u_axis: stack.frame.u,
        v_axis: stack.frame.v,
        layers: stack
            .layers
            .iter()
            .enumerate()
            .map(|(k, l)| ManifestLayer {
                file: format!("layer{k:05}.{ext}"),
                z: l.z,
                thickness: l.thickness,
            })
            .collect(),
    };
    let json = serde_json::to_vec_pretty(&manifest)
        .map_err(|e| Error::io(&dir.path, std::io::Error::other(e)))?;
    dir.put("stack.json", &json)
}

/// A folder of PNG masks and its `stack.json`.
pub struct PngDirWriter {
    dir: LayerDir,
    grid: PixelGrid,
}

impl PngDirWriter {
    /// Starts the folder `path` at pixel size `pixel`.
    pub fn create(path: &Path, stack: &Stack, pixel: f64, sharded: bool) -> Result<PngDirWriter> {
        let grid = PixelGrid::around(stack.bounds, pixel)?;
        let dir = LayerDir::create(path, sharded)?;
        write_manifest(&dir, stack, Some(grid), "png")?;
        Ok(PngDirWriter { dir, grid })
    }
}

impl StackWriter for PngDirWriter {
    fn encode(&self, _index: usize, section: &Section) -> Result<Vec<u8>> {
        let g = self.grid;
        encode_grey(g.width as u32, g.height as u32, &g.mask(section).grey())
    }

    fn put(&mut self, index: usize, encoded: Vec<u8>) -> Result<()> {
        self.dir.put(&format!("layer{index:05}.png"), &encoded)
    }

    fn finish(self: Box<Self>) -> Result<()> {
        self.dir.finish()
    }
}

/// The Original Prusa SL1's display: pixels across, pixels along, pixel size (mm).
pub const SL1_DISPLAY: (usize, usize, f64) = (1440, 2560, 0.046875);

/// Exposure of a layer, and of the first (fading) layers, s; the tilt after each layer, s.
const EXPOSURE: f64 = 6.0;
const EXPOSURE_FIRST: f64 = 20.0;
const TILT: f64 = 5.0;
/// Layers whose exposure fades from the first layers' to the others'.
const FADE: usize = 10;

/// Thumbnail size in an SL1 archive.
const THUMB: usize = 400;

/// A PrusaSlicer SL1 archive.
pub struct Sl1Writer {
    path: PathBuf,
    tmp: tempfile::NamedTempFile,
    zip: zip::ZipWriter<std::io::BufWriter<std::fs::File>>,
    grid: PixelGrid,
    thumb_grid: PixelGrid,
    thumb: Vec<u8>,
    /// Resin used so far, mm³.
    material: f64,
    job: String,
    stack: Stack,
}

impl Sl1Writer {
    /// Starts `path`; the layers must be of one thickness (the SL1 format has one layer height).
    pub fn create(path: &Path, stack: &Stack) -> Result<Sl1Writer> {
        let t = stack.layers.first().map_or(0.05, |l| l.thickness);
        if stack
            .layers
            .iter()
            .any(|l| (l.thickness - t).abs() > 1e-9 * t)
        {
            return Err(Error::invalid(
                "an SL1 archive has one layer height: slice it with uniform layers (--layer H, no --first-layer or --adaptive)",
            ));
        }
        let (w, h, p) = SL1_DISPLAY;
        let grid = PixelGrid::display(stack.bounds, p, w, h)?;
        let b = stack.bounds;
        let side = (b[2] - b[0]).max(b[3] - b[1]).max(1e-6) * 1.1;
        let tp = side / THUMB as f64;
        let c = [0.5 * (b[0] + b[2]), 0.5 * (b[1] + b[3])];
        let thumb_grid = PixelGrid {
            pixel: tp,
            width: THUMB,
            height: THUMB,
            u0: c[0] - 0.5 * side,
            v_top: c[1] + 0.5 * side,
        };
        let tmp = crate::io::atomic::temp_beside(path)?;
        let file = tmp.reopen().map_err(|e| Error::io(path, e))?;
        let zip = zip::ZipWriter::new(std::io::BufWriter::with_capacity(1 << 20, file));
        let job: String = stack
            .name
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                    c
                } else {
                    '_'
                }
            })
            .collect();
        Ok(Sl1Writer {
            path: path.to_path_buf(),
            tmp,
            zip,
            grid,
            thumb_grid,
            thumb: vec![0; THUMB * THUMB],
            material: 0.0,
            job: if job.is_empty() { "part".into() } else { job },
            stack: stack.clone(),
        })
    }

    fn config(&self) -> String {
        let n = self.stack.layers.len();
        let t = self.stack.layers.first().map_or(0.05, |l| l.thickness);
        let stamp = humantime::format_rfc3339_seconds(std::time::SystemTime::now()).to_string();
        format!(
            "action = print\njobDir = {}\nexpTime = {EXPOSURE}\nexpTimeFirst = {EXPOSURE_FIRST}\n\
             fileCreationTimestamp = {}\n\
             hollow = 0\nlayerHeight = {t}\nmaterialName = Generic\nnumFade = {}\nnumFast = {n}\n\
             numSlow = 0\nprintProfile = latvox {t} mm\nprintTime = {:.0}\nprinterModel = SL1\n\
             printerProfile = Original Prusa SL1\nprinterVariant = default\n\
             prusaSlicerVersion = latvox-{}\nusedMaterial = {:.3}\n",
            self.job,
            stamp.replace('T', " at ").replace('Z', " UTC"),
            FADE.min(n),
            // An estimate: the exposures, and the SL1's fast tilt (about 5 s) after each layer.
            EXPOSURE_FIRST * FADE.min(n) as f64 + (EXPOSURE + TILT) * n as f64
                - EXPOSURE * FADE.min(n) as f64,
            env!("CARGO_PKG_VERSION"),
            self.material / 1000.0
        )
    }
}

impl StackWriter for Sl1Writer {
    /// The layer's PNG, then the layer's thumbnail coverage (THUMB² bytes) and its area (mm²,
    /// f64) appended.
    fn encode(&self, _index: usize, section: &Section) -> Result<Vec<u8>> {
        let g = self.grid;
        let mut out = encode_grey(g.width as u32, g.height as u32, &g.mask(section).grey())?;
        out.extend(self.thumb_grid.mask(section).grey());
        out.extend(section.measures().area.to_le_bytes());
        Ok(out)
    }

    fn put(&mut self, index: usize, mut encoded: Vec<u8>) -> Result<()> {
        let area = encoded.split_off(encoded.len() - 8);
        let area = f64::from_le_bytes(area.try_into().expect("8 bytes"));
        self.material += area * self.stack.layers[index].thickness;
        let thumb = encoded.split_off(encoded.len() - THUMB * THUMB);
        for (a, b) in self.thumb.iter_mut().zip(thumb) {
            *a = (*a).max(b);
        }
        let opts = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Stored);
        let path = self.path.clone();
        self.zip
            .start_file(format!("{}{index:05}.png", self.job), opts)
            .map_err(|e| Error::io(&path, std::io::Error::other(e)))?;
        self.zip
            .write_all(&encoded)
            .map_err(|e| Error::io(&path, e))
    }

    fn finish(mut self: Box<Self>) -> Result<()> {
        let path = self.path.clone();
        let zerr = |e: zip::result::ZipError| Error::io(&path, std::io::Error::other(e));
        let io = |e: std::io::Error| Error::io(&path, e);
        let deflate = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Deflated);
        let config = self.config();
        self.zip.start_file("config.ini", deflate).map_err(zerr)?;
        self.zip.write_all(config.as_bytes()).map_err(io)?;
        let (w, h, p) = SL1_DISPLAY;
        let t = self.stack.layers.first().map_or(0.05, |l| l.thickness);
        let profile = format!(
            "display_width = {}\ndisplay_height = {}\ndisplay_pixels_x = {w}\ndisplay_pixels_y = {h}\n\
             display_orientation = portrait\nlayer_height = {t}\nprinter_technology = SLA\n",
            w as f64 * p,
            h as f64 * p
        );
        self.zip
            .start_file("prusaslicer.ini", deflate)
            .map_err(zerr)?;
        self.zip.write_all(profile.as_bytes()).map_err(io)?;
        // The thumbnail: every layer's outline at once, dark on light.
        let light: Vec<u8> = self
            .thumb
            .iter()
            .map(|&c| 255 - (c as u16 * 200 / 255) as u8)
            .collect();
        let png = encode_grey(THUMB as u32, THUMB as u32, &light)?;
        let stored = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Stored);
        self.zip
            .start_file(format!("thumbnail/thumbnail{THUMB}x{THUMB}.png"), stored)
            .map_err(zerr)?;
        self.zip.write_all(&png).map_err(io)?;
        let mut file = self.zip.finish().map_err(zerr)?;
        file.flush().map_err(io)?;
        let f = file.into_inner().map_err(|e| io(e.into_error()))?;
        f.sync_data().map_err(io)?;
        drop(f);
        self.tmp
            .persist(&path)
            .map_err(|e| Error::io(&path, e.error))?;
        Ok(())
    }
}
