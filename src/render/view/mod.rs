//! The browser editor: a local HTTP server (127.0.0.1 only) that hands a page its part as the
//! numbers a WebGL2 fragment shader sphere-traces (TPMS terms, the augmented strut cell, a
//! filled part's shell and kept solids as BVHs: [`scene::Scene`]), and
//! carries out what the page asks — a new part from edited settings, saving the part file,
//! meshing it or writing its slices as a `latvox` child process whose progress the page polls.
//! The page never meshes; everything it loads is served from here (no CDN, no build step).
//!
//! Routes: `GET /` (the page), `/view.js`, `/trace.glsl`; `GET /api/part` (settings, scene,
//! choices, the folder written in); `POST /api/scene` (settings → scene), `/api/save`,
//! `/api/mesh`, `/api/slice`; `GET /api/job`. A bad request gets a 4xx answer with
//! `{"error": "…"}` and the server goes on.
//!
//! Only the page the user opened is obeyed ([`guard`]): every request must name this server by
//! its loopback address (no DNS rebinding) and come from no other site's page, every request but
//! the page's own files must carry the run's token, and what is written stays in one folder.
//! Requests are read and answered as [`http`] bounds them (time, size, connections).

pub mod guard;
mod http;
pub mod scene;

use crate::error::{Error, Result};
use guard::{Folder, Local, Outside, Token};
use http::{Head, Response};
use scene::Scene;
use serde_json::{json, Value};
use std::io::{BufRead, BufReader, Read};
use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::Instant;

const PAGE: &str = include_str!("page/index.html");
const SCRIPT: &str = include_str!("page/view.js");
const SHADER: &str = include_str!("page/trace.glsl");

/// What the page may load and where it may connect: this server only, and no other page may
/// frame it. The page never evaluates strings, but scripts that drive it (Playwright, in the
/// browser tests) do: `'unsafe-eval'` lets them see the page as users do, under this policy.
const POLICY: &str = "default-src 'self'; script-src 'self' 'unsafe-eval'; \
                      style-src 'self' 'unsafe-inline'; img-src 'self' data:; object-src 'none'; \
                      base-uri 'none'; form-action 'none'; frame-ancestors 'none'";

/// The commands whose parts the editor meshes (the command a child `latvox` runs).
const COMMANDS: &[&str] = &["tpms", "strut", "voronoi", "fill"];

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
    /// The part file opened (the page saves there unless told another name, when it lies in
    /// `folder`).
    pub path: PathBuf,
    /// Its settings, `command` included.
    pub settings: toml::Table,
    /// The part's choices the page offers: option name → values.
    pub choices: Value,
    /// The latvox executable that meshes and slices.
    pub exe: PathBuf,
    /// The command line's part handling.
    pub hooks: Hooks,
    /// The folder the page's part files, meshes and slices are written in.
    pub folder: Folder,
    /// The secret every request must carry.
    pub token: Token,
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

/// A name outside the folder: refused, nothing written.
fn outside(e: Outside) -> Answer {
    bad(403, e.0)
}

/// The server's state: the part, where the page saves by default, the running job.
struct Server {
    editor: Editor,
    local: Local,
    /// The part file saved when the page names none.
    save: PathBuf,
    job: Arc<Mutex<Job>>,
}

/// Serves `editor` on `listener` until the process is stopped; the listener must be bound to a
/// loopback address (127.0.0.1), as nothing else is served.
pub fn serve(listener: TcpListener, editor: Editor) -> Result<()> {
    let address = listener
        .local_addr()
        .map_err(|e| Error::io("127.0.0.1", e))?;
    if !address.ip().is_loopback() {
        return Err(Error::invalid(format!(
            "{address}: the editor listens on the loopback address only"
        )));
    }
    let port = address.port();
    let part = editor
        .path
        .canonicalize()
        .unwrap_or_else(|_| editor.path.clone());
    let save = if editor.folder.holds(&part) {
        part
    } else {
        let name = part.file_name().unwrap_or("part.toml".as_ref());
        editor.folder.root().join(name)
    };
    let server = Server {
        editor,
        local: Local::new(port),
        save,
        job: Arc::new(Mutex::new(Job::default())),
    };
    http::serve(listener, Arc::new(server));
    Ok(())
}

/// The page's own files: served without the token (they hold no secret, and the page reads the
/// token from its own address).
fn public(head: &Head) -> bool {
    head.method == "GET" && matches!(head.path.as_str(), "/" | "/view.js" | "/trace.glsl")
}

impl http::Handler for Server {
    fn admit(&self, head: &Head) -> Option<Response> {
        let refuse = |status: u16, message: &str| {
            Some(if head.path.starts_with("/api/") {
                Response::error(status, message)
            } else {
                Response::new(status, "text/plain; charset=utf-8", message)
            })
        };
        if !self.local.host_ok(head.header("host")) {
            return refuse(
                403,
                "this server answers to 127.0.0.1, localhost and [::1] with its port only",
            );
        }
        if head.count("origin") > 1 || !self.local.origin_ok(head.header("origin")) {
            return refuse(403, "requests from other sites' pages are refused");
        }
        if !public(head) && !self.editor.token.admits(head.header("authorization")) {
            return refuse(
                401,
                "the request lacks the editor's token: open the URL `latvox view` printed, with its ?token=",
            );
        }
        None
    }

    fn answer(&self, head: &Head, body: &[u8]) -> Response {
        let page = |text: &str, kind: &'static str| {
            let mut r = Response::new(200, kind, text);
            r.headers
                .push(("Content-Security-Policy", POLICY.to_string()));
            r
        };
        match (head.method.as_str(), head.path.as_str()) {
            ("GET", "/") => page(PAGE, "text/html; charset=utf-8"),
            ("GET", "/view.js") => page(SCRIPT, "text/javascript; charset=utf-8"),
            ("GET", "/trace.glsl") => page(SHADER, "text/plain; charset=utf-8"),
            (method, path) if path.starts_with("/api/") => {
                let (status, value) = match json_body(body) {
                    Ok(body) => self.api(method, path, body),
                    Err(a) => a,
                };
                Response::json(status, &value)
            }
            _ => Response::new(404, "text/plain; charset=utf-8", "not found"),
        }
    }
}

/// The request's JSON body (`Null` when empty).
fn json_body(raw: &[u8]) -> std::result::Result<Value, Answer> {
    if raw.iter().all(u8::is_ascii_whitespace) {
        return Ok(Value::Null);
    }
    serde_json::from_slice(raw).map_err(|e| bad(400, format!("the request is not JSON: {e}")))
}

impl Server {
    fn api(&self, method: &str, path: &str, body: Value) -> Answer {
        let editor = &self.editor;
        match (method, path) {
            ("GET", "/api/part") => match scene_of(editor, &editor.settings) {
                Ok(scene) => (
                    200,
                    json!({
                        "path": editor.path.display().to_string(),
                        "folder": editor.folder.root().display().to_string(),
                        "save": self.save.display().to_string(),
                        "settings": editor.settings,
                        "choices": editor.choices,
                        "scene": scene,
                    }),
                ),
                Err(e) => bad(422, e.to_string()),
            },
            ("POST", "/api/scene") => {
                match settings(editor, &body).and_then(|s| scene_of(editor, &s)) {
                    Ok(scene) => (200, json!({ "scene": scene })),
                    Err(e) => bad(422, e.to_string()),
                }
            }
            ("POST", "/api/save") => self.save(&body),
            ("POST", "/api/mesh") | ("POST", "/api/slice") => {
                match start(editor, &self.job, path == "/api/mesh", &body) {
                    Ok(()) => (202, json!({ "started": true })),
                    Err(a) => a,
                }
            }
            ("GET", "/api/job") => {
                let j = self.job.lock().unwrap_or_else(|e| e.into_inner());
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
            (
                _,
                "/api/part" | "/api/scene" | "/api/save" | "/api/mesh" | "/api/slice" | "/api/job",
            ) => bad(405, format!("{path} does not take {method}")),
            _ => bad(404, format!("{path}: no such request")),
        }
    }

    /// Writes the request's settings as a part file, in the folder.
    fn save(&self, body: &Value) -> Answer {
        let editor = &self.editor;
        let to = match output(body, "path") {
            Ok(Some(name)) => match editor.folder.resolve(&name) {
                Ok(p) => p,
                Err(e) => return outside(e),
            },
            Ok(None) => self.save.clone(),
            Err(e) => return bad(422, e.to_string()),
        };
        let run = || -> Result<String> {
            let s = settings(editor, body)?;
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
fn output(body: &Value, key: &str) -> Result<Option<String>> {
    match body.get(key) {
        None | Some(Value::Null) => Ok(None),
        // Control characters (a NUL above all) name no file a user means, and a program's
        // arguments cannot hold a NUL.
        Some(Value::String(s)) if s.chars().any(char::is_control) => Err(Error::invalid(format!(
            "'{key}' holds control characters: not a file name"
        ))),
        Some(Value::String(s)) if !s.trim().is_empty() => Ok(Some(s.trim().to_string())),
        Some(_) => Err(Error::invalid(format!("'{key}' must be a file name"))),
    }
}

/// Starts meshing (`mesh`) or slicing the part of the request's settings in a child process
/// that writes inside the folder.
fn start(
    editor: &Editor,
    job: &Arc<Mutex<Job>>,
    mesh: bool,
    body: &Value,
) -> std::result::Result<(), Answer> {
    let invalid = |e: Error| bad(422, e.to_string());
    let s = settings(editor, body).map_err(invalid)?;
    let name = output(body, "output")
        .map_err(invalid)?
        .ok_or_else(|| bad(422, "the request names no output"))?;
    let mut out = editor
        .folder
        .resolve(&name)
        .map_err(outside)?
        .display()
        .to_string();
    // A name ending in `/` asks `slice` for a folder of layers.
    if name.ends_with('/') {
        out.push('/');
    }
    (editor.hooks.scene)(&s).map_err(invalid)?;
    // The program run is always latvox, and its subcommand one that makes a part: never what a
    // request or a part file names.
    let command = s.get("command").and_then(toml::Value::as_str).unwrap_or("");
    if !COMMANDS.contains(&command) {
        return Err(bad(422, format!("'{command}' parts are not meshed here")));
    }
    let dir = tempfile::tempdir()
        .map_err(|e| bad(500, Error::io(std::env::temp_dir(), e).to_string()))?;
    let part = dir.path().join("part.toml");
    (editor.hooks.save)(&part, &s).map_err(|e| bad(500, e.to_string()))?;
    let mut args: Vec<String> = if mesh {
        vec![command.into(), "--part".into(), part.display().to_string()]
    } else {
        vec!["slice".into(), part.display().to_string()]
    };
    // The meshing commands write their report to a file, `slice` prints it.
    let report = dir.path().join("report.json");
    args.extend(["-o".into(), out.clone()]);
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
                .ok_or_else(|| bad(422, "'layer' must be a thickness in mm"))?;
            args.extend(["--layer".into(), h.to_string()]);
        }
    }
    {
        let mut j = job.lock().unwrap_or_else(|e| e.into_inner());
        if j.state == "running" {
            return Err(bad(409, format!("{} is still running", j.what)));
        }
        *j = Job {
            state: "running",
            what: if mesh { "meshing" } else { "slicing" }.into(),
            output: out,
            stage: "starting".into(),
            started: Some(Instant::now()),
            ..Job::default()
        };
    }
    let mut child = Command::new(&editor.exe)
        .args(&args)
        .env("LATVOX_PROGRESS", "lines")
        .current_dir(editor.folder.root())
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| {
            job.lock().unwrap_or_else(|e| e.into_inner()).state = "failed";
            bad(500, Error::io(&editor.exe, e).to_string())
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
