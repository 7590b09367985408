//! Progress on long steps: a spinner on stderr for any stage that lasts over a second, only when
//! stderr is a terminal and the user did not ask for quiet. Pipes and logs stay clean.
//! Work made of many items (the jobs of a batch) gets a counting bar instead. With
//! `LATVOX_PROGRESS=lines` in the environment each stage is a line `progress: NAME` on stderr
//! instead, for a program that runs latvox and shows its progress (the browser editor).

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::sync::{mpsc, RwLock};
use std::time::Duration;

/// What hears of each stage as it starts (see [`listen`]).
pub type Listener = Box<dyn Fn(&str) + Send + Sync>;

static LISTENER: RwLock<Option<Listener>> = RwLock::new(None);

/// From now on, `listener` is called with each stage's name as the stage starts, from whatever
/// thread starts it, shown or not (`None`: no one is). For a program that shows latvox's progress
/// its own way (the Python package's callback or bar).
pub fn listen(listener: Option<Listener>) {
    *LISTENER.write().unwrap_or_else(|e| e.into_inner()) = listener;
}

/// Shows stage spinners, or nothing.
#[derive(Debug, Clone, Copy)]
pub struct Progress {
    enabled: bool,
    lines: bool,
}

impl Progress {
    /// Spinners on stderr if it is a terminal and `quiet` is false; stage lines instead where
    /// `LATVOX_PROGRESS=lines` (and `quiet` is false).
    pub fn new(quiet: bool) -> Self {
        let lines = std::env::var("LATVOX_PROGRESS").is_ok_and(|v| v == "lines");
        Progress {
            enabled: !quiet && (lines || std::io::stderr().is_terminal()),
            lines,
        }
    }

    /// No progress shown (library use, tests, batch workers).
    pub fn hidden() -> Self {
        Progress {
            enabled: false,
            lines: false,
        }
    }

    /// Starts a stage; its spinner appears once the stage has run for a second, and disappears
    /// when the returned guard is dropped.
    pub fn stage(&self, name: &str) -> Stage {
        if let Some(l) = LISTENER.read().unwrap_or_else(|e| e.into_inner()).as_ref() {
            l(name);
        }
        if !self.enabled || self.lines {
            if self.enabled {
                eprintln!("progress: {name}");
            }
            return Stage {
                done: None,
                thread: None,
            };
        }
        let (tx, rx) = mpsc::channel::<()>();
        let name = name.to_string();
        let thread = std::thread::spawn(move || {
            if rx.recv_timeout(Duration::from_secs(1)).is_ok() {
                return;
            }
            let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
            bar.set_style(
                ProgressStyle::with_template("{spinner} {msg} {elapsed}")
                    .unwrap_or_else(|_| ProgressStyle::default_spinner()),
            );
            bar.set_message(name);
            bar.enable_steady_tick(Duration::from_millis(100));
            let _ = rx.recv();
            bar.finish_and_clear();
        });
        Stage {
            done: Some(tx),
            thread: Some(thread),
        }
    }
}

impl Progress {
    /// A bar counting `len` items of `what` (e.g. "jobs"), drawn on stderr when enabled.
    pub fn counter(&self, len: u64, what: &str) -> Counter {
        if !self.enabled || len == 0 {
            return Counter { bar: None };
        }
        let bar = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
        bar.set_style(
            ProgressStyle::with_template(&format!(
                "{{bar:30}} {{pos}}/{{len}} {what} · {{elapsed}} (about {{eta}} left) {{msg}}"
            ))
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        bar.enable_steady_tick(Duration::from_millis(200));
        Counter { bar: Some(bar) }
    }
}

/// A counting bar, or nothing; cleared when dropped.
pub struct Counter {
    bar: Option<ProgressBar>,
}

impl Counter {
    /// One more item done.
    pub fn inc(&self) {
        if let Some(b) = &self.bar {
            b.inc(1);
        }
    }

    /// A short note after the count (e.g. "2 failed").
    pub fn note(&self, msg: String) {
        if let Some(b) = &self.bar {
            b.set_message(msg);
        }
    }

    /// Runs `print` (which writes to the terminal) without tearing the bar.
    pub fn suspend<R>(&self, print: impl FnOnce() -> R) -> R {
        match &self.bar {
            Some(b) => b.suspend(print),
            None => print(),
        }
    }
}

impl Drop for Counter {
    fn drop(&mut self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}

/// A running stage; dropping it ends the stage.
pub struct Stage {
    done: Option<mpsc::Sender<()>>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl Drop for Stage {
    fn drop(&mut self) {
        if let Some(tx) = self.done.take() {
            let _ = tx.send(());
        }
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}
