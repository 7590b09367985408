//! Output files: the one place an output's format is chosen, by its extension. Mesh formats
//! (STL, 3MF, OBJ, OFF, PLY) are written by `io`'s writers and sinks; `.vdb` holds the part's
//! narrow-band level set (the solid the mesh as written bounds, voids kept: `Grid::of_solid`),
//! a grid named `sdf` that OpenVDB's tools (`vdb_print`, `vdb_view`) and its Python module read.

use crate::error::{Error, Result};
use crate::geom::Mesh;
use crate::io::sink::{MeshCollector, MeshSink, StlSink, ThreeMfSink, Triangle};
use crate::io::{Format, StlFormat};
use std::path::{Path, PathBuf};

/// Half-width of the level set written to `.vdb`, in voxels (OpenVDB's default band).
const VDB_HALF_WIDTH: f64 = 3.0;

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
        Ok(match self.written {
            Written::Mesh(Format::Stl) => FileSink::Stl(StlSink::create(&self.path, stl)?),
            Written::Mesh(Format::ThreeMf) => FileSink::ThreeMf(ThreeMfSink::create(&self.path)?),
            Written::Mesh(Format::Obj | Format::Off | Format::Ply) | Written::Vdb => {
                FileSink::Indexed {
                    file: self.clone(),
                    collector: MeshCollector::default(),
                }
            }
        })
    }

    /// Writes `mesh` to the file atomically, its vertices indexed as they are.
    pub fn save(&self, mesh: &Mesh) -> Result<()> {
        match self.written {
            Written::Mesh(format) => crate::io::atomic::write_atomic(&self.path, |w| {
                crate::io::write(mesh, format, self.ascii, w)
            }),
            Written::Vdb => {
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
pub enum FileSink {
    /// Binary or ASCII STL, streamed.
    Stl(StlSink),
    /// 3MF, streamed.
    ThreeMf(ThreeMfSink),
    /// OBJ, OFF, PLY or `.vdb`: gathered, written at commit.
    Indexed {
        /// The file to write.
        file: MeshFile,
        /// The triangles gathered, welded.
        collector: MeshCollector,
    },
}

impl FileSink {
    /// Moves the finished file into place.
    pub fn commit(self) -> Result<()> {
        match self {
            FileSink::Stl(s) => s.commit(),
            FileSink::ThreeMf(s) => s.commit(),
            FileSink::Indexed { file, collector } => file.save(&collector.mesh),
        }
    }

    /// Sets the voxel size of a `.vdb`'s level set (the part's own voxels), mm.
    pub fn set_voxel(&mut self, voxel: f64) {
        if let FileSink::Indexed { file, .. } = self {
            *file = file.clone().with_voxel(voxel);
        }
    }

    fn inner(&mut self) -> &mut dyn MeshSink {
        match self {
            FileSink::Stl(s) => s,
            FileSink::ThreeMf(s) => s,
            FileSink::Indexed { collector, .. } => collector,
        }
    }
}

impl MeshSink for FileSink {
    fn begin(&mut self, triangles: Option<u64>) -> Result<()> {
        self.inner().begin(triangles)
    }

    fn triangles(&mut self, batch: &[Triangle]) -> Result<()> {
        self.inner().triangles(batch)
    }

    fn finish(&mut self) -> Result<()> {
        self.inner().finish()
    }
}
