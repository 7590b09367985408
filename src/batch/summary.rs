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
    pub origin: String,
    pub command: String,
    pub output: String,
    pub report: String,
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
    #[serde(flatten)]
    pub name: JobName,
    pub status: Status,
    /// Wall time of this run of the job (0 when skipped).
    pub seconds: f64,
    /// The run that made the outputs: this one, or for a skipped job the earlier one.
    pub run_id: Option<String>,
    pub warnings: usize,
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
    pub ok: usize,
    pub skipped: usize,
    pub defects: usize,
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
    pub job_file: String,
    /// Jobs in the whole batch (all shards).
    pub jobs_in_batch: usize,
    pub shard: Option<String>,
    pub workers: usize,
    /// RFC 3339, UTC.
    pub started: String,
    pub seconds: f64,
    pub counts: Counts,
    /// This shard's jobs, by job number.
    pub jobs: Vec<JobResult>,
}

impl Summary {
    /// Whether every job of the shard is done (ran or skipped) without defects.
    pub fn all_done(&self) -> bool {
        self.counts.failed == 0 && self.counts.defects == 0
    }

    pub fn write_json(&self, path: &Path) -> Result<()> {
        crate::io::atomic::write_json(path, self)
    }

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
