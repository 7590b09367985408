//! The layers hold, read off the source (as rust-analyzer's `tidy` tests guard its
//! architecture): every `crate::` path in `src/` (outside comments) is checked against the order
//! the library is built in.
//!
//! - The base (`error`, `progress`, `ffi`) is used by anything.
//! - The stages, bottom to top, [`STAGES`]: a stage uses only stages below it.
//! - The capabilities, [`CAPABILITIES`]: each uses stages (and the base), never another
//!   capability — what two capabilities share lives in a stage (the lattices in `lattice`, the
//!   BVH and contours in `geom`), and a capability reaches others only through a trait a stage
//!   defines.
//! - `main.rs` and `src/cli/` (the command line) may use anything.
//!
//! A new top-level module must be placed in one of the lists, so that its place is decided.

use std::collections::BTreeSet;
use std::path::Path;

/// Used by every module.
const BASE: [&str; 3] = ["error", "progress", "ffi"];

/// The stages, from the bottom: each uses only those before it.
const STAGES: [&str; 12] = [
    "geom",    // points, boxes, the mesh and its topology, BVH, contours
    "io",      // readers, writers, sinks, atomic output
    "cad",     // B-spline curves, IGES and DXF
    "field",   // the Field trait and its combinators
    "grid",    // OpenVDB level sets
    "verify",  // the proof that a mesh is a valid solid
    "mesh",    // the meshing pipeline
    "lattice", // TPMS and strut lattices as fields, calibrated
    "check",   // every defect of any mesh counted; files checked
    "repair",  // meshes mended
    "slice",   // layers
    "render",  // pictures and the browser editor
];

/// The capabilities: each uses the base and the stages only.
const CAPABILITIES: [&str; 9] = [
    "tpms",
    "strut",
    "fill",
    "fgm",
    "interpret",
    "topopt",
    "homogenize",
    "voronoi",
    "batch",
];

/// The top-level module a file of `src/` belongs to (`None`: the command line).
fn module_of(rel: &Path) -> Option<String> {
    let mut parts = rel
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned());
    let first = parts.next()?;
    match first.as_str() {
        "main.rs" | "lib.rs" | "cli" => None,
        f => Some(f.trim_end_matches(".rs").to_string()),
    }
}

/// The top-level modules named by `crate::` paths in `text`, comments left out, with the line
/// each is on.
fn uses(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let code = line.split("//").next().unwrap_or("");
        let mut rest = code;
        while let Some(at) = rest.find("crate::") {
            let after = &rest[at + "crate::".len()..];
            let name: String = after
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            if !name.is_empty() {
                out.push((i + 1, name));
            }
            rest = after;
        }
    }
    out
}

fn files(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// Whether `from` may use `to`; the reason when not.
fn allowed(from: &str, to: &str) -> Result<(), String> {
    let stage = |m: &str| STAGES.iter().position(|s| *s == m);
    if from == to || BASE.contains(&to) {
        return Ok(());
    }
    if BASE.contains(&from) {
        return Err(format!("the base module `{from}` uses `{to}`"));
    }
    match (stage(from), stage(to)) {
        (Some(a), Some(b)) if b < a => Ok(()),
        (Some(_), Some(_)) => Err(format!("stage `{from}` uses `{to}`, a stage above it")),
        (Some(_), None) => Err(format!("stage `{from}` uses the capability `{to}`")),
        (None, Some(_)) => Ok(()),
        (None, None) => Err(format!(
            "capability `{from}` uses the capability `{to}` (share it through a stage)"
        )),
    }
}

#[test]
fn no_module_uses_one_above_it() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut all = Vec::new();
    files(&src, &mut all);
    all.sort();
    let known: BTreeSet<&str> = BASE
        .iter()
        .chain(STAGES.iter())
        .chain(CAPABILITIES.iter())
        .copied()
        .collect();
    let mut wrong = Vec::new();
    let mut seen = BTreeSet::new();
    for path in &all {
        let rel = path.strip_prefix(&src).unwrap();
        let Some(from) = module_of(rel) else { continue };
        seen.insert(from.clone());
        if !known.contains(from.as_str()) {
            wrong.push(format!(
                "src/{}: module `{from}` is in no layer (add it to tests/it/tidy.rs)",
                rel.display()
            ));
            continue;
        }
        let text = std::fs::read_to_string(path).unwrap();
        for (line, to) in uses(&text) {
            if !known.contains(to.as_str()) {
                continue; // an item of lib.rs (`crate::Error`, `crate::Result`)
            }
            if let Err(why) = allowed(&from, &to) {
                wrong.push(format!("src/{}:{line}: {why}", rel.display()));
            }
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    // Every layer named is a module that exists.
    for m in &known {
        assert!(
            seen.contains(*m),
            "`{m}` is listed but src/ has no such module"
        );
    }
}

#[test]
fn the_rules_refuse_what_they_should() {
    assert!(allowed("mesh", "grid").is_ok());
    assert!(allowed("grid", "mesh").is_err());
    assert!(allowed("fill", "lattice").is_ok());
    assert!(allowed("fill", "tpms").is_err());
    assert!(allowed("render", "fill").is_err());
    assert!(allowed("error", "geom").is_err());
    assert!(allowed("tpms", "error").is_ok());
    let found = uses("use crate::mesh::pipeline; // crate::tpms\n    x(crate::grid::Grid::sample)");
    assert_eq!(
        found,
        [(1, "mesh".to_string()), (2, "grid".to_string())],
        "paths in code, not in comments"
    );
    assert_eq!(module_of(Path::new("tpms/job.rs")).as_deref(), Some("tpms"));
    assert_eq!(module_of(Path::new("cli/view.rs")), None);
}
