//! `latvox batch JOBS.toml`: many part-making jobs from one job file, in one process.
//!
//! Each job's table becomes its subcommand's long options (`cells = [4, 4, 2]` → `--cells=4,4,2`,
//! `ascii = true` → `--ascii`, `input = "a.npy"` → the positional input) and is parsed by that
//! subcommand's own clap `Args` — the very parser of `latvox tpms ...`, `latvox interpret ...` or
//! `latvox repair ...` — and run in-process by the same code as the subcommand. Every job
//! is parsed before any runs, so a typo in the last job stops the batch at once, not hours in.
//! The library ([`latvox::batch`]) does the rest: shards, resuming, workers, reports, summary.
//!
//! A subcommand joins the batch by implementing [`Task`] for its arguments and naming it in its
//! [`Command`]'s `job`.

use super::clap_message;
use super::command::{find, names_with, parsed, Command};
use super::out::outln;
use clap::Args;
use latvox::batch::{self, Event, Job, JobFile, Settings, Shard, Status, Task, Value};
use latvox::progress::Progress;
use latvox::{Error, Result};
use std::path::{Path, PathBuf};

pub(crate) const EXAMPLES: &str = "\
Job file (paths relative to it; keys are the subcommand's long options; a [defaults] table
holds options every job of the file takes):
  [[job]]
  command = \"tpms\"
  output = \"out/g-030.stl\"       # the report goes to out/g-030.json
  type = \"gyroid\"
  structure = \"net\"
  density = 0.3
  cells = [4, 4, 2]              # --cells 4,4,2
  cell-size = 5
  resolution = 32

  [[sweep]]                      # every list is an axis: 2 × 3 = 6 jobs
  command = \"tpms\"
  output = \"out/{type}-{density}.stl\"
  type = [\"gyroid\", \"d\"]
  density = [0.2, 0.3, 0.4]
  cells = 3

  [[job]]
  command = \"interpret\"          # a density field to a printable part
  input = \"bracket.npy\"
  output = \"out/bracket.stl\"
  element-size = 2
  min-feature = 3
  iges = \"out/bracket.igs\"       # every file the job writes is an output

  [[job]]
  command = \"repair\"             # a mesh file mended
  input = \"scan.stl\"
  output = \"out/scan-fixed.stl\"
  drop-open-shells = true

  [[job]]
  command = \"slice\"              # a mesh cut into layers for the printer
  input = \"out/bracket.stl\"
  output = \"out/bracket.cli\"
  layer = 0.05
  csv = \"out/bracket-layers.csv\"

Jobs run the subcommands that make a part — tpms, strut, fill, fgm, interpret and repair —
and slice, with the options of `latvox tpms`, `latvox strut`, `latvox fill`, `latvox fgm`,
`latvox interpret`, `latvox repair` and `latvox slice` (`input` is the input file; a slice job
passes when every loop closed).

Examples:
  latvox batch jobs.toml                       # run all jobs, 1 worker per thread
  latvox batch jobs.toml --workers 2 --threads 8
  latvox batch jobs.toml --dry-run             # list the jobs and which are done
  latvox batch jobs.toml --shard 2/4           # every 4th job, from the 2nd
  sbatch --array=0-3 --wrap 'latvox batch jobs.toml'   # shard from SLURM_ARRAY_TASK_*

Each job writes its outputs, then its JSON report (the subcommand's report, with a `batch`
record: parameter hash, run id, times, host), all atomically. A job passes when its subcommand
would exit 0: the part is a valid closed, outward solid and meets what the job asked for
(density, one piece, printable features); otherwise it is recorded as having defects. Running
again skips jobs whose report has the same parameter hash and whose outputs are intact, so a
killed batch resumes where it stopped; failed jobs run again. The summary goes to
JOBS-summary.csv and .json beside the job file.
Exit code 0 when every job is done, 1 when some failed or found defects, 2 when the job file
or an option is wrong (nothing is run).";

/// `latvox batch`.
pub(crate) const COMMAND: Command = Command::new(
    "batch",
    "Run many jobs from a TOML job file: sweeps, workers, resume after a kill, Slurm arrays",
    EXAMPLES,
    <BatchArgs as clap::Args>::augment_args,
    |m, quiet| run(&parsed(m)?, quiet),
);

#[derive(Args)]
pub struct BatchArgs {
    /// Job file (TOML) with [[job]] and [[sweep]] tables.
    #[arg(value_name = "JOBS.toml")]
    pub jobs: PathBuf,
    /// Jobs run at once (default: one per thread). Each job's own parallel work shares the
    /// --threads pool; lower this when jobs are large, to bound memory.
    #[arg(long, short = 'w', value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
    pub workers: Option<u32>,
    /// Run only shard K of N (every N-th job from the K-th). Default under a Slurm job array:
    /// from SLURM_ARRAY_TASK_ID, _MIN, _STEP and _COUNT; --shard 1/1 runs the whole batch.
    #[arg(long, value_name = "K/N", value_parser = parse_shard)]
    pub shard: Option<Shard>,
    /// Run every job, even those already done.
    #[arg(long)]
    pub force: bool,
    /// List the jobs (of this shard) and whether each is done; run nothing.
    #[arg(long)]
    pub dry_run: bool,
    /// Summary files: FILE.csv and FILE.json (default: beside the job file, JOBS-summary, with
    /// -shard-K-of-N added when sharded).
    #[arg(long, value_name = "FILE")]
    pub summary: Option<PathBuf>,
    /// Print the summary (or with --dry-run, the job list) as JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

fn parse_shard(s: &str) -> std::result::Result<Shard, String> {
    Shard::parse(s).map_err(|e| e.to_string())
}

/// Parses `job` with the clap arguments of its subcommand, `command`.
fn parse_job(command: &Command, job: &Job) -> std::result::Result<Box<dyn Task>, String> {
    let (Some(task), mut cmd) = (command.job, command.parser()) else {
        return Err(format!("`latvox {}` cannot run as a job", command.name));
    };
    let argv = command_line(&cmd, job)?;
    // A job may name a part file (`part = "octet.toml"`): its settings, the job's own first.
    let argv = match command.part {
        Some(_) => super::part::expand(command, argv).map_err(|e| e.to_string())?,
        None => argv,
    };
    let matches = cmd.try_get_matches_from_mut(argv).map_err(clap_message)?;
    task(&matches).map_err(|e| e.to_string())
}

/// The job's options as the subcommand's command line: `key = v` → `--key=v` (so a value such
/// as `-5,0,0` is not read as an option), switches only when true, positional arguments by name.
fn command_line(cmd: &clap::Command, job: &Job) -> std::result::Result<Vec<String>, String> {
    let mut argv = Vec::new();
    let mut positionals: Vec<(usize, Vec<String>)> = Vec::new();
    for (key, value) in &job.options {
        if let Some(arg) = cmd.get_arguments().find(|a| a.get_long() == Some(key)) {
            if arg.get_action().takes_values() {
                argv.push(format!("--{key}={}", value.to_arg()));
            } else {
                match value {
                    Value::Bool(true) => argv.push(format!("--{key}")),
                    Value::Bool(false) => {}
                    _ => {
                        return Err(format!(
                            "'{key}' is a switch: write {key} = true (or false)"
                        ))
                    }
                }
            }
        } else if let Some(arg) = cmd
            .get_positionals()
            .find(|a| a.get_id().as_str().replace('_', "-") == *key)
        {
            let values = match value {
                Value::List(v) => v.iter().map(Value::to_arg).collect(),
                v => vec![v.to_arg()],
            };
            positionals.push((arg.get_index().unwrap_or(usize::MAX), values));
        } else {
            // Not an option of this subcommand: clap says so, with its suggestion.
            argv.push(format!("--{key}={}", value.to_arg()));
        }
    }
    positionals.sort_by_key(|p| p.0);
    if !positionals.is_empty() {
        argv.push("--".into());
        argv.extend(positionals.into_iter().flat_map(|p| p.1));
    }
    Ok(argv)
}

/// clap's error as one line, keeping its "similar argument" tip.
fn task_for(job: &Job) -> Result<Box<dyn Task>> {
    let command = find(&job.command)
        .filter(|c| c.job.is_some())
        .ok_or_else(|| {
            Error::invalid(format!(
                "{}: '{}' is not a subcommand a job can run (jobs can run: {})",
                job.origin,
                job.command,
                names_with(|c| c.job.is_some())
            ))
        })?;
    parse_job(command, job)
        .map_err(|m| Error::invalid(format!("{} ({}): {m}", job.origin, job.command)))
}

pub fn run(a: &BatchArgs, quiet: bool) -> Result<i32> {
    let path = std::fs::canonicalize(&a.jobs).map_err(|e| Error::io(&a.jobs, e))?;
    let summary_base = a
        .summary
        .as_ref()
        .map(|s| std::path::absolute(s).map_err(|e| Error::io(s, e)))
        .transpose()?;
    let file = JobFile::load(&path).map_err(|e| match e {
        Error::Format { message, .. } => Error::Format {
            path: a.jobs.clone(),
            message,
        },
        e => e,
    })?;
    // Every relative path in the job file — outputs, reports and any input a subcommand reads —
    // is relative to the job file: work from its folder.
    std::env::set_current_dir(&file.dir).map_err(|e| Error::io(&file.dir, e))?;
    let owned: Vec<Box<dyn Task>> = file
        .jobs
        .iter()
        .map(task_for)
        .collect::<Result<_>>()
        .map_err(|e| prefixed(&a.jobs, e))?;
    let tasks: Vec<&dyn Task> = owned.iter().map(|t| t.as_ref()).collect();

    let (shard, shard_from) = match a.shard {
        Some(s) => (Some(s), "--shard"),
        None => match Shard::from_slurm(|k| std::env::var(k).ok())? {
            Some(s) => (Some(s), "SLURM_ARRAY_TASK_ID"),
            None => (None, ""),
        },
    };
    let shard = shard.filter(|s| s.count > 1);
    let workers = a
        .workers
        .map(|w| w as usize)
        .unwrap_or_else(rayon::current_num_threads);
    let settings = Settings {
        workers,
        shard,
        force: a.force,
    };
    if a.dry_run {
        return dry_run(&file, &tasks, settings, a.json);
    }

    let name = a.jobs.display().to_string();
    let shard_note = shard
        .map(|s| format!(", shard {s} (from {shard_from})"))
        .unwrap_or_default();
    let mut counter = None;
    let mut failed = 0;
    let summary = batch::run(&file, &tasks, settings, &mut |event| match event {
        Event::Begin {
            jobs,
            skipped,
            to_run,
        } => {
            if !a.json {
                let on = match workers.min(to_run) {
                    0 => String::new(),
                    1 => " on 1 worker".into(),
                    w => format!(" on {w} workers"),
                };
                outln!(
                    "batch {name}: {} jobs{shard_note}: {jobs} here, {skipped} already done, {to_run} to run{on}",
                    file.jobs.len(),
                );
            }
            counter = Some(Progress::new(quiet || a.json).counter(to_run as u64, "jobs"));
        }
        Event::Done(r) => {
            let Some(c) = &counter else { return };
            c.inc();
            if r.status != Status::Ok {
                failed += 1;
                c.note(format!("· {failed} not ok"));
            }
            if !a.json {
                let mut line = format!(
                    "  {:<8}{:>8.2} s  #{:<5} {}",
                    r.status.name(),
                    r.seconds,
                    r.name.job,
                    r.name.output
                );
                if let Some(e) = &r.error {
                    line.push_str(&format!(": {e}"));
                } else if r.status == Status::Defects {
                    line.push_str(&format!(": checks found defects (see {})", r.name.report));
                }
                c.suspend(|| outln!("{line}"));
            }
        }
    })?;
    drop(counter);

    let base = match summary_base {
        Some(b) if matches!(b.extension().and_then(|e| e.to_str()), Some("csv" | "json")) => {
            b.with_extension("")
        }
        Some(b) => b,
        None => {
            let stem = path.file_stem().unwrap_or_default().to_string_lossy();
            file.dir.join(format!("{stem}-summary"))
        }
    };
    let base = match shard {
        Some(s) => suffixed(&base, &format!("-shard-{}-of-{}", s.index + 1, s.count)),
        None => base,
    };
    let (csv, json) = (suffixed(&base, ".csv"), suffixed(&base, ".json"));
    summary.write_csv(&csv)?;
    summary.write_json(&json)?;
    if a.json {
        super::out::json(&summary);
    } else {
        let c = summary.counts;
        outln!(
            "done {:.1} s: {} ok, {} skipped (done before), {} with defects, {} failed · summary {}",
            summary.seconds,
            c.ok,
            c.skipped,
            c.defects,
            c.failed,
            csv.display()
        );
    }
    Ok(if summary.all_done() { 0 } else { 1 })
}

fn dry_run(file: &JobFile, tasks: &[&dyn Task], settings: Settings, json: bool) -> Result<i32> {
    let jobs = batch::plan(file, tasks, settings);
    if json {
        super::out::json(&jobs);
    } else {
        for j in &jobs {
            outln!(
                "#{:<5} {:<9} {} {}  ({})",
                j.name.job,
                if j.done { "done" } else { "to run" },
                j.name.command,
                j.name.output,
                j.name.origin
            );
        }
    }
    Ok(0)
}

/// An error about the job file, with its name in front.
fn prefixed(jobs: &Path, e: Error) -> Error {
    match e {
        Error::Invalid(m) => Error::Format {
            path: jobs.to_path_buf(),
            message: m,
        },
        e => e,
    }
}

fn suffixed(base: &Path, suffix: &str) -> PathBuf {
    let mut s = base.as_os_str().to_owned();
    s.push(suffix);
    PathBuf::from(s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::tpms::TpmsArgs;
    use clap::{CommandFactory, FromArgMatches};

    fn job(text: &str) -> Job {
        latvox::batch::jobfile::parse(text).unwrap().remove(0)
    }

    /// A subcommand shaped like `latvox repair IN -o OUT`: a positional input and a switch.
    #[derive(clap::Parser)]
    struct RepairLike {
        input: PathBuf,
        #[arg(long, short = 'o')]
        output: PathBuf,
        #[arg(long)]
        fill_holes: bool,
        #[arg(long)]
        weld_tolerance: Option<f64>,
    }

    #[test]
    fn tables_become_the_subcommands_command_line() {
        let mut cmd = RepairLike::command().no_binary_name(true);
        cmd.build();
        let j = job(
            "[[job]]\ncommand='repair'\noutput='fixed.stl'\ninput='broken.stl'\n\
             fill_holes=true\nweld-tolerance=1e-5\n",
        );
        let argv = command_line(&cmd, &j).unwrap();
        assert_eq!(
            argv,
            [
                "--output=fixed.stl",
                "--fill-holes",
                "--weld-tolerance=0.00001",
                "--",
                "broken.stl"
            ]
        );
        let m = cmd.try_get_matches_from_mut(argv).unwrap();
        let a = RepairLike::from_arg_matches(&m).unwrap();
        assert_eq!(a.input, Path::new("broken.stl"));
        assert!(a.fill_holes);
        assert_eq!(a.weld_tolerance, Some(1e-5));

        let off =
            job("[[job]]\ncommand='repair'\noutput='f.stl'\ninput='b.stl'\nfill-holes=false\n");
        assert_eq!(
            command_line(&cmd, &off).unwrap(),
            ["--output=f.stl", "--", "b.stl"]
        );
    }

    #[test]
    fn tpms_jobs_parse_like_the_command_line() {
        let j = job(
            "[[job]]\ncommand='tpms'\noutput='a.stl'\ntype='d'\nstructure='sheet'\n\
             density=0.25\ncells=[4,4,2]\ncell-size=6\norigin=[-5, 0, 2.5]\nascii=true\n",
        );
        let t = parse_job(&crate::cli::tpms::COMMAND, &j).unwrap();
        assert_eq!(t.outputs(), [PathBuf::from("a.stl")]);
        let mut cmd = TpmsArgs::augment_args(clap::Command::new("tpms")).no_binary_name(true);
        cmd.build();
        let m = cmd
            .try_get_matches_from_mut(command_line(&cmd, &j).unwrap())
            .unwrap();
        let a = TpmsArgs::from_arg_matches(&m).unwrap();
        assert_eq!(a.domain.cells, Some([4, 4, 2]));
        assert_eq!(a.domain.cell_size, Some([6.0; 3]));
        assert_eq!(a.domain.origin, [-5.0, 0.0, 2.5]);
        assert_eq!(a.density, 0.25);
        assert!(a.mesh.ascii);
        assert!(!a.allow_islands);

        let bad = job("[[job]]\ncommand='tpms'\noutput='a.stl'\ncell_sise=5\n");
        let e = parse_job(&crate::cli::tpms::COMMAND, &bad).err().unwrap();
        assert!(
            e.contains("'--cell-sise'") && e.contains("'--cell-size'"),
            "{e}"
        );
    }
}
