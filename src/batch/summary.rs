//! The batch summary: one row per job of the shard (ran, skipped as already done, found defects,
//! or failed with its error), written as CSV for spreadsheets and JSON for scripts.

use super::jobfile::Job;
use crate::error::Result;
use serde::Serialize;
use std::path::Path;

/// What happened to a job in this run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Status {
    /// Ran; outputs and report written; checks passed.
    Ok,
    /// Already done by an earlier run with the same parameters: not run again.
    Skipped,
    /// Ran and wrote its outputs, but its checks found defects; runs again next time.
    Defects,
    /// Stopped with an error; nothing written; runs again next time.
    Failed,
}

impl Status {
    /// The status as the summary writes it: `ok`, `skipped`, `defects` or `failed`.
    pub fn name(self) -> &'static str {
        match self {
            Status::Ok => "ok",
            Status::Skipped => "skipped",
            Status::Defects => "defects",
            Status::Failed => "failed",
        }
    }
}

/// A job as listings and summaries name it.
#[derive(Debug, Clone, Serialize)]
pub struct JobName {
    /// Number of the job in the batch, from 1.
    pub job: usize,
    /// Where the job comes from in the job file: `job 3` or `sweep 1, variant 5`.
    pub origin: String,
    /// The latvox subcommand.
    pub command: String,
    /// The output, relative to the job file's folder.
    pub output: String,
    /// The JSON report, relative to the job file's folder.
    pub report: String,
    /// The parameter hash: the job's identity for resuming.
    pub hash: String,
}

impl From<&Job> for JobName {
    fn from(job: &Job) -> JobName {
        JobName {
            job: job.index + 1,
            origin: job.origin.clone(),
            command: job.command.clone(),
            output: job.output.clone(),
            report: job.report.clone(),
            hash: job.hash.clone(),
        }
    }
}

/// One row of the summary.
#[derive(Debug, Clone, Serialize)]
pub struct JobResult {
    /// Which job.
    #[serde(flatten)]
    pub name: JobName,
    /// What happened to it.
    pub status: Status,
    /// Wall time of this run of the job (0 when skipped).
    pub seconds: f64,
    /// The run that made the outputs: this one, or for a skipped job the earlier one.
    pub run_id: Option<String>,
    /// Warnings the subcommand gave.
    pub warnings: usize,
    /// The error, when the job failed.
    pub error: Option<String>,
}

impl JobResult {
    pub(crate) fn new(job: &Job, status: Status, seconds: f64, run_id: Option<String>) -> Self {
        JobResult {
            name: JobName::from(job),
            status,
            seconds,
            run_id,
            warnings: 0,
            error: None,
        }
    }
}

/// Jobs by status.
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct Counts {
    /// Jobs that ran and passed their checks.
    pub ok: usize,
    /// Jobs done by an earlier run, not run again.
    pub skipped: usize,
    /// Jobs whose checks found defects.
    pub defects: usize,
    /// Jobs that stopped with an error.
    pub failed: usize,
}

impl Counts {
    pub(crate) fn of(results: &[JobResult]) -> Counts {
        let mut c = Counts::default();
        for r in results {
            *match r.status {
                Status::Ok => &mut c.ok,
                Status::Skipped => &mut c.skipped,
                Status::Defects => &mut c.defects,
                Status::Failed => &mut c.failed,
            } += 1;
        }
        c
    }
}

/// The whole run.
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    /// The job file, as given.
    pub job_file: String,
    /// Jobs in the whole batch (all shards).
    pub jobs_in_batch: usize,
    /// `K/N` when this run is one shard of the batch.
    pub shard: Option<String>,
    /// Jobs running at once.
    pub workers: usize,
    /// RFC 3339, UTC.
    pub started: String,
    /// Wall time of the whole run, seconds.
    pub seconds: f64,
    /// Jobs of this shard by status.
    pub counts: Counts,
    /// This shard's jobs, by job number.
    pub jobs: Vec<JobResult>,
}

impl Summary {
    /// Whether every job of the shard is done (ran or skipped) without defects.
    pub fn all_done(&self) -> bool {
        self.counts.failed == 0 && self.counts.defects == 0
    }

    /// Writes the summary as JSON, atomically.
    pub fn write_json(&self, path: &Path) -> Result<()> {
        crate::io::atomic::write_json(path, self)
    }

    /// Writes the summary as CSV (one row per job, a header first), atomically.
    pub fn write_csv(&self, path: &Path) -> Result<()> {
        crate::io::atomic::write_atomic(path, |w| {
            writeln!(
                w,
                "job,status,seconds,output,report,command,origin,hash,run_id,warnings,error"
            )?;
            for r in &self.jobs {
                let n = &r.name;
                let fields = [
                    n.job.to_string(),
                    r.status.name().to_string(),
                    format!("{:.3}", r.seconds),
                    n.output.clone(),
                    n.report.clone(),
                    n.command.clone(),
                    n.origin.clone(),
                    n.hash.clone(),
                    r.run_id.clone().unwrap_or_default(),
                    r.warnings.to_string(),
                    r.error.clone().unwrap_or_default(),
                ];
                let row: Vec<String> = fields.iter().map(|f| csv_field(f)).collect();
                writeln!(w, "{}", row.join(","))?;
            }
            Ok(())
        })
    }
}

/// RFC 4180 quoting: fields with a comma, quote or line break are quoted, quotes doubled.
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::csv_field;

    #[test]
    fn csv_quotes_only_what_needs_it() {
        assert_eq!(csv_field("out/a.stl"), "out/a.stl");
        assert_eq!(csv_field("a,b"), "\"a,b\"");
        assert_eq!(csv_field("say \"x\""), "\"say \"\"x\"\"\"");
    }
}
