//! `latvox render` as a user runs it, each case a process of its own (wall time and peak
//! resident memory from `wait4`, median of `--runs`): 800 × 600 pictures of BCC strut blocks of
//! 10×10×10 and 100×100×100 cells of 5 mm at density 0.1, sphere-traced from their part files,
//! and of a 50 mm cube with a 1 mm skin filled with BCC at density 0.1 in 10×10×10 cells of 5 mm
//! and 100×100×100 cells of 0.5 mm, cut open at mid-height (`--section z=25`) so that the
//! lattice is what is traced; beside them, the 10×10×10 block and cube meshed by `latvox strut`
//! and `latvox fill` (default settings) and the mesh rendered from the same camera: what seeing
//! the part costs without the implicit renderer.
//!
//! Run: `cargo bench --bench render -- --runs 5`.

#[path = "../tests/it/common/child.rs"]
mod child;
#[path = "../tests/it/meshkit.rs"]
mod meshkit;
mod support;

use child::run_measured;
use std::path::Path;
use support::{latvox, median, runs_arg};

/// Median seconds and median peak memory (MB) of `runs` runs of each command in turn (one
/// process after another; the case's time is their sum).
fn measure(dir: &Path, runs: usize, steps: &[&[&str]]) -> (f64, f64) {
    let mut secs = Vec::new();
    let mut mem = Vec::new();
    for _ in 0..runs {
        let (mut s, mut m) = (0.0, 0.0f64);
        for args in steps {
            let r = run_measured(&mut latvox(dir, args));
            assert_eq!(r.code, 0, "{args:?} failed");
            s += r.seconds;
            m = m.max(r.peak_rss_mb());
        }
        secs.push(s);
        mem.push(m);
    }
    (median(secs), median(mem))
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let runs = runs_arg(&args, 3);
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for n in [10, 100] {
        std::fs::write(
            d.join(format!("bcc{n}.toml")),
            format!(
                "command = \"strut\"\ncell = \"bcc\"\ndensity = 0.1\ncells = {n}\ncell-size = 5\n"
            ),
        )
        .unwrap();
    }
    meshkit::write_stl(&d.join("cube.stl"), &meshkit::cuboid([0.0; 3], [50.0; 3]));
    for (name, cell) in [("cube10", "5"), ("cube100", "0.5")] {
        std::fs::write(
            d.join(format!("{name}.toml")),
            format!(
                "command = \"fill\"\ninput = \"{}\"\nskin = 1\nlattice = \"bcc\"\ncell-size = {cell}\ndensity = 0.1\n",
                d.join("cube.stl").display()
            ),
        )
        .unwrap();
    }
    let view = ["-o", "view.png", "--width", "800", "--height", "600"];
    let cut = [
        "-o",
        "view.png",
        "--width",
        "800",
        "--height",
        "600",
        "--section",
        "z=25",
    ];
    fn render<'a>(part: &'a str, view: &[&'a str]) -> Vec<&'a str> {
        let mut v = vec!["render", part];
        v.extend_from_slice(view);
        v
    }
    println!("case                                         median s   peak MB   ({runs} runs)");
    let cases: [(&str, Vec<Vec<&str>>); 6] = [
        ("BCC 10×10×10, implicit", vec![render("bcc10.toml", &view)]),
        (
            "BCC 100×100×100, implicit",
            vec![render("bcc100.toml", &view)],
        ),
        (
            "BCC 10×10×10, meshed then rendered",
            vec![
                vec!["strut", "--part", "bcc10.toml", "-o", "bcc10.stl", "-q"],
                render("bcc10.stl", &view),
            ],
        ),
        (
            "cube of BCC 10×10×10, cut, implicit",
            vec![render("cube10.toml", &cut)],
        ),
        (
            "cube of BCC 100×100×100, cut, implicit",
            vec![render("cube100.toml", &cut)],
        ),
        (
            "cube of BCC 10×10×10, meshed then rendered",
            vec![
                vec!["fill", "--part", "cube10.toml", "-o", "cube10.stl", "-q"],
                render("cube10.stl", &cut),
            ],
        ),
    ];
    for (name, steps) in cases {
        let steps: Vec<&[&str]> = steps.iter().map(|s| s.as_slice()).collect();
        let (s, m) = measure(d, runs, &steps);
        println!("{name:<44} {s:>9.2} {m:>9.0}");
    }
}
