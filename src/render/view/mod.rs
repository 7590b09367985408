//! The browser editor: a local HTTP server (127.0.0.1 only) that hands a page its part as the
//! numbers a WebGL2 fragment shader sphere-traces (TPMS terms, the augmented strut cell, a
//! filled part's shell and kept solids as BVHs: [`scene::Scene`]), and
//! carries out what the page asks — a new part from edited settings, saving the part file,
//! meshing it or writing its slices as a `latvox` child process whose progress the page polls.
//! The page never meshes; everything it loads is served from here (no CDN, no build step).
//!
//! Routes: `GET /` (the page), `/view.js`, `/trace.glsl`; `GET /api/part` (settings, scene,
//! choices); `POST /api/scene` (settings → scene), `/api/save`, `/api/mesh`, `/api/slice`;
//! `GET /api/job`. A bad request gets a 4xx answer with `{"error": "…"}` and the server goes on.

pub mod scene;

use crate::error::{Error, Result};
use scene::Scene;
use serde_json::{json, Value};
use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::Instant;
use tiny_http::{Header, Method, Request, Response};

const PAGE: &str = include_str!("page/index.html");
const SCRIPT: &str = include_str!("page/view.js");
const SHADER: &str = include_str!("page/trace.glsl");

/// The largest request body read, bytes.
const MAX_BODY: u64 = 1 << 20;

/// What the page draws of a part's settings, with every refusal of the part's command.
pub type SceneOf = Box<dyn Fn(&toml::Table) -> Result<Scene> + Send + Sync>;

/// Writes settings as a part file.
pub type SavePart = Box<dyn Fn(&Path, &toml::Table) -> Result<()> + Send + Sync>;

/// What the server needs from the command line: how settings become a scene and a part file.
pub struct Hooks {
    /// What the page draws of a part's settings.
    pub scene: SceneOf,
    /// Writes settings as a part file.
    pub save: SavePart,
}

/// The part being edited.
pub struct Editor {
    /// The part file opened (the page saves there unless told another name).
    pub path: PathBuf,
    /// Its settings, `command` included.
    pub settings: toml::Table,
    /// The part's choices the page offers: option name → values.
    pub choices: Value,
    /// The latvox executable that meshes and slices.
    pub exe: PathBuf,
    /// The command line's part handling.
    pub hooks: Hooks,
}

/// A meshing or slicing run.
#[derive(Default)]
struct Job {
    /// `"running"`, `"done"` or `"failed"` (`""` before the first).
    state: &'static str,
    what: String,
    output: String,
    stage: String,
    message: String,
    report: Value,
    started: Option<Instant>,
    seconds: f64,
}

/// An answer: status and JSON body.
type Answer = (u16, Value);

fn bad(status: u16, message: impl Into<String>) -> Answer {
    (status, json!({ "error": message.into() }))
}

/// Serves `editor` on `server` until the process is stopped.
pub fn serve(server: tiny_http::Server, editor: Editor) -> Result<()> {
    let job = Arc::new(Mutex::new(Job::default()));
    for mut request in server.incoming_requests() {
        let url = request.url().split('?').next().unwrap_or("").to_string();
        let method = request.method().clone();
        let response = match (&method, url.as_str()) {
            (Method::Get, "/") => text(PAGE, "text/html; charset=utf-8"),
            (Method::Get, "/view.js") => text(SCRIPT, "text/javascript; charset=utf-8"),
            (Method::Get, "/trace.glsl") => text(SHADER, "text/plain; charset=utf-8"),
            (_, path) if path.starts_with("/api/") => {
                let (status, body) = match read_body(&mut request) {
                    Ok(body) => api(&editor, &job, &method, path, body),
                    Err(a) => a,
                };
                let mut r = Response::from_string(body.to_string()).with_status_code(status);
                r.add_header(header("Content-Type", "application/json"));
                r
            }
            _ => Response::from_string("not found").with_status_code(404),
        };
        // A client gone before its answer is no reason to stop.
        let _ = request.respond(response);
    }
    Ok(())
}

fn header(name: &str, value: &str) -> Header {
    Header::from_bytes(name.as_bytes(), value.as_bytes()).expect("a valid header")
}

fn text(body: &str, kind: &str) -> Response<std::io::Cursor<Vec<u8>>> {
    let mut r = Response::from_string(body);
    r.add_header(header("Content-Type", kind));
    r.add_header(header("Cache-Control", "no-store"));
    r
}

/// The request's JSON body (`Null` when empty).
fn read_body(request: &mut Request) -> std::result::Result<Value, Answer> {
    if request.body_length().unwrap_or(0) as u64 > MAX_BODY {
        return Err(bad(413, "the request is larger than 1 MB"));
    }
    let mut raw = Vec::new();
    request
        .as_reader()
        .take(MAX_BODY + 1)
        .read_to_end(&mut raw)
        .map_err(|e| bad(400, format!("the request could not be read: {e}")))?;
    if raw.len() as u64 > MAX_BODY {
        return Err(bad(413, "the request is larger than 1 MB"));
    }
    if raw.iter().all(u8::is_ascii_whitespace) {
        return Ok(Value::Null);
    }
    serde_json::from_slice(&raw).map_err(|e| bad(400, format!("the request is not JSON: {e}")))
}

fn api(editor: &Editor, job: &Arc<Mutex<Job>>, method: &Method, path: &str, body: Value) -> Answer {
    match (method, path) {
        (Method::Get, "/api/part") => match scene_of(editor, &editor.settings) {
            Ok(scene) => (
                200,
                json!({
                    "path": editor.path.display().to_string(),
                    "settings": editor.settings,
                    "choices": editor.choices,
                    "scene": scene,
                }),
            ),
            Err(e) => bad(422, e.to_string()),
        },
        (Method::Post, "/api/scene") => {
            match settings(editor, &body).and_then(|s| scene_of(editor, &s)) {
                Ok(scene) => (200, json!({ "scene": scene })),
                Err(e) => bad(422, e.to_string()),
            }
        }
        (Method::Post, "/api/save") => {
            let run = || -> Result<String> {
                let s = settings(editor, &body)?;
                let to = output(&body, "path")?.unwrap_or_else(|| editor.path.clone());
                if !to
                    .extension()
                    .is_some_and(|e| e.eq_ignore_ascii_case("toml"))
                {
                    return Err(Error::invalid(format!(
                        "{}: part files are saved as .toml",
                        to.display()
                    )));
                }
                // Only a part the command accepts is saved.
                (editor.hooks.scene)(&s)?;
                (editor.hooks.save)(&to, &s)?;
                Ok(to.display().to_string())
            };
            match run() {
                Ok(saved) => (200, json!({ "saved": saved })),
                Err(e) => bad(422, e.to_string()),
            }
        }
        (Method::Post, "/api/mesh") | (Method::Post, "/api/slice") => {
            match start(editor, job, path == "/api/mesh", &body) {
                Ok(()) => (202, json!({ "started": true })),
                Err((status, e)) => bad(status, e.to_string()),
            }
        }
        (Method::Get, "/api/job") => {
            let j = job.lock().unwrap_or_else(|e| e.into_inner());
            let seconds = match (j.state, j.started) {
                ("running", Some(s)) => s.elapsed().as_secs_f64(),
                _ => j.seconds,
            };
            (
                200,
                json!({
                    "state": j.state,
                    "what": j.what,
                    "output": j.output,
                    "stage": j.stage,
                    "message": j.message,
                    "report": j.report,
                    "seconds": seconds,
                }),
            )
        }
        (_, "/api/part" | "/api/scene" | "/api/save" | "/api/mesh" | "/api/slice" | "/api/job") => {
            bad(405, format!("{path} does not take {method}"))
        }
        _ => bad(404, format!("{path}: no such request")),
    }
}

fn scene_of(editor: &Editor, settings: &toml::Table) -> Result<Scene> {
    (editor.hooks.scene)(settings)
}

/// The settings a request gives (`{"settings": {…}}`), of the part's own command.
fn settings(editor: &Editor, body: &Value) -> Result<toml::Table> {
    let given = body
        .get("settings")
        .ok_or_else(|| Error::invalid("the request gives no settings"))?;
    let mut table: toml::Table = serde_json::from_value(given.clone())
        .map_err(|e| Error::invalid(format!("settings: {e}")))?;
    let command = editor.settings.get("command").cloned();
    if table
        .get("command")
        .is_some_and(|c| Some(c) != command.as_ref())
    {
        return Err(Error::invalid(
            "settings: the part's command cannot be changed",
        ));
    }
    if let Some(c) = command {
        table.insert("command".into(), c);
    }
    Ok(table)
}

/// An output name a request gives under `key`, if any.
fn output(body: &Value, key: &str) -> Result<Option<PathBuf>> {
    match body.get(key) {
        None | Some(Value::Null) => Ok(None),
        Some(Value::String(s)) if !s.trim().is_empty() => Ok(Some(PathBuf::from(s.trim()))),
        Some(_) => Err(Error::invalid(format!("'{key}' must be a file name"))),
    }
}

/// Starts meshing (`mesh`) or slicing the part of the request's settings in a child process.
fn start(
    editor: &Editor,
    job: &Arc<Mutex<Job>>,
    mesh: bool,
    body: &Value,
) -> std::result::Result<(), (u16, Error)> {
    let invalid = |e: Error| (422, e);
    let s = settings(editor, body).map_err(invalid)?;
    let out = output(body, "output")
        .map_err(invalid)?
        .ok_or_else(|| invalid(Error::invalid("the request names no output")))?;
    (editor.hooks.scene)(&s).map_err(invalid)?;
    let dir = tempfile::tempdir().map_err(|e| (500, Error::io(std::env::temp_dir(), e)))?;
    let part = dir.path().join("part.toml");
    (editor.hooks.save)(&part, &s).map_err(|e| (500, e))?;
    let command = s.get("command").and_then(toml::Value::as_str).unwrap_or("");
    let mut args: Vec<String> = if mesh {
        vec![command.into(), "--part".into(), part.display().to_string()]
    } else {
        vec!["slice".into(), part.display().to_string()]
    };
    // The meshing commands write their report to a file, `slice` prints it.
    let report = dir.path().join("report.json");
    args.extend(["-o".into(), out.display().to_string()]);
    if mesh {
        args.extend(["--report".into(), report.display().to_string()]);
    } else {
        args.push("--json".into());
    }
    if !mesh {
        if let Some(layer) = body.get("layer") {
            let h = layer
                .as_f64()
                .filter(|h| *h > 0.0)
                .ok_or_else(|| invalid(Error::invalid("'layer' must be a thickness in mm")))?;
            args.extend(["--layer".into(), h.to_string()]);
        }
    }
    {
        let mut j = job.lock().unwrap_or_else(|e| e.into_inner());
        if j.state == "running" {
            return Err((409, Error::invalid(format!("{} is still running", j.what))));
        }
        *j = Job {
            state: "running",
            what: if mesh { "meshing" } else { "slicing" }.into(),
            output: out.display().to_string(),
            stage: "starting".into(),
            started: Some(Instant::now()),
            ..Job::default()
        };
    }
    let mut child = Command::new(&editor.exe)
        .args(&args)
        .env("LATVOX_PROGRESS", "lines")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| {
            job.lock().unwrap_or_else(|e| e.into_inner()).state = "failed";
            (500, Error::io(&editor.exe, e))
        })?;
    let job = Arc::clone(job);
    std::thread::spawn(move || {
        let _keep = dir;
        // stdout read beside stderr, so that neither pipe fills while the other is read.
        let stdout = child.stdout.take().map(|mut o| {
            std::thread::spawn(move || {
                let mut s = String::new();
                let _ = o.read_to_string(&mut s);
                s
            })
        });
        let mut last = String::new();
        if let Some(err) = child.stderr.take() {
            for line in BufReader::new(err).lines().map_while(|l| l.ok()) {
                let mut j = job.lock().unwrap_or_else(|e| e.into_inner());
                match line.strip_prefix("progress: ") {
                    Some(stage) => j.stage = stage.to_string(),
                    None if !line.trim().is_empty() => last = line,
                    None => {}
                }
            }
        }
        let stdout = stdout.and_then(|t| t.join().ok()).unwrap_or_default();
        let ok = child.wait().is_ok_and(|s| s.success());
        let mut j = job.lock().unwrap_or_else(|e| e.into_inner());
        j.seconds = j.started.map_or(0.0, |s| s.elapsed().as_secs_f64());
        j.state = if ok { "done" } else { "failed" };
        j.stage.clear();
        let text = std::fs::read_to_string(&report).unwrap_or(stdout);
        j.report = serde_json::from_str(text.trim()).unwrap_or(Value::Null);
        j.message = if ok { String::new() } else { last };
    });
    Ok(())
}
