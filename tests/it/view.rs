//! `latvox view`, run as a user runs it: the server started on a part file, its page driven in
//! headless Chromium (tests/reference/view_page.py, through Playwright) and compared with what
//! `latvox render` draws on the CPU from the same camera; the page's edits re-render and its
//! saved part file renders as the page drew it. The server's API is spoken to directly over
//! HTTP: bad requests get 4xx answers and the server goes on; meshing and slicing from it make
//! the files the commands make. It obeys only its page: requests without the run's token, naming
//! another host, or sent by another site's page are refused, names leading out of its folder
//! are refused with nothing written, slow clients do not hold it, and random requests neither
//! stop it nor write outside its folder.

use crate::common::*;
use crate::meshkit;
use std::collections::BTreeMap;
use std::io::{BufRead, BufReader, Read, Write};
use std::net::{Shutdown, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A running `latvox view`, stopped when dropped.
struct Server {
    child: Child,
    port: u16,
    token: String,
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// A request's headers, name and value.
type Headers = Vec<(String, String)>;

/// An answer: status, head (lower-cased) and body.
struct Answer {
    status: u16,
    head: String,
    body: String,
}

impl Server {
    fn start(part: &str, dir: &Path) -> Server {
        Server::start_with(&["view", part], dir)
    }

    fn start_with(args: &[&str], dir: &Path) -> Server {
        let mut child = latvox()
            .args(args)
            .current_dir(dir)
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .unwrap();
        let mut line = String::new();
        BufReader::new(child.stdout.take().unwrap())
            .read_line(&mut line)
            .unwrap();
        // The first line is the URL with the run's token, and nothing else.
        let (port, token) = line
            .trim()
            .strip_prefix("http://127.0.0.1:")
            .and_then(|r| r.split_once("/?token="))
            .and_then(|(p, t)| Some((p.parse().ok()?, t.to_string())))
            .unwrap_or_else(|| panic!("the first line is not the URL: {line:?}"));
        assert!(
            token.len() >= 32 && token.bytes().all(|b| b.is_ascii_hexdigit()),
            "{token}: not 128 bits or more"
        );
        Server { child, port, token }
    }

    fn url(&self) -> String {
        format!("http://127.0.0.1:{}/?token={}", self.port, self.token)
    }

    /// The headers the page sends: this server's host and the token.
    fn page_headers(&self) -> Headers {
        vec![
            ("Host".into(), format!("127.0.0.1:{}", self.port)),
            ("Authorization".into(), format!("token {}", self.token)),
        ]
    }

    /// One HTTP request as the page makes it: the status and the body.
    fn ask(&self, method: &str, path: &str, body: &str) -> (u16, String) {
        let mut headers = self.page_headers();
        headers.push(("Content-Type".into(), "application/json".into()));
        let a = self.send(method, path, &headers, body);
        (a.status, a.body)
    }

    /// One request with exactly `headers` (and Content-Length).
    fn send(&self, method: &str, path: &str, headers: &[(String, String)], body: &str) -> Answer {
        let mut raw = format!("{method} {path} HTTP/1.1\r\n");
        for (k, v) in headers {
            raw.push_str(&format!("{k}: {v}\r\n"));
        }
        raw.push_str(&format!(
            "Connection: close\r\nContent-Length: {}\r\n\r\n{body}",
            body.len()
        ));
        let answer = self.raw(raw.as_bytes());
        let status = answer
            .split(' ')
            .nth(1)
            .and_then(|c| c.parse().ok())
            .unwrap_or_else(|| panic!("no status: {answer:?}"));
        let (head, body) = answer.split_once("\r\n\r\n").unwrap_or((&answer, ""));
        Answer {
            status,
            head: head.to_ascii_lowercase(),
            body: body.to_string(),
        }
    }

    /// Sends `bytes` as they are, then reads the answer to its end.
    fn raw(&self, bytes: &[u8]) -> String {
        let mut s = TcpStream::connect(("127.0.0.1", self.port)).unwrap();
        s.set_read_timeout(Some(Duration::from_secs(120))).unwrap();
        // A server that answers before reading all (a refusal) may close first: not an error.
        let _ = s.write_all(bytes);
        let mut answer = Vec::new();
        let _ = s.read_to_end(&mut answer);
        String::from_utf8_lossy(&answer).into_owned()
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
/// it. A TPMS part in a box of odd origin, a strut part, a part filled with a lattice under
/// a skin, cut open by a section so that the lattice, skin and cut faces are what is compared,
/// and Voronoi foams: a random net turned into a sheet, and a sheet with pores cut open.
#[test]
#[ignore = "long: headless Chromium draws, edits and saves the part"]
fn the_page_draws_the_part_as_render_does() {
    let d = tempdir();
    meshkit::write_stl(
        &d.path().join("cube.stl"),
        &meshkit::cuboid([-2.0, 0.0, 1.0], [18.0, 14.0, 13.0]),
    );
    let cases: [(&[&str], Option<&str>, &str, &str); 5] = [
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
        (
            &[
                "voronoi",
                "--spacing",
                "3",
                "--density",
                "0.15",
                "--size",
                "9,8,7",
                "--origin",
                "-1,2,0",
                "-r",
                "16",
            ],
            None,
            "structure=sheet",
            "structure = \"sheet\"",
        ),
        (
            &[
                "voronoi",
                "--structure",
                "sheet",
                "--pores",
                "0.5",
                "--spacing",
                "3",
                "--density",
                "0.2",
                "--size",
                "9,9,7",
                "--origin",
                "1,-2,0.5",
                "-r",
                "12",
            ],
            Some("y=2"),
            "pores=0.8",
            "pores = 0.8",
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

/// The page, in headless Chromium, meshes and slices its part through its buttons: the jobs
/// end done, in the part's folder, with the files `latvox` makes.
#[test]
#[ignore = "long: headless Chromium meshes and slices the part"]
fn the_page_meshes_and_slices() {
    let d = tempdir();
    let root = d.path().canonicalize().unwrap();
    make_part(
        &root,
        &[
            "tpms",
            "--type",
            "gyroid",
            "--density",
            "0.3",
            "--cells",
            "2",
            "--cell-size",
            "5",
            "--resolution",
            "16",
        ],
    );
    let server = Server::start("part.toml", &root);
    let args = [
        "--width",
        "160",
        "--height",
        "120",
        "--mesh",
        "m.stl",
        "--slice",
        "layers.cli",
        "--layer",
        "0.5",
    ];
    let Some(seen) = drive(&server.url(), &root, &args) else {
        return;
    };
    assert_eq!(seen["error"], serde_json::Value::Null, "{seen}");
    assert_eq!(seen["page_errors"], serde_json::json!([]), "{seen}");
    let mesh = &seen["meshing"];
    assert_eq!(mesh["state"], "done", "{seen}");
    assert_eq!(mesh["output"], root.join("m.stl").display().to_string());
    let density = mesh["report"]["achieved_density"].as_f64().unwrap();
    assert!((density - 0.3).abs() < 0.01, "{seen}");
    let vol = volume(&read_stl(&root.join("m.stl")));
    assert!((vol / 1000.0 - density).abs() < 0.002, "{vol}");
    let slice = &seen["slicing"];
    assert_eq!(slice["state"], "done", "{seen}");
    assert_eq!(
        slice["output"],
        root.join("layers.cli").display().to_string()
    );
    assert_eq!(slice["report"]["layers"], 20, "{seen}");
    assert!(root.join("layers.cli").is_file());
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
/// that does not exist, an output folder that is a file.
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
        (
            &["view", "part.toml", "--out-dir", "part.stl"],
            "not a folder",
        ),
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

/// Every file and link under `dir`, with its contents or target: what a refused request must
/// leave as it was.
fn snapshot(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut all = BTreeMap::new();
    let mut todo = vec![dir.to_path_buf()];
    while let Some(d) = todo.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            let m = std::fs::symlink_metadata(&p).unwrap();
            let seen = if m.file_type().is_symlink() {
                let to = std::fs::read_link(&p).unwrap();
                format!("link to {}", to.display()).into_bytes()
            } else if m.is_dir() {
                todo.push(p.clone());
                b"folder".to_vec()
            } else {
                std::fs::read(&p).unwrap()
            };
            all.insert(p, seen);
        }
    }
    all
}

/// A part in `root/part/` (with a folder `sub`), beside `root/outside/` holding one file, with links in the part's
/// folder leading out: a folder (`out`), an existing file (`there.toml`) and a file not yet
/// made (`gone.toml`).
fn part_beside_outside(root: &Path) -> PathBuf {
    let part = root.join("part");
    let outside = root.join("outside");
    std::fs::create_dir_all(part.join("sub")).unwrap();
    std::fs::create_dir_all(&outside).unwrap();
    make_part(
        &part,
        &[
            "tpms",
            "--type",
            "gyroid",
            "--density",
            "0.3",
            "--cells",
            "1",
            "--cell-size",
            "4",
            "--resolution",
            "12",
        ],
    );
    std::fs::write(outside.join("there.toml"), "# theirs\n").unwrap();
    std::os::unix::fs::symlink(&outside, part.join("out")).unwrap();
    std::os::unix::fs::symlink(outside.join("there.toml"), part.join("there.toml")).unwrap();
    std::os::unix::fs::symlink(outside.join("gone.toml"), part.join("gone.toml")).unwrap();
    part
}

/// The server obeys only the page opened with its URL, and writes only in its folder. Refused,
/// with nothing anywhere changed: a request without the token, with a wrong token of the right
/// length, a cross-site "simple" request (text/plain, another site's Origin), the right token
/// sent by another site's page, the right token under another Host (DNS rebinding; the page
/// too), and saving, meshing or slicing to names outside the folder — absolute, `../`, through
/// a link to a folder or to a file outside, the folder itself. No answer lets another site read
/// it (no Access-Control-Allow-Origin). The page's own requests are served.
#[test]
fn the_server_obeys_only_its_page_and_writes_only_in_its_folder() {
    let d = tempdir();
    let root = d.path().canonicalize().unwrap();
    let part = part_beside_outside(&root);
    let server = Server::start("part.toml", &part);
    let host = format!("127.0.0.1:{}", server.port);
    let own = format!("http://{host}");
    let wrong = "0".repeat(server.token.len());
    assert_ne!(wrong, server.token);
    let h = |pairs: &[(&str, &str)]| -> Headers {
        pairs
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect()
    };
    let token = format!("token {}", server.token);
    let bad_token = format!("token {wrong}");
    let evil_host = format!("evil.example:{}", server.port);
    let outside_abs = root.join("outside/x.toml").display().to_string();
    let save = |path: &str| format!(r#"{{"settings": {{"type": "gyroid"}}, "path": "{path}"}}"#);
    let settings =
        r#"{"type": "gyroid", "density": 0.3, "cells": 1, "cell-size": 4, "resolution": 12}"#;
    let job = |output: &str| format!(r#"{{"settings": {settings}, "output": "{output}"}}"#);
    let before = snapshot(&root);

    let json = "application/json";
    let cases: Vec<(&str, &str, Headers, String, u16)> = vec![
        // No token, a wrong one: nothing but the page's files.
        (
            "GET",
            "/api/part",
            h(&[("Host", &host)]),
            String::new(),
            401,
        ),
        ("GET", "/api/job", h(&[("Host", &host)]), String::new(), 401),
        (
            "POST",
            "/api/save",
            h(&[("Host", &host), ("Content-Type", json)]),
            save("saved.toml"),
            401,
        ),
        (
            "GET",
            "/api/part",
            h(&[("Host", &host), ("Authorization", &bad_token)]),
            String::new(),
            401,
        ),
        (
            "POST",
            "/api/save",
            h(&[("Host", &host), ("Authorization", &bad_token)]),
            save("saved.toml"),
            401,
        ),
        (
            "POST",
            "/api/mesh",
            h(&[("Host", &host), ("Authorization", "token")]),
            job("a.stl"),
            401,
        ),
        // A cross-site simple request: no preflight, no token.
        (
            "POST",
            "/api/save",
            h(&[
                ("Host", &host),
                ("Origin", "http://evil.example"),
                ("Content-Type", "text/plain"),
            ]),
            save(&outside_abs),
            403,
        ),
        // Another site's page holding the token, and a preflight from it.
        (
            "POST",
            "/api/save",
            h(&[
                ("Host", &host),
                ("Origin", "http://evil.example"),
                ("Authorization", &token),
            ]),
            save("saved.toml"),
            403,
        ),
        (
            "GET",
            "/api/part",
            h(&[
                ("Host", &host),
                ("Origin", "null"),
                ("Authorization", &token),
            ]),
            String::new(),
            403,
        ),
        (
            "OPTIONS",
            "/api/save",
            h(&[
                ("Host", &host),
                ("Origin", "http://evil.example"),
                ("Access-Control-Request-Method", "POST"),
            ]),
            String::new(),
            403,
        ),
        // DNS rebinding: the right token, another name.
        (
            "GET",
            "/api/part",
            h(&[("Host", &evil_host), ("Authorization", &token)]),
            String::new(),
            403,
        ),
        ("GET", "/", h(&[("Host", &evil_host)]), String::new(), 403),
        (
            "GET",
            "/view.js",
            h(&[("Host", "evil.example")]),
            String::new(),
            403,
        ),
        ("GET", "/", h(&[]), String::new(), 403),
        (
            "POST",
            "/api/save",
            h(&[("Host", &evil_host), ("Authorization", &token)]),
            save("saved.toml"),
            403,
        ),
    ];
    for (method, path, headers, body, want) in &cases {
        let a = server.send(method, path, headers, body);
        assert_eq!(a.status, *want, "{method} {path} {headers:?}: {}", a.body);
        assert!(!a.head.contains("access-control-allow"), "{}", a.head);
        assert_eq!(snapshot(&root), before, "{method} {path} {headers:?} wrote");
    }

    // With the token, names leading out of the folder.
    let outside_stl = root.join("outside/x.stl").display().to_string();
    let outside_cli = root.join("outside/x.cli").display().to_string();
    let out_of_folder: Vec<(&str, String)> = vec![
        ("/api/save", save(&outside_abs)),
        ("/api/save", save("../x.toml")),
        ("/api/save", save("sub/../../x.toml")),
        ("/api/save", save("out/x.toml")),
        ("/api/save", save("there.toml")),
        ("/api/save", save("gone.toml")),
        ("/api/mesh", job(&outside_stl)),
        ("/api/mesh", job("../x.stl")),
        ("/api/mesh", job("out/x.stl")),
        ("/api/slice", job(&outside_cli)),
        ("/api/slice", job("../x.cli")),
        ("/api/slice", job("out/x.cli")),
        ("/api/slice", job("out/")),
        ("/api/slice", job(".")),
        ("/api/slice", job("./")),
    ];
    for (path, body) in &out_of_folder {
        let (status, text) = server.ask("POST", path, body);
        assert_eq!(status, 403, "{path} {body}: {text}");
        assert!(text.contains("outside the folder"), "{text}");
        assert_eq!(snapshot(&root), before, "{path} {body} wrote");
    }
    let (_, job_now) = server.json("GET", "/api/job", "");
    assert_eq!(job_now["state"], "", "a job started: {job_now}");

    // The page's own requests: its files, its part (from its own origin too), a save inside.
    for (path, headers) in [
        ("/", h(&[("Host", &format!("localhost:{}", server.port))])),
        (
            "/view.js",
            h(&[("Host", &format!("[::1]:{}", server.port))]),
        ),
    ] {
        let a = server.send("GET", path, &headers, "");
        assert_eq!(a.status, 200, "{path}");
        assert!(a.head.contains("content-security-policy"), "{}", a.head);
    }
    let a = server.send(
        "GET",
        "/api/part",
        &h(&[("Host", &host), ("Origin", &own), ("Authorization", &token)]),
        "",
    );
    assert_eq!(a.status, 200, "{}", a.body);
    let p: serde_json::Value = serde_json::from_str(&a.body).unwrap();
    assert_eq!(p["folder"], part.display().to_string());
    assert_eq!(p["save"], part.join("part.toml").display().to_string());
    let (status, v) = server.json("POST", "/api/save", &save("sub/../saved.toml"));
    assert_eq!(status, 200, "{v}");
    assert_eq!(v["saved"], part.join("saved.toml").display().to_string());
    let text = std::fs::read_to_string(part.join("saved.toml")).unwrap();
    assert!(text.contains("type = \"gyroid\""), "{text}");
    // Only that file is new.
    let mut after = snapshot(&root);
    after.remove(&part.join("saved.toml"));
    assert_eq!(after, before);
}

/// Clients that send half a request, or nothing, do not hold the server: the page's requests
/// are answered at once beside them.
#[test]
fn slow_clients_do_not_hold_the_server() {
    let d = tempdir();
    let root = d.path().canonicalize().unwrap();
    let part = part_beside_outside(&root);
    let server = Server::start("part.toml", &part);
    let host = format!("127.0.0.1:{}", server.port);
    let open = |bytes: &str| {
        let mut s = TcpStream::connect(("127.0.0.1", server.port)).unwrap();
        s.write_all(bytes.as_bytes()).unwrap();
        s
    };
    let _held = [
        open(""),
        open("GET /api/part HTT"),
        open(&format!("GET /api/part HTTP/1.1\r\nHost: {host}\r\n")),
        open(&format!(
            "POST /api/scene HTTP/1.1\r\nHost: {host}\r\nAuthorization: token {}\r\n\
             Content-Length: 1000\r\n\r\n{{\"settings\": ",
            server.token
        )),
        open(&format!(
            "POST /api/save HTTP/1.1\r\nHost: {host}\r\nAuthorization: token {}\r\n\
             Content-Length: 100\r\n\r\n",
            server.token
        )),
    ];
    for _ in 0..3 {
        let t = Instant::now();
        let (status, _) = server.ask("GET", "/api/part", "");
        assert_eq!(status, 200);
        let (status, v) = server.json(
            "POST",
            "/api/scene",
            r#"{"settings": {"type": "d", "cells": 1}}"#,
        );
        assert_eq!(status, 200, "{v}");
        let (status, page) = server.ask("GET", "/", "");
        assert_eq!(status, 200);
        assert!(page.contains("<canvas"));
        let took = t.elapsed();
        assert!(took < Duration::from_secs(3), "the page waited {took:?}");
    }
    // A refusal needs no body: a client that sends a head and stalls is answered at once.
    let mut s = open(&format!(
        "POST /api/save HTTP/1.1\r\nHost: {host}\r\nContent-Length: 100\r\n\r\n"
    ));
    s.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
    let mut answer = String::new();
    let _ = s.read_to_string(&mut answer);
    assert!(answer.starts_with("HTTP/1.1 401"), "{answer:?}");
}

/// With `--out-dir`, the page writes there (names relative to it) and nowhere else, its part
/// file's folder included; the default part file it saves is there too.
#[test]
fn out_dir_is_where_the_page_writes() {
    let d = tempdir();
    let root = d.path().canonicalize().unwrap();
    let part = part_beside_outside(&root);
    let server = Server::start_with(
        &["view", "part/part.toml", "--out-dir", "runs/today"],
        &root,
    );
    let runs = root.join("runs/today");
    assert!(runs.is_dir());
    let (status, p) = server.json("GET", "/api/part", "");
    assert_eq!(status, 200, "{p}");
    assert_eq!(p["folder"], runs.display().to_string());
    assert_eq!(p["save"], runs.join("part.toml").display().to_string());
    let before = snapshot(&part);
    let body = |path: &str| format!(r#"{{"settings": {{"type": "d"}}, "path": "{path}"}}"#);
    let in_part = part.join("part.toml").display().to_string();
    for name in [in_part.as_str(), "../../part/x.toml"] {
        let (status, v) = server.json("POST", "/api/save", &body(name));
        assert_eq!(status, 403, "{name}: {v}");
    }
    assert_eq!(snapshot(&part), before);
    let (status, v) = server.json("POST", "/api/save", r#"{"settings": {"type": "d"}}"#);
    assert_eq!(status, 200, "{v}");
    let (status, v) = server.json("POST", "/api/save", &body("d.toml"));
    assert_eq!(status, 200, "{v}");
    assert!(runs.join("part.toml").is_file() && runs.join("d.toml").is_file());
    assert_eq!(snapshot(&part), before);
}

/// Random requests — methods, paths, headers (hosts, origins, tokens, lengths, encodings) and
/// bodies (JSON settings with names in and out of the folder, garbage) — for a few seconds,
/// from a fixed seed: the server answers each (never a 500), keeps serving, and nothing outside
/// its folder changes.
#[test]
fn random_requests_neither_stop_the_server_nor_write_outside() {
    let d = tempdir();
    let root = d.path().canonicalize().unwrap();
    let part = part_beside_outside(&root);
    let mut server = Server::start("part.toml", &part);
    let outside = root.join("outside");
    let watched = |root: &Path| {
        let mut s = snapshot(root);
        s.retain(|p, _| !p.starts_with(&part) || p.parent() == Some(&part) && p.is_symlink());
        s
    };
    let before = watched(&root);
    let port = server.port;
    let mut rng = Rng(0x1a77_0c5e);
    let pick = |rng: &mut Rng, xs: &[String]| xs[rng.below(xs.len() as u64) as usize].clone();
    let s = |xs: &[&str]| xs.iter().map(|x| x.to_string()).collect::<Vec<String>>();
    let methods = s(&["PUT", "DELETE", "OPTIONS", "HEAD", "get", "BREW"]);
    let routes = s(&[
        "/api/save",
        "/api/save",
        "/api/mesh",
        "/api/slice",
        "/api/scene",
        "/api/part",
        "/api/job",
        "/",
    ]);
    let paths = s(&[
        "/view.js",
        "/trace.glsl",
        "/api/",
        "/api/save/..",
        "/API/SAVE",
        "//api/save",
        "/api/save?x=1",
        "/%2e%2e/api/save",
        "/api/../api/save",
        "*",
        "http://evil.example/api/save",
    ]);
    let outside_names = [
        outside.join("x.toml").display().to_string(),
        outside.join("x.stl").display().to_string(),
        outside.join("l.cli").display().to_string(),
        "/tmp/../".to_string() + &outside.join("y.toml").display().to_string(),
    ];
    let mut names = s(&[
        "a.toml",
        "b.stl",
        "c.cli",
        "layers/",
        "sub/e.toml",
        "sub/../f.toml",
        "../x.toml",
        "../outside/x.stl",
        "out/x.toml",
        "out/",
        "there.toml",
        "gone.toml",
        ".",
        "./",
        "",
        "a\u{0}b.toml",
        "üñí.toml",
        "sub",
        "x.xyz",
        "part.toml",
        "//",
        "~/x.toml",
    ]);
    names.extend(outside_names);
    names.push("n".repeat(300) + ".toml");
    let hosts = vec![
        format!("127.0.0.1:{port}"),
        format!("127.0.0.1:{port}"),
        format!("127.0.0.1:{port}"),
        format!("localhost:{port}"),
        format!("evil.example:{port}"),
        "127.0.0.1".into(),
        String::new(),
    ];
    let origins = vec![
        String::new(),
        String::new(),
        String::new(),
        format!("http://127.0.0.1:{port}"),
        "http://evil.example".into(),
        "null".into(),
    ];
    let good = format!("token {}", server.token);
    let auths = vec![
        good.clone(),
        good.clone(),
        good.clone(),
        good.clone(),
        String::new(),
        format!("token {}", "f".repeat(server.token.len())),
        format!("Bearer {}", server.token),
        "token".into(),
    ];
    let values = s(&[
        "0.3",
        "0.2",
        "1",
        "-1",
        "0",
        "1e308",
        "\"x\"",
        "null",
        "true",
        "[1, 2]",
        "[2, 1, 1]",
        "{}",
        "\"gyroid\"",
        "\"d\"",
        "\"net\"",
        "\"sheet\"",
        "4",
        "12",
    ]);
    let keys = s(&[
        "type",
        "structure",
        "density",
        "cells",
        "cell-size",
        "resolution",
        "command",
        "bogus",
        "radius",
        "input",
        "size",
        "origin",
    ]);
    let settings = |rng: &mut Rng| -> String {
        let mut kv = vec![
            r#""cells": 1"#.to_string(),
            r#""cell-size": 4"#.to_string(),
            r#""resolution": 12"#.to_string(),
        ];
        for _ in 0..rng.below(4) {
            let k = pick(rng, &keys);
            let v = if k == "input" || k == "command" {
                quoted(&pick(rng, &names))
            } else {
                pick(rng, &values)
            };
            kv.push(format!("{}: {v}", quoted(&k)));
        }
        format!("{{{}}}", kv.join(", "))
    };
    let deadline = Instant::now() + Duration::from_secs(3);
    let mut sent = 0;
    let mut answered: BTreeMap<u16, usize> = BTreeMap::new();
    while Instant::now() < deadline && sent < 1500 {
        sent += 1;
        let method = match rng.below(10) {
            0..=4 => "POST".to_string(),
            5..=7 => "GET".to_string(),
            _ => pick(&mut rng, &methods),
        };
        let from = if rng.below(5) > 0 { &routes } else { &paths };
        let path = pick(&mut rng, from);
        let body = match rng.below(16) {
            0 => String::new(),
            1 => {
                let n = rng.below(64) as usize;
                (0..n).map(|_| (32 + rng.below(95) as u8) as char).collect()
            }
            2 => "[".repeat(rng.below(3000) as usize),
            _ => {
                let mut fields = vec![format!(r#""settings": {}"#, settings(&mut rng))];
                for key in ["path", "output"] {
                    if rng.below(3) > 0 {
                        fields.push(format!("{key:?}: {}", quoted(&pick(&mut rng, &names))));
                    }
                }
                if rng.below(2) == 0 {
                    fields.push(format!(
                        r#""layer": {}"#,
                        pick(&mut rng, &s(&["0.5", "1", "-1", "0", "\"x\"", "null"]))
                    ));
                }
                format!("{{{}}}", fields.join(", "))
            }
        };
        let mut head = format!("{method} {path} HTTP/1.1\r\n");
        let mut header = |k: &str, v: &str| {
            if !v.is_empty() {
                head.push_str(&format!("{k}: {v}\r\n"));
            }
        };
        // Most requests are the page's own, to reach past the checks into the API.
        if rng.below(4) > 0 {
            header("Host", &hosts[0]);
            header("Authorization", &good);
        } else {
            header("Host", &pick(&mut rng, &hosts));
            header("Origin", &pick(&mut rng, &origins));
            header("Authorization", &pick(&mut rng, &auths));
        }
        header(
            "Content-Type",
            if rng.below(4) == 0 {
                "text/plain"
            } else {
                "application/json"
            },
        );
        let length = match rng.below(30) {
            0 => String::new(),
            1 => (body.len() + 1 + rng.below(50) as usize).to_string(),
            2 => body
                .len()
                .saturating_sub(1 + rng.below(5) as usize)
                .to_string(),
            3 => "99999999999999999999".into(),
            4 => "-1".into(),
            5 => format!("{0}\r\nContent-Length: {0}", body.len()),
            _ => body.len().to_string(),
        };
        header("Content-Length", &length);
        if rng.below(20) == 0 {
            header("Transfer-Encoding", "chunked");
        }
        if rng.below(10) == 0 {
            header("Expect", "100-continue");
        }
        if rng.below(30) == 0 {
            head.push_str("Bad Header Line\r\n");
        }
        head.push_str("Connection: close\r\n\r\n");
        let mut bytes = head.into_bytes();
        bytes.extend_from_slice(body.as_bytes());
        if rng.below(25) == 0 {
            // Bytes that are not text.
            let at = rng.below(bytes.len() as u64) as usize;
            bytes[at] = 0xff;
        }
        if rng.below(25) == 0 {
            let at = rng.below(bytes.len() as u64) as usize;
            bytes.truncate(at);
        }
        let mut c = TcpStream::connect(("127.0.0.1", port)).unwrap();
        c.set_read_timeout(Some(Duration::from_secs(15))).unwrap();
        let _ = c.write_all(&bytes);
        // The request ends here: a length that promises more meets the end of the stream.
        let _ = c.shutdown(Shutdown::Write);
        let mut answer = Vec::new();
        let _ = c.read_to_end(&mut answer);
        let text = String::from_utf8_lossy(&answer);
        // The final answer, past a "100 Continue".
        let last = text.rsplit("HTTP/1.1 ").next().unwrap_or_default();
        let status: u16 = last
            .split(' ')
            .next()
            .and_then(|c| c.parse().ok())
            .unwrap_or(0);
        // A request that ends inside its head may go unanswered; any answer is one of ours.
        assert!(
            status != 500 && (status == 0 || (100..600).contains(&status)),
            "{text}"
        );
        if status == 0 {
            assert!(answer.is_empty(), "{text}");
        }
        *answered.entry(status).or_default() += 1;
        assert!(
            server_alive(&mut server),
            "the server stopped after {bytes:?}"
        );
    }
    eprintln!("{sent} random requests: answers by status {answered:?}");
    assert!(answered.get(&200).copied().unwrap_or(0) > 0, "{answered:?}");
    assert!(
        answered.keys().filter(|&&s| s >= 400).count() >= 5,
        "{answered:?}"
    );
    // A job started at random ends before the folder is looked at.
    let start = Instant::now();
    loop {
        let (status, j) = server.json("GET", "/api/job", "");
        assert_eq!(status, 200);
        if j["state"] != "running" {
            break;
        }
        assert!(start.elapsed() < Duration::from_secs(120), "{j}");
        std::thread::sleep(Duration::from_millis(100));
    }
    let (status, _) = server.ask("GET", "/api/part", "");
    assert_eq!(status, 200);
    assert_eq!(
        watched(&root),
        before,
        "something outside the folder changed"
    );
}

fn server_alive(server: &mut Server) -> bool {
    server.child.try_wait().unwrap().is_none()
}

/// `s` as a JSON string.
fn quoted(s: &str) -> String {
    serde_json::to_string(s).unwrap()
}
