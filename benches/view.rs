//! The browser editor's frame rate: `latvox view` serving BCC strut blocks of 10×10×10 and
//! 100×100×100 cells of 5 mm at density 0.1, a 10×10×10 gyroid block and a 50 mm cube with a
//! 1 mm skin filled with BCC in 5 mm cells (cut open at z = 25 mm), its page opened in
//! headless Chromium (tests/reference/view_page.py, Playwright) at 800 × 600, and `--frames`
//! frames drawn back to back from the iso view, each waited for (a pixel read back); the median
//! of `--runs` page loads. By default Chromium draws with SwiftShader (software WebGL2 on the
//! CPU); `--gpu` asks for the machine's GPU (ANGLE on Vulkan). The renderer Chromium reports is
//! printed beside each figure. The server's peak memory is printed too: the page gets one
//! unit cell, whatever the number of cells.
//!
//! Run: `cargo bench --bench view -- --runs 3 --frames 5 [--gpu]`.

#[path = "../tests/it/meshkit.rs"]
mod meshkit;
mod support;

use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};
use support::{latvox, median, peak_rss_mb_of, runs_arg};

fn arg(args: &[String], name: &str, default: usize) -> usize {
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let runs = runs_arg(&args, 3);
    let frames = arg(&args, "--frames", 5);
    let gpu = args.iter().any(|a| a == "--gpu");
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let parts = [
        (
            "bcc10",
            "command = \"strut\"\ncell = \"bcc\"\ndensity = 0.1\ncells = 10\ncell-size = 5\n",
        ),
        (
            "bcc100",
            "command = \"strut\"\ncell = \"bcc\"\ndensity = 0.1\ncells = 100\ncell-size = 5\n",
        ),
        (
            "gyroid10",
            "command = \"tpms\"\ntype = \"gyroid\"\ndensity = 0.2\ncells = 10\ncell-size = 5\n",
        ),
        (
            "cube10",
            "command = \"fill\"\ninput = \"cube.stl\"\nskin = 1\nlattice = \"bcc\"\ncell-size = 5\ndensity = 0.1\n",
        ),
    ];
    meshkit::write_stl(&d.join("cube.stl"), &meshkit::cuboid([0.0; 3], [50.0; 3]));
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/reference/view_page.py");
    println!("latvox view, 800×600, {frames} frames a load, median of {runs} loads");
    for (name, text) in parts {
        let file = format!("{name}.toml");
        std::fs::write(d.join(&file), text).unwrap();
        let mut server = latvox(d, &["view", &file])
            .stdout(Stdio::piped())
            .spawn()
            .unwrap();
        let mut url = String::new();
        BufReader::new(server.stdout.take().unwrap())
            .read_line(&mut url)
            .unwrap();
        let mut fps = Vec::new();
        let mut renderer = String::new();
        for _ in 0..runs {
            let mut c = Command::new("python3");
            c.arg(script).arg(url.trim()).arg(d).args([
                "--width",
                "800",
                "--height",
                "600",
                "--fps",
                &frames.to_string(),
            ]);
            if gpu {
                c.arg("--gpu");
            }
            if name == "cube10" {
                c.args(["--section", "z=25"]);
            }
            let r = c.output().unwrap();
            assert!(
                r.status.success(),
                "the page driver failed: {}",
                String::from_utf8_lossy(&r.stderr)
            );
            let v: serde_json::Value = serde_json::from_slice(&r.stdout).unwrap();
            fps.push(v["fps"].as_f64().unwrap());
            renderer = v["renderer"].as_str().unwrap_or("?").to_string();
        }
        let rss = peak_rss_mb_of(&server.id().to_string());
        let _ = server.kill();
        let _ = server.wait();
        println!(
            "{name:<9} {:>7.2} fps  (server peak {rss:.0} MB)  [{renderer}]",
            median(fps)
        );
    }
}
