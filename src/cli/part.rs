//! Part files: the settings that define a part (`tpms`, `strut`, `fill` or `fgm`), saved as TOML with
//! `--save-part FILE.toml` and given back with `--part FILE.toml`, so that a part can be made
//! again, varied, or handed to another tool.
//!
//! A part file holds `command` and the subcommand's own long options, with the same names and
//! values as on the command line (`cell-size = [5.0, 5.0, 5.0]` is `--cell-size 5,5,5`). Given
//! with `--part`, its options come first and the command line's override them: an option given
//! on the command line replaces the file's (and `--radius` replaces the file's `--density`, and
//! the reverse). Where the file names a file by a relative path (a cell file, the part filled,
//! the solids kept), it is relative to the part file.

use super::clap_message;
use super::command::{find, names_with, Command};
use latvox::fill::traced::Traced;
use latvox::render::{Fidelity, Model};
use latvox::{Error, Result};
use std::path::Path;

/// Options naming files that define the part (the mesh filled, the solids kept, the scan):
/// saved as absolute paths, so that the part file makes the same part from any folder.
const PATHS: &[&str] = &["input", "keep", "points", "mesh"];

/// Whether the value of `key` names a file: an option of [`PATHS`], a cell file, a sampled
/// density field.
fn names_file(key: &str, value: &str) -> bool {
    let v = value.to_ascii_lowercase();
    PATHS.contains(&key)
        || (key == "cell" && v.ends_with(".json"))
        || ((key == "density-field" || key == "stiffness-field") && v.ends_with(".npy"))
}

/// Options that may be given several times: saved as lists.
const REPEATED: &[&str] = &["keep", "feature", "law"];

/// Options whose values may name a file after a kind (`curve:FILE`, `surface:FILE`,
/// `table:FILE`): the file is saved by its absolute path, and read relative to the part file.
const EMBEDDED: &[&str] = &["feature", "law"];

/// The file a value of an [`EMBEDDED`] option names, split from its kind.
fn embedded_file(v: &str) -> Option<(&str, &str)> {
    let (kind, file) = v.split_once(':')?;
    ["curve", "surface", "table"]
        .contains(&kind)
        .then_some((kind, file))
}

/// The options of the box and the meshing that define a lattice part in a box.
pub(crate) const LATTICE_BOX: &[&str] = &[
    "cells",
    "cell-size",
    "size",
    "origin",
    "resolution",
    "fixed-resolution",
    "adaptivity",
    "tolerance",
    "keep-fragments",
];

/// The options of the meshing that define a lattice part whose box is another part's.
pub(crate) const MESHING: &[&str] = &[
    "resolution",
    "fixed-resolution",
    "adaptivity",
    "tolerance",
    "keep-fragments",
];

/// Options that exclude each other: giving one on the command line drops the other from the
/// file.
const EXCLUSIVE: &[[&str; 2]] = &[
    ["density", "radius"],
    ["density", "density-grade"],
    ["density", "density-field"],
    ["radius", "density-grade"],
    ["radius", "density-field"],
    ["density-grade", "density-field"],
    ["density", "stiffness-field"],
    ["radius", "stiffness-field"],
    ["density-grade", "stiffness-field"],
    ["density-field", "stiffness-field"],
    ["density", "thickness"],
    ["radius", "thickness"],
    ["spacing-field", "seeds-in"],
    ["regularity", "seeds-in"],
    ["regularity", "spacing-field"],
];

/// The short forms of long options, to tell whether the command line gave one.
const SHORT: &[(&str, &str)] = &[("type", "-t"), ("density", "-d"), ("resolution", "-r")];

/// The settings a part of `command` holds (none for a command without part files).
pub(crate) fn keys(command: &Command) -> Vec<&'static str> {
    let Some(part) = command.part else {
        return Vec::new();
    };
    part.own.iter().chain(part.shared).copied().collect()
}

/// Writes the part file of `command` run with `matches`, atomically.
pub fn save(path: &Path, command: &Command, matches: &clap::ArgMatches) -> Result<()> {
    let cmd = command.clap();
    let mut table = toml::Table::new();
    table.insert("command".into(), toml::Value::String(command.name.into()));
    for key in keys(command) {
        // The option, or an argument of that name (`fill`'s PART, also given as `--input`).
        let ids = |key: &str| -> Vec<String> {
            cmd.get_arguments()
                .filter(|a| a.get_long() == Some(key) || a.get_id().as_str() == key)
                .map(|a| a.get_id().as_str().to_string())
                .collect()
        };
        let given = |key: &str| {
            ids(key).iter().any(|i| {
                matches!(
                    matches.value_source(i),
                    Some(s) if s != clap::parser::ValueSource::DefaultValue
                )
            })
        };
        // A default that an exclusive option given replaces (a density beside a graded one).
        let replaced = !given(key)
            && EXCLUSIVE
                .iter()
                .filter(|pair| pair.contains(&key))
                .flat_map(|pair| pair.iter())
                .any(|k| *k != key && given(k));
        let raw = ids(key)
            .into_iter()
            .find_map(|i| matches.try_get_raw(&i).ok().flatten());
        let Some(raw) = raw.filter(|_| !replaced) else {
            continue;
        };
        let mut raw: Vec<String> = raw.map(|v| v.to_string_lossy().into_owned()).collect();
        let full = |v: &str| -> Result<String> {
            let p = Path::new(v);
            Ok(p.canonicalize()
                .map_err(|e| Error::io(p, e))?
                .display()
                .to_string())
        };
        for v in raw.iter_mut() {
            if names_file(key, v) {
                *v = full(v)?;
            }
        }
        if EMBEDDED.contains(&key) {
            for v in raw.iter_mut() {
                if let Some((kind, file)) = embedded_file(v) {
                    *v = format!("{kind}:{}", full(file)?);
                }
            }
        }
        let value = match raw.as_slice() {
            [v] if PATHS.contains(&key) => toml::Value::String(v.clone()),
            _ if REPEATED.contains(&key) => {
                toml::Value::Array(raw.iter().map(|v| toml::Value::String(v.clone())).collect())
            }
            // A switch: kept only when on.
            [v] if v == "true" || v == "false" => {
                if v == "false" {
                    continue;
                }
                toml::Value::Boolean(true)
            }
            [v] => value_of(v),
            _ => continue,
        };
        table.insert(key.into(), value);
    }
    write(path, &table)
}

/// Writes a part file's table (`command` and the settings), atomically.
pub(crate) fn write(path: &Path, table: &toml::Table) -> Result<()> {
    let command = table
        .get("command")
        .and_then(toml::Value::as_str)
        .unwrap_or_default();
    let text = format!(
        "# A latvox part: `latvox {command} --part {}` makes it again; options given on the command\n# line override these.\n{}",
        path.file_name().map_or(String::new(), |f| f.to_string_lossy().into_owned()),
        toml::to_string(table).map_err(|e| Error::invalid(e.to_string()))?
    );
    latvox::io::atomic::write_atomic(path, |w| w.write_all(text.as_bytes()))
}

/// `table` with the files it names by relative paths (relative to the part file at `path`)
/// named by absolute ones, so that it can be written anywhere.
pub(crate) fn absolute(mut table: toml::Table, path: &Path) -> toml::Table {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let dir = dir.canonicalize().unwrap_or_else(|_| dir.to_path_buf());
    let fix = |v: &mut toml::Value| {
        if let toml::Value::String(s) = v {
            if Path::new(s.as_str()).is_relative() {
                *s = dir.join(s.as_str()).display().to_string();
            }
        }
    };
    for (key, value) in table.iter_mut() {
        let key = key.replace('_', "-");
        let file = value.as_str().is_some_and(|v| names_file(&key, v));
        if PATHS.contains(&key.as_str()) || file {
            match value {
                toml::Value::Array(items) => items.iter_mut().for_each(fix),
                v => fix(v),
            }
        }
    }
    table
}

/// A command-line value as TOML: a number, a list of numbers (`4,4,2`), or a string.
fn value_of(v: &str) -> toml::Value {
    let number = |s: &str| -> Option<toml::Value> {
        let s = s.trim();
        s.parse::<i64>()
            .map(toml::Value::Integer)
            .ok()
            .or_else(|| s.parse::<f64>().ok().map(toml::Value::Float))
    };
    if let Some(n) = number(v) {
        return n;
    }
    if v.contains(',') {
        let items: Option<Vec<toml::Value>> = v.split(',').map(number).collect();
        if let Some(items) = items {
            return toml::Value::Array(items);
        }
    }
    toml::Value::String(v.into())
}

/// A TOML value as a command-line value.
fn arg_of(v: &toml::Value) -> Option<String> {
    Some(match v {
        toml::Value::String(s) => s.clone(),
        toml::Value::Integer(i) => i.to_string(),
        toml::Value::Float(f) => f.to_string(),
        toml::Value::Boolean(b) => b.to_string(),
        toml::Value::Array(a) => a.iter().map(arg_of).collect::<Option<Vec<_>>>()?.join(","),
        _ => return None,
    })
}

/// A part file's table.
pub(crate) fn read(path: &Path) -> Result<toml::Table> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    text.parse().map_err(|e: toml::de::Error| {
        Error::invalid(format!(
            "{}: not a part file: {}",
            path.display(),
            e.message()
        ))
    })
}

/// `argv` (a subcommand's arguments, after its name) with the options of the part file it
/// names with `--part` put in front, those the command line gives itself left out.
pub fn expand(command: &Command, argv: Vec<String>) -> Result<Vec<String>> {
    let at = argv
        .iter()
        .position(|a| a == "--part" || a.starts_with("--part="));
    let Some(at) = at else { return Ok(argv) };
    let path = match argv[at].strip_prefix("--part=") {
        Some(p) => p.to_string(),
        None => argv
            .get(at + 1)
            .cloned()
            .ok_or_else(|| Error::invalid("--part needs a part file (FILE.toml)"))?,
    };
    let path = Path::new(&path);
    expand_table(command, argv, &read(path)?, path)
}

/// `argv` with the options of a part file's `table` (the file at `path`, which files it names
/// are relative to) put in front, those the command line gives itself left out.
fn expand_table(
    command: &Command,
    argv: Vec<String>,
    table: &toml::Table,
    path: &Path,
) -> Result<Vec<String>> {
    match table.get("command").and_then(toml::Value::as_str) {
        Some(c) if command.is(c) => {}
        Some(c) => {
            return Err(Error::invalid(format!(
                "{} is a part of `latvox {c}`, not of `latvox {}`",
                path.display(),
                command.name
            )))
        }
        None => {
            return Err(Error::invalid(format!(
                "{}: a part file needs `command` ({})",
                path.display(),
                names_with(|c| c.part.is_some())
            )))
        }
    }
    let given = |key: &str| {
        let long = format!("--{key}");
        let short = SHORT.iter().find(|(k, _)| *k == key).map(|(_, s)| *s);
        argv.iter().any(|a| {
            a == &long
                || a.starts_with(&format!("{long}="))
                || short.is_some_and(|s| a == s || (a.starts_with(s) && !a.starts_with("--")))
        })
    };
    let mut front = Vec::new();
    for (key, value) in table {
        if key == "command" {
            continue;
        }
        let key = key.replace('_', "-");
        if !keys(command).contains(&key.as_str()) {
            return Err(Error::invalid(format!(
                "{}: '{key}' is not a setting of a {} part (settings: {})",
                path.display(),
                command.name,
                keys(command).join(", ")
            )));
        }
        let excluded = EXCLUSIVE
            .iter()
            .filter(|pair| pair.contains(&key.as_str()))
            .flat_map(|pair| pair.iter())
            .any(|k| given(k));
        if given(&key) || excluded {
            continue;
        }
        let mut arg = arg_of(value).ok_or_else(|| {
            Error::invalid(format!(
                "{}: '{key}' is not a value an option takes",
                path.display()
            ))
        })?;
        // Files the part file names by a relative path are relative to it.
        let names_file = names_file(&key, &arg);
        let beside = |file: &str| match path.parent() {
            Some(dir) if names_file && Path::new(file).is_relative() => {
                dir.join(file).display().to_string()
            }
            Some(dir) if EMBEDDED.contains(&key.as_str()) => match embedded_file(file) {
                Some((kind, f)) if Path::new(f).is_relative() => {
                    format!("{kind}:{}", dir.join(f).display())
                }
                _ => file.to_string(),
            },
            _ => file.to_string(),
        };
        if !matches!(value, toml::Value::Array(_)) {
            arg = beside(&arg);
        }
        match value {
            // A switch in the file: on when true.
            toml::Value::Boolean(true) => front.push(format!("--{key}")),
            toml::Value::Boolean(false) => {}
            // A repeated option: once per item.
            toml::Value::Array(items) if items.iter().all(toml::Value::is_str) => {
                for item in items {
                    front.push(format!(
                        "--{key}={}",
                        beside(item.as_str().unwrap_or_default())
                    ));
                }
            }
            _ => front.push(format!("--{key}={arg}")),
        }
    }
    front.extend(argv);
    Ok(front)
}

/// What a part file describes, ready to trace: a lattice block as an implicit model, or a
/// filled part as its meshes and lattice.
pub(crate) enum Part {
    /// A TPMS or strut part.
    Block(Box<Model>),
    /// A filled part.
    Filled(Box<Traced>),
}

/// A part file's part, modelled for `fidelity`.
pub(crate) fn part_of(path: &Path, fidelity: Fidelity) -> Result<Part> {
    part_of_table(&read(path)?, path, fidelity)
}

/// The part of a part file's `table` (the file at `path`, which files it names are relative
/// to).
pub(crate) fn part_of_table(table: &toml::Table, path: &Path, fidelity: Fidelity) -> Result<Part> {
    let command = table
        .get("command")
        .and_then(toml::Value::as_str)
        .unwrap_or_default()
        .to_string();
    // A setting the part file gives wrongly: said of the part file.
    let named = |e: Error| {
        let name = path.display().to_string();
        if e.to_string().contains(&name) {
            e
        } else {
            e.prefixed(&name)
        }
    };
    part_from(&command, table, path, fidelity).map_err(named)
}

fn part_from(command: &str, table: &toml::Table, path: &Path, fidelity: Fidelity) -> Result<Part> {
    let (command, trace) = match find(command) {
        Some(c @ Command { trace: Some(t), .. }) => (c, *t),
        Some(c) => {
            return Err(Error::invalid(format!(
                "{}: a `latvox {}` part is drawn and sliced from its mesh, not its settings: make it with `latvox {} --part {} -o part.stl`, then use part.stl (parts traced from their settings: {})",
                path.display(),
                c.name,
                c.name,
                path.display(),
                names_with(|c| c.trace.is_some())
            )))
        }
        None => {
            return Err(Error::invalid(format!(
                "{}: a part file needs `command` ({})",
                path.display(),
                names_with(|c| c.trace.is_some())
            )))
        }
    };
    let argv = expand_table(command, Vec::new(), table, path)?;
    let m = command
        .parser()
        .try_get_matches_from(argv)
        .map_err(|e| Error::invalid(clap_message(e)))?;
    trace(&m, fidelity)
}

pub(crate) fn is_part_file(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("toml"))
}
