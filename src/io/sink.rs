//! Sinks: where a mesh streams to, a batch of triangles at a time, so a part never has to be
//! held whole in memory to be written.
//!
//! [`StlSink`] writes binary or ASCII STL into a temporary file beside the destination and
//! renames it over the destination only when [`StlSink::commit`] is called: a run that fails, or
//! is killed, leaves no partial file. [`MeshCollector`] gathers the triangles into an indexed
//! [`Mesh`] instead (welding bit-identical vertices), for callers that want the mesh itself.
//! [`Measures`] accumulates what every sink's caller reports: triangle count, enclosed volume,
//! area and bounds of the triangles exactly as they are written. `mesh::output` chooses among
//! them by the output's extension.

use crate::error::{Error, Result};
use crate::geom::Aabb;
use crate::geom::Mesh;
use crate::io::stl::StlFormat;
use crate::io::weld::ExactIndex;
use rayon::prelude::*;
use std::io::Write;
use std::path::{Path, PathBuf};

/// A triangle as written: three corners in single precision, wound outward.
pub type Triangle = [[f32; 3]; 3];

/// Receives a mesh as batches of triangles, in order.
pub trait MeshSink {
    /// Called once before any triangle, with the total count when it is known in advance.
    fn begin(&mut self, triangles: Option<u64>) -> Result<()>;
    /// Called with each batch of triangles, in order.
    fn triangles(&mut self, batch: &[Triangle]) -> Result<()>;
    /// Called once after the last triangle.
    fn finish(&mut self) -> Result<()>;
}

/// Running measures of the triangles written so far.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measures {
    /// Triangles written.
    pub triangles: u64,
    /// Signed enclosed volume by the divergence theorem, mm³ (exact only for a closed mesh).
    pub volume: f64,
    /// Surface area, mm².
    pub area: f64,
    /// Bounding box of the corners written, mm.
    pub bounds: Aabb,
}

impl Default for Measures {
    fn default() -> Self {
        Measures {
            triangles: 0,
            volume: 0.0,
            area: 0.0,
            bounds: Aabb {
                min: [f64::INFINITY; 3],
                max: [f64::NEG_INFINITY; 3],
            },
        }
    }
}

impl Measures {
    /// The measures of `batch`, computed in parallel and summed in a fixed order (the same
    /// result whatever the thread count).
    pub fn of(batch: &[Triangle]) -> Measures {
        let parts: Vec<Measures> = batch.par_chunks(4096).map(Measures::of_serial).collect();
        parts.iter().fold(Measures::default(), |a, b| a.merged(b))
    }

    /// The measures of `batch`, on this thread.
    pub fn of_serial(batch: &[Triangle]) -> Measures {
        let mut m = Measures::default();
        for t in batch {
            m.add(t);
        }
        m
    }

    fn add(&mut self, t: &Triangle) {
        use crate::geom::{cross, norm, signed_volume, sub};
        let p = t.map(|v| v.map(|x| x as f64));
        self.triangles += 1;
        self.volume += signed_volume(p[0], p[1], p[2]);
        self.area += 0.5 * norm(cross(sub(p[1], p[0]), sub(p[2], p[0])));
        for v in p {
            for (a, x) in v.into_iter().enumerate() {
                self.bounds.min[a] = self.bounds.min[a].min(x);
                self.bounds.max[a] = self.bounds.max[a].max(x);
            }
        }
    }

    /// The measures of both sets of triangles together.
    pub fn merged(&self, o: &Measures) -> Measures {
        Measures {
            triangles: self.triangles + o.triangles,
            volume: self.volume + o.volume,
            area: self.area + o.area,
            bounds: Aabb {
                min: [0, 1, 2].map(|a| self.bounds.min[a].min(o.bounds.min[a])),
                max: [0, 1, 2].map(|a| self.bounds.max[a].max(o.bounds.max[a])),
            },
        }
    }
}

/// Streams STL into a temporary file beside `path`; [`StlSink::commit`] renames it into place.
///
/// Binary STL has fixed-size records, so each batch is serialized and written at its offset in
/// pieces by several threads at once (positional writes): the copy into the page cache, as
/// costly as the serialization on a large part, overlaps it instead of waiting for it. (Measured
/// on a 16 M-triangle part, 2 cores: faster than one buffered stream, and than a writer thread
/// fed the serialized batches.)
pub struct StlSink {
    path: PathBuf,
    format: StlFormat,
    tmp: Option<tempfile::NamedTempFile>,
    file: std::fs::File,
    /// ASCII only: the buffered stream.
    out: Option<std::io::BufWriter<std::fs::File>>,
    written: u64,
    announced: Option<u64>,
    buf: Vec<u8>,
}

/// Binary STL: the header's length and each record's.
const STL_HEADER: u64 = 84;
const STL_RECORD: usize = 50;
/// Records serialized and written per piece.
const RECORDS_PER_WRITE: usize = 1 << 16;

impl StlSink {
    /// Opens the temporary file (the destination folder must be writable).
    pub fn create(path: &Path, format: StlFormat) -> Result<StlSink> {
        let tmp = crate::io::atomic::temp_beside(path)?;
        let file = tmp.reopen().map_err(|e| Error::io(path, e))?;
        let out = match format {
            StlFormat::Ascii => Some(std::io::BufWriter::with_capacity(
                1 << 22,
                file.try_clone().map_err(|e| Error::io(path, e))?,
            )),
            StlFormat::Binary => None,
        };
        Ok(StlSink {
            path: path.to_path_buf(),
            format,
            tmp: Some(tmp),
            file,
            out,
            written: 0,
            announced: None,
            buf: Vec::new(),
        })
    }

    fn io(&self, e: std::io::Error) -> Error {
        Error::io(&self.path, e)
    }

    fn writer(&mut self) -> &mut std::io::BufWriter<std::fs::File> {
        self.out.as_mut().expect("ASCII STL sink used after commit")
    }

    /// Moves the finished file into place.
    pub fn commit(mut self) -> Result<()> {
        if let Some(mut w) = self.out.take() {
            w.flush().map_err(|e| Error::io(&self.path, e))?;
        }
        let tmp = self.tmp.take().expect("STL sink committed twice");
        tmp.persist(&self.path)
            .map_err(|e| Error::io(&self.path, e.error))?;
        Ok(())
    }

    /// Writes `count` as the binary file's triangle count.
    fn write_count(&self, count: u64) -> Result<()> {
        use std::os::unix::fs::FileExt;
        let count = u32::try_from(count).map_err(|_| {
            Error::invalid("more than 2^32 triangles cannot be written as binary STL")
        })?;
        self.file
            .write_all_at(&count.to_le_bytes(), 80)
            .map_err(|e| self.io(e))
    }
}

fn unit_normal(t: &Triangle) -> [f32; 3] {
    use crate::geom::{cross, norm, sub};
    let p = t.map(|v| v.map(|x| x as f64));
    let n = cross(sub(p[1], p[0]), sub(p[2], p[0]));
    let l = norm(n);
    if l > 0.0 {
        n.map(|x| (x / l) as f32)
    } else {
        [0.0; 3]
    }
}

/// The binary STL record of `t`.
fn stl_record(t: &Triangle, rec: &mut [u8]) {
    let n = unit_normal(t);
    let vals = n.iter().chain(t.iter().flatten());
    for (k, v) in vals.enumerate() {
        rec[4 * k..4 * k + 4].copy_from_slice(&v.to_le_bytes());
    }
    rec[48] = 0;
    rec[49] = 0;
}

impl MeshSink for StlSink {
    fn begin(&mut self, triangles: Option<u64>) -> Result<()> {
        use std::os::unix::fs::FileExt;
        self.announced = triangles;
        match self.format {
            StlFormat::Binary => {
                let mut header = [b' '; 80];
                let tag = b"binary STL written by latvox";
                header[..tag.len()].copy_from_slice(tag);
                let r = self.file.write_all_at(&header, 0);
                r.map_err(|e| self.io(e))?;
                self.write_count(triangles.unwrap_or(0))
            }
            StlFormat::Ascii => {
                let r = writeln!(self.writer(), "solid latvox");
                r.map_err(|e| self.io(e))
            }
        }
    }

    fn triangles(&mut self, batch: &[Triangle]) -> Result<()> {
        let first = self.written;
        self.written += batch.len() as u64;
        match self.format {
            StlFormat::Binary => {
                use std::os::unix::fs::FileExt;
                let file = &self.file;
                batch
                    .par_chunks(RECORDS_PER_WRITE)
                    .enumerate()
                    .try_for_each_init(Vec::new, |bytes, (k, chunk)| {
                        bytes.resize(chunk.len() * STL_RECORD, 0);
                        for (rec, t) in bytes.chunks_exact_mut(STL_RECORD).zip(chunk) {
                            stl_record(t, rec);
                        }
                        let record = first + (k * RECORDS_PER_WRITE) as u64;
                        file.write_all_at(bytes, STL_HEADER + STL_RECORD as u64 * record)
                    })
                    .map_err(|e| self.io(e))
            }
            StlFormat::Ascii => {
                let mut buf = std::mem::take(&mut self.buf);
                buf.clear();
                for t in batch {
                    let n = unit_normal(t);
                    let _ = writeln!(buf, "  facet normal {:e} {:e} {:e}", n[0], n[1], n[2]);
                    let _ = writeln!(buf, "    outer loop");
                    for p in t {
                        let _ = writeln!(buf, "      vertex {:e} {:e} {:e}", p[0], p[1], p[2]);
                    }
                    let _ = writeln!(buf, "    endloop");
                    let _ = writeln!(buf, "  endfacet");
                }
                let r = self.writer().write_all(&buf);
                self.buf = buf;
                r.map_err(|e| self.io(e))
            }
        }
    }

    fn finish(&mut self) -> Result<()> {
        match self.format {
            StlFormat::Ascii => {
                let r = writeln!(self.writer(), "endsolid latvox");
                r.map_err(|e| self.io(e))?;
                let r = self.writer().flush();
                r.map_err(|e| self.io(e))
            }
            // The count was not known up front: patch it into the header.
            StlFormat::Binary if self.announced != Some(self.written) => {
                self.write_count(self.written)
            }
            StlFormat::Binary => Ok(()),
        }
    }
}

/// Gathers streamed triangles into an indexed mesh, welding bit-identical corners.
#[derive(Default)]
pub struct MeshCollector {
    /// The mesh gathered so far.
    pub mesh: Mesh,
    weld: ExactIndex,
}

impl MeshSink for MeshCollector {
    fn begin(&mut self, triangles: Option<u64>) -> Result<()> {
        if let Some(n) = triangles {
            // A closed mesh has about half as many vertices as triangles.
            self.mesh.indices.reserve(3 * n as usize);
            self.mesh.positions.reserve(3 * (n as usize / 2 + 2));
            if self.weld.is_empty() {
                self.weld = ExactIndex::with_capacity(n as usize / 2 + 2);
            }
        }
        Ok(())
    }

    fn triangles(&mut self, batch: &[Triangle]) -> Result<()> {
        for t in batch {
            for p in t {
                let (id, new) = self.weld.index(*p);
                if new {
                    self.mesh.positions.extend_from_slice(p);
                }
                self.mesh.indices.push(id);
            }
        }
        Ok(())
    }

    fn finish(&mut self) -> Result<()> {
        Ok(())
    }
}

/// Streams a 3MF package: corners are welded exactly as they arrive (one index per distinct
/// vertex is all that is held in memory), vertex and triangle records go to two temporary files
/// beside `path`, and [`ThreeMfSink::commit`] zips them into the model XML and renames the
/// package into place.
pub struct ThreeMfSink {
    path: PathBuf,
    vertices: std::io::BufWriter<std::fs::File>,
    triangles: std::io::BufWriter<std::fs::File>,
    weld: ExactIndex,
}

impl ThreeMfSink {
    /// Opens the temporary files (the destination folder must be writable).
    pub fn create(path: &Path) -> Result<ThreeMfSink> {
        let scratch = || {
            let dir = path.parent().filter(|d| !d.as_os_str().is_empty());
            tempfile::tempfile_in(dir.unwrap_or(Path::new(".")))
                .map(|f| std::io::BufWriter::with_capacity(1 << 20, f))
                .map_err(|e| Error::io(path, e))
        };
        Ok(ThreeMfSink {
            path: path.to_path_buf(),
            vertices: scratch()?,
            triangles: scratch()?,
            weld: ExactIndex::default(),
        })
    }

    /// Zips the records into the package and moves it into place.
    pub fn commit(self) -> Result<()> {
        use crate::io::threemf;
        use std::io::{Seek, SeekFrom};
        let path = self.path.clone();
        let io = |e: std::io::Error| Error::io(&path, e);
        let zerr = |e: zip::result::ZipError| Error::io(&path, std::io::Error::other(e));
        let rewound = |w: std::io::BufWriter<std::fs::File>| -> std::io::Result<std::fs::File> {
            let mut f = w.into_inner().map_err(|e| e.into_error())?;
            f.seek(SeekFrom::Start(0))?;
            Ok(f)
        };
        let (mut v, mut t) = (
            rewound(self.vertices).map_err(io)?,
            rewound(self.triangles).map_err(io)?,
        );
        let body = v.metadata().map_err(io)?.len() + t.metadata().map_err(io)?.len();
        let tmp = crate::io::atomic::temp_beside(&path)?;
        let file = std::io::BufWriter::with_capacity(1 << 20, tmp.reopen().map_err(io)?);
        let mut zip = zip::ZipWriter::new(file);
        let opts = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Deflated);
        zip.start_file("[Content_Types].xml", opts).map_err(zerr)?;
        zip.write_all(threemf::CONTENT_TYPES).map_err(io)?;
        zip.start_file("_rels/.rels", opts).map_err(zerr)?;
        zip.write_all(threemf::rels().as_bytes()).map_err(io)?;
        // Zip64 once the model could pass 4 GiB.
        let large = body + 4096 >= u32::MAX as u64;
        zip.start_file("3D/3dmodel.model", opts.large_file(large))
            .map_err(zerr)?;
        zip.write_all(threemf::model_head().as_bytes())
            .map_err(io)?;
        std::io::copy(&mut v, &mut zip).map_err(io)?;
        zip.write_all(threemf::MODEL_MIDDLE.as_bytes())
            .map_err(io)?;
        std::io::copy(&mut t, &mut zip).map_err(io)?;
        zip.write_all(threemf::MODEL_TAIL.as_bytes()).map_err(io)?;
        let mut file = zip.finish().map_err(zerr)?;
        file.flush().map_err(io)?;
        drop(file);
        tmp.persist(&path).map_err(|e| Error::io(&path, e.error))?;
        Ok(())
    }
}

impl MeshSink for ThreeMfSink {
    fn begin(&mut self, _triangles: Option<u64>) -> Result<()> {
        Ok(())
    }

    fn triangles(&mut self, batch: &[Triangle]) -> Result<()> {
        use crate::io::threemf::{triangle_line, vertex_line};
        for t in batch {
            let mut ids = [0u32; 3];
            for (id, p) in ids.iter_mut().zip(t) {
                let new;
                (*id, new) = self.weld.index(*p);
                if new {
                    vertex_line(&mut self.vertices, p).map_err(|e| Error::io(&self.path, e))?;
                }
            }
            if ids[0] == ids[1] || ids[1] == ids[2] || ids[0] == ids[2] {
                return Err(Error::invalid(
                    "3MF forbids degenerate triangles and the mesh has one (write STL instead)",
                ));
            }
            triangle_line(&mut self.triangles, &ids).map_err(|e| Error::io(&self.path, e))?;
        }
        Ok(())
    }

    fn finish(&mut self) -> Result<()> {
        Ok(())
    }
}
