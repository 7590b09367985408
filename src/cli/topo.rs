//! `latvox topo`: a density field to a printable STL and parametric CAD (seed 003).

use super::{write_json, yes};
use clap::Args;
use latvox::grid::Smoothing;
use latvox::io::stl::StlFormat;
use latvox::topo::job::{self, TopoJob};
use latvox::topo::{CleanOptions, Density};
use latvox::{Error, Result};
use std::path::PathBuf;

pub(crate) const EXAMPLES: &str = "\
Examples:
  # Seed 003's cantilever: 30 × 10 elements of 4 mm, 2 mm printer limit, 4 mm thick plate
  latvox topo cantilever.npy --element-size 4 --cutoff 0.5 --refine 8 --min-feature 2 \\
      --thickness 4 -o part.stl --iges part.igs --dxf part.dxf --report r.json --images stages

  # A 3D field (shape ny, nx, nz) straight to a closed STL through OpenVDB
  latvox topo bracket3d.npy --element-size 1 --refine 2 --min-feature 1.5 -o bracket.stl

  # The same, smoothed by two passes of OpenVDB's Gaussian level-set filter
  latvox topo bracket3d.npy --element-size 1 --refine 2 --smooth 2 -o bracket-smooth.stl

Input: .npy (float, int or bool; C or Fortran order), .csv (2D, one row per line) or text with a
dimension header line `ny nx [nz]` then the values. 2D arrays are (ny, nx) with row 0 at the
top, as the 88-line code's xPhys; 3D arrays (ny, nx, nz), as top3d's. Densities in [0, 1].

The pipeline (seed 003): threshold at --cutoff and refine every element into --refine pixels
per edge; skeleton with spur pruning, inscribed radius = local feature size (3D: distance
transforms); thin features (radius < min-feature/2), islands and point contacts are raised by
0.1, density-filtered (radius --filter-radius elements) and re-thresholded at the level that
keeps the thresholded volume, until none is left (at most --max-iterations passes).
2D results are extruded by --thickness; 3D results are meshed by OpenVDB (optionally smoothed
with its level-set filter, --smooth), at the level that keeps the thresholded volume. Every mesh is checked
by CGAL. The CAD curves (2D) are closed cubic B-splines within --tolerance of the boundary,
uniform and adaptive; the IGES and DXF files hold the adaptive ones.

Exit code 0: clean and valid; 1: defects remain after the last pass or a mesh check failed;
2: bad input or arguments.";

#[derive(Clone, Copy, clap::ValueEnum)]
pub enum SmoothArg {
    Gaussian,
    MeanCurvature,
    Laplacian,
    Mean,
}

#[derive(Args)]
pub struct TopoArgs {
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
    /// Max deviation of the CAD curves from the boundary, mm (default: half a refined pixel).
    #[arg(long, value_name = "MM")]
    pub tolerance: Option<f64>,
    /// Output STL.
    #[arg(long, short = 'o', value_name = "FILE.stl", default_value = "part.stl")]
    pub output: PathBuf,
    /// Write ASCII STL.
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
    /// Skip CGAL's self-intersection test.
    #[arg(long)]
    pub no_self_intersection_check: bool,
}

pub fn run(a: &TopoArgs, quiet: bool) -> Result<i32> {
    let d = Density::read(&a.input, a.element_size)?;
    let is_3d = d.is_3d;
    if !is_3d && a.refine.is_none() && (d.nx * 8) * (d.ny * 8) > 200_000_000 {
        return Err(Error::invalid(
            "field too large for --refine 8; give a smaller --refine",
        ));
    }
    if is_3d && (a.iges.is_some() || a.dxf.is_some()) {
        return Err(Error::invalid(
            "--iges/--dxf take 2D fields (boundary curves); a 3D field gives the STL only",
        ));
    }
    let refine = a.refine.unwrap_or(if is_3d { 2 } else { 8 });
    let thickness = a.thickness.unwrap_or(a.element_size);
    let tolerance = a.tolerance.unwrap_or(0.5 * a.element_size / refine as f64);
    if !(tolerance > 0.0 && tolerance.is_finite()) {
        return Err(Error::invalid(
            "--tolerance must be a positive length in mm",
        ));
    }
    if a.max_iterations == 0 {
        return Err(Error::invalid("--max-iterations must be at least 1"));
    }
    let job = TopoJob {
        clean: CleanOptions {
            cutoff: a.cutoff,
            refine,
            min_feature: a.min_feature,
            filter_radius: a.filter_radius,
            raise: 0.1,
            max_iterations: a.max_iterations,
        },
        thickness,
        tolerance,
        fit_curves: !is_3d,
        self_intersection: !a.no_self_intersection_check,
        smooth_iterations: a.smooth,
        smoothing: match a.smooth_filter {
            SmoothArg::Gaussian => Smoothing::Gaussian,
            SmoothArg::MeanCurvature => Smoothing::MeanCurvature,
            SmoothArg::Laplacian => Smoothing::Laplacian,
            SmoothArg::Mean => Smoothing::Mean,
        },
    };
    if a.smooth > 0 && !is_3d {
        return Err(Error::invalid(
            "--smooth applies to 3D fields (2D outlines are smooth B-splines)",
        ));
    }
    if a.smooth > 100 {
        return Err(Error::invalid("--smooth takes at most 100 passes"));
    }
    let outputs = [
        &Some(a.output.clone()),
        &a.iges,
        &a.dxf,
        &a.report,
        &a.cleaned,
    ];
    for f in outputs.into_iter().flatten() {
        latvox::output::check_writable(f)?;
    }
    let progress = latvox::progress::Progress::new(quiet);
    let r = job::run(&d, &job, &progress)?;
    let format = if a.ascii {
        StlFormat::Ascii
    } else {
        StlFormat::Binary
    };
    latvox::io::stl::save(&r.mesh, format, &a.output)?;
    let stamp = timestamp();
    let name = |p: &PathBuf| {
        p.file_name()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default()
    };
    if let Some(p) = &a.iges {
        latvox::output::write_atomic(p, |w| {
            latvox::cad::iges::write(w, &r.adaptive, &name(p), &stamp)
        })?;
        if a.uniform_too {
            let stem = p
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default();
            let u = p.with_file_name(format!("{stem}-uniform.igs"));
            latvox::output::write_atomic(&u, |w| {
                latvox::cad::iges::write(w, &r.uniform, &name(&u), &stamp)
            })?;
        }
    }
    if let Some(p) = &a.dxf {
        latvox::output::write_atomic(p, |w| latvox::cad::dxf::write(w, &r.adaptive))?;
    }
    if let Some(p) = &a.boundary {
        latvox::output::write_atomic(p, |w| {
            writeln!(w, "loop,x,y")?;
            for (k, l) in r.loops.iter().enumerate() {
                for q in l {
                    writeln!(w, "{k},{:.9},{:.9}", q[0], q[1])?;
                }
            }
            Ok(())
        })?;
    }
    if let Some(p) = &a.cleaned {
        let f = &r.cleaned.field;
        let (nx, ny, nz) = (f.n[0], f.n[1], f.n[2]);
        let mut v = Vec::with_capacity(f.len());
        for row in 0..ny {
            for x in 0..nx {
                for z in 0..nz {
                    v.push(if r.cleaned.mask[f.index(x, ny - 1 - row, z)] {
                        1.0
                    } else {
                        0.0
                    });
                }
            }
        }
        let shape = if is_3d {
            vec![ny, nx, nz]
        } else {
            vec![ny, nx]
        };
        latvox::output::write_atomic(p, |w| latvox::topo::npy::write(w, &shape, &v))?;
    }
    let images = match &a.images {
        Some(prefix) => latvox::topo::images::write_stages(&r.cleaned, prefix)?,
        None => Vec::new(),
    };
    if let Some(p) = &a.report {
        write_json(p, &r.report)?;
    }
    summary(&r.report, a, &images);
    if r.report.measure_change.abs() > 0.01 {
        eprintln!(
            "latvox: warning: the part's volume differs from the thresholded volume by {:+.1} % \
             (heavy smoothing erases thin members; try fewer --smooth passes)",
            100.0 * r.report.measure_change
        );
    }
    let valid = r.report.checks.closed
        && r.report.checks.outward
        && r.report.checks.manifold
        && !r.report.checks.self_intersecting;
    Ok(if r.report.clean && valid { 0 } else { 1 })
}

fn timestamp() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs())
        .unwrap_or(0);
    let (days, rem) = (secs / 86_400, secs % 86_400);
    // Civil date from days since 1970-01-01 (Howard Hinnant's algorithm).
    let z = days as i64 + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}{month:02}{day:02}.{:02}{:02}{:02}",
        rem / 3600,
        (rem / 60) % 60,
        rem % 60
    )
}

fn summary(r: &job::TopoReport, a: &TopoArgs, images: &[PathBuf]) {
    let dims = if r.is_3d {
        format!("{}×{}×{}", r.dims[0], r.dims[1], r.dims[2])
    } else {
        format!("{}×{}", r.dims[0], r.dims[1])
    };
    println!(
        "input     {dims} elements of {} mm, refined ×{} to {} mm pixels",
        r.element_size, r.job.clean.refine, r.pixel_size
    );
    println!(
        "initial   thin-feature pixels {}, islands {}, point contacts {}",
        r.initial.thin_pixels, r.initial.islands, r.initial.point_contacts
    );
    println!(
        "cleaned   {} after {} pass(es): thin {}, islands {}, contacts {} (level {:.4})",
        if r.clean { "clean" } else { "NOT CLEAN" },
        r.iterations,
        r.remaining.thin_pixels,
        r.remaining.islands,
        r.remaining.point_contacts,
        r.level
    );
    let unit = if r.is_3d { "mm³" } else { "mm²" };
    println!(
        "volume    thresholded {:.3} {unit}, final {:.3} {unit} ({:+.3} %)",
        r.thresholded_measure,
        r.final_measure,
        100.0 * r.measure_change
    );
    let c = &r.checks;
    println!(
        "mesh      {} triangles; CGAL closed {}  outward {}  manifold {}  self-intersections {}",
        r.triangles,
        yes(c.closed),
        yes(c.outward),
        yes(c.manifold),
        if !c.self_intersection_checked {
            "not checked"
        } else if c.self_intersecting {
            "FOUND"
        } else {
            "none"
        }
    );
    if !r.loops.is_empty() {
        println!(
            "curves    {} loop(s): uniform {} control points, adaptive {} ({:.0} %), tolerance {} mm",
            r.loops.len(),
            r.uniform_control_points,
            r.adaptive_control_points,
            100.0 * r.control_point_ratio.unwrap_or(f64::NAN),
            r.job.tolerance
        );
    }
    println!("time      {:.3} s", r.timings.total);
    println!("wrote     {}", a.output.display());
    for p in [&a.iges, &a.dxf, &a.report, &a.cleaned]
        .into_iter()
        .flatten()
    {
        println!("wrote     {}", p.display());
    }
    for p in images {
        println!("wrote     {}", p.display());
    }
}
