//! Output files: the one place an output's format is chosen, by its extension. Mesh formats
//! (STL, 3MF, OBJ, OFF, PLY) are written by `io`'s writers and sinks; `.vdb` holds the part's
//! narrow-band level set (the solid the mesh as written bounds, voids kept: `Grid::of_solid`),
//! a grid named `sdf` that OpenVDB's tools (`vdb_print`, `vdb_view`) and its Python module read.

use crate::error::{Error, Result};
use crate::geom::Mesh;
use crate::io::sink::{MeshCollector, MeshSink, StlSink, ThreeMfSink, Triangle};
use crate::io::{Format, StlFormat};
use std::cell::RefCell;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Half-width of the level set written to `.vdb`, in voxels (OpenVDB's default band).
const VDB_HALF_WIDTH: f64 = 3.0;

/// How this thread's outputs are written, when a caller runs a command under [`capturing`] or
/// [`stoppable`].
struct Session {
    /// Mesh outputs kept in memory instead of written (`None`: written).
    kept: Option<Vec<(PathBuf, Mesh)>>,
    /// Set by the caller to stop the work.
    stop: Arc<AtomicBool>,
}

thread_local! {
    static SESSION: RefCell<Option<Session>> = const { RefCell::new(None) };
}

/// Runs `f` with every mesh output this thread writes (through [`MeshFile::sink`] or
/// [`MeshFile::save`], whatever its format; `.vdb` level sets are still written) kept in memory
/// instead of written: the caller gets the meshes, by the paths they would have gone to, and no
/// file appears. A caller that wants the mesh itself (the Python package) runs a command this way.
/// Stops as [`stoppable`] does.
pub fn capturing<R>(stop: Arc<AtomicBool>, f: impl FnOnce() -> R) -> (R, Vec<(PathBuf, Mesh)>) {
    let (r, kept) = in_session(Some(Vec::new()), stop, f);
    (r, kept.unwrap_or_default())
}

/// Runs `f` with its outputs written as usual, until `stop` is set: then the next batch of
/// triangles a mesh output takes, or its commit, fails ("stopped") and the output is not written.
pub fn stoppable<R>(stop: Arc<AtomicBool>, f: impl FnOnce() -> R) -> R {
    in_session(None, stop, f).0
}

fn in_session<R>(
    kept: Option<Vec<(PathBuf, Mesh)>>,
    stop: Arc<AtomicBool>,
    f: impl FnOnce() -> R,
) -> (R, Option<Vec<(PathBuf, Mesh)>>) {
    let outer = SESSION.replace(Some(Session { kept, stop }));
    let r = f();
    let ours = SESSION.replace(outer).and_then(|s| s.kept);
    (r, ours)
}

/// This thread's stop flag, and whether it keeps meshes, when it runs in a session.
fn session() -> Option<(Arc<AtomicBool>, bool)> {
    SESSION.with_borrow(|s| s.as_ref().map(|s| (s.stop.clone(), s.kept.is_some())))
}

/// "stopped", once `stop` is set.
fn check_stop(stop: Option<&Arc<AtomicBool>>) -> Result<()> {
    match stop {
        Some(s) if s.load(Ordering::Relaxed) => Err(Error::invalid("stopped")),
        _ => Ok(()),
    }
}

/// Keeps `mesh` for `path` when this thread keeps meshes; gives it back otherwise.
fn keep(path: &Path, mesh: Mesh) -> Option<Mesh> {
    SESSION.with_borrow_mut(|s| match s.as_mut().and_then(|s| s.kept.as_mut()) {
        Some(kept) => {
            kept.push((path.to_path_buf(), mesh));
            None
        }
        None => Some(mesh),
    })
}

/// What an output file holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Written {
    /// A triangle mesh in this format.
    Mesh(Format),
    /// The part's level set, as an OpenVDB `.vdb`.
    Vdb,
}

/// An output file: its path and what its extension names. [`MeshFile::new`] is the one place an
/// output's format is chosen.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshFile {
    /// Where the file goes.
    pub path: PathBuf,
    /// What the extension names.
    pub written: Written,
    /// ASCII STL or ASCII PLY (binary otherwise; OBJ and OFF are text, 3MF a zip package).
    pub ascii: bool,
    /// The voxel size of a `.vdb`'s level set, mm (by default the mesh's mean edge length).
    pub voxel: Option<f64>,
}

impl MeshFile {
    /// `path` in the format its extension names (case-insensitive: `.stl`, `.obj`, `.off`,
    /// `.ply`, `.3mf`, `.vdb`). Any other extension is refused, naming the path and those it
    /// could be.
    pub fn new(path: &Path, ascii: bool) -> Result<MeshFile> {
        let vdb = path
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| e.eq_ignore_ascii_case("vdb"));
        let written = match Format::from_path(path) {
            Some(f) => Written::Mesh(f),
            None if vdb => Written::Vdb,
            None => {
                return Err(Error::invalid(format!(
                    "{}: unknown output extension (use .stl, .3mf, .obj, .off, .ply or .vdb)",
                    path.display()
                )))
            }
        };
        Ok(MeshFile {
            path: path.to_path_buf(),
            written,
            ascii,
            voxel: None,
        })
    }

    /// As [`MeshFile::new`], refusing `.vdb` (for outputs that are read back as meshes).
    pub fn mesh(path: &Path, ascii: bool) -> Result<MeshFile> {
        let f = Self::new(path, ascii)?;
        match f.written {
            Written::Mesh(_) => Ok(f),
            Written::Vdb => Err(Error::invalid(format!(
                "{}: this command writes a mesh (use .stl, .3mf, .obj, .off or .ply)",
                path.display()
            ))),
        }
    }

    /// The file with a `.vdb`'s voxel size set (mm); mesh formats ignore it.
    pub fn with_voxel(mut self, voxel: f64) -> MeshFile {
        self.voxel = Some(voxel).filter(|v| v.is_finite() && *v > 0.0);
        self
    }

    /// A sink into the file; the file appears, whole, on [`FileSink::commit`].
    pub fn sink(&self) -> Result<FileSink> {
        let stl = if self.ascii {
            StlFormat::Ascii
        } else {
            StlFormat::Binary
        };
        let (stop, keeps) = match session() {
            Some((stop, keeps)) => (Some(stop), keeps),
            None => (None, false),
        };
        let indexed = || Target::Indexed {
            file: self.clone(),
            collector: MeshCollector::default(),
        };
        let streamed = matches!(self.written, Written::Mesh(Format::Stl | Format::ThreeMf));
        let target = match self.written {
            Written::Mesh(_) if keeps => indexed(),
            // Work that may be stopped opens its temporary only when the first triangles come,
            // after checking the flag: a stopped run leaves nothing behind while its worker
            // finishes the stage it was in.
            _ if streamed && stop.is_some() => {
                crate::io::atomic::check_writable(&self.path)?;
                Target::Pending {
                    file: self.clone(),
                    stl,
                    begun: None,
                }
            }
            Written::Mesh(Format::Stl) => Target::Stl(StlSink::create(&self.path, stl)?),
            Written::Mesh(Format::ThreeMf) => Target::ThreeMf(ThreeMfSink::create(&self.path)?),
            Written::Mesh(Format::Obj | Format::Off | Format::Ply) | Written::Vdb => indexed(),
        };
        Ok(FileSink { target, stop })
    }

    /// Writes `mesh` to the file atomically, its vertices indexed as they are (or keeps a copy,
    /// where this thread is [`capturing`]).
    pub fn save(&self, mesh: &Mesh) -> Result<()> {
        match (self.written, session()) {
            (_, Some((stop, _))) if stop.load(Ordering::Relaxed) => check_stop(Some(&stop)),
            (Written::Mesh(_), Some((_, true))) => {
                keep(&self.path, mesh.clone());
                Ok(())
            }
            _ => self.write(mesh),
        }
    }

    /// Writes `mesh`, or keeps it where this thread is [`capturing`].
    fn save_owned(&self, mesh: Mesh) -> Result<()> {
        match self.written {
            Written::Mesh(_) => match keep(&self.path, mesh) {
                Some(mesh) => self.write(&mesh),
                None => Ok(()),
            },
            Written::Vdb => self.write(&mesh),
        }
    }

    fn write(&self, mesh: &Mesh) -> Result<()> {
        match self.written {
            Written::Mesh(format) => crate::io::atomic::write_atomic(&self.path, |w| {
                crate::io::write(mesh, format, self.ascii, w)
            }),
            Written::Vdb => {
                if mesh.positions.iter().any(|x| !x.is_finite()) {
                    return Err(Error::invalid(format!(
                        "{}: a vertex is not finite (NaN or infinite): no level set can be made of the mesh",
                        self.path.display()
                    )));
                }
                let voxel = self.voxel.or_else(|| mean_edge(mesh)).ok_or_else(|| {
                    Error::invalid(format!(
                        "{}: the part has no triangles to make a level set of",
                        self.path.display()
                    ))
                })?;
                let grid = crate::grid::Grid::of_solid(mesh, voxel, VDB_HALF_WIDTH)?;
                let tmp = crate::io::atomic::temp_beside(&self.path)?;
                crate::grid::write_vdb_grids(tmp.path(), &[("sdf", &grid)])?;
                tmp.persist(&self.path)
                    .map_err(|e| Error::io(&self.path, e.error))?;
                Ok(())
            }
        }
    }
}

/// The mean length of a mesh's edges (each triangle's three), or `None` for no triangles.
fn mean_edge(mesh: &Mesh) -> Option<f64> {
    let p = |i: u32| {
        let i = i as usize * 3;
        [0, 1, 2].map(|a| mesh.positions[i + a] as f64)
    };
    let (mut sum, mut n) = (0.0, 0usize);
    for t in mesh.indices.chunks_exact(3) {
        for k in 0..3 {
            let (a, b) = (p(t[k]), p(t[(k + 1) % 3]));
            sum += crate::geom::norm(crate::geom::sub(a, b));
            n += 1;
        }
    }
    (n > 0 && sum > 0.0).then(|| sum / n as f64)
}

/// A sink into a [`MeshFile`]: STL and 3MF stream to a temporary file as the triangles come;
/// OBJ, OFF, PLY (which list each vertex once) and `.vdb` gather the triangles (welding
/// bit-identical corners, as [`MeshCollector`] does) and write them at [`FileSink::commit`].
/// Under [`capturing`], every mesh is gathered and kept; under [`capturing`] or [`stoppable`],
/// it fails once the caller stops the work.
pub struct FileSink {
    target: Target,
    stop: Option<Arc<AtomicBool>>,
}

enum Target {
    /// Binary or ASCII STL, streamed.
    Stl(StlSink),
    /// 3MF, streamed.
    ThreeMf(ThreeMfSink),
    /// STL or 3MF not yet opened (work that may be stopped): opened at the first triangles.
    Pending {
        /// The file to stream to.
        file: MeshFile,
        /// STL's flavour.
        stl: StlFormat,
        /// The count announced by `begin`, if it was called.
        begun: Option<Option<u64>>,
    },
    /// OBJ, OFF, PLY or `.vdb` (or any mesh kept): gathered, written (or kept) at commit.
    Indexed {
        /// The file to write.
        file: MeshFile,
        /// The triangles gathered, welded.
        collector: MeshCollector,
    },
}

impl FileSink {
    /// Moves the finished file into place (or keeps the mesh).
    pub fn commit(mut self) -> Result<()> {
        check_stop(self.stop.as_ref())?;
        self.open()?;
        match self.target {
            Target::Stl(s) => s.commit(),
            Target::ThreeMf(s) => s.commit(),
            Target::Indexed { file, collector } => file.save_owned(collector.mesh),
            Target::Pending { .. } => unreachable!("opened above"),
        }
    }

    /// Opens a pending STL or 3MF, announcing the count `begin` was given.
    fn open(&mut self) -> Result<()> {
        if let Target::Pending { file, stl, begun } = &self.target {
            let begun = *begun;
            self.target = match file.written {
                Written::Mesh(Format::ThreeMf) => Target::ThreeMf(ThreeMfSink::create(&file.path)?),
                _ => Target::Stl(StlSink::create(&file.path, *stl)?),
            };
            if let Some(n) = begun {
                self.inner().begin(n)?;
            }
        }
        Ok(())
    }

    /// Sets the voxel size of a `.vdb`'s level set (the part's own voxels), mm.
    pub fn set_voxel(&mut self, voxel: f64) {
        if let Target::Indexed { file, .. } = &mut self.target {
            *file = file.clone().with_voxel(voxel);
        }
    }

    fn inner(&mut self) -> &mut dyn MeshSink {
        match &mut self.target {
            Target::Stl(s) => s,
            Target::ThreeMf(s) => s,
            Target::Indexed { collector, .. } => collector,
            Target::Pending { .. } => unreachable!("a pending sink is opened before use"),
        }
    }
}

impl MeshSink for FileSink {
    fn begin(&mut self, triangles: Option<u64>) -> Result<()> {
        if let Target::Pending { begun, .. } = &mut self.target {
            *begun = Some(triangles);
            return Ok(());
        }
        self.inner().begin(triangles)
    }

    fn triangles(&mut self, batch: &[Triangle]) -> Result<()> {
        check_stop(self.stop.as_ref())?;
        self.open()?;
        self.inner().triangles(batch)
    }

    fn finish(&mut self) -> Result<()> {
        check_stop(self.stop.as_ref())?;
        self.open()?;
        self.inner().finish()
    }
}
