//! A child process measured as the kernel counts it: wall time, exit code and peak resident
//! memory (`ru_maxrss` from `wait4`). Shared by the tests and the benchmarks
//! (`#[path = "../tests/it/common/child.rs"]`).

use std::process::Command;
use std::time::Instant;

/// What one run of a child cost.
pub struct Measured {
    pub seconds: f64,
    /// Peak resident memory, bytes.
    pub peak_rss: u64,
    /// Exit code (−1 when killed by a signal).
    pub code: i32,
}

impl Measured {
    pub fn peak_rss_mb(&self) -> f64 {
        self.peak_rss as f64 / (1024.0 * 1024.0)
    }
}

/// Spawns `cmd` and waits for it with `wait4`. Its peak memory is right only when this process
/// is small: Linux gives a child, when it execs, the peak resident memory of the process it was
/// forked from (the benchmarks are their own small processes; in the test binary, where other
/// tests' memory counts, `scale.rs` measures through GNU time instead).
pub fn run_measured(cmd: &mut Command) -> Measured {
    let start = Instant::now();
    let child = cmd.spawn().expect("spawn the child");
    let pid = child.id() as libc::pid_t;
    let mut status = 0;
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: plain wait4 on our own child; `usage` is a valid out-pointer.
    let r = unsafe { libc::wait4(pid, &mut status, 0, &mut usage) };
    assert_eq!(r, pid, "wait4 failed");
    let seconds = start.elapsed().as_secs_f64();
    // Reaped by wait4 above: the handle must not wait again.
    std::mem::forget(child);
    let code = if libc::WIFEXITED(status) {
        libc::WEXITSTATUS(status)
    } else {
        -1
    };
    Measured {
        seconds,
        peak_rss: usage.ru_maxrss as u64 * 1024,
        code,
    }
}
