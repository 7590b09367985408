//! Standard output for the commands. A reader that goes away early (`latvox check big.stl --json
//! | head`) ends the process quietly with exit code 0, as a pipe's writer is expected to, where
//! `println!` would panic.

use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};

static SILENT: AtomicBool = AtomicBool::new(false);

/// Whether the commands print their summaries and warnings (`true`: they do not — a program that
/// runs them in its own process and takes their reports instead, the Python package).
#[allow(dead_code)] // the binary always prints
pub(crate) fn silence(silent: bool) {
    SILENT.store(silent, Ordering::Relaxed);
}

/// Prints a warning on stderr (`latvox: warning: …`), unless silenced.
pub(crate) fn warning(w: &str) {
    if !SILENT.load(Ordering::Relaxed) {
        eprintln!("latvox: warning: {w}");
    }
}

/// Writes `args` and a newline to stdout; on a closed pipe, exits with 0 at once. Nothing when
/// silenced.
pub(crate) fn line(args: std::fmt::Arguments) {
    if SILENT.load(Ordering::Relaxed) {
        return;
    }
    let mut out = std::io::stdout().lock();
    if let Err(e) = out.write_fmt(args).and_then(|()| out.write_all(b"\n")) {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            std::process::exit(0);
        }
        // Any other failure to print (a full disk behind a redirect) is the shell's to see.
        drop(out);
        eprintln!("latvox: standard output: {e}");
        std::process::exit(2);
    }
}

/// `println!` for the commands: see [`line`].
macro_rules! outln {
    ($($arg:tt)*) => {
        $crate::cli::out::line(format_args!($($arg)*))
    };
}
pub(crate) use outln;

/// Prints `value` as pretty JSON on stdout.
pub(crate) fn json<T: serde::Serialize>(value: &T) {
    outln!(
        "{}",
        serde_json::to_string_pretty(value).expect("JSON of plain values")
    );
}

/// Prints the line of a mesh simplified within a tolerance: `of` names the uniform mesh it was
/// made from ("remesh"), `from` the surface its deviation is measured from.
pub(crate) fn simplified(s: &latvox::mesh::simplify::Simplified, of: &str, from: &str) {
    let st = &s.stats;
    outln!(
        "simplified {} of the {of}'s {} triangles ({:.1}× fewer); deviation {:.4} mm from {from} measured, tolerance {} mm (the {of}'s own {:.4} mm)",
        st.triangles_after,
        st.triangles_before,
        st.triangles_before as f64 / st.triangles_after.max(1) as f64,
        s.deviation,
        st.tolerance,
        s.uniform_deviation
    );
}
