//! Pieces shared by the subcommands: option parsers, JSON output, summary formatting.
//! Each subcommand lives in its own file and defines itself once, as a [`command::Command`]
//! named `COMMAND`; [`COMMANDS`] lists them.

pub mod batch;
pub mod check;
pub(crate) mod command;
pub mod fgm;
pub mod fill;
pub mod homogenize;
pub mod interpret;
pub mod lattice;
pub(crate) mod out;
pub mod part;
pub mod render;
pub mod repair;
pub mod slice;
pub mod strut;
pub mod topopt;
pub mod tpms;
pub mod view;
pub mod voronoi;

use latvox::Result;
use std::path::{Path, PathBuf};

/// Every subcommand, in the order the help lists them.
pub(crate) const COMMANDS: &[&command::Command] = &[
    &tpms::COMMAND,
    &strut::COMMAND,
    &voronoi::COMMAND,
    &fill::COMMAND,
    &check::COMMAND,
    &repair::COMMAND,
    &topopt::COMMAND,
    &homogenize::COMMAND,
    &interpret::COMMAND,
    &fgm::COMMAND,
    &render::COMMAND,
    &view::COMMAND,
    &slice::COMMAND,
    &batch::COMMAND,
];

/// Runs the command `name` (or a former name) on `args`, its options as they follow its name on
/// the command line (a part file's put in where `--part` names one); the exit code. For a
/// program that runs latvox's commands in its own process (the Python package).
#[allow(dead_code)] // the binary parses its whole command line itself
pub(crate) fn run_one(name: &str, args: Vec<String>, quiet: bool) -> Result<i32> {
    let command = command::find(name)
        .ok_or_else(|| latvox::Error::invalid(format!("unknown command '{name}'")))?;
    let args = match command.part {
        Some(_) => part::expand(command, args)?,
        None => args,
    };
    let matches = command
        .clap()
        .no_binary_name(true)
        .try_get_matches_from(args)
        .map_err(|e| {
            // The option a bad value was given to, as its name: "--density <DENSITY>" → density.
            let setting = e.get(clap::error::ContextKind::InvalidArg).map(|a| {
                a.to_string()
                    .trim_start_matches('-')
                    .split([' ', '='])
                    .next()
                    .unwrap_or_default()
                    .to_string()
            });
            match setting {
                Some(s) if !s.is_empty() && !s.starts_with('<') => {
                    latvox::Error::setting(s, clap_message(e))
                }
                _ => latvox::Error::invalid(clap_message(e)),
            }
        })?;
    execute(command, &matches, quiet)
}

/// Runs `command` on its parsed options (`quiet`: no progress) and writes the part file
/// `--save-part` asks for once the part is made; the exit code.
pub(crate) fn execute(
    command: &command::Command,
    sub: &clap::ArgMatches,
    quiet: bool,
) -> Result<i32> {
    // The part file is written once the part is made; its folder must take it.
    let save_part = sub.try_get_one::<PathBuf>("save_part").ok().flatten();
    if let Some(p) = save_part {
        latvox::io::atomic::check_writable(p)?;
    }
    let code = (command.run)(sub, quiet)?;
    if let Some(p) = save_part {
        part::save(p, command, sub)?;
    }
    Ok(code)
}

pub(crate) fn split3<T: Copy>(
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

pub(crate) fn parse_f64(s: &str) -> std::result::Result<f64, String> {
    s.parse::<f64>()
        .map_err(|_| format!("'{s}' is not a number"))
}

pub(crate) fn parse_positive(s: &str) -> std::result::Result<f64, String> {
    let v = parse_f64(s)?;
    if v > 0.0 && v.is_finite() {
        Ok(v)
    } else {
        Err(format!("{s} must be a positive length in mm"))
    }
}

pub(crate) fn parse_length0(s: &str) -> std::result::Result<f64, String> {
    let v = parse_f64(s)?;
    if v >= 0.0 && v.is_finite() {
        Ok(v)
    } else {
        Err(format!("{s} must be a length ≥ 0 mm"))
    }
}

pub(crate) fn parse_positive3(s: &str) -> std::result::Result<[f64; 3], String> {
    split3(s, |p| {
        let v = parse_f64(p)?;
        if v > 0.0 && v.is_finite() {
            Ok(v)
        } else {
            Err(format!("{p} must be a positive length in mm"))
        }
    })
}

pub(crate) fn parse_finite3(s: &str) -> std::result::Result<[f64; 3], String> {
    split3(s, |p| {
        let v = parse_f64(p)?;
        v.is_finite()
            .then_some(v)
            .ok_or_else(|| format!("{p} must be finite"))
    })
}

pub(crate) fn parse_counts(s: &str) -> std::result::Result<[u32; 3], String> {
    split3(s, |p| match p.parse::<u32>() {
        Ok(0) => Err("cell counts must be at least 1".to_string()),
        Ok(v) => Ok(v),
        Err(_) => Err(format!("'{p}' is not a whole number of cells")),
    })
}

pub(crate) fn parse_density(s: &str) -> std::result::Result<f64, String> {
    let v = parse_f64(s)?;
    if v > 0.0 && v < 1.0 {
        Ok(v)
    } else {
        Err(format!("density must be strictly between 0 and 1, got {s}"))
    }
}

pub(crate) fn parse_unit(s: &str) -> std::result::Result<f64, String> {
    let v = parse_f64(s)?;
    if (0.0..=1.0).contains(&v) {
        Ok(v)
    } else {
        Err(format!("must be in [0, 1], got {s}"))
    }
}

/// A size in bytes: a number with an optional K, M, G or T suffix (powers of 1024).
pub(crate) fn parse_size(s: &str) -> std::result::Result<u64, String> {
    let t = s.trim();
    let (num, mult) = match t.chars().last().map(|c| c.to_ascii_uppercase()) {
        Some('K') => (&t[..t.len() - 1], 1u64 << 10),
        Some('M') => (&t[..t.len() - 1], 1 << 20),
        Some('G') => (&t[..t.len() - 1], 1 << 30),
        Some('T') => (&t[..t.len() - 1], 1 << 40),
        _ => (t, 1),
    };
    match num.trim().parse::<f64>() {
        Ok(v) if v > 0.0 && v.is_finite() => Ok((v * mult as f64) as u64),
        _ => Err(format!("'{s}' is not a size (examples: 2G, 512M, 1000000)")),
    }
}

/// A tile edge in voxels: a multiple of 8, at least 16.
pub(crate) fn parse_tile(s: &str) -> std::result::Result<i64, String> {
    match s.trim().parse::<i64>() {
        Ok(v) if v >= 16 && v % 8 == 0 => Ok(v),
        _ => Err(format!(
            "tile must be a multiple of 8 voxels, at least 16, got '{s}'"
        )),
    }
}

/// A clap error as one line: its first line, with its tip where it gives one.
pub(crate) fn clap_message(e: clap::Error) -> String {
    let text = e.render().to_string();
    let mut lines = text.lines().map(str::trim).filter(|l| !l.is_empty());
    let first = lines.next().unwrap_or("invalid options");
    let first = first.strip_prefix("error: ").unwrap_or(first).to_string();
    match lines.find(|l| l.starts_with("tip:")) {
        Some(tip) => format!("{first} ({tip})"),
        None => first,
    }
}

pub(crate) fn write_json<T: serde::Serialize>(path: &Path, value: &T) -> Result<()> {
    latvox::io::atomic::write_json(path, value)
}

/// Writes `value` to `report` if given and prints it if `json`; returns whether it was printed
/// (the caller prints its human summary otherwise).
pub(crate) fn emit_json(
    report: Option<&Path>,
    json: bool,
    value: &impl serde::Serialize,
) -> Result<bool> {
    if let Some(r) = report {
        write_json(r, value)?;
    }
    if json {
        out::json(value);
    }
    Ok(json)
}

/// The findings of a verification (latvox's or CGAL's), as the summaries print them.
pub(crate) fn cgal_findings(c: &latvox::verify::cgal::Verification) -> String {
    if c.checked_by == latvox::verify::Verify::None.by() {
        return "not checked (--verify none)".into();
    }
    let refused = c
        .not_checked
        .map(|r| format!("  (not checked: {r})"))
        .unwrap_or_default();
    format!(
        "closed {}  outward {}  manifold {}  self-intersections {}{refused}",
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
    )
}

pub(crate) fn yes(b: bool) -> &'static str {
    if b {
        "yes"
    } else {
        "NO"
    }
}
