//! The job file: TOML with `[[job]]` tables (one job each), `[[sweep]]` tables (lists expanded to
//! their product) and an optional `[defaults]` table merged into both.
//!
//! ```toml
//! [defaults]
//! resolution = 32
//!
//! [[job]]
//! command = "tpms"            # the latvox subcommand that writes the part
//! output = "out/g-030.stl"    # relative to the job file
//! type = "gyroid"             # then the subcommand's long options, same names and values
//! density = 0.3
//! cells = [4, 4, 2]           # a list is one value: --cells 4,4,2
//!
//! [[sweep]]
//! command = "tpms"
//! output = "out/{type}-{density}.stl"
//! type = ["gyroid", "d"]      # in a sweep every list is an axis: 2 × 3 jobs
//! density = [0.2, 0.3, 0.4]
//! cells = [[4, 4, 2]]         # a list value inside a sweep: a list of lists (or "4,4,2")
//! ```
//!
//! Jobs come in a fixed order — every `[[job]]` in file order, then every `[[sweep]]`'s variants,
//! the first listed axis varying slowest — so a job's number is stable and shards are
//! reproducible. Keys may be written `cell-size` or `cell_size`. `report` (where the job's JSON
//! report goes; default: the output's name with `.json`) belongs to the batch, not to the
//! subcommand.

use super::resume;
use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

/// One option value, as the job file gives it.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    /// A string.
    Str(String),
    /// An integer.
    Int(i64),
    /// A floating-point number.
    Float(f64),
    /// A boolean (a flag).
    Bool(bool),
    /// A list, one value on the command line (comma-separated).
    List(Vec<Value>),
}

impl Value {
    /// The value as it is written on the command line: lists comma-separated.
    pub fn to_arg(&self) -> String {
        self.render(",")
    }

    /// The value inside a file name: lists joined by `x` (`4x4x2`).
    pub fn to_name(&self) -> String {
        self.render("x")
    }

    fn render(&self, sep: &str) -> String {
        match self {
            Value::Str(s) => s.clone(),
            Value::Int(i) => i.to_string(),
            // Rust prints the shortest text that reads back to the same number: 0.3 → "0.3".
            Value::Float(f) => f.to_string(),
            Value::Bool(b) => b.to_string(),
            Value::List(v) => v
                .iter()
                .map(|x| x.render(sep))
                .collect::<Vec<_>>()
                .join(sep),
        }
    }

    fn to_json(&self) -> serde_json::Value {
        match self {
            Value::Str(s) => s.clone().into(),
            Value::Int(i) => (*i).into(),
            Value::Float(f) => (*f).into(),
            Value::Bool(b) => (*b).into(),
            Value::List(v) => v.iter().map(Value::to_json).collect(),
        }
    }
}

/// One job of the batch, after sweeps are expanded and defaults merged.
#[derive(Debug, Clone)]
pub struct Job {
    /// Position in the batch, from 0: stable for a given job file.
    pub index: usize,
    /// Where it comes from, for messages: `job 3` or `sweep 1, variant 5` (counted from 1).
    pub origin: String,
    /// The latvox subcommand.
    pub command: String,
    /// The output as the job file gives it (relative to the job file's folder).
    pub output: String,
    /// The report, relative to the job file's folder.
    pub report: String,
    /// The subcommand's options (key without dashes, value), in file order; `output` included.
    pub options: Vec<(String, Value)>,
    /// Stable hash of the command and its options: the job's identity for resuming.
    pub hash: String,
}

impl Job {
    /// The options as a JSON object, for reports and summaries.
    pub fn options_json(&self) -> serde_json::Value {
        let mut m = serde_json::Map::new();
        for (k, v) in &self.options {
            m.insert(k.clone(), v.to_json());
        }
        serde_json::Value::Object(m)
    }
}

/// A parsed job file: its folder (every relative path is relative to it) and its jobs.
#[derive(Debug, Clone)]
pub struct JobFile {
    /// The job file, as given.
    pub path: PathBuf,
    /// Its folder (`.` when the path has none).
    pub dir: PathBuf,
    /// The jobs, sweeps expanded, in batch order.
    pub jobs: Vec<Job>,
}

impl JobFile {
    /// Reads and expands the job file at `path`.
    pub fn load(path: &Path) -> Result<JobFile> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        let jobs = parse(&text).map_err(|e| e.in_file(path))?;
        let dir = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        Ok(JobFile {
            path: path.to_path_buf(),
            dir,
            jobs,
        })
    }

    /// `path` relative to the job file's folder (absolute paths are kept).
    pub fn resolve(&self, path: impl AsRef<Path>) -> PathBuf {
        self.dir.join(path)
    }
}

type Table = Vec<(String, toml::Value)>;

/// Parses job-file text into its expanded jobs; errors are one line, with the line number.
pub fn parse(text: &str) -> Result<Vec<Job>> {
    let doc: toml::Table = text.parse().map_err(|e: toml::de::Error| {
        let line = e
            .span()
            .map(|s| format!("line {}: ", text[..s.start].lines().count().max(1)))
            .unwrap_or_default();
        Error::parse(format!("{line}{}", e.message().trim()))
    })?;
    let mut defaults = Table::new();
    let mut job_tables = Vec::new();
    let mut sweep_tables = Vec::new();
    for (key, value) in doc {
        match (key.as_str(), value) {
            ("defaults", toml::Value::Table(t)) => defaults = normalise(t, "[defaults]")?,
            ("job", toml::Value::Array(a)) => job_tables = tables(a, "job")?,
            ("sweep", toml::Value::Array(a)) => sweep_tables = tables(a, "sweep")?,
            (k, _) => {
                return Err(Error::parse(format!(
                    "unexpected '{k}': a job file holds [[job]] and [[sweep]] tables and one [defaults] table"
                )))
            }
        }
    }
    if job_tables.is_empty() && sweep_tables.is_empty() {
        return Err(Error::parse(
            "no [[job]] or [[sweep]] table: nothing to run",
        ));
    }

    let mut jobs = Vec::new();
    for (i, t) in job_tables.into_iter().enumerate() {
        let origin = format!("job {}", i + 1);
        let t = with_defaults(normalise(t, &origin)?, &defaults);
        let mut options = Vec::new();
        for (k, v) in t {
            let v = value(&v).map_err(|m| Error::parse(format!("{origin}: '{k}': {m}")))?;
            options.push((k, v));
        }
        jobs.push(make_job(jobs.len(), origin, options)?);
    }
    for (i, t) in sweep_tables.into_iter().enumerate() {
        let name = format!("sweep {}", i + 1);
        let t = with_defaults(normalise(t, &name)?, &defaults);
        // Each key's values: one for a scalar, the list's elements for a list.
        let mut axes: Vec<(String, Vec<Value>)> = Vec::new();
        for (k, v) in t {
            let values = match &v {
                toml::Value::Array(a) if k != "output" && k != "command" => {
                    if a.is_empty() {
                        return Err(Error::parse(format!(
                            "{name}: '{k}' is an empty list: nothing to sweep"
                        )));
                    }
                    a.iter()
                        .map(value)
                        .collect::<std::result::Result<Vec<_>, _>>()
                        .map_err(|m| Error::parse(format!("{name}: '{k}': {m}")))?
                }
                _ => vec![value(&v).map_err(|m| Error::parse(format!("{name}: '{k}': {m}")))?],
            };
            axes.push((k, values));
        }
        let variants: usize = axes.iter().map(|(_, v)| v.len()).product();
        for n in 0..variants {
            // Mixed-radix digits of n, the last axis varying fastest.
            let mut rest = n;
            let mut options = vec![(String::new(), Value::Bool(false)); axes.len()];
            for (slot, (k, values)) in options.iter_mut().zip(&axes).rev() {
                *slot = (k.clone(), values[rest % values.len()].clone());
                rest /= values.len();
            }
            let origin = format!("{name}, variant {}", n + 1);
            jobs.push(make_job(jobs.len(), origin, options)?);
        }
    }
    check_distinct(&jobs)?;
    Ok(jobs)
}

fn tables(a: Vec<toml::Value>, what: &str) -> Result<Vec<toml::Table>> {
    a.into_iter()
        .map(|v| match v {
            toml::Value::Table(t) => Ok(t),
            _ => Err(Error::parse(format!(
                "'{what}' must be written as [[{what}]] tables"
            ))),
        })
        .collect()
}

/// Keys with `_` read as `-` (clap's long names), refusing a key given both ways.
fn normalise(t: toml::Table, origin: &str) -> Result<Table> {
    let mut out: Table = Vec::new();
    for (k, v) in t {
        let key = k.replace('_', "-");
        if out.iter().any(|(o, _)| *o == key) {
            return Err(Error::parse(format!("{origin}: '{key}' is given twice")));
        }
        out.push((key, v));
    }
    Ok(out)
}

fn with_defaults(mut t: Table, defaults: &Table) -> Table {
    for (k, v) in defaults {
        if !t.iter().any(|(o, _)| o == k) {
            t.push((k.clone(), v.clone()));
        }
    }
    t
}

fn value(v: &toml::Value) -> Result<Value> {
    Ok(match v {
        toml::Value::String(s) => Value::Str(s.clone()),
        toml::Value::Integer(i) => Value::Int(*i),
        toml::Value::Float(f) if f.is_finite() => Value::Float(*f),
        toml::Value::Float(f) => return Err(Error::parse(format!("{f} is not a finite number"))),
        toml::Value::Boolean(b) => Value::Bool(*b),
        toml::Value::Array(a) => Value::List(
            a.iter()
                .map(|x| match x {
                    toml::Value::Array(_) | toml::Value::Table(_) => Err(Error::parse(
                        "a list inside a list is only allowed in a [[sweep]]",
                    )),
                    x => value(x),
                })
                .collect::<std::result::Result<_, _>>()?,
        ),
        toml::Value::Datetime(_) => return Err(Error::parse("dates are not option values")),
        toml::Value::Table(_) => return Err(Error::parse("a table is not an option value")),
    })
}

fn make_job(index: usize, origin: String, options: Vec<(String, Value)>) -> Result<Job> {
    let text = |key: &str| -> Result<Option<String>> {
        match options.iter().find(|(k, _)| k == key) {
            None => Ok(None),
            Some((_, Value::Str(s))) if !s.trim().is_empty() => Ok(Some(s.clone())),
            Some(_) => Err(Error::parse(format!(
                "{origin}: '{key}' must be a non-empty string"
            ))),
        }
    };
    let command = text("command")?.ok_or_else(|| {
        Error::parse(format!(
            "{origin}: no 'command' (the latvox subcommand to run, e.g. command = \"tpms\")"
        ))
    })?;
    let pattern = text("output")?
        .ok_or_else(|| Error::parse(format!("{origin}: no 'output' (the file the job writes)")))?;
    let report_pattern = text("report")?;
    let mut options: Vec<(String, Value)> = options
        .into_iter()
        .filter(|(k, _)| k != "command" && k != "report")
        .collect();
    let output =
        expand(&pattern, &options).map_err(|m| Error::parse(format!("{origin}: output: {m}")))?;
    for (k, v) in options.iter_mut() {
        if k == "output" {
            *v = Value::Str(output.clone());
        }
    }
    let report = match report_pattern {
        Some(p) => {
            expand(&p, &options).map_err(|m| Error::parse(format!("{origin}: report: {m}")))?
        }
        None => {
            let p = Path::new(&output);
            if p.extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("json"))
            {
                return Err(Error::parse(format!(
                    "{origin}: the output '{output}' is a .json file; give the report its own name with report = \"...\""
                )));
            }
            p.with_extension("json").to_string_lossy().into_owned()
        }
    };
    let hash = resume::job_hash(&command, &options);
    Ok(Job {
        index,
        origin,
        command,
        output,
        report,
        options,
        hash,
    })
}

/// Fills `{key}` in an output pattern with that option's value (lists as `4x4x2`).
fn expand(pattern: &str, options: &[(String, Value)]) -> Result<String> {
    let mut out = String::new();
    let mut rest = pattern;
    while let Some(open) = rest.find(['{', '}']) {
        out.push_str(&rest[..open]);
        if rest[open..].starts_with('}') {
            return Err(Error::parse(format!("'}}' without '{{' in '{pattern}'")));
        }
        let close = rest[open..]
            .find('}')
            .ok_or_else(|| Error::parse(format!("'{{' without '}}' in '{pattern}'")))?
            + open;
        let key = rest[open + 1..close].trim().replace('_', "-");
        let v = options
            .iter()
            .find(|(k, _)| *k == key && k != "output")
            .ok_or_else(|| Error::parse(format!("'{{{key}}}' names no option of this job")))?;
        out.push_str(&v.1.to_name());
        rest = &rest[close + 1..];
    }
    out.push_str(rest);
    Ok(out)
}

/// Two jobs writing the same file would overwrite each other: refuse before running anything.
fn check_distinct(jobs: &[Job]) -> Result<()> {
    let mut seen: std::collections::HashMap<PathBuf, (usize, &str)> = Default::default();
    for j in jobs {
        for (what, p) in [("output", &j.output), ("report", &j.report)] {
            if let Some((other, other_what)) = seen.insert(lexical(p), (j.index, what)) {
                let o = &jobs[other];
                let hint = if o.origin.starts_with("sweep") && j.origin.starts_with("sweep") {
                    " (the output pattern must tell the sweep's variants apart: add a {key} for every list)"
                } else {
                    ""
                };
                return Err(Error::parse(format!(
                    "{} and {} both write '{p}' (as {other_what} and {what}){hint}",
                    o.origin, j.origin
                )));
            }
        }
    }
    Ok(())
}

/// A path with `.` parts and repeated separators dropped, and `dir/..` folded, for comparing.
fn lexical(p: &str) -> PathBuf {
    use std::path::Component;
    let mut out = PathBuf::new();
    for c in Path::new(p).components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir
                if matches!(out.components().next_back(), Some(Component::Normal(_))) =>
            {
                out.pop();
            }
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn arg(j: &Job, k: &str) -> String {
        j.options.iter().find(|(o, _)| o == k).unwrap().1.to_arg()
    }

    #[test]
    fn job_values_become_command_line_text() {
        let jobs = parse(
            r#"
            [[job]]
            command = "tpms"
            output = "out/g.stl"
            type = "gyroid"
            density = 0.3
            cells = [4, 4, 2]
            cell_size = 5
            allow-islands = true
            "#,
        )
        .unwrap();
        assert_eq!(jobs.len(), 1);
        let j = &jobs[0];
        assert_eq!(j.command, "tpms");
        assert_eq!(j.output, "out/g.stl");
        assert_eq!(j.report, "out/g.json");
        assert_eq!(arg(j, "density"), "0.3");
        assert_eq!(arg(j, "cells"), "4,4,2");
        assert_eq!(arg(j, "cell-size"), "5");
        assert_eq!(arg(j, "allow-islands"), "true");
        assert_eq!(arg(j, "output"), "out/g.stl");
    }

    #[test]
    fn sweep_is_the_product_in_file_order() {
        let jobs = parse(
            r#"
            [defaults]
            resolution = 16
            [[job]]
            command = "tpms"
            output = "single.stl"
            [[sweep]]
            command = "tpms"
            output = "out/{type}-{density}-{cells}.stl"
            type = ["gyroid", "d"]
            density = [0.2, 0.3, 0.4]
            cells = [[4, 4, 2]]
            "#,
        )
        .unwrap();
        assert_eq!(jobs.len(), 1 + 6);
        let outs: Vec<&str> = jobs.iter().map(|j| j.output.as_str()).collect();
        assert_eq!(
            outs,
            [
                "single.stl",
                "out/gyroid-0.2-4x4x2.stl",
                "out/gyroid-0.3-4x4x2.stl",
                "out/gyroid-0.4-4x4x2.stl",
                "out/d-0.2-4x4x2.stl",
                "out/d-0.3-4x4x2.stl",
                "out/d-0.4-4x4x2.stl",
            ]
        );
        assert!(jobs.iter().all(|j| arg(j, "resolution") == "16"));
        assert_eq!(arg(&jobs[3], "cells"), "4,4,2");
        assert_eq!(jobs[6].origin, "sweep 1, variant 6");
        assert_eq!(
            jobs.iter().map(|j| j.index).collect::<Vec<_>>(),
            (0..7).collect::<Vec<_>>()
        );
    }

    #[test]
    fn hash_follows_the_parameters_not_their_spelling() {
        let a =
            parse("[[job]]\ncommand='tpms'\noutput='a.stl'\ndensity=0.3\ncell_size=5\n").unwrap();
        let b =
            parse("[[job]]\noutput='a.stl'\ncell-size=5\ndensity=0.30\ncommand='tpms'\n").unwrap();
        let c =
            parse("[[job]]\ncommand='tpms'\noutput='a.stl'\ndensity=0.31\ncell_size=5\n").unwrap();
        assert_eq!(a[0].hash, b[0].hash);
        assert_ne!(a[0].hash, c[0].hash);
        assert_eq!(a[0].hash.len(), 64);
    }

    #[test]
    fn bad_files_are_refused_with_a_reason() {
        let cases = [
            ("[[job]]\ncommand='tpms'\n", "no 'output'"),
            ("[[job]]\noutput='a.stl'\n", "no 'command'"),
            ("[[jobs]]\ncommand='tpms'\n", "unexpected 'jobs'"),
            ("", "nothing to run"),
            ("[[job]]\ncommand='tpms'\noutput='a.stl'\ncells=[[1]]\n", "only allowed in a [[sweep]]"),
            (
                "[[sweep]]\ncommand='tpms'\noutput='a.stl'\ndensity=[0.2,0.3]\n",
                "sweep 1, variant 1 and sweep 1, variant 2 both write 'a.stl'",
            ),
            ("[[sweep]]\ncommand='tpms'\noutput='{x}.stl'\n", "'{x}' names no option"),
            ("[[sweep]]\ncommand='tpms'\noutput='a.stl'\ndensity=[]\n", "empty list"),
            ("[[job]]\ncommand='tpms'\noutput='a.json'\n", "give the report its own name"),
            (
                "[[job]]\ncommand='tpms'\noutput='a.stl'\n[[job]]\ncommand='tpms'\noutput='./x/../a.stl'\n",
                "job 1 and job 2 both write",
            ),
            ("[[job]]\ncommand='tpms'\noutput='a.stl'\ncell_size=1\ncell-size=2\n", "given twice"),
            ("[[job]]\ncommand = 'tpms'\noutput = \n", "line 3"),
        ];
        for (text, want) in cases {
            let e = parse(text).unwrap_err().to_string();
            assert!(e.contains(want), "{text:?}: got {e:?}, want {want:?}");
            assert!(!e.contains('\n'), "{e:?}");
        }
    }
}
