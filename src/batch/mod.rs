//! Batches: many latvox jobs from one TOML job file, run with a bounded number of workers,
//! resumable after a kill, and shardable over the tasks of a Slurm job array.
//!
//! - [`jobfile`]: `[[job]]` and `[[sweep]]` tables → a fixed, numbered list of [`Job`]s, each with
//!   its output, its report and a stable hash of its parameters.
//! - [`shard`]: `--shard K/N` and the Slurm array environment → which jobs this process runs.
//! - [`resume`]: the record each job leaves in its report, and the test that a job is done.
//! - [`mod@run`]: the worker pool; a job's outputs and then its report are written atomically.
//! - [`summary`]: the per-job summary, CSV and JSON.
//!
//! The batch does not know how to make a part: each job is a [`Task`] built by the CLI from the
//! job's subcommand and options, and run in-process.

pub mod jobfile;
pub mod resume;
pub mod run;
pub mod shard;
pub mod summary;

pub use jobfile::{Job, JobFile, Value};
pub use resume::Provenance;
pub use run::{plan, previous_run, run, Event, PlannedJob, Settings, Task, TaskReport};
pub use shard::Shard;
pub use summary::{Counts, JobName, JobResult, Status, Summary};
