//! The Python package (`python/`): built and installed with pip into a virtual environment under
//! `target/`, then its pytest suite (`python/tests`) runs against it — each function's results
//! checked with trimesh and against this `latvox` binary's.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The virtual environment's Python, with this tree's package installed (once per test run).
fn python() -> &'static Path {
    static PYTHON: OnceLock<PathBuf> = OnceLock::new();
    PYTHON.get_or_init(|| {
        let venv = root().join("target").join("python-venv");
        let python = venv.join("bin").join("python");
        if !python.exists() {
            // The test tier's packages (NumPy, trimesh, pytest, maturin) come from the system's.
            let made = Command::new("python3")
                .args(["-m", "venv", "--system-site-packages"])
                .arg(&venv)
                .status()
                .expect("python3 runs (scripts/install-deps.sh --tests)");
            assert!(made.success(), "python3 -m venv failed");
        }
        let out = Command::new(&python)
            .args([
                "-m",
                "pip",
                "install",
                "--quiet",
                "--disable-pip-version-check",
                "--no-build-isolation",
                "--no-deps",
                "--force-reinstall",
                ".",
            ])
            .current_dir(root())
            .output()
            .expect("pip runs");
        assert!(
            out.status.success(),
            "pip install . failed (maturin from scripts/install-deps.sh --tests):\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
        python
    })
}

fn pytest(marks: &str) {
    let out = Command::new(python())
        .args(["-m", "pytest", "-q", "-p", "no:cacheprovider", "-m", marks])
        .arg(root().join("python").join("tests"))
        .env("LATVOX_BIN", env!("CARGO_BIN_EXE_latvox"))
        // From a folder that is not the sources', so that `import latvox` is the installed one.
        .current_dir(std::env::temp_dir())
        .output()
        .expect("pytest runs");
    assert!(
        out.status.success(),
        "pytest -m '{marks}':\n{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn the_python_package_installs_and_passes_its_tests() {
    pytest("not long");
}

#[test]
#[ignore = "long: a four-million-triangle part returned to Python, its peak memory measured"]
fn the_python_package_returns_large_parts_without_doubling_memory() {
    pytest("long");
}
