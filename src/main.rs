//! The `latvox` command line: parses arguments, calls the library, prints one line on error.
//! Exit codes: 0 success, 1 a check found defects, 2 bad input or arguments, 3 a backend failed
//! unexpectedly (a bug to report).

use clap::{CommandFactory, FromArgMatches, Parser};
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
    after_help = EXIT_CODES,
    subcommand_required = true,
    arg_required_else_help = true
)]
struct Cli {
    /// Worker threads for latvox and OpenVDB/TBB (default: all cores).
    #[arg(long, global = true, value_name = "N")]
    threads: Option<usize>,
    /// No progress display.
    #[arg(long, short, global = true)]
    quiet: bool,
}

/// The whole command line: the global options and every subcommand of [`cli::COMMANDS`].
fn command_line() -> clap::Command {
    cli::COMMANDS
        .iter()
        .fold(Cli::command(), |cmd, c| cmd.subcommand(c.clap()))
}

/// The command line with a part file's options put in (`--part`, for the commands whose parts
/// part files hold).
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
    match argv.get(i).and_then(|name| cli::command::find(name)) {
        Some(command) if command.part.is_some() => {
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
    let parsed = command_line()
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
    let (name, sub) = matches.subcommand().expect("clap requires a subcommand");
    let command = cli::command::find(name).expect("every subcommand is in cli::COMMANDS");
    let result = cli::execute(command, sub, cli.quiet);
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
