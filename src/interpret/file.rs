//! A density-field file to a part, as `latvox interpret` does: read the field, settle the options that
//! depend on it, run the job, and write the part and every other file asked for (CAD curves,
//! boundary points, the cleaned grid, stage images), each atomically. The report is the
//! caller's to write.

use super::job::{self, InterpretJob, InterpretResult};
use super::{images, CleanOptions, Density};
use crate::error::{Error, Result};
use crate::grid::Smoothing;
use crate::io::atomic::{check_writable, write_atomic};
use crate::mesh::output::MeshFile;
use crate::progress::Progress;
use std::path::{Path, PathBuf};

/// What a user asks of the job; `None` takes a default that depends on the field.
#[derive(Debug, Clone, Copy)]
pub struct InterpretOptions {
    /// Element edge length, mm.
    pub element_size: f64,
    /// Threshold density (step 1.1).
    pub cutoff: f64,
    /// Pixels per element edge (default 8 in 2D, 2 in 3D).
    pub refine: Option<usize>,
    /// The printer's minimum feature size, mm.
    pub min_feature: f64,
    /// Density filter radius, in elements.
    pub filter_radius: f64,
    /// Bound on the cleanup loop's passes.
    pub max_iterations: usize,
    /// Extrusion of a 2D field, mm (default: one element).
    pub thickness: Option<f64>,
    /// 2D: max deviation of the CAD curves from the boundary, mm (default: half a refined
    /// pixel). 3D: the mesh is simplified within it of the surface (default: not simplified).
    pub tolerance: Option<f64>,
    /// 3D: passes of OpenVDB's level-set smoothing before meshing (0: none).
    pub smooth_iterations: u32,
    /// 3D: the smoothing flow.
    pub smoothing: Smoothing,
    /// How the 3D part is verified.
    pub verify: crate::verify::Verify,
}

/// A 2D field refined by the default 8 pixels per element may have at most this many pixels.
const MAX_DEFAULT_PIXELS: usize = 200_000_000;

/// Smoothing passes allowed at most.
const MAX_SMOOTH: u32 = 100;

impl InterpretOptions {
    /// The job for field `d`: defaults filled in, the options checked against the field.
    pub fn job(&self, d: &Density) -> Result<InterpretJob> {
        if !d.is_3d && self.refine.is_none() && (d.nx * 8) * (d.ny * 8) > MAX_DEFAULT_PIXELS {
            return Err(Error::invalid(
                "field too large for --refine 8; give a smaller --refine",
            ));
        }
        let refine = self.refine.unwrap_or(if d.is_3d { 2 } else { 8 });
        let tolerance = self
            .tolerance
            .unwrap_or(0.5 * self.element_size / refine as f64);
        if !(tolerance > 0.0 && tolerance.is_finite()) {
            return Err(Error::invalid(
                "--tolerance must be a positive length in mm",
            ));
        }
        let mesh_tolerance = if d.is_3d { self.tolerance } else { None };
        if self.max_iterations == 0 {
            return Err(Error::invalid("--max-iterations must be at least 1"));
        }
        if self.smooth_iterations > 0 && !d.is_3d {
            return Err(Error::invalid(
                "--smooth applies to 3D fields (2D outlines are smooth B-splines)",
            ));
        }
        if self.smooth_iterations > MAX_SMOOTH {
            return Err(Error::invalid("--smooth takes at most 100 passes"));
        }
        Ok(InterpretJob {
            clean: CleanOptions {
                cutoff: self.cutoff,
                refine,
                min_feature: self.min_feature,
                filter_radius: self.filter_radius,
                raise: 0.1,
                max_iterations: self.max_iterations,
            },
            thickness: self.thickness.unwrap_or(self.element_size),
            tolerance,
            mesh_tolerance,
            fit_curves: !d.is_3d,
            verify: self.verify,
            smooth_iterations: self.smooth_iterations,
            smoothing: self.smoothing,
        })
    }
}

/// The files the job writes besides its report.
#[derive(Debug, Clone)]
pub struct InterpretFiles {
    /// The part, in the format its extension names.
    pub mesh: PathBuf,
    /// ASCII STL (or ASCII PLY).
    pub ascii: bool,
    /// IGES file of the adaptive B-spline curves (2D).
    pub iges: Option<PathBuf>,
    /// Also write the uniform fits, as `FILE-uniform.igs` next to `iges`.
    pub uniform_too: bool,
    /// DXF file of the adaptive B-spline curves (2D).
    pub dxf: Option<PathBuf>,
    /// Boundary points of the 2D result (CSV: loop, x, y in mm).
    pub boundary: Option<PathBuf>,
    /// The cleaned solid on the refined grid (.npy of 0/1, the input's layout).
    pub cleaned: Option<PathBuf>,
    /// Prefix of the stage images.
    pub images: Option<PathBuf>,
}

impl InterpretFiles {
    /// The uniform fits' IGES file, when asked for.
    pub fn uniform_iges(&self) -> Option<PathBuf> {
        let p = self.iges.as_ref().filter(|_| self.uniform_too)?;
        let stem = p.file_stem().unwrap_or_default().to_string_lossy();
        Some(p.with_file_name(format!("{stem}-uniform.igs")))
    }

    /// Every file a successful run writes, the part first.
    pub fn paths(&self) -> Vec<PathBuf> {
        let mut v = vec![self.mesh.clone()];
        v.extend(self.iges.clone());
        v.extend(self.uniform_iges());
        v.extend(
            [&self.dxf, &self.boundary, &self.cleaned]
                .into_iter()
                .flatten()
                .cloned(),
        );
        if let Some(prefix) = &self.images {
            v.extend(
                images::STAGES
                    .iter()
                    .filter_map(|s| images::stage_path(prefix, s).ok()),
            );
        }
        v
    }
}

/// What [`interpret_file`] made.
pub struct InterpretPart {
    /// The job's results and report.
    pub result: InterpretResult,
    /// The stage images written, in order.
    pub images: Vec<PathBuf>,
}

/// Reads the density field `input` (elements of `opts.element_size` mm), runs the job and writes
/// `files`. Every option and destination is checked before the work starts.
pub fn interpret_file(
    input: &Path,
    opts: &InterpretOptions,
    files: &InterpretFiles,
    progress: &Progress,
) -> Result<InterpretPart> {
    let d = Density::read(input, opts.element_size)?;
    if d.is_3d && (files.iges.is_some() || files.dxf.is_some()) {
        return Err(Error::invalid(
            "--iges/--dxf take 2D fields (boundary curves); a 3D field gives the STL only",
        ));
    }
    let job = opts.job(&d)?;
    let written = [
        &Some(files.mesh.clone()),
        &files.iges,
        &files.dxf,
        &files.cleaned,
    ];
    for f in written.into_iter().flatten() {
        check_writable(f)?;
    }
    let mesh_file = MeshFile::new(&files.mesh, files.ascii)?;
    let r = job::run(&d, &job, progress)?;
    mesh_file.with_voxel(r.cleaned.field.h).save(&r.mesh)?;
    write_curves(&r, files)?;
    if let Some(p) = &files.cleaned {
        write_cleaned(&r, p)?;
    }
    let images = match &files.images {
        Some(prefix) => images::write_stages(&r.cleaned, prefix)?,
        None => Vec::new(),
    };
    Ok(InterpretPart { result: r, images })
}

/// Writes the CAD curves (IGES, DXF) and the boundary points the curves fit (CSV).
fn write_curves(r: &InterpretResult, files: &InterpretFiles) -> Result<()> {
    if let Some(p) = &files.iges {
        crate::cad::iges::write_file(p, &r.adaptive)?;
    }
    if let Some(p) = files.uniform_iges() {
        crate::cad::iges::write_file(&p, &r.uniform)?;
    }
    if let Some(p) = &files.dxf {
        write_atomic(p, |w| crate::cad::dxf::write(w, &r.adaptive))?;
    }
    if let Some(p) = &files.boundary {
        write_atomic(p, |w| {
            writeln!(w, "loop,x,y")?;
            for (k, l) in r.loops.iter().enumerate() {
                for q in l {
                    writeln!(w, "{k},{:.9},{:.9}", q[0], q[1])?;
                }
            }
            Ok(())
        })?;
    }
    Ok(())
}

/// Writes the cleaned solid on the refined grid as .npy of 0/1, in the input's layout.
fn write_cleaned(r: &InterpretResult, path: &Path) -> Result<()> {
    let f = &r.cleaned.field;
    let solid = Density {
        nx: f.n[0],
        ny: f.n[1],
        nz: f.n[2],
        is_3d: r.report.is_3d,
        data: r
            .cleaned
            .mask
            .iter()
            .map(|&m| if m { 1.0 } else { 0.0 })
            .collect(),
        element_size: f.h,
    };
    let (shape, data) = solid.to_array();
    write_atomic(path, |w| crate::io::npy::write(w, &shape, &data))
}
