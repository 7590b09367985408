//! `latvox check`: every defect of a mesh file counted (latvox's own topology and CGAL's
//! verdict), as a summary or as JSON.

use super::yes;
use clap::Args;
use latvox::check::{CheckOptions, CheckReport, Orientation};
use latvox::io::{Loaded, ReadOptions};
use latvox::Result;
use std::path::{Path, PathBuf};

pub(crate) const EXAMPLES: &str = "\
Examples:
  latvox check part.stl
  latvox check scan.ply --weld-tolerance 0.001
  latvox check part.3mf --json > part-check.json
  latvox check big.stl --no-self-intersection --report big-check.json

Reads STL (binary or ASCII), OBJ, OFF, PLY (ASCII or binary) and 3MF. Counts facets, vertices,
edges and shells (each with volume, area, Euler characteristic and genus); boundary edges and
hole loops; non-manifold edges and vertices; stored normals that disagree with the winding;
inconsistently wound neighbours; inward-facing shells; degenerate and duplicate facets;
T-junctions; and self-intersecting facet pairs (CGAL).

Exit code 0 when the mesh is a valid closed, outward, self-intersection-free solid; 1 when
defects are found; 2 when the file cannot be read.";

#[derive(Args)]
pub struct CheckArgs {
    /// Mesh file: .stl, .obj, .off, .ply or .3mf (others are recognised by content).
    pub file: PathBuf,
    #[command(flatten)]
    pub common: CheckFlags,
}

/// Options shared by `check` and `repair`.
#[derive(Args)]
pub struct CheckFlags {
    /// Print the result as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// Also write the JSON result to this file.
    #[arg(long, value_name = "FILE.json")]
    pub report: Option<PathBuf>,
    /// Merge vertices closer than this (mm) when reading; exact matches are always merged.
    #[arg(long, value_name = "MM", default_value_t = 0.0, value_parser = super::parse_length0)]
    pub weld_tolerance: f64,
    /// Skip CGAL's self-intersection test (the costliest check).
    #[arg(long)]
    pub no_self_intersection: bool,
}

/// Reads a mesh file as the CLI does.
pub(crate) fn load(path: &Path, weld_tolerance: f64) -> Result<Loaded> {
    latvox::io::read(path, &ReadOptions { weld_tolerance })
}

pub fn run(a: &CheckArgs, quiet: bool) -> Result<i32> {
    if let Some(r) = &a.common.report {
        latvox::output::check_writable(r)?;
    }
    let progress = latvox::progress::Progress::new(quiet);
    let loaded = {
        let _s = progress.stage("reading");
        load(&a.file, a.common.weld_tolerance)?
    };
    let mesh = &loaded.mesh;
    let opts = CheckOptions {
        self_intersections: !a.common.no_self_intersection,
        tolerance: a.common.weld_tolerance,
    };
    // CGAL's own checks (building a mesh of its own, one facet at a time) run alongside ours.
    let (report, cgal) = {
        let _s = progress.stage("checking");
        rayon::join(
            || latvox::check::check(mesh, loaded.normals.as_deref(), &opts),
            || latvox::verify::verify(mesh, false),
        )
    };
    let (report, mut cgal) = (report?, cgal?);
    // The check above already ran CGAL's self-intersection test (on the facets that are neither
    // degenerate nor duplicate); it is not run twice.
    cgal.self_intersection_checked = report.self_intersections.is_some();
    cgal.self_intersecting = report.self_intersections.unwrap_or(0) > 0;
    // The edge counts of the first `check` (kept for scripts that read them).
    let edges = latvox::mesh::EdgeStats {
        edges: report.edges,
        boundary: report.boundary_edges,
        non_manifold: report.non_manifold_edges,
        misoriented: report.inconsistent_edges,
    };
    let ok = report.valid_solid
        && cgal.manifold
        && cgal.closed
        && cgal.outward
        && !cgal.self_intersecting;
    let v = serde_json::json!({
        "file": a.file.display().to_string(),
        "format": loaded.format,
        "valid_solid": ok,
        "triangles": mesh.triangle_count(),
        "vertices": mesh.vertex_count(),
        "edges": edges,
        "reading": reading_json(&loaded),
        "check": report,
        "defects": defects_json(&report),
        "cgal": cgal,
    });
    if !super::emit_json(a.common.report.as_deref(), a.common.json, &v)? {
        print_header(&a.file, &loaded);
        print_summary(&report);
        println!(
            "CGAL      closed {}  outward {}  manifold {}  self-intersections {}",
            yes(cgal.closed),
            yes(cgal.outward),
            yes(cgal.manifold),
            if !cgal.self_intersection_checked {
                "not checked"
            } else if cgal.self_intersecting {
                "FOUND"
            } else {
                "none"
            },
        );
        println!(
            "verdict   {}",
            if ok {
                "valid closed solid"
            } else {
                "DEFECTS FOUND (latvox repair can fix most)"
            }
        );
    }
    Ok(if ok { 0 } else { 1 })
}

pub(crate) fn reading_json(l: &Loaded) -> serde_json::Value {
    serde_json::json!({
        "faces_with_fewer_than_3_corners_skipped": l.short_faces,
        "polygons_split_into_triangles": l.polygons_split,
        "vertices_merged_by_tolerance": l.tolerance_welded,
    })
}

pub(crate) fn defects_json(r: &CheckReport) -> serde_json::Value {
    r.defects()
        .into_iter()
        .map(|(k, n)| (k.to_string(), serde_json::json!(n)))
        .collect::<serde_json::Map<_, _>>()
        .into()
}

/// The file line of a summary, and what reading did.
pub(crate) fn print_header(path: &Path, l: &Loaded) {
    println!(
        "{} ({}, {} facets read)",
        path.display(),
        l.format.name(),
        l.mesh.triangle_count()
    );
    let mut notes = Vec::new();
    if l.polygons_split > 0 {
        notes.push(format!(
            "{} polygons split into triangles",
            l.polygons_split
        ));
    }
    if l.short_faces > 0 {
        notes.push(format!(
            "{} faces with fewer than 3 corners skipped",
            l.short_faces
        ));
    }
    if l.tolerance_welded > 0 {
        notes.push(format!(
            "{} vertices merged by tolerance",
            l.tolerance_welded
        ));
    }
    if !notes.is_empty() {
        println!("reading   {}", notes.join(", "));
    }
}

/// The human-readable summary of a check.
pub(crate) fn print_summary(r: &CheckReport) {
    println!(
        "mesh      facets {}  vertices {}  edges {}  shells {}",
        r.facets, r.vertices, r.edges, r.shell_count
    );
    println!(
        "measures  volume {:.4} mm³  area {:.4} mm²",
        r.volume, r.area
    );
    let d = r.defects();
    if d.is_empty() {
        println!("defects   none");
    } else {
        for (k, n) in &d {
            println!("defect    {n} {k}");
        }
    }
    if let Some(n) = r.normals {
        if n.unset > 0 {
            println!(
                "note      {} stored normals are unset (zero or not finite)",
                n.unset
            );
        }
    }
    if r.self_intersections.is_none() {
        println!("note      self-intersections not checked");
    }
    const SHOWN: usize = 12;
    for (i, s) in r.shells.iter().enumerate().take(SHOWN) {
        let orient = match s.orientation {
            Orientation::Outward => "outward",
            Orientation::Inward => "INWARD",
            Orientation::Inconsistent => "INCONSISTENT",
            Orientation::Open => "open",
        };
        let genus = s
            .genus
            .map(|g| format!("genus {g}"))
            .unwrap_or_else(|| "genus -".into());
        println!(
            "shell {:<3} F {} V {} E {}  χ {}  {genus}  {}  {orient}  volume {:.4} mm³  area {:.4} mm²{}",
            i + 1,
            s.facets,
            s.vertices,
            s.edges,
            s.euler,
            if s.closed {
                "closed".to_string()
            } else {
                format!("OPEN ({} boundary edges, {} holes)", s.boundary_edges, s.hole_loops)
            },
            s.volume,
            s.area,
            match s.nesting {
                Some(d) if d > 0 => format!("  inside {d} other shell(s)"),
                _ => String::new(),
            }
        );
    }
    if r.shells.len() > SHOWN {
        println!(
            "…         {} more shells (see --json)",
            r.shells.len() - SHOWN
        );
    }
}
