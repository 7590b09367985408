//! Resuming: a job's identity (a hash of its parameters), the record a finished job leaves in its
//! JSON report (the report's `batch` object), and the test that says a job is already done.
//!
//! A job writes its outputs first and its report last, each atomically, so a report whose hash
//! matches proves the outputs were complete when it was written; the recorded sizes catch an
//! output replaced or truncated since. Anything less — no report, another hash, a job that found
//! defects, a missing or resized output — and the job runs again.

use super::jobfile::{Job, Value};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::path::Path;

/// SHA-256 of the command and its options as command-line text, keys sorted: `density = 0.30`
/// and `density = "0.3"` are the same job, `cells = [4, 4, 2]` and `cells = "4,4,2"` too.
pub fn job_hash(command: &str, options: &[(String, Value)]) -> String {
    let mut kv: Vec<(&str, String)> = options
        .iter()
        .map(|(k, v)| (k.as_str(), v.to_arg()))
        .collect();
    kv.sort();
    let mut h = Sha256::new();
    // Length-prefixed fields: no value can imitate a field boundary.
    let mut field = |b: &[u8]| {
        h.update((b.len() as u64).to_le_bytes());
        h.update(b);
    };
    field(b"latvox batch job v1");
    field(command.as_bytes());
    for (k, v) in &kv {
        field(k.as_bytes());
        field(v.as_bytes());
    }
    h.finalize()
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect::<String>()
}

/// How a job that ran ended, as its report records it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Outcome {
    /// Outputs written and every check passed.
    Ok,
    /// Outputs written, but the job's own checks found defects (it will run again).
    Defects,
}

/// An output file and its size when the job finished.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct FileRecord {
    /// Relative to the job file's folder.
    pub path: String,
    /// Size in bytes.
    pub bytes: u64,
}

/// The Slurm job a batch job ran under.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct SlurmIds {
    /// `SLURM_JOB_ID`.
    pub job_id: Option<String>,
    /// `SLURM_ARRAY_JOB_ID`, under a job array.
    pub array_job_id: Option<String>,
    /// `SLURM_ARRAY_TASK_ID`, under a job array.
    pub array_task_id: Option<String>,
}

impl SlurmIds {
    /// From the environment, when running under Slurm.
    pub fn from_env() -> Option<SlurmIds> {
        let var = |k: &str| std::env::var(k).ok();
        let ids = SlurmIds {
            job_id: var("SLURM_JOB_ID"),
            array_job_id: var("SLURM_ARRAY_JOB_ID"),
            array_task_id: var("SLURM_ARRAY_TASK_ID"),
        };
        (ids.job_id.is_some() || ids.array_task_id.is_some()).then_some(ids)
    }
}

/// The `batch` object of a job's report: which job, with which parameters, run when and where.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Provenance {
    /// Number of the job in the batch, from 1.
    pub job: usize,
    /// Where the job comes from in the job file: `job 3` or `sweep 1, variant 5`.
    pub origin: String,
    /// The parameter hash ([`job_hash`]): the job's identity for resuming.
    pub hash: String,
    /// The latvox subcommand.
    pub command: String,
    /// The subcommand's options as the job file gives them.
    pub options: serde_json::Value,
    /// How the run ended.
    pub outcome: Outcome,
    /// Unique to this execution of the job: a job that is skipped keeps its old run id.
    pub run_id: String,
    /// RFC 3339, UTC.
    pub started: String,
    /// RFC 3339, UTC.
    pub finished: String,
    /// Wall time of the job, seconds.
    pub seconds: f64,
    /// The machine's name ([`host_name`]).
    pub host: String,
    /// Process id of the batch that ran it.
    pub pid: u32,
    /// Version of the latvox that ran it.
    pub latvox_version: String,
    /// `K/N` when the batch ran as a shard.
    pub shard: Option<String>,
    /// The Slurm job, when run under Slurm.
    pub slurm: Option<SlurmIds>,
    /// Each output file and its size when the job finished.
    pub outputs: Vec<FileRecord>,
}

/// The record of the job's last run when that run is still valid for `job` (same hash, no
/// defects, every output present at its recorded size); `outputs` are the files the job writes
/// and `dir` the folder their paths and the report's are relative to.
pub fn completed(job: &Job, dir: &Path, outputs: &[String]) -> Option<Provenance> {
    let text = std::fs::read(dir.join(&job.report)).ok()?;
    let mut doc: serde_json::Value = serde_json::from_slice(&text).ok()?;
    let p: Provenance = serde_json::from_value(doc.get_mut("batch")?.take()).ok()?;
    let same_files = p.outputs.len() == outputs.len()
        && outputs
            .iter()
            .all(|o| p.outputs.iter().any(|r| r.path == *o));
    let intact = p.outputs.iter().all(|r| {
        std::fs::metadata(dir.join(&r.path))
            .map(|m| m.is_file() && m.len() == r.bytes)
            .unwrap_or(false)
    });
    (p.hash == job.hash && p.outcome == Outcome::Ok && same_files && intact).then_some(p)
}

/// This machine's name, for the record.
pub fn host_name() -> String {
    std::env::var("SLURMD_NODENAME")
        .ok()
        .or_else(|| {
            std::fs::read_to_string("/proc/sys/kernel/hostname")
                .ok()
                .map(|s| s.trim().to_string())
        })
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| "unknown".into())
}
