//! `latvox interpret`: a density field to a printable STL and parametric CAD (feature-preserving
//! cleanup and adaptive B-spline fitting, after Liu et al. 2018).

use super::command::{self, parsed, Command};
use super::out::outln;
use super::{cgal_findings, write_json};
use clap::Args;
use latvox::grid::Smoothing;
use latvox::interpret::job;
use latvox::interpret::{interpret_file, InterpretFiles, InterpretOptions, InterpretPart};
use latvox::progress::Progress;
use latvox::verify::Verify;
use latvox::Result;
use std::path::PathBuf;

pub(crate) const EXAMPLES: &str = "\
Examples:
  # Liu et al. 2018's cantilever: 30 × 10 elements of 4 mm, 2 mm printer limit, 4 mm thick plate
  latvox interpret cantilever.npy --element-size 4 --cutoff 0.5 --refine 8 --min-feature 2 \\
      --thickness 4 -o part.stl --iges part.igs --dxf part.dxf --report r.json --images stages

  # A 3D field (shape ny, nx, nz) straight to a closed STL through OpenVDB
  latvox interpret bracket3d.npy --element-size 1 --refine 2 --min-feature 1.5 -o bracket.stl

  # The same, smoothed by two passes of OpenVDB's Gaussian level-set filter
  latvox interpret bracket3d.npy --element-size 1 --refine 2 --smooth 2 -o bracket-smooth.stl

  # A 3D field's mesh simplified within 0.1 mm of the surface: a fraction of the triangles
  latvox interpret bracket3d.npy --element-size 1 --refine 2 --tolerance 0.1 -o bracket-small.stl

Input: .npy (float, int or bool; C or Fortran order), .csv (2D, one row per line) or text with a
dimension header line `ny nx [nz]` then the values. 2D arrays are (ny, nx) with row 0 at the
top, as the 88-line code's xPhys; 3D arrays (ny, nx, nz), as top3d's. Densities in [0, 1].

The pipeline is the feature-preserving cleanup and adaptive B-spline fitting of Liu S. et al.,
\"A realization method for transforming a topology optimization design into additive
manufacturing structures\", Engineering 4(2), 2018: threshold at --cutoff and refine every
element into --refine pixels per edge; skeleton with spur pruning, inscribed radius = local
feature size (3D: distance transforms); thin features (radius < min-feature/2), islands and
point contacts are raised by 0.1, density-filtered (radius --filter-radius elements) and
re-thresholded at the level that keeps the thresholded volume, until none is left (at most
--max-iterations passes). 2D results are extruded by --thickness; 3D results are meshed by
OpenVDB (optionally smoothed with its level-set filter, --smooth), at the level that keeps the
thresholded volume. Every mesh is verified (closed, manifold, outward, no self-intersection). The CAD curves (2D) are closed cubic
B-splines within --tolerance of the boundary, uniform and adaptive; the IGES and DXF files hold
the adaptive ones.

Exit code 0: clean and valid; 1: defects remain after the last pass or a mesh check failed;
2: bad input or arguments.";

/// `latvox interpret` (formerly `latvox topo`).
pub(crate) const COMMAND: Command = Command {
    aliases: &["topo"],
    job: Some(command::job::<InterpretArgs>),
    ..Command::new(
        "interpret",
        "Density field to printable STL and parametric CAD (IGES, DXF): feature-preserving cleanup and adaptive B-spline fitting (Liu et al., Engineering 2018)",
        EXAMPLES,
        <InterpretArgs as clap::Args>::augment_args,
        |m, quiet| run(&parsed(m)?, quiet),
    )
};

impl latvox::batch::Task for InterpretArgs {
    fn outputs(&self) -> Vec<PathBuf> {
        self.files().paths()
    }

    fn run(&self) -> Result<latvox::batch::TaskReport> {
        let r = execute(self, &Progress::hidden())?.result.report;
        latvox::batch::TaskReport::new(&r, &r.verdict(), r.warnings())
    }
}

#[derive(Clone, Copy, clap::ValueEnum)]
pub enum SmoothArg {
    Gaussian,
    MeanCurvature,
    Laplacian,
    Mean,
}

#[derive(Args)]
pub struct InterpretArgs {
    /// Density field: .npy, .csv or text with a dimension header.
    pub input: PathBuf,
    /// Element edge length, mm.
    #[arg(long, default_value_t = 1.0, value_name = "MM")]
    pub element_size: f64,
    /// ρcutoff: threshold density of step 1.1.
    #[arg(long, default_value_t = 0.5)]
    pub cutoff: f64,
    /// nc: pixels per element edge (default 8 in 2D, 2 in 3D).
    #[arg(long, value_name = "NC")]
    pub refine: Option<usize>,
    /// l_limit: the printer's minimum feature size, mm.
    #[arg(long, default_value_t = 2.0, value_name = "MM")]
    pub min_feature: f64,
    /// Density filter radius, in elements.
    #[arg(long, default_value_t = 1.0)]
    pub filter_radius: f64,
    /// Bound on the repair loop's passes.
    #[arg(long, default_value_t = 30)]
    pub max_iterations: usize,
    /// Extrusion of a 2D field, mm (default: one element).
    #[arg(long, value_name = "MM")]
    pub thickness: Option<f64>,
    /// 2D: the largest deviation of the CAD curves from the boundary, mm (default: half a
    /// refined pixel). 3D: simplify the mesh within this distance of the density's iso-surface
    /// (of the smoothed surface with --smooth): large triangles where it is flat, the volume
    /// kept, the deviation measured and reported (default: the uniform mesh, two triangles per
    /// voxel the surface crosses).
    #[arg(long, value_name = "MM")]
    pub tolerance: Option<f64>,
    /// Output, in the format its extension names: a mesh (.stl, .obj, .off, .ply, .3mf) or the
    /// part's level set (.vdb, OpenVDB, a grid named sdf).
    #[arg(long, short = 'o', value_name = "FILE.stl", default_value = "part.stl")]
    pub output: PathBuf,
    /// Write ASCII STL (or ASCII PLY).
    #[arg(long)]
    pub ascii: bool,
    /// IGES file of the adaptive B-spline curves (2D).
    #[arg(long, value_name = "FILE.igs")]
    pub iges: Option<PathBuf>,
    /// DXF file of the adaptive B-spline curves (2D).
    #[arg(long, value_name = "FILE.dxf")]
    pub dxf: Option<PathBuf>,
    /// Also write the uniform fits, as FILE-uniform.igs next to --iges.
    #[arg(long)]
    pub uniform_too: bool,
    /// JSON report.
    #[arg(long, value_name = "FILE.json")]
    pub report: Option<PathBuf>,
    /// PNG images of the stages: PREFIX-raw.png, -thresholded, -skeleton, -final.
    #[arg(long, value_name = "PREFIX")]
    pub images: Option<PathBuf>,
    /// Boundary points of the 2D result (CSV: loop, x, y in mm), the points the curves fit.
    #[arg(long, value_name = "FILE.csv")]
    pub boundary: Option<PathBuf>,
    /// Cleaned solid on the refined grid (.npy of 0/1, the input's layout).
    #[arg(long, value_name = "FILE.npy")]
    pub cleaned: Option<PathBuf>,
    /// 3D: passes of OpenVDB's level-set smoothing before meshing (0: none).
    #[arg(long, default_value_t = 0, value_name = "N")]
    pub smooth: u32,
    /// 3D: the smoothing flow.
    #[arg(long, value_enum, default_value = "gaussian")]
    pub smooth_filter: SmoothArg,
    /// How the 3D part is verified: full, fast (no self-intersection search), none, or cgal
    /// (CGAL's own checks)
    #[arg(long, value_enum, default_value = "full", value_name = "HOW")]
    pub verify: Verify,
    /// The same as --verify fast.
    #[arg(long, hide = true)]
    pub no_self_intersection_check: bool,
}

impl InterpretArgs {
    /// The job's options.
    pub(crate) fn options(&self) -> InterpretOptions {
        InterpretOptions {
            element_size: self.element_size,
            cutoff: self.cutoff,
            refine: self.refine,
            min_feature: self.min_feature,
            filter_radius: self.filter_radius,
            max_iterations: self.max_iterations,
            thickness: self.thickness,
            tolerance: self.tolerance,
            smooth_iterations: self.smooth,
            smoothing: match self.smooth_filter {
                SmoothArg::Gaussian => Smoothing::Gaussian,
                SmoothArg::MeanCurvature => Smoothing::MeanCurvature,
                SmoothArg::Laplacian => Smoothing::Laplacian,
                SmoothArg::Mean => Smoothing::Mean,
            },
            verify: if self.no_self_intersection_check && self.verify == Verify::Full {
                Verify::Fast
            } else {
                self.verify
            },
        }
    }

    /// The files the job writes besides its report.
    pub(crate) fn files(&self) -> InterpretFiles {
        InterpretFiles {
            mesh: self.output.clone(),
            ascii: self.ascii,
            iges: self.iges.clone(),
            uniform_too: self.uniform_too,
            dxf: self.dxf.clone(),
            boundary: self.boundary.clone(),
            cleaned: self.cleaned.clone(),
            images: self.images.clone(),
        }
    }
}

/// Runs the job and writes its files (not the report), for `run` to print and `latvox batch` to
/// record.
pub fn execute(a: &InterpretArgs, progress: &Progress) -> Result<InterpretPart> {
    interpret_file(&a.input, &a.options(), &a.files(), progress)
}

pub fn run(a: &InterpretArgs, quiet: bool) -> Result<i32> {
    // Fail on an unwritable destination before the work, not after.
    if let Some(p) = &a.report {
        latvox::io::atomic::check_writable(p)?;
    }
    let part = execute(a, &Progress::new(quiet))?;
    let r = &part.result.report;
    if let Some(p) = &a.report {
        write_json(p, r)?;
    }
    summary(r, a, &part.images);
    for w in r.warnings() {
        super::out::warning(&w);
    }
    // Features the printer cannot make that remain after the last pass are defects too.
    Ok(r.verdict().exit_code())
}

fn summary(r: &job::InterpretReport, a: &InterpretArgs, images: &[PathBuf]) {
    let dims = if r.is_3d {
        format!("{}×{}×{}", r.dims[0], r.dims[1], r.dims[2])
    } else {
        format!("{}×{}", r.dims[0], r.dims[1])
    };
    outln!(
        "input     {dims} elements of {} mm, refined ×{} to {} mm pixels",
        r.element_size,
        r.job.clean.refine,
        r.pixel_size
    );
    outln!(
        "initial   thin-feature pixels {}, islands {}, point contacts {}",
        r.initial.thin_pixels,
        r.initial.islands,
        r.initial.point_contacts
    );
    outln!(
        "cleaned   {} after {} pass(es): thin {}, islands {}, contacts {} (level {:.4})",
        if r.clean { "clean" } else { "NOT CLEAN" },
        r.iterations,
        r.remaining.thin_pixels,
        r.remaining.islands,
        r.remaining.point_contacts,
        r.level
    );
    let unit = if r.is_3d { "mm³" } else { "mm²" };
    outln!(
        "volume    thresholded {:.3} {unit}, final {:.3} {unit} ({:+.3} %)",
        r.thresholded_measure,
        r.final_measure,
        100.0 * r.measure_change
    );
    outln!(
        "mesh      {} triangles; {} (verified by {})",
        r.triangles,
        cgal_findings(&r.checks),
        r.checks.checked_by
    );
    if let Some(s) = &r.simplified {
        super::out::simplified(
            s,
            "uniform mesh",
            if r.job.smooth_iterations > 0 {
                "the smoothed uniform mesh"
            } else {
                "the iso-surface"
            },
        );
    }
    if !r.loops.is_empty() {
        outln!(
            "curves    {} loop(s): uniform {} control points, adaptive {} ({:.0} %), tolerance {} mm",
            r.loops.len(),
            r.uniform_control_points,
            r.adaptive_control_points,
            100.0 * r.control_point_ratio.unwrap_or(f64::NAN),
            r.job.tolerance
        );
    }
    outln!("time      {:.3} s", r.timings.total);
    outln!("wrote     {}", a.output.display());
    for p in [&a.iges, &a.dxf, &a.report, &a.cleaned]
        .into_iter()
        .flatten()
    {
        outln!("wrote     {}", p.display());
    }
    for p in images {
        outln!("wrote     {}", p.display());
    }
}
