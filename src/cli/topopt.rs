//! `latvox topopt`: SIMP minimum-compliance optimisation; writes the densities (.npy), the
//! per-iteration log and a JSON report.

use super::command::{parsed, Command};
use super::out::outln;
use super::write_json;
use clap::{Args, ValueEnum};
use latvox::topopt::{self, FilterKind, Settings};
use latvox::{Error, Result};
use std::path::PathBuf;

pub(crate) const EXAMPLES: &str = "\
Examples:
  # The 88-line code's half MBB beam
  latvox topopt --problem mbb --nelx 60 --nely 20 --volfrac 0.5 --penal 3 --rmin 1.5 \\
      --filter sensitivity -o mbb.npy --report mbb.json

  # Liu et al. 2018's cantilever (120 × 40 mm on 30 × 10 elements), then to STL and CAD
  latvox topopt --problem cantilever --volfrac 0.3 -o cantilever.npy
  latvox interpret cantilever.npy --element-size 4 --thickness 4 -o cantilever.stl --iges c.igs

  # top3d's cantilever, 3D
  latvox topopt --problem cantilever3d --nelx 30 --nely 10 --nelz 4 --volfrac 0.3 -o c3.npy

  # ... and its SIMP stiffness at the nodes, in the part's coordinates (elements of 1 mm here)
  latvox topopt --problem cantilever3d --nelx 30 --nely 10 --nelz 4 -o c3.npy --stiffness s.npy

  # Your own supports and loads
  latvox topopt --problem bracket.toml -o bracket.npy

Built-in problems: mbb (half MBB beam), cantilever (left edge clamped, load down at the lower
right), lbeam (L-bracket, top clamped, load at the arm's end), heat (conduction plate, uniform
heat, sink at the middle of the left edge), cantilever3d (top3d's line-loaded cantilever).

A problem file (TOML): node ranges are inclusive grid coordinates from the lower-left corner,
in elements; passive element ranges are half-open.
  nelx = 40
  nely = 20
  volfrac = 0.4
  [[support]]
  x = [0, 0]
  y = [0, 20]
  fix = \"xy\"
  [[load]]
  x = [40, 40]
  y = [10, 10]
  f = [0.0, -1.0]
  [[passive]]
  x = [10, 20]
  y = [5, 15]
  solid = false

The .npy holds the physical densities, shape (nely, nelx) or (nely, nelx, nelz), row 0 at the
top (as the published MATLAB codes' xPhys). The report holds `compliance` (one value per
iteration) and `iterations`.";

/// `latvox topopt`.
pub(crate) const COMMAND: Command = Command::new(
    "topopt",
    "SIMP topology optimisation (88-line code in 2D, top3d in 3D): densities to .npy",
    EXAMPLES,
    <TopoptArgs as clap::Args>::augment_args,
    |m, quiet| run(&parsed(m)?, quiet),
);

#[derive(Clone, Copy, ValueEnum)]
pub enum FilterArg {
    Sensitivity,
    Density,
}

#[derive(Args)]
pub struct TopoptArgs {
    /// Built-in problem (mbb, cantilever, lbeam, heat, cantilever3d) or a .toml problem file.
    #[arg(long, default_value = "mbb")]
    pub problem: String,
    /// Elements along x.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    pub nelx: Option<u32>,
    /// Elements along y.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    pub nely: Option<u32>,
    /// Elements along z (3D problems).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    pub nelz: Option<u32>,
    /// Volume fraction (default: the problem's own, 0.5 for mbb, 0.3 otherwise).
    #[arg(long)]
    pub volfrac: Option<f64>,
    /// SIMP penalty.
    #[arg(long, default_value_t = 3.0)]
    pub penal: f64,
    /// Filter radius, in elements.
    #[arg(long, default_value_t = 1.5)]
    pub rmin: f64,
    /// Filter the sensitivities (88-line ft = 1) or the densities (ft = 2; top3d's choice).
    /// Default: sensitivity in 2D, density in 3D.
    #[arg(long, value_enum)]
    pub filter: Option<FilterArg>,
    /// Stop after this many iterations even if the change is still above 0.01.
    #[arg(long, default_value_t = 1000)]
    pub max_iterations: usize,
    /// Element size in mm, recorded in the report for `latvox interpret`.
    #[arg(long, value_name = "MM")]
    pub element_size: Option<f64>,
    /// Output densities (.npy).
    #[arg(
        long,
        short = 'o',
        value_name = "FILE.npy",
        default_value = "densities.npy"
    )]
    pub output: PathBuf,
    /// The design's SIMP stiffness relative to the solid (Emin + ρᵖ(1 − Emin)) at the elements'
    /// nodes, in the part's coordinates (shape (nelx+1, nely+1, nelz+1), y up, the box
    /// nelx·h × nely·h × nelz·h mm): what `tpms`, `strut` and `fill --stiffness-field` read, to
    /// print the design as a lattice graded by stiffness.
    #[arg(long, value_name = "FILE.npy")]
    pub stiffness: Option<PathBuf>,
    /// Per-iteration log (CSV: iteration, compliance, volume, change).
    #[arg(long, value_name = "FILE.csv")]
    pub log: Option<PathBuf>,
    /// JSON report: settings, compliance per iteration, iterations, convergence, time.
    #[arg(long, value_name = "FILE.json")]
    pub report: Option<PathBuf>,
}

#[derive(serde::Serialize)]
struct Report<'a> {
    problem: &'a str,
    physics: topopt::Physics,
    nelx: usize,
    nely: usize,
    nelz: usize,
    element_size: f64,
    settings: Settings,
    #[serde(flatten)]
    result: &'a topopt::Optimised,
    final_compliance: f64,
    time_s: f64,
    output: String,
}

pub fn run(a: &TopoptArgs, quiet: bool) -> Result<i32> {
    let t0 = std::time::Instant::now();
    let mut p = if a.problem.ends_with(".toml") {
        if a.nelx.is_some() || a.nely.is_some() || a.nelz.is_some() {
            return Err(Error::invalid(
                "--nelx/--nely/--nelz do not apply to a problem file (it gives its own mesh)",
            ));
        }
        topopt::from_toml(std::path::Path::new(&a.problem))?
    } else {
        let dims = match (a.nelx, a.nely, a.nelz) {
            (None, None, None) => None,
            (Some(x), Some(y), z) => Some([x as usize, y as usize, z.unwrap_or(0) as usize]),
            _ => return Err(Error::invalid("give both --nelx and --nely")),
        };
        topopt::builtin(&a.problem, dims)?
    };
    if let Some(h) = a.element_size {
        if !(h > 0.0 && h.is_finite()) {
            return Err(Error::invalid(
                "--element-size must be a positive length in mm",
            ));
        }
        p.element_size = h;
    }
    let filter = match a.filter {
        Some(FilterArg::Sensitivity) => FilterKind::Sensitivity,
        Some(FilterArg::Density) => FilterKind::Density,
        None if p.is_3d() => FilterKind::Density,
        None => FilterKind::Sensitivity,
    };
    let mut s = Settings::new(a.volfrac.unwrap_or(p.volfrac), a.penal, a.rmin, filter);
    s.max_iterations = a.max_iterations;
    latvox::io::atomic::check_writable(&a.output)?;
    for f in [&a.log, &a.report, &a.stiffness].into_iter().flatten() {
        latvox::io::atomic::check_writable(f)?;
    }
    let progress = latvox::progress::Progress::new(quiet);
    let verbose = !quiet;
    let r = topopt::optimise(&p, &s, &progress, |i, c, v, ch| {
        if verbose {
            outln!(" It.:{i:5} Obj.:{c:11.4} Vol.:{v:7.3} ch.:{ch:7.3}");
        }
    })?;
    let (shape, data) = topopt::to_array(&p, &r.densities);
    latvox::io::atomic::write_atomic(&a.output, |w| latvox::io::npy::write(w, &shape, &data))?;
    if let Some(path) = &a.stiffness {
        let (shape, data) = topopt::stiffness_at_nodes(&p, &r.densities, s.penal);
        latvox::io::atomic::write_atomic(path, |w| latvox::io::npy::write(w, &shape, &data))?;
    }
    if let Some(log) = &a.log {
        latvox::io::atomic::write_atomic(log, |w| {
            writeln!(w, "iteration,compliance,volume,change")?;
            for i in 0..r.iterations {
                writeln!(
                    w,
                    "{},{:.17e},{:.17e},{:.17e}",
                    i + 1,
                    r.compliance[i],
                    r.volume[i],
                    r.change[i]
                )?;
            }
            Ok(())
        })?;
    }
    let report = Report {
        problem: &p.name,
        physics: p.physics,
        nelx: p.nelx,
        nely: p.nely,
        nelz: p.nelz,
        element_size: p.element_size,
        settings: s,
        result: &r,
        final_compliance: *r.compliance.last().unwrap_or(&f64::NAN),
        time_s: t0.elapsed().as_secs_f64(),
        output: a.output.display().to_string(),
    };
    if let Some(f) = &a.report {
        write_json(f, &report)?;
    }
    outln!(
        "{} {}×{}{}: compliance {:.4} after {} iterations ({}), volume {:.4}, {:.2} s",
        p.name,
        p.nelx,
        p.nely,
        if p.is_3d() {
            format!("×{}", p.nelz)
        } else {
            String::new()
        },
        report.final_compliance,
        r.iterations,
        if r.converged {
            "converged"
        } else {
            "iteration limit reached"
        },
        r.volume.last().unwrap_or(&f64::NAN),
        report.time_s
    );
    outln!("wrote     {}", a.output.display());
    Ok(0)
}
