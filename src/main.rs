//! The `latvox` command line: parses arguments, calls the library, prints one line on error.
//! Exit codes: 0 success, 1 a check found defects, 2 bad input or arguments, 3 backend failure.

use clap::{Args, Parser, Subcommand};
use latvox::stl::StlFormat;
use latvox::tpms::{Domain, Structure, Surface, TpmsJob};
use latvox::{Error, Result};
use std::path::{Path, PathBuf};

const TPMS_EXAMPLES: &str = "\
Examples:
  # 4×4×4 gyroid cells of 5 mm, network solid at exactly 30 % density
  latvox tpms --type gyroid --structure net --density 0.3 --cells 4 --cell-size 5 -o gyroid.stl

  # Diamond sheet, 4×4×2 cells of 6 mm, finer voxels, JSON report
  latvox tpms --type d --structure sheet --density 0.2 --cells 4,4,2 --cell-size 6 \\
      --resolution 48 -o diamond.stl --report diamond.json

  # A 50×30×10 mm block filled with 10 mm Schwarz-P cells (partial cells at the far sides)
  latvox tpms --type p --density 0.35 --size 50,30,10 --cell-size 10 -o p-block.stl

Types: p (Schwarz primitive), g|gyroid, d (Schwarz diamond), iwp (Schoen I-WP),
       s (Fischer–Koch S), frd (Schoen F-RD), n|neovius.
Structures: net (solid on one side of F = t), sheet (solid where |F| ≤ t).
The level t is found by latvox so that the written mesh has the requested volume fraction;
the report gives the target, the fraction CGAL measures on the mesh, and the CGAL checks.";

const CHECK_EXAMPLES: &str = "\
Examples:
  latvox check part.stl
  latvox check part.stl --json > part-check.json

Exit code 0 when the mesh is a closed, outward, self-intersection-free solid; 1 when a check
fails; 2 when the file cannot be read.";

#[derive(Parser)]
#[command(
    name = "latvox",
    version,
    about = "Sparse-volume voxel engine for additive manufacturing: TPMS lattices at exact density, verified by CGAL",
    long_about = None
)]
struct Cli {
    /// Worker threads for latvox and OpenVDB/TBB (default: all cores).
    #[arg(long, global = true, value_name = "N")]
    threads: Option<usize>,
    /// No progress display.
    #[arg(long, short, global = true)]
    quiet: bool,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Generate a closed TPMS lattice at an exact volume fraction.
    #[command(after_help = TPMS_EXAMPLES)]
    Tpms(TpmsArgs),
    /// Check an STL with CGAL: closed, outward, self-intersections, volume, area.
    #[command(after_help = CHECK_EXAMPLES)]
    Check(CheckArgs),
}

#[derive(Args)]
struct TpmsArgs {
    /// Surface: p, gyroid (g), d, iwp, s, frd, neovius (n).
    #[arg(long = "type", short = 't', value_name = "TYPE", default_value = "gyroid", value_parser = parse_surface)]
    surface: Surface,
    /// Solid side: net (F ≤ t) or sheet (|F| ≤ t).
    #[arg(long, value_name = "net|sheet", default_value = "net", value_parser = parse_structure)]
    structure: Structure,
    /// Target volume fraction of solid, in (0, 1).
    #[arg(long, short = 'd', default_value_t = 0.3, value_parser = parse_density)]
    density: f64,
    /// Cells per axis: N or NX,NY,NZ.
    #[arg(long, value_name = "N[,NY,NZ]", value_parser = parse_counts)]
    cells: Option<[u32; 3]>,
    /// Cell size in mm: A or AX,AY,AZ.
    #[arg(long, value_name = "MM[,MM,MM]", value_parser = parse_positive3)]
    cell_size: Option<[f64; 3]>,
    /// Overall box size in mm (with --cells or --cell-size): S or SX,SY,SZ.
    #[arg(long, value_name = "MM[,MM,MM]", value_parser = parse_positive3)]
    size: Option<[f64; 3]>,
    /// Lower corner of the box in mm (lattice phase starts there).
    #[arg(long, value_name = "X,Y,Z", default_value = "0,0,0", value_parser = parse_finite3)]
    origin: [f64; 3],
    /// Voxels per cell along the cell's shortest side.
    #[arg(long, short = 'r', default_value_t = 32, value_parser = clap::value_parser!(u32).range(4..=4096))]
    resolution: u32,
    /// OpenVDB mesh adaptivity: 0 keeps uniform triangles, up to 1 merges flat regions.
    #[arg(long, default_value_t = 0.0, value_parser = parse_unit)]
    adaptivity: f64,
    /// Output mesh (binary STL unless --ascii).
    #[arg(
        long,
        short = 'o',
        value_name = "FILE.stl",
        default_value = "lattice.stl"
    )]
    output: PathBuf,
    /// Write ASCII STL instead of binary.
    #[arg(long)]
    ascii: bool,
    /// Write a JSON report (type, level, densities, mesh counts, CGAL checks, timings).
    #[arg(long, value_name = "FILE.json")]
    report: Option<PathBuf>,
    /// Build even when the solid falls apart into islands at this density.
    #[arg(long)]
    allow_islands: bool,
    /// Fail instead of raising the resolution when sheet walls would be under 1.25 voxels.
    #[arg(long)]
    fixed_resolution: bool,
    /// Skip CGAL's self-intersection test (the slowest check) on very large meshes.
    #[arg(long)]
    no_self_intersection_check: bool,
}

#[derive(Args)]
struct CheckArgs {
    /// STL file (binary or ASCII).
    file: PathBuf,
    /// Print the result as JSON.
    #[arg(long)]
    json: bool,
}

fn split3<T: Copy>(
    s: &str,
    parse: impl Fn(&str) -> std::result::Result<T, String>,
) -> std::result::Result<[T; 3], String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    match parts.len() {
        1 => {
            let v = parse(parts[0])?;
            Ok([v, v, v])
        }
        3 => Ok([parse(parts[0])?, parse(parts[1])?, parse(parts[2])?]),
        _ => Err(format!(
            "expected one value or three comma-separated values, got '{s}'"
        )),
    }
}

fn parse_f64(s: &str) -> std::result::Result<f64, String> {
    s.parse::<f64>()
        .map_err(|_| format!("'{s}' is not a number"))
}

fn parse_positive3(s: &str) -> std::result::Result<[f64; 3], String> {
    split3(s, |p| {
        let v = parse_f64(p)?;
        if v > 0.0 && v.is_finite() {
            Ok(v)
        } else {
            Err(format!("{p} must be a positive length in mm"))
        }
    })
}

fn parse_finite3(s: &str) -> std::result::Result<[f64; 3], String> {
    split3(s, |p| {
        let v = parse_f64(p)?;
        v.is_finite()
            .then_some(v)
            .ok_or_else(|| format!("{p} must be finite"))
    })
}

fn parse_counts(s: &str) -> std::result::Result<[u32; 3], String> {
    split3(s, |p| match p.parse::<u32>() {
        Ok(0) => Err("cell counts must be at least 1".to_string()),
        Ok(v) => Ok(v),
        Err(_) => Err(format!("'{p}' is not a whole number of cells")),
    })
}

fn parse_density(s: &str) -> std::result::Result<f64, String> {
    let v = parse_f64(s)?;
    if v > 0.0 && v < 1.0 {
        Ok(v)
    } else {
        Err(format!("density must be strictly between 0 and 1, got {s}"))
    }
}

fn parse_unit(s: &str) -> std::result::Result<f64, String> {
    let v = parse_f64(s)?;
    if (0.0..=1.0).contains(&v) {
        Ok(v)
    } else {
        Err(format!("must be in [0, 1], got {s}"))
    }
}

fn parse_surface(s: &str) -> std::result::Result<Surface, String> {
    Surface::parse(s).ok_or_else(|| {
        format!("unknown TPMS type '{s}' (known: p, gyroid, d, iwp, s, frd, neovius)")
    })
}

fn parse_structure(s: &str) -> std::result::Result<Structure, String> {
    match s.to_ascii_lowercase().as_str() {
        "net" | "network" | "solid" => Ok(Structure::Net),
        "sheet" | "shell" => Ok(Structure::Sheet),
        _ => Err(format!("unknown structure '{s}' (known: net, sheet)")),
    }
}

fn domain(a: &TpmsArgs) -> Result<Domain> {
    match (a.cells, a.cell_size, a.size) {
        (Some(n), Some(c), None) => Domain::from_cells(n, c, a.origin),
        (Some(n), None, Some(s)) => Domain::from_size_and_cells(s, n, a.origin),
        (None, Some(c), Some(s)) => Domain::from_size_and_cell(s, c, a.origin),
        (Some(n), None, None) => Domain::from_cells(n, [5.0; 3], a.origin),
        (None, Some(c), None) => Domain::from_cells([4; 3], c, a.origin),
        (None, None, None) => Domain::from_cells([4; 3], [5.0; 3], a.origin),
        (None, None, Some(_)) => Err(Error::invalid("--size needs --cells or --cell-size")),
        (Some(_), Some(_), Some(_)) => Err(Error::invalid(
            "give two of --cells, --cell-size, --size, not all three",
        )),
    }
}

fn run_tpms(a: &TpmsArgs, quiet: bool) -> Result<i32> {
    let job = TpmsJob {
        surface: a.surface,
        structure: a.structure,
        density: a.density,
        domain: domain(a)?,
        resolution: a.resolution,
        adaptivity: a.adaptivity,
        allow_islands: a.allow_islands,
        auto_resolution: !a.fixed_resolution,
        self_intersection: !a.no_self_intersection_check,
    };
    // Fail on an unwritable destination before the work, not after.
    latvox::output::check_writable(&a.output)?;
    if let Some(r) = &a.report {
        latvox::output::check_writable(r)?;
    }
    let progress = latvox::progress::Progress::new(quiet);
    let (mesh, mut report) = job.run(&progress)?;
    let t = std::time::Instant::now();
    {
        let _p = progress.stage("writing STL");
        let format = if a.ascii {
            StlFormat::Ascii
        } else {
            StlFormat::Binary
        };
        latvox::stl::save(&mesh, format, &a.output)?;
    }
    report.timings.write = t.elapsed().as_secs_f64();
    report.timings.total += report.timings.write;
    report.output = Some(a.output.display().to_string());
    if let Some(r) = &a.report {
        write_json(r, &report)?;
    }
    for w in &report.warnings {
        eprintln!("latvox: warning: {w}");
    }
    print_tpms_summary(&report);
    Ok(
        if report.checks.is_valid_solid()
            || !report.checks.self_intersection_checked
                && report.checks.closed
                && report.checks.outward
        {
            0
        } else {
            1
        },
    )
}

fn yes(b: bool) -> &'static str {
    if b {
        "yes"
    } else {
        "NO"
    }
}

fn print_tpms_summary(r: &latvox::tpms::TpmsReport) {
    let c = &r.checks;
    println!(
        "{} {} · {}×{}×{} cells of {}×{}×{} mm · {} voxels/cell ({:.4} mm)",
        r.surface.name(),
        r.structure.name(),
        r.cells[0],
        r.cells[1],
        r.cells[2],
        r.cell_size[0],
        r.cell_size[1],
        r.cell_size[2],
        r.resolution,
        r.voxel_size
    );
    println!(
        "density   target {:.4}  achieved {:.4}  (error {:+.5}, level t = {:.5})",
        r.target_density, r.achieved_density, r.density_error, r.level
    );
    println!(
        "mesh      {} triangles, {} vertices, area {:.2} mm², volume {:.2} mm³",
        r.triangles,
        r.vertices,
        r.area,
        r.volume.unwrap_or(f64::NAN)
    );
    if let Some(b) = r.bounding_box {
        println!(
            "bounds    [{:.3}, {:.3}, {:.3}] – [{:.3}, {:.3}, {:.3}] mm",
            b.min[0], b.min[1], b.min[2], b.max[0], b.max[1], b.max[2]
        );
    }
    println!(
        "CGAL      closed {}  outward {}  manifold {}  self-intersections {}",
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
    let t = &r.timings;
    println!(
        "time      {:.3} s (calibrate {:.3}, sample {:.3}, mesh {:.3}, snap {:.3}, verify {:.3}, write {:.3})",
        t.total, t.calibrate, t.sample, t.mesh, t.snap, t.verify, t.write
    );
    if let Some(o) = &r.output {
        println!("wrote     {o}");
    }
}

fn write_json<T: serde::Serialize>(path: &Path, value: &T) -> Result<()> {
    latvox::output::write_atomic(path, |w| {
        serde_json::to_writer_pretty(&mut *w, value).map_err(std::io::Error::other)?;
        w.write_all(b"\n")
    })
}

fn run_check(a: &CheckArgs) -> Result<i32> {
    let mesh = latvox::stl::read(&a.file)?;
    let edges = mesh.edge_stats();
    let checks = latvox::verify::verify(&mesh, true)?;
    let ok = checks.is_valid_solid() && edges.boundary == 0 && edges.non_manifold == 0;
    if a.json {
        let v = serde_json::json!({
            "file": a.file.display().to_string(),
            "valid_solid": ok,
            "triangles": mesh.triangle_count(),
            "vertices": mesh.vertex_count(),
            "edges": edges,
            "cgal": checks,
        });
        println!(
            "{}",
            serde_json::to_string_pretty(&v).expect("JSON of plain values")
        );
    } else {
        println!("{}", a.file.display());
        println!(
            "triangles {}  vertices {}  edges {}",
            mesh.triangle_count(),
            mesh.vertex_count(),
            edges.edges
        );
        println!(
            "edges     boundary {}  non-manifold {}  inconsistently wound {}",
            edges.boundary, edges.non_manifold, edges.misoriented
        );
        println!(
            "CGAL      closed {}  outward {}  manifold {}  self-intersections {}  shells {}",
            yes(checks.closed),
            yes(checks.outward),
            yes(checks.manifold),
            if checks.self_intersecting {
                "FOUND"
            } else {
                "none"
            },
            checks.components
        );
        match checks.volume {
            Some(v) => println!("measures  volume {v:.4} mm³  area {:.4} mm²", checks.area),
            None => println!(
                "measures  volume undefined (not closed)  area {:.4} mm²",
                checks.area
            ),
        }
        println!(
            "verdict   {}",
            if ok {
                "valid closed solid"
            } else {
                "DEFECTS FOUND"
            }
        );
    }
    Ok(if ok { 0 } else { 1 })
}

fn main() {
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            use clap::error::ErrorKind;
            match e.kind() {
                ErrorKind::DisplayHelp
                | ErrorKind::DisplayVersion
                | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
                    let _ = e.print();
                    std::process::exit(
                        if e.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand {
                            2
                        } else {
                            0
                        },
                    );
                }
                _ => {
                    let msg = e.to_string();
                    let first = msg.lines().next().unwrap_or("invalid arguments").trim();
                    let first = first.strip_prefix("error: ").unwrap_or(first);
                    eprintln!("latvox: {first}");
                    std::process::exit(2);
                }
            }
        }
    };
    if let Some(n) = cli.threads {
        if n == 0 {
            eprintln!("latvox: --threads must be at least 1");
            std::process::exit(2);
        }
        let _ = rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global();
        latvox::grid::set_backend_threads(n);
    }
    let result = match &cli.command {
        Command::Tpms(a) => run_tpms(a, cli.quiet),
        Command::Check(a) => run_check(a),
    };
    match result {
        Ok(code) => std::process::exit(code),
        Err(e) => {
            eprintln!("latvox: {}", one_line(&e));
            std::process::exit(e.exit_code());
        }
    }
}

fn one_line(e: &Error) -> String {
    e.to_string().replace('\n', " ")
}
