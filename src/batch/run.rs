//! Running a batch: pick this shard's jobs, skip those already done, run the rest on a bounded
//! pool of worker threads, and write each job's report (with its [`Provenance`]) after its outputs.
//!
//! Workers are plain threads pulling the next job from a shared counter; each job's own
//! parallelism runs on the process's shared rayon and TBB pools, so `--threads` bounds the
//! whole batch however many workers run. A job that fails (an error or even a panic) is recorded
//! and the batch goes on.

use super::jobfile::{Job, JobFile};
use super::resume::{self, FileRecord, Outcome, Provenance, SlurmIds};
use super::shard::Shard;
use super::summary::{Counts, JobName, JobResult, Status, Summary};
use crate::error::{Error, Result};
use crate::verify::Verdict;
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Instant, SystemTime};

/// A job ready to run: what the batch needs from the subcommand that makes the part.
pub trait Task: Send + Sync {
    /// The files the job writes besides its report, relative to the job file's folder.
    fn outputs(&self) -> Vec<PathBuf>;
    /// Runs the job, writing every output atomically, and returns its report.
    fn run(&self) -> Result<TaskReport>;
}

/// What a finished task hands back.
#[derive(Debug, Clone)]
pub struct TaskReport {
    /// The subcommand's JSON report (an object; the batch adds its `batch` record to it).
    pub report: serde_json::Value,
    /// Whether the part passed the subcommand's own checks.
    pub passed: bool,
    /// Warnings the subcommand gave (the summary counts them).
    pub warnings: Vec<String>,
}

impl TaskReport {
    /// The report of a job that made a part: `report` is the subcommand's, and the job passed
    /// when `verdict` finds the part a valid solid.
    pub fn new(
        report: &impl serde::Serialize,
        verdict: &Verdict,
        warnings: Vec<String>,
    ) -> Result<TaskReport> {
        Ok(TaskReport {
            report: serde_json::to_value(report).map_err(|e| Error::invalid(e.to_string()))?,
            passed: verdict.is_valid_solid(),
            warnings,
        })
    }
}

/// How to run.
#[derive(Debug, Clone, Copy)]
pub struct Settings {
    /// Jobs running at once (at least 1).
    pub workers: usize,
    /// Run only this shard's jobs.
    pub shard: Option<Shard>,
    /// Run every job, even those already done.
    pub force: bool,
}

/// Progress of a running batch, for display.
pub enum Event<'a> {
    /// Jobs of this shard, how many are already done, how many will run.
    Begin {
        /// Jobs in this shard.
        jobs: usize,
        /// Of them, already done (skipped).
        skipped: usize,
        /// Of them, to run now.
        to_run: usize,
    },
    /// A job ran (or failed).
    Done(&'a JobResult),
}

/// A job as a dry run lists it: where it comes from, what it writes, and whether it is done.
#[derive(Debug, Clone, serde::Serialize)]
pub struct PlannedJob {
    /// Which job, and the files it writes.
    #[serde(flatten)]
    pub name: JobName,
    /// A previous run is still valid (and `force` is off): running the batch skips it.
    pub done: bool,
    /// The subcommand's options, as the job file gives them.
    pub options: serde_json::Value,
}

/// The jobs of this shard, in order, each with whether running the batch would skip it;
/// `tasks[i]` is the task of `file.jobs[i]`.
pub fn plan(file: &JobFile, tasks: &[&dyn Task], settings: Settings) -> Vec<PlannedJob> {
    file.jobs
        .iter()
        .zip(tasks)
        .filter(|(job, _)| settings.shard.is_none_or(|s| s.contains(job.index)))
        .map(|(job, task)| PlannedJob {
            name: JobName::from(job),
            done: !settings.force && previous_run(file, job, *task).is_some(),
            options: job.options_json(),
        })
        .collect()
}

/// The job's previous run, if it is still valid (see [`resume::completed`]).
pub fn previous_run(file: &JobFile, job: &Job, task: &dyn Task) -> Option<Provenance> {
    resume::completed(job, &file.dir, &record_paths(&task.outputs()))
}

fn record_paths(paths: &[PathBuf]) -> Vec<String> {
    paths
        .iter()
        .map(|p| p.to_string_lossy().into_owned())
        .collect()
}

/// Runs the batch: `tasks[i]` is the task of `file.jobs[i]`. Job failures are in the summary.
pub fn run(
    file: &JobFile,
    tasks: &[&dyn Task],
    settings: Settings,
    on_event: &mut dyn FnMut(Event),
) -> Result<Summary> {
    if tasks.len() != file.jobs.len() {
        return Err(Error::invalid(format!(
            "{} tasks for {} jobs",
            tasks.len(),
            file.jobs.len()
        )));
    }
    let started = SystemTime::now();
    let clock = Instant::now();
    let shard = settings.shard;
    let mut results = Vec::new();
    let mut queue = Vec::new();
    let mine: Vec<usize> = (0..file.jobs.len())
        .filter(|&i| shard.is_none_or(|s| s.contains(i)))
        .collect();
    for &i in &mine {
        let job = &file.jobs[i];
        match (!settings.force)
            .then(|| previous_run(file, job, tasks[i]))
            .flatten()
        {
            Some(p) => results.push(JobResult::new(job, Status::Skipped, 0.0, Some(p.run_id))),
            None => queue.push(i),
        }
    }
    on_event(Event::Begin {
        jobs: mine.len(),
        skipped: results.len(),
        to_run: queue.len(),
    });

    let context = Context {
        file,
        host: resume::host_name(),
        shard: shard.map(|s| s.to_string()),
        slurm: SlurmIds::from_env(),
    };
    let next = AtomicUsize::new(0);
    let (tx, rx) = std::sync::mpsc::channel::<JobResult>();
    std::thread::scope(|scope| {
        for _ in 0..settings.workers.max(1).min(queue.len()) {
            let (tx, next, queue, context) = (tx.clone(), &next, &queue, &context);
            scope.spawn(move || loop {
                let k = next.fetch_add(1, Ordering::Relaxed);
                let Some(&i) = queue.get(k) else { break };
                let result = context.run_one(&file.jobs[i], tasks[i]);
                if tx.send(result).is_err() {
                    break;
                }
            });
        }
        drop(tx);
        for r in rx {
            on_event(Event::Done(&r));
            results.push(r);
        }
    });
    results.sort_by_key(|r| r.name.job);
    Ok(Summary {
        job_file: file.path.to_string_lossy().into_owned(),
        jobs_in_batch: file.jobs.len(),
        shard: shard.map(|s| s.to_string()),
        workers: settings.workers,
        started: rfc3339(started),
        seconds: clock.elapsed().as_secs_f64(),
        counts: Counts::of(&results),
        jobs: results,
    })
}

struct Context<'a> {
    file: &'a JobFile,
    host: String,
    shard: Option<String>,
    slurm: Option<SlurmIds>,
}

impl Context<'_> {
    fn run_one(&self, job: &Job, task: &dyn Task) -> JobResult {
        let started = SystemTime::now();
        let clock = Instant::now();
        let nanos = started
            .duration_since(SystemTime::UNIX_EPOCH)
            .map(|d| d.as_nanos())
            .unwrap_or(0);
        let run_id = format!(
            "{}-{}-{nanos}-{}",
            self.host,
            std::process::id(),
            job.index + 1
        );
        match self.attempt(job, task, started, clock, &run_id) {
            Ok((outcome, warnings)) => {
                let status = match outcome {
                    Outcome::Ok => Status::Ok,
                    Outcome::Defects => Status::Defects,
                };
                let mut r =
                    JobResult::new(job, status, clock.elapsed().as_secs_f64(), Some(run_id));
                r.warnings = warnings;
                r
            }
            Err(e) => {
                let mut r =
                    JobResult::new(job, Status::Failed, clock.elapsed().as_secs_f64(), None);
                r.error = Some(e.to_string().replace('\n', " "));
                r
            }
        }
    }

    fn attempt(
        &self,
        job: &Job,
        task: &dyn Task,
        started: SystemTime,
        clock: Instant,
        run_id: &str,
    ) -> Result<(Outcome, usize)> {
        let dir = &self.file.dir;
        let outputs = task.outputs();
        let report_path = dir.join(&job.report);
        for p in outputs
            .iter()
            .map(|o| dir.join(o))
            .chain([report_path.clone()])
        {
            if let Some(parent) = p.parent().filter(|p| !p.as_os_str().is_empty()) {
                std::fs::create_dir_all(parent).map_err(|e| Error::io(parent, e))?;
            }
            // This process owns the job now: what a killed run left half-written goes.
            crate::io::atomic::remove_stale_temporaries(&p)?;
        }
        let done = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| task.run())).map_err(
            |panic| {
                let what = panic
                    .downcast_ref::<&str>()
                    .map(|s| s.to_string())
                    .or_else(|| panic.downcast_ref::<String>().cloned())
                    .unwrap_or_default();
                Error::invalid(format!("internal error (a bug in latvox): panic: {what}"))
            },
        )??;
        let mut records = Vec::new();
        for (o, path) in record_paths(&outputs).into_iter().zip(&outputs) {
            let m = std::fs::metadata(dir.join(path)).map_err(|e| Error::io(dir.join(path), e))?;
            records.push(FileRecord {
                path: o,
                bytes: m.len(),
            });
        }
        let outcome = if done.passed {
            Outcome::Ok
        } else {
            Outcome::Defects
        };
        let finished = SystemTime::now();
        let provenance = Provenance {
            job: job.index + 1,
            origin: job.origin.clone(),
            hash: job.hash.clone(),
            command: job.command.clone(),
            options: job.options_json(),
            outcome,
            run_id: run_id.to_string(),
            started: rfc3339(started),
            finished: rfc3339(finished),
            seconds: clock.elapsed().as_secs_f64(),
            host: self.host.clone(),
            pid: std::process::id(),
            latvox_version: env!("CARGO_PKG_VERSION").to_string(),
            shard: self.shard.clone(),
            slurm: self.slurm.clone(),
            outputs: records,
        };
        let mut report = match done.report {
            serde_json::Value::Object(m) => m,
            other => [("report".to_string(), other)].into_iter().collect(),
        };
        report.insert(
            "batch".into(),
            serde_json::to_value(&provenance).map_err(|e| Error::invalid(e.to_string()))?,
        );
        crate::io::atomic::write_json(&report_path, &report)?;
        Ok((outcome, done.warnings.len()))
    }
}

pub(crate) fn rfc3339(t: SystemTime) -> String {
    humantime::format_rfc3339_millis(t).to_string()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::batch::jobfile::parse;

    /// Writes `text` to its output, then reports `passed`, or panics, or writes nothing.
    struct Fake {
        output: PathBuf,
        behaviour: &'static str,
    }

    impl Task for Fake {
        fn outputs(&self) -> Vec<PathBuf> {
            vec![self.output.clone()]
        }
        fn run(&self) -> Result<TaskReport> {
            match self.behaviour {
                "panic" => panic!("fake failure"),
                "nothing" => {}
                _ => crate::io::atomic::write_atomic(&self.output, |w| w.write_all(b"part"))?,
            }
            Ok(TaskReport {
                report: serde_json::json!({ "kind": "fake" }),
                passed: self.behaviour != "defects",
                warnings: vec!["w".into()],
            })
        }
    }

    #[test]
    fn outcomes_are_recorded_and_only_good_jobs_are_skipped_later() {
        let dir = tempfile::tempdir().unwrap();
        let behaviours = ["ok", "defects", "panic", "nothing"];
        let text: String = behaviours
            .iter()
            .map(|b| format!("[[job]]\ncommand = 'fake'\noutput = '{b}.part'\n"))
            .collect();
        let file = JobFile {
            path: dir.path().join("jobs.toml"),
            dir: dir.path().to_path_buf(),
            jobs: parse(&text).unwrap(),
        };
        let fakes: Vec<Fake> = behaviours
            .iter()
            .map(|b| Fake {
                output: dir.path().join(format!("{b}.part")),
                behaviour: b,
            })
            .collect();
        let tasks: Vec<&dyn Task> = fakes.iter().map(|f| f as &dyn Task).collect();
        let settings = Settings {
            workers: 3,
            shard: None,
            force: false,
        };
        let s = run(&file, &tasks, settings, &mut |_| {}).unwrap();
        let status: Vec<Status> = s.jobs.iter().map(|r| r.status).collect();
        assert_eq!(
            status,
            [Status::Ok, Status::Defects, Status::Failed, Status::Failed]
        );
        assert_eq!(s.jobs[0].warnings, 1);
        assert!(s.jobs[2]
            .error
            .as_deref()
            .unwrap()
            .contains("panic: fake failure"));
        assert!(s.jobs[3].error.as_deref().unwrap().contains("nothing.part"));
        assert!(!s.all_done());
        let report: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.path().join("defects.json")).unwrap())
                .unwrap();
        assert_eq!(report["kind"], "fake");
        assert_eq!(report["batch"]["outcome"], "defects");
        assert_eq!(report["batch"]["outputs"][0]["bytes"], 4);
        assert!(!dir.path().join("panic.json").exists());

        let again = run(&file, &tasks, settings, &mut |_| {}).unwrap();
        let status: Vec<Status> = again.jobs.iter().map(|r| r.status).collect();
        assert_eq!(
            status,
            [
                Status::Skipped,
                Status::Defects,
                Status::Failed,
                Status::Failed
            ]
        );
        assert_eq!(again.jobs[0].run_id, s.jobs[0].run_id);
    }
}
