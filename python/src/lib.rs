//! The native half of latvox's Python package: runs a command of the command line in this process
//! (the same definitions, compiled in from `src/cli`), its meshes kept in memory and handed to
//! NumPy, the GIL released while it works. The Python half (`python/latvox`) turns keyword
//! arguments into the command's options and errors into exceptions.

// The commands' definitions, as the binary has them; the binary's own parts of them (its whole
// command line, its printing) are not used here.
#[path = "../../src/cli/mod.rs"]
#[allow(dead_code, unused_imports)]
mod cli;

use latvox::geom::Mesh;
use numpy::ndarray::Array2;
use numpy::{PyArray2, PyReadonlyArray2};
use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{mpsc, Arc, Mutex};
use std::time::Duration;

create_exception!(
    _latvox,
    Failure,
    PyException,
    "A command failed: args are (kind, message, data as JSON); the Python half raises the public exception of that kind."
);

/// How often the waiting caller looks for Ctrl-C and progress, while latvox works.
const POLL: Duration = Duration::from_millis(50);

/// A mesh handed to Python: vertices (N, 3) float64, faces (M, 3) uint32 (Rust's own buffer,
/// not copied).
type PyMesh = (Py<PyArray2<f64>>, Py<PyArray2<u32>>);

/// A run's exit code and the meshes it kept: (the path each would have gone to, vertices, faces).
type Ran = (i32, Vec<(String, Py<PyArray2<f64>>, Py<PyArray2<u32>>)>);

fn arrays(py: Python<'_>, mesh: Mesh) -> PyResult<PyMesh> {
    let Mesh { positions, indices } = mesh;
    let vertices: Vec<f64> = positions.iter().map(|&x| x as f64).collect();
    drop(positions);
    let (n, m) = (vertices.len() / 3, indices.len() / 3);
    let shape = |e: numpy::ndarray::ShapeError| Failure::new_err(("backend", e.to_string(), "{}"));
    let v = Array2::from_shape_vec((n, 3), vertices).map_err(shape)?;
    let f = Array2::from_shape_vec((m, 3), indices).map_err(shape)?;
    Ok((
        PyArray2::from_owned_array(py, v).unbind(),
        PyArray2::from_owned_array(py, f).unbind(),
    ))
}

/// The exception for a latvox error: its kind, its one-line message, and its data.
fn failure(e: &latvox::Error) -> PyErr {
    use latvox::Error;
    let data = match e {
        Error::Setting { setting, .. } => serde_json::json!({ "setting": setting }),
        Error::Infeasible {
            setting,
            value,
            min,
            max,
            ..
        } => serde_json::json!({ "setting": setting, "value": value, "min": min, "max": max }),
        Error::Resolution {
            requested, needed, ..
        } => serde_json::json!({ "requested": requested, "needed": needed }),
        Error::Io { path, .. } | Error::Format { path, .. } => {
            serde_json::json!({ "path": path.display().to_string() })
        }
        _ => serde_json::json!({}),
    };
    let kind = if e.exit_code() == 3 {
        "backend"
    } else {
        "input"
    };
    Failure::new_err((kind, e.to_string().replace('\n', " "), data.to_string()))
}

enum Message {
    Stage(String),
    Done(latvox::Result<i32>, Vec<(PathBuf, Mesh)>),
}

/// Runs the command `name` on `args` (its options, as they follow its name on the command line)
/// in this process. Every mesh it would write is kept instead and returned as
/// `(path, vertices, faces)`, beside the exit code (0, or 1 where a check found defects) — or,
/// with `keep` false, written as the command line writes them (for a command that reads its
/// output back, as repair checks the file it wrote). The GIL
/// is released while it works; Ctrl-C stops it (KeyboardInterrupt, nothing kept); `progress` is
/// called with each stage's name as it starts; `threads` bounds the workers.
#[pyfunction]
#[pyo3(signature = (name, args, threads=None, progress=None, keep=true))]
fn run(
    py: Python<'_>,
    name: String,
    args: Vec<String>,
    threads: Option<usize>,
    progress: Option<Py<PyAny>>,
    keep: bool,
) -> PyResult<Ran> {
    let pool = match threads {
        Some(0) => {
            return Err(Failure::new_err((
                "input",
                "threads must be at least 1".to_string(),
                r#"{"setting": "threads"}"#.to_string(),
            )))
        }
        Some(n) => {
            latvox::grid::set_backend_threads(n);
            Some(
                rayon::ThreadPoolBuilder::new()
                    .num_threads(n)
                    .build()
                    .map_err(|e| Failure::new_err(("backend", e.to_string(), "{}")))?,
            )
        }
        None => None,
    };
    let (tx, rx) = mpsc::channel::<Message>();
    if progress.is_some() {
        let stages = Mutex::new(tx.clone());
        latvox::progress::listen(Some(Box::new(move |s: &str| {
            if let Ok(t) = stages.lock() {
                let _ = t.send(Message::Stage(s.to_string()));
            }
        })));
    }
    let stop = Arc::new(AtomicBool::new(false));
    let stopper = stop.clone();
    std::thread::spawn(move || {
        let command = move || {
            std::panic::catch_unwind(|| cli::run_one(&name, args, true)).unwrap_or_else(|_| {
                Err(latvox::Error::Backend {
                    context: "latvox",
                    message: "the command panicked (a bug to report)".into(),
                })
            })
        };
        let job = move || match keep {
            true => latvox::mesh::output::capturing(stopper, command),
            false => (
                latvox::mesh::output::stoppable(stopper, command),
                Vec::new(),
            ),
        };
        let (result, meshes) = match pool {
            Some(p) => p.install(job),
            None => job(),
        };
        let _ = tx.send(Message::Done(result, meshes));
    });
    let finish = |stop_it: bool| {
        if stop_it {
            stop.store(true, Ordering::Relaxed);
        }
        if progress.is_some() {
            latvox::progress::listen(None);
        }
    };
    // Held only by this thread: a Mutex to be Sync for the GIL-free wait.
    let rx = Mutex::new(rx);
    let recv = || {
        rx.lock()
            .map_err(|_| mpsc::RecvTimeoutError::Disconnected)?
            .recv_timeout(POLL)
    };
    loop {
        match py.detach(recv) {
            Ok(Message::Stage(s)) => {
                if let Some(cb) = &progress {
                    if let Err(e) = cb.call1(py, (s,)) {
                        finish(true);
                        return Err(e);
                    }
                }
            }
            Ok(Message::Done(result, meshes)) => {
                finish(false);
                let code = result.map_err(|e| failure(&e))?;
                let mut out = Vec::with_capacity(meshes.len());
                for (path, mesh) in meshes {
                    let (v, f) = arrays(py, mesh)?;
                    out.push((path.display().to_string(), v, f));
                }
                return Ok((code, out));
            }
            Err(mpsc::RecvTimeoutError::Timeout) => {
                if let Err(e) = py.check_signals() {
                    finish(true);
                    return Err(e);
                }
            }
            Err(mpsc::RecvTimeoutError::Disconnected) => {
                finish(false);
                return Err(Failure::new_err((
                    "backend",
                    "latvox's worker ended without a result (a bug to report)".to_string(),
                    "{}".to_string(),
                )));
            }
        }
    }
}

/// The command's help, as `latvox NAME --help` prints it (options, then examples).
#[pyfunction]
fn help(name: &str) -> PyResult<String> {
    let c = cli::command::find(name)
        .ok_or_else(|| Failure::new_err(("input", format!("unknown command '{name}'"), "{}")))?;
    Ok(c.clap().render_long_help().to_string())
}

/// The commands: (name, summary), in the help's order.
#[pyfunction]
fn commands() -> Vec<(&'static str, &'static str)> {
    cli::COMMANDS.iter().map(|c| (c.name, c.about)).collect()
}

/// A command's arguments, each a dict: name (as a keyword argument), long (the option, without
/// dashes; None for a positional), flag (takes no value), required, multiple (may be given more
/// than once), default (as the help shows it, or None), values (the choices, or empty), help.
#[pyfunction]
fn options(py: Python<'_>, name: &str) -> PyResult<Vec<Py<PyAny>>> {
    let c = cli::command::find(name)
        .ok_or_else(|| Failure::new_err(("input", format!("unknown command '{name}'"), "{}")))?;
    let mut cmd = c.clap();
    cmd.build();
    let mut out = Vec::new();
    for a in cmd.get_arguments() {
        let id = a.get_id().as_str();
        if id == "help" || id == "version" {
            continue;
        }
        let flag = !a.get_action().takes_values();
        let d = pyo3::types::PyDict::new(py);
        d.set_item("name", a.get_long().unwrap_or(id).replace('-', "_"))?;
        d.set_item("long", a.get_long())?;
        d.set_item("flag", flag)?;
        d.set_item("required", a.is_required_set())?;
        d.set_item(
            "multiple",
            matches!(a.get_action(), clap::ArgAction::Append),
        )?;
        let defaults: Vec<String> = a
            .get_default_values()
            .iter()
            .map(|v| v.to_string_lossy().into_owned())
            .collect();
        d.set_item(
            "default",
            (!flag && !defaults.is_empty()).then(|| defaults.join(",")),
        )?;
        let values: Vec<String> = a
            .get_possible_values()
            .iter()
            .filter(|v| !v.is_hide_set())
            .map(|v| v.get_name().to_string())
            .collect();
        d.set_item("values", values)?;
        d.set_item(
            "help",
            a.get_long_help()
                .or(a.get_help())
                .map(|h| h.to_string())
                .unwrap_or_default(),
        )?;
        out.push(d.into_any().unbind());
    }
    Ok(out)
}

/// Reads a mesh file of any format latvox reads: (vertices, faces).
#[pyfunction]
fn read_mesh(py: Python<'_>, path: PathBuf) -> PyResult<PyMesh> {
    let loaded = py
        .detach(|| latvox::io::read(&path, &latvox::io::ReadOptions::default()))
        .map_err(|e| failure(&e))?;
    arrays(py, loaded.mesh)
}

/// Writes vertices (N, 3) and faces (M, 3) to `path`, in the format its extension names,
/// atomically.
#[pyfunction]
fn save_mesh(
    py: Python<'_>,
    vertices: PyReadonlyArray2<'_, f64>,
    faces: PyReadonlyArray2<'_, u32>,
    path: PathBuf,
) -> PyResult<()> {
    let mesh = mesh_of(vertices, faces)?;
    py.detach(|| save(&mesh, &path)).map_err(|e| failure(&e))
}

fn save(mesh: &Mesh, path: &Path) -> latvox::Result<()> {
    latvox::mesh::output::MeshFile::new(path, false)?.save(mesh)
}

fn mesh_of(
    vertices: PyReadonlyArray2<'_, f64>,
    faces: PyReadonlyArray2<'_, u32>,
) -> PyResult<Mesh> {
    let (v, f) = (vertices.as_array(), faces.as_array());
    if v.ncols() != 3 || f.ncols() != 3 {
        return Err(Failure::new_err((
            "input",
            format!(
                "a mesh is vertices (N, 3) and faces (M, 3), got {:?} and {:?}",
                v.shape(),
                f.shape()
            ),
            "{}".to_string(),
        )));
    }
    let n = v.nrows() as u64;
    if let Some(bad) = f.iter().find(|&&i| i as u64 >= n) {
        return Err(Failure::new_err((
            "input",
            format!("a face names vertex {bad}, but there are {n} vertices"),
            "{}".to_string(),
        )));
    }
    Ok(Mesh {
        positions: v.iter().map(|&x| x as f32).collect(),
        indices: f.iter().copied().collect(),
    })
}

/// A part file's command and settings (as JSON).
#[pyfunction]
fn read_part(path: PathBuf) -> PyResult<(String, String)> {
    let table = cli::part::read(&path).map_err(|e| failure(&e))?;
    let command = table
        .get("command")
        .and_then(|c| c.as_str())
        .unwrap_or_default()
        .to_string();
    let command = cli::command::find(&command)
        .map(|c| c.name.to_string())
        .unwrap_or(command);
    let mut settings = table.clone();
    settings.remove("command");
    let json = serde_json::to_string(&settings)
        .map_err(|e| Failure::new_err(("backend", e.to_string(), "{}")))?;
    Ok((command, json))
}

/// A PNG file as an (H, W, 3) uint8 array (RGB; grey and alpha converted).
#[pyfunction]
fn read_png(py: Python<'_>, path: PathBuf) -> PyResult<Py<numpy::PyArray3<u8>>> {
    let bad = |e: String| {
        Failure::new_err((
            "input",
            format!("{}: {e}", path.display()),
            "{}".to_string(),
        ))
    };
    let file = std::fs::File::open(&path).map_err(|e| bad(e.to_string()))?;
    let mut decoder = png::Decoder::new(std::io::BufReader::new(file));
    decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = decoder.read_info().map_err(|e| bad(e.to_string()))?;
    let mut buf = vec![0; reader.output_buffer_size().unwrap_or(0)];
    let info = reader
        .next_frame(&mut buf)
        .map_err(|e| bad(e.to_string()))?;
    let (w, h) = (info.width as usize, info.height as usize);
    let channels = info.color_type.samples();
    let rgb: Vec<u8> = buf[..info.buffer_size()]
        .chunks_exact(channels)
        .flat_map(|p| match channels {
            1 | 2 => [p[0], p[0], p[0]],
            _ => [p[0], p[1], p[2]],
        })
        .collect();
    let a =
        numpy::ndarray::Array3::from_shape_vec((h, w, 3), rgb).map_err(|e| bad(e.to_string()))?;
    Ok(numpy::PyArray3::from_owned_array(py, a).unbind())
}

#[pymodule]
fn _latvox(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // The commands print nothing here: the caller takes their reports and warnings.
    cli::out::silence(true);
    m.add("Failure", m.py().get_type::<Failure>())?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(help, m)?)?;
    m.add_function(wrap_pyfunction!(commands, m)?)?;
    m.add_function(wrap_pyfunction!(options, m)?)?;
    m.add_function(wrap_pyfunction!(read_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(save_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(read_part, m)?)?;
    m.add_function(wrap_pyfunction!(read_png, m)?)?;
    Ok(())
}
