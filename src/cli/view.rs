//! `latvox view`: the browser editor of a part file — a local server whose page sphere-traces
//! the part on the GPU and edits it live (see `latvox::render::view`).

use super::command::{parsed, Command};
use super::part::{absolute, is_part_file, part_of_table, read, Part};
use clap::Args;
use latvox::render::view::guard::{Folder, Token};
use latvox::render::view::scene::Scene;
use latvox::render::view::{serve, Editor, Hooks};
use latvox::{Error, Result};
use std::io::Write;
use std::path::PathBuf;

pub(crate) const EXAMPLES: &str = "\
Examples:
  # A gyroid part, then its editor: open the URL printed on the first line in a browser
  latvox tpms --type gyroid --density 0.3 --cells 4 -o gyroid.stl --save-part gyroid.toml
  latvox view gyroid.toml
  # prints http://127.0.0.1:PORT/?token=T — the token is the key: keep the whole URL

  # Meshes, slices and saved parts written in another folder than the part file's
  latvox view gyroid.toml --out-dir runs/today

  # A strut part on a cluster's login node: the server stays on the node's loopback; an SSH
  # tunnel from this machine brings the port here (run ssh here, latvox there, open the
  # printed URL, token and all, in a browser here)
  ssh -L 8080:127.0.0.1:8080 login-node
  latvox strut --cell octet --density 0.2 --cells 5 -o octet.stl --save-part octet.toml
  latvox view octet.toml --port 8080

  # A filled part: open it, cut it with the section control, turn it, save, mesh
  latvox fill bracket.stl --skin 1 --lattice gyroid --cell-size 4 --density 0.2 \\
      -o filled.stl --save-part filled.toml
  latvox view filled.toml

The page draws the part straight from its settings, never from a mesh: a WebGL2 shader
sphere-traces the TPMS formula, or the struts of one augmented unit cell — inside a filled
part's shell, cast at through its BVH — so a part of a million cells draws as fast as one of
ten. Drag to turn it, scroll to zoom; the controls edit the part (type, structure, cell or
lattice, cell size, density or radius, skin, blend, drains, the box) and cut it with a section
plane. \"Save part\" writes the part file; \"Mesh\" and \"Slice\" run latvox on the
saved settings and show their progress.

The server listens on 127.0.0.1 only and serves until it is stopped (Ctrl-C). It obeys only
the page opened with its URL: each run draws a new secret token, and a request without it, one
naming another host than 127.0.0.1, localhost or [::1] with the port (DNS rebinding), or one
sent by another site's page is refused. The page writes only inside the part file's folder, or
the folder given with --out-dir (names relative to it; `..` and links leading out refused); the
files a part reads (the mesh a fill part fills) are read where the part file names them.";

/// `latvox view`.
pub(crate) const COMMAND: Command = Command::new(
    "view",
    "Edit a part file live in the browser: a local server whose page sphere-traces the part on the GPU (no mesh), with controls, sections, saving, meshing and slicing",
    EXAMPLES,
    <ViewArgs as clap::Args>::augment_args,
    |m, _| run(&parsed(m)?),
);

#[derive(Args)]
pub struct ViewArgs {
    /// The part file (from --save-part of tpms, strut, voronoi or fill).
    #[arg(value_name = "PART.toml")]
    pub input: PathBuf,
    /// The port to listen on (0: a free one).
    #[arg(long, default_value_t = 0)]
    pub port: u16,
    /// The folder the page writes part files, meshes and slices in (made if missing; default:
    /// the part file's folder). Nothing is written outside it.
    #[arg(long, value_name = "DIR")]
    pub out_dir: Option<PathBuf>,
}

pub fn run(a: &ViewArgs) -> Result<i32> {
    if !is_part_file(&a.input) {
        return Err(Error::invalid(format!(
            "{}: the editor opens part files (.toml, from --save-part of tpms, strut, voronoi or fill); a mesh is drawn by `latvox render`",
            a.input.display()
        )));
    }
    let path = a.input.clone();
    let settings = absolute(read(&path)?, &path);
    let command = settings
        .get("command")
        .and_then(toml::Value::as_str)
        .unwrap_or_default()
        .to_string();
    let scene_path = path.clone();
    let hooks = Hooks {
        scene: Box::new(move |t| {
            Ok(
                match part_of_table(t, &scene_path, latvox::render::Fidelity::Look)? {
                    Part::Block(m) => Scene::of(&m),
                    Part::Filled(traced) => traced.editor_scene(),
                },
            )
        }),
        save: Box::new(super::part::write),
    };
    // The part must be drawable before anything is served.
    (hooks.scene)(&settings)?;
    let choices = super::command::find(&command)
        .and_then(|c| c.choices)
        .map_or(serde_json::Value::Null, |choices| choices());
    let listener = std::net::TcpListener::bind(("127.0.0.1", a.port))
        .map_err(|e| Error::invalid(format!("cannot listen on 127.0.0.1:{}: {e}", a.port)))?;
    let port = listener
        .local_addr()
        .map_err(|e| Error::io("127.0.0.1", e))?
        .port();
    let folder = match &a.out_dir {
        Some(dir) => {
            if dir.exists() && !dir.is_dir() {
                return Err(Error::invalid(format!(
                    "{}: --out-dir names a file, not a folder",
                    dir.display()
                )));
            }
            std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
            Folder::new(dir)?
        }
        None => Folder::new(match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => std::path::Path::new("."),
        })?,
    };
    let token = Token::new()?;
    let exe = std::env::current_exe().map_err(|e| Error::io("latvox", e))?;
    let mut out = std::io::stdout();
    let _ = writeln!(out, "http://127.0.0.1:{port}/?token={}", token.as_str());
    let _ = writeln!(
        out,
        "latvox view: editing {} ({command}), writing in {}; stop with Ctrl-C",
        path.display(),
        folder.root().display()
    );
    let _ = out.flush();
    serve(
        listener,
        Editor {
            path,
            settings,
            choices,
            exe,
            hooks,
            folder,
            token,
        },
    )?;
    Ok(0)
}
