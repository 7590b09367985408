//! Shards: `--shard K/N` runs every N-th job of the batch, starting with the K-th (K from 1), so
//! N processes — on one machine or as the tasks of a Slurm job array — share a batch without
//! talking to each other. Jobs are dealt round-robin rather than in blocks, so the heavy end of a
//! sweep is spread over all shards.
//!
//! Under Slurm (`sbatch --array=...`) the shard comes from the task's environment:
//! `SLURM_ARRAY_TASK_ID`, `SLURM_ARRAY_TASK_MIN`, `SLURM_ARRAY_TASK_STEP` and
//! `SLURM_ARRAY_TASK_COUNT` (or `SLURM_ARRAY_TASK_MAX` where the count is missing), so
//! `--array=0-3`, `--array=1-4` and `--array=0-30:10` all make shards 1/4 … 4/4.

use crate::error::{Error, Result};

/// Shard `index + 1` of `count`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// From 0.
    pub index: usize,
    /// The number of shards N (at least 1).
    pub count: usize,
}

impl Shard {
    /// Parses `K/N` with 1 ≤ K ≤ N.
    pub fn parse(s: &str) -> Result<Shard> {
        let bad = || Error::invalid(format!("shard '{s}' is not K/N with 1 ≤ K ≤ N (e.g. 2/4)"));
        let (k, n) = s.split_once('/').ok_or_else(bad)?;
        let k: usize = k.trim().parse().map_err(|_| bad())?;
        let n: usize = n.trim().parse().map_err(|_| bad())?;
        if k == 0 || n == 0 || k > n {
            return Err(bad());
        }
        Ok(Shard {
            index: k - 1,
            count: n,
        })
    }

    /// The shard of a Slurm array task, read through `var` (e.g. `std::env::var`); `None` when
    /// the process is not an array task.
    pub fn from_slurm(var: impl Fn(&str) -> Option<String>) -> Result<Option<Shard>> {
        let Some(id) = var("SLURM_ARRAY_TASK_ID") else {
            return Ok(None);
        };
        let num = |name: &str, default: Option<i64>| -> Result<i64> {
            match var(name) {
                Some(v) => v.trim().parse().map_err(|_| {
                    Error::invalid(format!("{name}={v} is not a whole number"))
                }),
                None => default.ok_or_else(|| {
                    Error::invalid(format!(
                        "SLURM_ARRAY_TASK_ID is set but {name} is not: cannot tell the shard (give --shard K/N)"
                    ))
                }),
            }
        };
        let id = num("SLURM_ARRAY_TASK_ID", None).map_err(|_| {
            Error::invalid(format!("SLURM_ARRAY_TASK_ID={id} is not a whole number"))
        })?;
        let min = num("SLURM_ARRAY_TASK_MIN", Some(0))?;
        let step = num("SLURM_ARRAY_TASK_STEP", Some(1))?.max(1);
        let count = match var("SLURM_ARRAY_TASK_COUNT") {
            Some(_) => num("SLURM_ARRAY_TASK_COUNT", None)?,
            None => (num("SLURM_ARRAY_TASK_MAX", None)? - min) / step + 1,
        };
        let offset = id - min;
        if count < 1 || offset < 0 || offset % step != 0 || offset / step >= count {
            return Err(Error::invalid(format!(
                "Slurm array task {id} (min {min}, step {step}, count {count}) is not on an evenly spaced array such as --array=0-{}: give --shard K/N",
                count.max(1) - 1
            )));
        }
        Ok(Some(Shard {
            index: (offset / step) as usize,
            count: count as usize,
        }))
    }

    /// Whether the job at `index` (from 0) belongs to this shard.
    pub fn contains(&self, index: usize) -> bool {
        index % self.count == self.index
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index + 1, self.count)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn slurm(vars: &[(&str, &str)]) -> Result<Option<Shard>> {
        let vars: Vec<(String, String)> = vars
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect();
        Shard::from_slurm(|k| vars.iter().find(|(n, _)| n == k).map(|(_, v)| v.clone()))
    }

    #[test]
    fn parses_k_of_n() {
        assert_eq!(Shard::parse("2/4").unwrap(), Shard { index: 1, count: 4 });
        assert_eq!(Shard::parse(" 1 / 1 ").unwrap().to_string(), "1/1");
        for bad in ["0/4", "5/4", "1/0", "2", "a/b", "-1/3", ""] {
            assert!(Shard::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn shards_partition_the_jobs() {
        let n = 3;
        let shards: Vec<Shard> = (1..=n)
            .map(|k| Shard::parse(&format!("{k}/{n}")).unwrap())
            .collect();
        for job in 0..20 {
            assert_eq!(shards.iter().filter(|s| s.contains(job)).count(), 1);
        }
    }

    #[test]
    fn reads_slurm_arrays() {
        assert_eq!(slurm(&[]).unwrap(), None);
        let s = |id: &str, min: &str, step: &str, count: &str| {
            slurm(&[
                ("SLURM_ARRAY_TASK_ID", id),
                ("SLURM_ARRAY_TASK_MIN", min),
                ("SLURM_ARRAY_TASK_STEP", step),
                ("SLURM_ARRAY_TASK_COUNT", count),
            ])
        };
        // --array=0-3
        assert_eq!(s("0", "0", "1", "4").unwrap().unwrap().to_string(), "1/4");
        assert_eq!(s("3", "0", "1", "4").unwrap().unwrap().to_string(), "4/4");
        // --array=1-4
        assert_eq!(s("1", "1", "1", "4").unwrap().unwrap().to_string(), "1/4");
        // --array=0-30:10
        assert_eq!(s("20", "0", "10", "4").unwrap().unwrap().to_string(), "3/4");
        // --array=1,3,7: not evenly spaced
        assert!(s("7", "1", "1", "3").is_err());
        // Older Slurm without the count: from MAX.
        let old = slurm(&[
            ("SLURM_ARRAY_TASK_ID", "5"),
            ("SLURM_ARRAY_TASK_MIN", "2"),
            ("SLURM_ARRAY_TASK_MAX", "9"),
        ])
        .unwrap()
        .unwrap();
        assert_eq!(old.to_string(), "4/8");
        assert!(slurm(&[("SLURM_ARRAY_TASK_ID", "x")]).is_err());
        assert!(slurm(&[("SLURM_ARRAY_TASK_ID", "1")]).is_err());
    }
}
