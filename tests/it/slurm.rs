//! Slurm for real: `scripts/slurm-test.sh` starts a one-node cluster (munged, slurmctld, slurmd
//! on loopback), submits a latvox batch as an `sbatch --array` of 3 tasks, waits, checks with
//! `latvox check` and the summaries, and stops the daemons. Here the parts and reports it leaves
//! are checked again without latvox: each job made once, by the array task of its shard, into a
//! closed part at its density.

use crate::common::*;
use std::collections::BTreeSet;
use std::path::Path;
use std::process::Command;

#[test]
#[ignore = "long: a one-node Slurm cluster (munged, slurmctld, slurmd) runs a batch as a job array"]
fn a_slurm_job_array_makes_every_part_of_the_batch_exactly_once() {
    let dir = tempdir();
    let work = dir.path();
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/slurm-test.sh");
    let o = Command::new("bash")
        .arg(&script)
        .arg(env!("CARGO_BIN_EXE_latvox"))
        .arg(work)
        .env("SLURM_TEST_TASKS", "3")
        .output()
        .expect("run scripts/slurm-test.sh");
    let log = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "slurm-test.sh failed:\n{log}");
    assert!(log.contains("daemons stopped"), "{log}");

    let mut jobs = BTreeSet::new();
    let mut runs = BTreeSet::new();
    let mut tasks = BTreeSet::new();
    for ty in ["gyroid", "d"] {
        for density in [0.2, 0.3, 0.4, 0.5] {
            let stl = work.join(format!("out/{ty}-net-{density}.stl"));
            let tris = read_stl(&stl);
            assert!(!tris.is_empty(), "{}", stl.display());
            assert_eq!(edges(&tris), Edges::default(), "{}", stl.display());
            let vf = volume(&tris) / 1000.0;
            assert!((vf - density).abs() < 0.004, "{}: {vf}", stl.display());

            let b = &json(&stl.with_extension("json"))["batch"];
            let job = b["job"].as_u64().unwrap();
            let task: u64 = b["slurm"]["array_task_id"]
                .as_str()
                .unwrap()
                .parse()
                .unwrap();
            // --array=1-3: task k runs shard k/3, which holds jobs k, k + 3, ...
            assert_eq!((job - 1) % 3 + 1, task, "job {job} ran in task {task}");
            assert_eq!(b["shard"], format!("{task}/3"));
            assert_eq!(b["outcome"], "ok");
            assert!(jobs.insert(job), "job {job} twice");
            assert!(runs.insert(b["run_id"].as_str().unwrap().to_string()));
            tasks.insert(task);
        }
    }
    assert_eq!(jobs, (1..=8).collect());
    assert_eq!(tasks, (1..=3).collect());
}
