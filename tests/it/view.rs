//! `latvox view`, run as a user runs it: the server started on a part file, its page driven in
//! headless Chromium (tests/reference/view_page.py, through Playwright) and compared with what
//! `latvox render` draws on the CPU from the same camera; the page's edits re-render and its
//! saved part file renders as the page drew it. The server's API is spoken to directly over
//! HTTP: bad requests get 4xx answers and the server goes on; meshing and slicing from it make
//! the files the commands make.

use crate::common::*;
use crate::meshkit;
use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A running `latvox view`, stopped when dropped.
struct Server {
    child: Child,
    port: u16,
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

impl Server {
    fn start(part: &str, dir: &Path) -> Server {
        let mut child = latvox()
            .args(["view", part])
            .current_dir(dir)
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .unwrap();
        let mut line = String::new();
        BufReader::new(child.stdout.take().unwrap())
            .read_line(&mut line)
            .unwrap();
        // The first line is the URL, and nothing else.
        let port = line
            .trim()
            .strip_prefix("http://127.0.0.1:")
            .and_then(|r| r.strip_suffix('/'))
            .and_then(|p| p.parse().ok())
            .unwrap_or_else(|| panic!("the first line is not the URL: {line:?}"));
        Server { child, port }
    }

    fn url(&self) -> String {
        format!("http://127.0.0.1:{}/", self.port)
    }

    /// One HTTP request: the status and the body.
    fn ask(&self, method: &str, path: &str, body: &str) -> (u16, String) {
        let mut s = TcpStream::connect(("127.0.0.1", self.port)).unwrap();
        s.set_read_timeout(Some(Duration::from_secs(120))).unwrap();
        write!(
            s,
            "{method} {path} HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\nContent-Type: application/json\r\nContent-Length: {}\r\n\r\n{body}",
            body.len()
        )
        .unwrap();
        let mut answer = String::new();
        s.read_to_string(&mut answer).unwrap();
        let status = answer
            .split(' ')
            .nth(1)
            .and_then(|c| c.parse().ok())
            .unwrap_or_else(|| panic!("no status: {answer:?}"));
        let body = answer
            .split_once("\r\n\r\n")
            .map_or("", |(_, b)| b)
            .to_string();
        (status, body)
    }

    fn json(&self, method: &str, path: &str, body: &str) -> (u16, serde_json::Value) {
        let (status, text) = self.ask(method, path, body);
        let v = serde_json::from_str(&text)
            .unwrap_or_else(|e| panic!("{method} {path}: not JSON ({e}): {text:?}"));
        (status, v)
    }
}

/// Where `latvox render` hits the part, from its depth image, top row first.
fn render_mask(dir: &Path, part: &str, camera: &[&str], w: u32, h: u32) -> Vec<bool> {
    let (ws, hs) = (w.to_string(), h.to_string());
    let mut args = vec![
        "render", part, "-o", "cpu.png", "--depth", "cpu.npy", "--width", &ws, "--height", &hs,
    ];
    args.extend(camera);
    ok(&args, dir);
    let a = latvox::io::npy::parse(&std::fs::read(dir.join("cpu.npy")).unwrap()).unwrap();
    assert_eq!(a.shape, vec![h as usize, w as usize]);
    a.data.iter().map(|d| d.is_finite()).collect()
}

fn page_mask(path: &Path) -> Vec<bool> {
    std::fs::read_to_string(path)
        .unwrap()
        .bytes()
        .map(|b| b == b'1')
        .collect()
}

fn agreement(a: &[bool], b: &[bool]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter().zip(b).filter(|(x, y)| x == y).count() as f64 / a.len() as f64
}

/// Runs the page driver; `None` (with the reason printed) where no browser can be started.
fn drive(url: &str, out: &Path, args: &[&str]) -> Option<serde_json::Value> {
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/reference/view_page.py");
    let r = Command::new("python3")
        .arg(script)
        .arg(url)
        .arg(out)
        .args(args)
        .output()
        .expect("python3");
    let err = String::from_utf8_lossy(&r.stderr);
    if r.status.code() == Some(3) {
        eprintln!(
            "skipped: the browser page is not tested here: {}",
            err.trim()
        );
        return None;
    }
    assert!(r.status.success(), "the page driver failed: {err}");
    Some(serde_json::from_slice(&r.stdout).unwrap())
}

/// The page, in headless Chromium (software WebGL2), draws what the CPU renderer draws from the
/// same camera: silhouettes agree on ≥ 98 % of pixels, and where both see the part, the colours
/// (the same shading from the same normals) agree within 24 levels on ≥ 95 % of the pixels.
/// Changing a control re-renders, and the part file the page saves renders (CPU) as the page drew
/// it. A TPMS part in a box of odd origin, a strut part, and a part filled with a lattice under
/// a skin, cut open by a section so that the lattice, skin and cut faces are what is compared.
#[test]
fn the_page_draws_the_part_as_render_does() {
    let d = tempdir();
    meshkit::write_stl(
        &d.path().join("cube.stl"),
        &meshkit::cuboid([-2.0, 0.0, 1.0], [18.0, 14.0, 13.0]),
    );
    let cases: [(&[&str], Option<&str>, &str, &str); 3] = [
        (
            &[
                "tpms",
                "--type",
                "gyroid",
                "--density",
                "0.3",
                "--cells",
                "3,2,2",
                "--cell-size",
                "5",
                "--origin",
                "1,-2,0.5",
            ],
            None,
            "structure=sheet",
            "structure = \"sheet\"",
        ),
        (
            &[
                "strut",
                "--cell",
                "bcc",
                "--density",
                "0.15",
                "--cells",
                "3",
            ],
            Some("x=7"),
            "cell=octet",
            "cell = \"octet\"",
        ),
        (
            &[
                "fill",
                "cube.stl",
                "--skin",
                "1",
                "--lattice",
                "bcc",
                "--cell-size",
                "5",
                "--density",
                "0.15",
            ],
            Some("z=8"),
            "lattice=gyroid",
            "lattice = \"gyroid\"",
        ),
    ];
    let (w, h) = (240u32, 180u32);
    for (make, section, edit, saved_line) in cases {
        make_part(d.path(), make);
        if make[0] == "fill" {
            // As a hand-written part file names its mesh: relative to itself.
            let part = d.path().join("part.toml");
            let text = std::fs::read_to_string(&part).unwrap();
            let abs = d.path().canonicalize().unwrap().join("cube.stl");
            let text = text.replace(abs.to_str().unwrap(), "cube.stl");
            assert!(text.contains("input = \"cube.stl\""), "{text}");
            std::fs::write(&part, text).unwrap();
        }
        let server = Server::start("part.toml", d.path());
        // Saved in another folder: the files the part names must still be found.
        std::fs::create_dir_all(d.path().join("saved")).unwrap();
        let saved = d.path().join("saved").join("edited.toml");
        let mut camera = vec!["--azimuth", "30", "--elevation", "25"];
        let (ws, hs) = (w.to_string(), h.to_string());
        let mut page_args = vec![
            "--width",
            &ws,
            "--height",
            &hs,
            "--azimuth",
            "30",
            "--elevation",
            "25",
            "--edit",
            edit,
            "--save",
            saved.to_str().unwrap(),
        ];
        if let Some(s) = section {
            camera.extend(["--section", s]);
            page_args.extend(["--section", s]);
        }
        let Some(seen) = drive(&server.url(), d.path(), &page_args) else {
            return;
        };
        assert_eq!(seen["error"], serde_json::Value::Null, "{seen}");
        assert_eq!(seen["page_errors"], serde_json::json!([]), "{seen}");

        let cpu = render_mask(d.path(), "part.toml", &camera, w, h);
        let page = page_mask(&d.path().join("first.mask"));
        let hits = page.iter().filter(|&&x| x).count();
        assert!(
            hits > (w * h / 10) as usize,
            "{make:?}: the page drew little: {hits}"
        );
        let a = agreement(&cpu, &page);
        let colours = colour_agreement(
            &std::fs::read(d.path().join("first.rgb")).unwrap(),
            &read_png(&d.path().join("cpu.png")).2,
            &cpu,
            &page,
        );
        eprintln!(
            "{}: silhouettes agree on {:.3} % of pixels, colours on {:.2} % of the pixels both hit",
            make[0],
            100.0 * a,
            100.0 * colours
        );
        assert!(a >= 0.98, "{make:?}: page and CPU render agree on {a}");
        assert!(colours >= 0.95, "{make:?}: colours agree on {colours}");

        // The edit re-rendered, changed the picture, and the saved file holds it.
        assert_eq!(seen["rerendered"], true, "{seen}");
        let text = std::fs::read_to_string(&saved).unwrap();
        assert!(text.contains(saved_line), "{text}");
        let edited = page_mask(&d.path().join("edited.mask"));
        let cpu_saved = render_mask(d.path(), "saved/edited.toml", &camera, w, h);
        let a = agreement(&cpu_saved, &edited);
        assert!(
            a >= 0.98,
            "{make:?}: the saved part renders unlike the page: {a}"
        );
        if section.is_none() {
            assert!(
                agreement(&page, &edited) < 0.99,
                "{make:?}: {edit} did not change the picture"
            );
        }
    }
}

/// The share of pixels both pictures hit where the colours agree within 24 levels a channel.
fn colour_agreement(page: &[u8], cpu: &[u8], cpu_hit: &[bool], page_hit: &[bool]) -> f64 {
    let (mut both, mut alike) = (0usize, 0usize);
    for (i, (&a, &b)) in cpu_hit.iter().zip(page_hit).enumerate() {
        if a && b {
            both += 1;
            let close = (0..3).all(|c| page[3 * i + c].abs_diff(cpu[3 * i + c]) <= 24);
            alike += close as usize;
        }
    }
    alike as f64 / both.max(1) as f64
}

/// Requests the server cannot carry out get 4xx answers with one-line reasons, and it keeps
/// serving; meshing and slicing from it make the files `latvox` makes, with progress polled.
#[test]
fn the_server_refuses_bad_requests_and_runs_jobs() {
    let d = tempdir();
    make_part(
        d.path(),
        &["tpms", "--type", "p", "--density", "0.3", "--cells", "2"],
    );
    let server = Server::start("part.toml", d.path());
    let (status, part) = server.json("GET", "/api/part", "");
    assert_eq!(status, 200);
    assert_eq!(part["scene"]["kind"], "tpms");
    assert_eq!(part["settings"]["type"], "p");
    let (status, page) = server.ask("GET", "/", "");
    assert_eq!(status, 200);
    assert!(page.contains("<canvas"));
    // Everything the page loads comes from this server: no address elsewhere.
    for file in ["/", "/view.js"] {
        let (_, text) = server.ask("GET", file, "");
        assert!(
            !text.contains("http://") && !text.contains("https://"),
            "{file} loads from afar"
        );
    }

    let bad: [(&str, &str, &str, u16, &str); 9] = [
        ("GET", "/nothing", "", 404, ""),
        ("GET", "/api/nothing", "", 404, "no such request"),
        ("DELETE", "/api/part", "", 405, "does not take"),
        ("POST", "/api/scene", "{not json", 400, "not JSON"),
        ("POST", "/api/scene", "{}", 422, "no settings"),
        (
            "POST",
            "/api/scene",
            r#"{"settings": {"type": "p", "density": 1.5}}"#,
            422,
            "density",
        ),
        (
            "POST",
            "/api/scene",
            r#"{"settings": {"type": "p", "bogus": 1}}"#,
            422,
            "bogus",
        ),
        (
            "POST",
            "/api/save",
            r#"{"settings": {"type": "p"}, "path": "x.stl"}"#,
            422,
            ".toml",
        ),
        (
            "POST",
            "/api/mesh",
            r#"{"settings": {"type": "p"}}"#,
            422,
            "no output",
        ),
    ];
    for (method, path, body, want, says) in bad {
        let (status, text) = server.ask(method, path, body);
        assert_eq!(status, want, "{method} {path} {body}: {text}");
        assert!(text.contains(says), "{method} {path}: {text}");
        assert!(!text.trim().contains('\n'), "{text}");
    }
    let big = format!(r#"{{"settings": {{"x": "{}"}}}}"#, "a".repeat(2 << 20));
    let (status, _) = server.ask("POST", "/api/scene", &big);
    assert_eq!(status, 413);
    assert!(!d.path().join("x.stl").exists());
    // Still serving, and a good edit gives a new scene.
    let (status, v) = server.json(
        "POST",
        "/api/scene",
        r#"{"settings": {"type": "d", "structure": "sheet", "density": 0.2, "cells": 2}}"#,
    );
    assert_eq!(status, 200, "{v}");
    assert_eq!(v["scene"]["tpms"]["sheet"], true);

    // Meshing and slicing run as latvox does them; a second job waits for the first.
    let settings = r#"{"type": "d", "density": 0.25, "cells": 2, "resolution": 16}"#;
    let (status, v) = server.json(
        "POST",
        "/api/mesh",
        &format!(r#"{{"settings": {settings}, "output": "edited.stl"}}"#),
    );
    assert_eq!(status, 202, "{v}");
    let (status, _) = server.json(
        "POST",
        "/api/slice",
        &format!(r#"{{"settings": {settings}, "output": "x.cli"}}"#),
    );
    assert!(status == 409 || status == 202, "{status}");
    let job = wait(&server);
    if status == 202 {
        // The mesh was done before the slice was asked for; this was the slice.
        assert_eq!(job["what"], "slicing");
    } else {
        assert_eq!(job["state"], "done", "{job}");
        assert_eq!(job["what"], "meshing");
        let density = job["report"]["achieved_density"].as_f64().unwrap();
        assert!((density - 0.25).abs() < 0.01, "{job}");
        let tris = read_stl(&d.path().join("edited.stl"));
        let vol = volume(&tris);
        assert!((vol / 1000.0 - density).abs() < 0.002, "{vol}");
        let (status, v) = server.json(
            "POST",
            "/api/slice",
            &format!(r#"{{"settings": {settings}, "output": "layers.cli", "layer": 0.5}}"#),
        );
        assert_eq!(status, 202, "{v}");
        let job = wait(&server);
        assert_eq!(job["state"], "done", "{job}");
        assert_eq!(job["report"]["layers"], 20, "{job}");
        assert!(d.path().join("layers.cli").exists());
    }
    // The stages a job's page shows: latvox's own, one line each when asked for lines.
    let lines = latvox()
        .args(["tpms", "--cells", "1", "-o", "staged.stl"])
        .env("LATVOX_PROGRESS", "lines")
        .current_dir(d.path())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&lines.stderr);
    assert!(err.lines().any(|l| l.starts_with("progress: ")), "{err}");
    // A job latvox refuses fails with latvox's reason.
    let (status, _) = server.json(
        "POST",
        "/api/mesh",
        &format!(r#"{{"settings": {settings}, "output": "edited.xyz"}}"#),
    );
    assert_eq!(status, 202);
    let job = wait(&server);
    assert_eq!(job["state"], "failed", "{job}");
    assert!(job["message"].as_str().unwrap().contains("xyz"), "{job}");
}

/// Polls the job until it ends.
fn wait(server: &Server) -> serde_json::Value {
    let start = Instant::now();
    loop {
        let (status, job) = server.json("GET", "/api/job", "");
        assert_eq!(status, 200);
        if job["state"] != "running" {
            return job;
        }
        assert!(start.elapsed() < Duration::from_secs(300), "{job}");
        std::thread::sleep(Duration::from_millis(200));
    }
}

/// What the editor cannot open is refused: exit 2, one line, nothing served or written — a
/// mesh, a missing file, a setting out of range, a filled part whose shell mesh is gone, a port
/// that does not exist.
#[test]
fn the_editor_refuses_what_it_cannot_open() {
    let d = tempdir();
    make_part(d.path(), &["tpms", "--cells", "1"]);
    std::fs::write(
        d.path().join("bad.toml"),
        "command = \"tpms\"\ndensity = 3\n",
    )
    .unwrap();
    std::fs::write(
        d.path().join("fill.toml"),
        "command = \"fill\"\ninput = \"gone.stl\"\n",
    )
    .unwrap();
    let before = files_in(d.path());
    for (args, what) in [
        (&["view", "part.stl"][..], "part files"),
        (&["view", "missing.toml"], "missing.toml"),
        (&["view", "bad.toml"], "density"),
        (&["view", "fill.toml"], "gone.stl"),
        (&["view", "part.toml", "--port", "70000"], "70000"),
    ] {
        // A server that starts where it should refuse is stopped, not waited for.
        let mut child = latvox()
            .args(args)
            .current_dir(d.path())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let start = Instant::now();
        while child.try_wait().unwrap().is_none() {
            if start.elapsed() > Duration::from_secs(60) {
                let _ = child.kill();
                panic!("{args:?} serves instead of refusing");
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        let out = child.wait_with_output().unwrap();
        assert_refusal(d.path(), &before, &out, args, what);
    }
}
