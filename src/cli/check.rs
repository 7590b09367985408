//! `latvox check`: CGAL's verdict on an STL.

use super::yes;
use clap::Args;
use latvox::Result;
use std::path::PathBuf;

pub(crate) const EXAMPLES: &str = "\
Examples:
  latvox check part.stl
  latvox check part.stl --json > part-check.json

Exit code 0 when the mesh is a closed, outward, self-intersection-free solid; 1 when a check
fails; 2 when the file cannot be read.";

#[derive(Args)]
pub struct CheckArgs {
    /// STL file (binary or ASCII).
    pub file: PathBuf,
    /// Print the result as JSON.
    #[arg(long)]
    pub json: bool,
}

pub fn run(a: &CheckArgs) -> Result<i32> {
    let mesh = latvox::io::stl::read(&a.file)?;
    let edges = mesh.edge_stats();
    let checks = latvox::verify::verify(&mesh, true)?;
    let ok = checks.is_valid_solid() && edges.boundary == 0 && edges.non_manifold == 0;
    if a.json {
        let v = serde_json::json!({
            "file": a.file.display().to_string(),
            "valid_solid": ok,
            "triangles": mesh.triangle_count(),
            "vertices": mesh.vertex_count(),
            "edges": edges,
            "cgal": checks,
        });
        println!(
            "{}",
            serde_json::to_string_pretty(&v).expect("JSON of plain values")
        );
    } else {
        println!("{}", a.file.display());
        println!(
            "triangles {}  vertices {}  edges {}",
            mesh.triangle_count(),
            mesh.vertex_count(),
            edges.edges
        );
        println!(
            "edges     boundary {}  non-manifold {}  inconsistently wound {}",
            edges.boundary, edges.non_manifold, edges.misoriented
        );
        println!(
            "CGAL      closed {}  outward {}  manifold {}  self-intersections {}  shells {}",
            yes(checks.closed),
            yes(checks.outward),
            yes(checks.manifold),
            if checks.self_intersecting {
                "FOUND"
            } else {
                "none"
            },
            checks.components
        );
        match checks.volume {
            Some(v) => println!("measures  volume {v:.4} mm³  area {:.4} mm²", checks.area),
            None => println!(
                "measures  volume undefined (not closed)  area {:.4} mm²",
                checks.area
            ),
        }
        println!(
            "verdict   {}",
            if ok {
                "valid closed solid"
            } else {
                "DEFECTS FOUND"
            }
        );
    }
    Ok(if ok { 0 } else { 1 })
}
