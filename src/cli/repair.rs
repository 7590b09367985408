//! `latvox repair`: mends a mesh file and reports every change by kind and count, with the check
//! before and after.

use super::check::{defects_json, load, print_header, print_summary, reading_json};
use clap::Args;
use latvox::check::CheckOptions;
use latvox::repair::RepairOptions;
use latvox::Result;
use std::path::PathBuf;

pub(crate) const EXAMPLES: &str = "\
Examples:
  latvox repair scan.stl -o fixed.stl
  latvox repair export.obj -o fixed.3mf --report repair.json
  latvox repair broken.ply -o solid.stl --remesh 0.2
  latvox repair assembly.stl -o part.stl --drop-open-shells

Removes degenerate and duplicate facets; stitches borders that match; splits edges at
T-junctions; separates shells that touch at a vertex or along an edge; makes winding
consistent and every closed shell outward (cavities inward); fills holes (planar ones by
triangulating the loop, curved ones with CGAL's triangulate-refine-fair); recomputes normals.
A valid mesh comes back unchanged. Shells that stay open are reported, and only dropped with
--drop-open-shells. --remesh VOXEL rebuilds the part through an OpenVDB level set: closed,
manifold and free of self-intersections at that resolution (details below a voxel are lost).

The output format follows the extension of -o (.stl .obj .off .ply .3mf).
Self-intersections are counted on the result only (repair does not mend them; --remesh does).
Exit code 0 when the result is a valid closed solid, 1 when defects remain (the repaired file is
still written), 2 on bad input or arguments (nothing written).";

#[derive(Args)]
pub struct RepairArgs {
    /// Mesh file to repair: .stl, .obj, .off, .ply or .3mf.
    pub input: PathBuf,
    /// Output mesh; the format follows the extension.
    #[arg(short, long, value_name = "FILE")]
    pub output: PathBuf,
    /// ASCII STL or ASCII PLY output (binary by default).
    #[arg(long)]
    pub ascii: bool,
    #[command(flatten)]
    pub common: super::check::CheckFlags,
    /// Merge border vertices closer than this (mm) [default: 10⁻⁶ of the part's diagonal].
    #[arg(long, value_name = "MM", value_parser = super::parse_length0)]
    pub stitch_tolerance: Option<f64>,
    /// Leave holes open.
    #[arg(long)]
    pub no_fill: bool,
    /// Fill curved holes without fairing (triangulate and refine only).
    #[arg(long)]
    pub no_fair: bool,
    /// Drop shells that are still open after repair (they are reported either way).
    #[arg(long)]
    pub drop_open_shells: bool,
    /// Rebuild the part through an OpenVDB level set with this voxel size (mm).
    #[arg(long, value_name = "VOXEL", value_parser = super::parse_positive)]
    pub remesh: Option<f64>,
}

pub fn run(a: &RepairArgs, quiet: bool) -> Result<i32> {
    latvox::output::check_writable(&a.output)?;
    if latvox::io::Format::from_path(&a.output).is_none() {
        return Err(latvox::Error::invalid(format!(
            "{}: unknown mesh extension (use .stl, .obj, .off, .ply or .3mf)",
            a.output.display()
        )));
    }
    if let Some(r) = &a.common.report {
        latvox::output::check_writable(r)?;
    }
    let progress = latvox::progress::Progress::new(quiet);
    let loaded = {
        let _s = progress.stage("reading");
        load(&a.input, a.common.weld_tolerance)?
    };
    let copts = CheckOptions {
        self_intersections: !a.common.no_self_intersection,
        tolerance: a.common.weld_tolerance,
    };
    // CGAL's self-intersection test (the costliest check) runs once, on the result: repair does
    // not mend self-intersections, so the count before would only repeat it.
    let before = {
        let _s = progress.stage("checking the input");
        let opts = CheckOptions {
            self_intersections: false,
            ..copts
        };
        latvox::check::check(&loaded.mesh, loaded.normals.as_deref(), &opts)?
    };
    let ropts = RepairOptions {
        fill_holes: !a.no_fill,
        fair: !a.no_fair,
        stitch_tolerance: a.stitch_tolerance,
        drop_open_shells: a.drop_open_shells,
        remesh: a.remesh,
    };
    let (mesh, changes) = latvox::repair::repair(&loaded.mesh, &ropts, &progress)?;
    if mesh.triangle_count() == 0 {
        return Err(latvox::Error::invalid(format!(
            "{}: nothing is left after repair (every facet was degenerate{}); no file written",
            a.input.display(),
            if a.drop_open_shells {
                " or in an open shell"
            } else {
                ""
            }
        )));
    }
    {
        let _s = progress.stage("writing");
        latvox::io::save(&mesh, &a.output, a.ascii)?;
    }
    // The verdict is on the file as written and read back, as the next program will see it
    // (STL, for one, welds vertices by position).
    let after = {
        let _s = progress.stage("checking the written file");
        let written = load(&a.output, 0.0)?;
        latvox::check::check(&written.mesh, written.normals.as_deref(), &copts)?
    };
    let normals_fixed = before
        .normals
        .map(|n| n.reversed + n.inaccurate + n.unset)
        .unwrap_or(0);
    let v = serde_json::json!({
        "input": a.input.display().to_string(),
        "output": a.output.display().to_string(),
        "format": loaded.format,
        "reading": reading_json(&loaded),
        "before": before,
        "defects_before": defects_json(&before),
        "repair": changes,
        "normals_recomputed": normals_fixed,
        "after": after,
        "defects_after": defects_json(&after),
        "valid_solid": after.valid_solid,
    });
    if !super::emit_json(a.common.report.as_deref(), a.common.json, &v)? {
        print_header(&a.input, &loaded);
        let d = before.defects();
        if d.is_empty() {
            println!("before    no defects (self-intersections are checked on the result)");
        } else {
            let list: Vec<String> = d.iter().map(|(k, n)| format!("{n} {k}")).collect();
            println!(
                "before    {} (self-intersections are checked on the result)",
                list.join(", ")
            );
        }
        if changes.changes.is_empty() && normals_fixed == 0 {
            println!("changes   none (the mesh is written unchanged)");
        }
        for c in &changes.changes {
            println!("changed   {} {}", c.count, c.kind);
        }
        if normals_fixed > 0 {
            println!("changed   {normals_fixed} stored normals recomputed from the winding");
        }
        for s in &changes.open_shells {
            println!(
                "open      a shell of {} facets still has {} boundary edges ({} hole loops){}",
                s.facets,
                s.boundary_edges,
                s.hole_loops,
                if s.dropped {
                    ", dropped as asked"
                } else {
                    " — kept; --drop-open-shells removes it"
                }
            );
        }
        if changes.non_orientable_shells > 0 {
            println!(
                "open      {} shell(s) cannot be wound consistently (one-sided)",
                changes.non_orientable_shells
            );
        }
        println!("after ({})", a.output.display());
        print_summary(&after);
        if after.self_intersections.unwrap_or(0) > 0 && a.remesh.is_none() {
            println!("hint      self-intersections remain: --remesh VOXEL rebuilds the part without them");
        }
        println!(
            "verdict   {}",
            if after.valid_solid {
                "valid closed solid"
            } else {
                "DEFECTS REMAIN"
            }
        );
    }
    Ok(if after.valid_solid { 0 } else { 1 })
}
