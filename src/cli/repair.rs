//! `latvox repair`: mends a mesh file and reports every change by kind and count, with the check
//! before and after.

use super::check::{print_header, print_summary};
use super::command::{job, parsed, Command};
use super::out::outln;
use clap::Args;
use latvox::mesh::output::MeshFile;
use latvox::progress::Progress;
use latvox::repair::{repair_file, FileRepairReport, Remesh, RepairOptions};
use latvox::Result;
use std::path::PathBuf;

pub(crate) const EXAMPLES: &str = "\
Examples:
  latvox repair scan.stl -o fixed.stl
  latvox repair export.obj -o fixed.3mf --report repair.json
  latvox repair assembly.3mf -o print.stl --solid
  latvox repair broken.ply -o solid.stl --remesh auto
  latvox repair broken.ply -o solid.stl --remesh 0.2
  latvox repair plate.stl -o plate-solid.stl --solid --tolerance 0.05
  latvox repair assembly.stl -o part.stl --drop-open-shells
  latvox repair implant-lattice.3mf -o implant.stl --beam-voxel 0.02

Removes degenerate and duplicate facets; stitches borders that match; splits edges at
T-junctions; separates shells that touch at a vertex or along an edge; makes winding
consistent and every closed shell outward (cavities inward); fills holes (planar ones by
triangulating the loop, curved ones with CGAL's triangulate-refine-fair); recomputes normals.
A valid mesh comes back unchanged. Shells that stay open are reported, and only dropped with
--drop-open-shells.

--solid: when the file must print as one solid (assemblies of overlapping parts, exports with
stray facets, shells crossing each other or themselves). After the repair above, shells that
are still open and enclose nothing are strays, dropped (counted); shells that overlap
or cross are joined: by CGAL's corefinement (an exact union) when each is a clean closed shell,
otherwise their group alone is remeshed through OpenVDB; if anything is still wrong, the whole
part is remeshed. Where the open shells enclose something together (a soup of open,
overlapping, non-manifold pieces, with no closed shell of their own), the whole is made solid by its generalised winding number
(Barill et al., \"Fast winding numbers for soups and clouds\", 2018): inside where it exceeds ½,
a hole spanned like a soap film. The result is one valid closed solid, or the reason none
exists.

--tolerance MM simplifies what a remesh made, within MM of the input's surface: triangles merged
where it is flat, each step checked against the input's distance field, the volume kept.

--remesh VOXEL|auto rebuilds the part through an OpenVDB level set: closed, manifold and free
of self-intersections at that resolution (details below a voxel are lost). auto: a quarter of
the part's smallest feature (the shortest ray from a facet, along or against its normal, to
another facet of its shell: a plate's thickness, a rod's diameter, a slot's gap), at most 1/64
of the part, within a memory bound. With --solid, it sets the voxel of the remeshes the solid needs
(shells that cross themselves are not measured for auto). When geometry moved,
the deviation from the input is measured both ways (every vertex to the other mesh, CGAL).

A 3MF file's beam lattices (Beam Lattice extension) are read as the solid they describe, meshed
as `latvox check --help` says (--beam-voxel sets the voxel): the output is that solid's mesh.
The output format follows the extension of -o (.stl .obj .off .ply .3mf).
Self-intersections are counted on the result only (--solid and --remesh mend them).
Exit codes: 0 the result written is a valid closed solid; 1 it is written but defects remain
(listed); 2 bad input or arguments, or no solid exists (nothing written); 3 an internal failure
(a bug to report).";

/// `latvox repair`.
pub(crate) const COMMAND: Command = Command {
    job: Some(job::<RepairArgs>),
    ..Command::new(
        "repair",
        "Repair a mesh file and report every change by kind and count",
        EXAMPLES,
        <RepairArgs as clap::Args>::augment_args,
        |m, quiet| run(&parsed(m)?, quiet),
    )
};

impl latvox::batch::Task for RepairArgs {
    fn outputs(&self) -> Vec<PathBuf> {
        vec![self.output.clone()]
    }

    fn run(&self) -> Result<latvox::batch::TaskReport> {
        let r = execute(self, &Progress::hidden())?;
        latvox::batch::TaskReport::new(&r, &r.verdict, Vec::new())
    }
}

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
    /// Rebuild the part through an OpenVDB level set with this voxel size (mm), or `auto`.
    #[arg(long, value_name = "VOXEL|auto", value_parser = parse_remesh)]
    pub remesh: Option<Remesh>,
    /// End in one valid closed solid: drop open shells, join overlapping or crossing ones.
    #[arg(long)]
    pub solid: bool,
    /// Simplify what a remesh makes (--remesh, or --solid where it remeshes) within this
    /// distance of the input's surface, mm: fewer triangles where the part is flat, the same
    /// valid solid.
    #[arg(long, value_name = "MM", value_parser = super::parse_positive)]
    pub tolerance: Option<f64>,
}

fn parse_remesh(s: &str) -> std::result::Result<Remesh, String> {
    if s == "auto" {
        Ok(Remesh::Auto)
    } else {
        super::parse_positive(s).map(Remesh::Voxel)
    }
}

impl RepairArgs {
    /// The repair these arguments ask for.
    fn options(&self) -> RepairOptions {
        RepairOptions {
            fill_holes: !self.no_fill,
            fair: !self.no_fair,
            stitch_tolerance: self.stitch_tolerance,
            drop_open_shells: self.drop_open_shells,
            remesh: self.remesh,
            solid: self.solid,
            tolerance: self.tolerance,
        }
    }
}

/// Repairs the input and writes the result (not the report), for `run` to print and `latvox
/// batch` to record.
pub fn execute(a: &RepairArgs, progress: &Progress) -> Result<FileRepairReport> {
    latvox::io::atomic::check_writable(&a.output)?;
    let output = MeshFile::mesh(&a.output, a.ascii)?;
    if let Some(r) = &a.common.report {
        latvox::io::atomic::check_writable(r)?;
    }
    repair_file(
        &a.input,
        &output,
        &a.common.options(),
        &a.options(),
        progress,
    )
}

pub fn run(a: &RepairArgs, quiet: bool) -> Result<i32> {
    let r = execute(a, &Progress::new(quiet))?;
    if !super::emit_json(a.common.report.as_deref(), a.common.json, &r)? {
        print_header(&r.input, r.format, r.before.facets, &r.reading);
        let d = &r.defects_before.0;
        if d.is_empty() {
            outln!("before    no defects (self-intersections are checked on the result)");
        } else {
            let list: Vec<String> = d.iter().map(|(k, n)| format!("{n} {k}")).collect();
            outln!(
                "before    {} (self-intersections are checked on the result)",
                list.join(", ")
            );
        }
        let changes = &r.repair;
        if changes.changes.is_empty() && r.normals_recomputed == 0 {
            outln!("changes   none (the mesh is written unchanged)");
        }
        for c in &changes.changes {
            outln!("changed   {} {}", c.count, c.kind);
        }
        if r.normals_recomputed > 0 {
            outln!(
                "changed   {} stored normals recomputed from the winding",
                r.normals_recomputed
            );
        }
        for s in &changes.open_shells {
            outln!(
                "open      a shell of {} facets still has {} boundary edges ({} hole loops){}",
                s.facets,
                s.boundary_edges,
                s.hole_loops,
                match (s.dropped, a.solid) {
                    (true, true) => ", dropped (a stray beside the closed shells)",
                    (true, false) => ", dropped as asked",
                    (false, true) => ", made solid with the rest by the winding number",
                    (false, false) => " — kept; --drop-open-shells removes it",
                }
            );
        }
        if changes.non_orientable_shells > 0 {
            outln!(
                "open      {} shell(s) cannot be wound consistently (one-sided)",
                changes.non_orientable_shells
            );
        }
        if let Some(sr) = &changes.solid {
            for why in &sr.remesh_reasons {
                outln!("remeshed  a group of crossing shells: {why}");
            }
        }
        if let Some(v) = changes.remesh_voxel {
            outln!("voxel     {v:.4} mm (remesh)");
        }
        if let Some(sm) = &changes.simplified {
            super::out::simplified(sm, "remesh", "the input's surface");
        } else if a.tolerance.is_some() {
            outln!("simplified nothing: no remesh was made (the facets are the input's own)");
        }
        if let Some(d) = &r.deviation {
            outln!(
                "deviation result→input max {:.4} mm, mean {:.4} mm; input→result max {:.4} mm, mean {:.4} mm (at vertices, CGAL){}",
                d.output_to_input.max,
                d.output_to_input.mean,
                d.input_to_output.max,
                d.input_to_output.mean,
                if d.input_vertices_inside > 0 {
                    format!(
                        "; {} input vertices on walls now inside the solid",
                        d.input_vertices_inside
                    )
                } else {
                    String::new()
                }
            );
        }
        outln!("after ({})", r.output);
        print_summary(&r.after);
        if r.verdict.self_intersecting && a.remesh.is_none() && !a.solid {
            outln!("hint      self-intersections remain: --solid joins the crossing shells");
        }
        outln!(
            "verdict   {}",
            if r.verdict.is_valid_solid() {
                "valid closed solid"
            } else {
                "DEFECTS REMAIN"
            }
        );
    }
    Ok(r.verdict.exit_code())
}
