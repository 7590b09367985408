//! The `latvox` command line: parses arguments, calls the library, prints one line on error.
//! Exit codes: 0 success, 1 a check found defects, 2 bad input or arguments, 3 a backend failed
//! unexpectedly (a bug to report).

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};
use latvox::Error;

mod cli;

const EXIT_CODES: &str = "\
Exit codes (every command):
  0  success; a part or mesh made or checked is a valid closed, outward solid
  1  a check found defects (the output is still written), or a batch job failed
  2  bad input or arguments: one line on stderr, no file written
  3  a backend (OpenVDB or CGAL) failed unexpectedly: a bug to report";

#[derive(Parser)]
#[command(
    name = "latvox",
    version,
    about = "Sparse-volume voxel engine for additive manufacturing: TPMS and strut lattices and lattice-filled parts at exact density, verified closed and free of self-intersections",
    long_about = None,
    after_help = EXIT_CODES
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
    #[command(after_help = cli::tpms::EXAMPLES)]
    Tpms(cli::tpms::TpmsArgs),
    /// Generate a closed strut (beam) lattice — BCC, octet, Kelvin or a cell of your own — at an
    /// exact volume fraction or strut radius.
    #[command(after_help = cli::strut::EXAMPLES)]
    Strut(cli::strut::StrutArgs),
    /// Fill a part with a lattice: a solid skin of the part's shape, its core a TPMS or strut
    /// lattice at an exact density, solids kept whole where asked.
    #[command(after_help = cli::fill::EXAMPLES)]
    Fill(cli::fill::FillArgs),
    /// Check a mesh file: every defect counted (holes, non-manifold, winding, normals, degenerate
    /// and duplicate facets, T-junctions, self-intersections), per shell too.
    #[command(after_help = cli::check::EXAMPLES)]
    Check(cli::check::CheckArgs),
    /// Repair a mesh file and report every change by kind and count.
    #[command(after_help = cli::repair::EXAMPLES)]
    Repair(cli::repair::RepairArgs),
    /// SIMP topology optimisation (88-line code in 2D, top3d in 3D): densities to .npy.
    #[command(after_help = cli::topopt::EXAMPLES)]
    Topopt(cli::topopt::TopoptArgs),
    /// Density field to printable STL and parametric CAD (IGES, DXF): feature-preserving cleanup
    /// and adaptive B-spline fitting (Liu et al., Engineering 2018).
    #[command(after_help = cli::topo::EXAMPLES)]
    Topo(cli::topo::TopoArgs),
    /// Functionally graded material from distance fields: a scanned point cloud (or a mesh) to
    /// a signed distance grid, material fractions graded by the distance to features, and .vdb
    /// grids, a coloured mesh and voxel-print PNG stacks.
    #[command(after_help = cli::fgm::EXAMPLES)]
    Fgm(cli::fgm::FgmArgs),
    /// Render a picture of a part file, sphere-traced from its implicit solid without meshing
    /// it, or of a mesh file, ray cast.
    #[command(after_help = cli::render::EXAMPLES)]
    Render(cli::render::RenderArgs),
    /// Edit a part file live in the browser: a local server whose page sphere-traces the part
    /// on the GPU (no mesh), with controls, sections, saving, meshing and slicing.
    #[command(after_help = cli::view::EXAMPLES)]
    View(cli::view::ViewArgs),
    /// Slice a mesh file, or a part file without meshing it, into layers for printing: CLI
    /// (Common Layer Interface), SVG, PNG masks, SL1; uniform or adaptive layers, any build
    /// direction.
    #[command(after_help = cli::slice::EXAMPLES)]
    Slice(cli::slice::SliceArgs),
    /// Run many jobs from a TOML job file: sweeps, workers, resume after a kill, Slurm arrays.
    #[command(after_help = cli::batch::EXAMPLES)]
    Batch(cli::batch::BatchArgs),
}

/// The command line with a part file's options put in (`--part`, for `tpms`, `strut`, `fill` and
/// `fgm`).
fn expanded_args() -> latvox::Result<Vec<String>> {
    let argv: Vec<String> = std::env::args().collect();
    // The subcommand: the first word that is not a global option or its value.
    let mut i = 1;
    while i < argv.len() {
        match argv[i].as_str() {
            "--threads" => i += 2,
            a if a.starts_with('-') => i += 1,
            _ => break,
        }
    }
    match argv.get(i).map(String::as_str) {
        Some(command @ ("tpms" | "strut" | "fill" | "fgm")) => {
            let tail = cli::part::expand(command, argv[i + 1..].to_vec())?;
            Ok([&argv[..=i], &tail[..]].concat())
        }
        _ => Ok(argv),
    }
}

fn main() {
    // A union for `repair --solid`, run apart so that it can be stopped (not a user command).
    let raw: Vec<std::ffi::OsString> = std::env::args_os().collect();
    if raw.len() == 4 && raw[1] == latvox::repair::solid::HELPER_ARG {
        std::process::exit(latvox::repair::solid::helper(
            std::path::Path::new(&raw[2]),
            std::path::Path::new(&raw[3]),
        ));
    }
    let argv = expanded_args().unwrap_or_else(|e| {
        eprintln!("latvox: {}", one_line(&e));
        std::process::exit(e.exit_code());
    });
    let parsed = Cli::command()
        .try_get_matches_from(argv)
        .and_then(|m| Cli::from_arg_matches(&m).map(|c| (c, m)));
    let (cli, matches) = match parsed {
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
                    let mut lines = msg.lines().map(str::trim).filter(|l| !l.is_empty());
                    let first = lines.next().unwrap_or("invalid arguments");
                    let first = first.strip_prefix("error: ").unwrap_or(first);
                    // "the following required arguments were not provided:" names them below.
                    match lines.next().filter(|_| first.ends_with(':')) {
                        Some(what) => eprintln!("latvox: {first} {what}"),
                        None => eprintln!("latvox: {first}"),
                    }
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
    // The part file (if asked for) is written once the part is made; its folder must take it.
    let save_part = matches.subcommand().and_then(|(name, sub)| {
        sub.try_get_one::<std::path::PathBuf>("save_part")
            .ok()
            .flatten()
            .map(|p| (name.to_string(), p.clone(), sub.clone()))
    });
    if let Some((_, p, _)) = &save_part {
        if let Err(e) = latvox::io::atomic::check_writable(p) {
            eprintln!("latvox: {}", one_line(&e));
            std::process::exit(e.exit_code());
        }
    }
    let result = match &cli.command {
        Command::Tpms(a) => cli::tpms::run(a, cli.quiet),
        Command::Strut(a) => cli::strut::run(a, cli.quiet),
        Command::Fill(a) => cli::fill::run(a, cli.quiet),
        Command::Check(a) => cli::check::run(a, cli.quiet),
        Command::Repair(a) => cli::repair::run(a, cli.quiet),
        Command::Topopt(a) => cli::topopt::run(a, cli.quiet),
        Command::Topo(a) => cli::topo::run(a, cli.quiet),
        Command::Fgm(a) => cli::fgm::run(a, cli.quiet),
        Command::Batch(a) => cli::batch::run(a, cli.quiet),
        Command::Render(a) => cli::render::run(a),
        Command::View(a) => cli::view::run(a),
        Command::Slice(a) => cli::slice::run(a, cli.quiet),
    };
    let result = result.and_then(|code| {
        if let Some((name, path, sub)) = &save_part {
            let cmd = Cli::command();
            let cmd = cmd
                .find_subcommand(name)
                .expect("the subcommand that ran is a subcommand");
            cli::part::save(path, name, cmd, sub)?;
        }
        Ok(code)
    });
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
