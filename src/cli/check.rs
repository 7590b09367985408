//! `latvox check`: every defect of a mesh file counted (latvox's own topology and CGAL's
//! verdict), as a summary or as JSON.

use super::cgal_findings;
use super::command::{parsed, Command};
use super::out::outln;
use clap::Args;
use latvox::check::{check_file, CheckOptions, CheckReport, Orientation};
use latvox::io::{Format, Reading};
use latvox::Result;
use std::path::PathBuf;

pub(crate) const EXAMPLES: &str = "\
Examples:
  latvox check part.stl
  latvox check scan.ply --weld-tolerance 0.001
  latvox check part.3mf --json > part-check.json
  latvox check big.stl --no-self-intersection --report big-check.json
  latvox check implant.3mf --beam-voxel 0.02

Reads STL (binary or ASCII), OBJ, OFF, PLY (ASCII or binary) and 3MF — with the Production
extension's model parts, and the Beam Lattice extension's beams and balls made a solid (each
beam a frustum capped as the file says, clipped by its clipping mesh, united with its object's
triangles; meshed on voxels of a sixth of the thinnest radius, or --beam-voxel). Counts facets,
vertices, edges and shells (each with volume, area, Euler characteristic and genus); boundary
edges and hole loops; non-manifold edges and vertices; stored normals that disagree with the
winding; inconsistently wound neighbours; inward-facing shells; degenerate and duplicate facets;
T-junctions; and self-intersecting facet pairs (exact, with CGAL's triangle tests). CGAL checks
closedness, orientation and volume beside latvox, as a second opinion.

Exit code 0 when the mesh is a valid closed, outward, self-intersection-free solid; 1 when
defects are found; 2 when the file cannot be read.";

/// `latvox check`.
pub(crate) const COMMAND: Command = Command::new(
    "check",
    "Check a mesh file: every defect counted (holes, non-manifold, winding, normals, degenerate and duplicate facets, T-junctions, self-intersections), per shell too",
    EXAMPLES,
    <CheckArgs as clap::Args>::augment_args,
    |m, quiet| run(&parsed(m)?, quiet),
);

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
    /// Skip the self-intersection search (the costliest check).
    #[arg(long)]
    pub no_self_intersection: bool,
    /// Voxel (mm) on which the beam lattices of a 3MF file are meshed into solids [default: a
    /// sixth of the thinnest beam's radius, coarser where the part would pass 2·10⁷ active
    /// voxels, down to four voxels across the thinnest beam].
    #[arg(long, value_name = "MM", value_parser = super::parse_positive)]
    pub beam_voxel: Option<f64>,
}

impl CheckFlags {
    /// The checks these flags ask for.
    pub(crate) fn options(&self) -> CheckOptions {
        CheckOptions {
            self_intersections: !self.no_self_intersection,
            tolerance: self.weld_tolerance,
            beam_voxel: self.beam_voxel,
        }
    }
}

pub fn run(a: &CheckArgs, quiet: bool) -> Result<i32> {
    if let Some(r) = &a.common.report {
        latvox::io::atomic::check_writable(r)?;
    }
    let progress = latvox::progress::Progress::new(quiet);
    let r = check_file(&a.file, &a.common.options(), &progress)?;
    if !super::emit_json(a.common.report.as_deref(), a.common.json, &r)? {
        print_header(&r.file, r.format, r.triangles, &r.reading);
        print_summary(&r.check);
        outln!("CGAL      {}", cgal_findings(&r.cgal));
        outln!(
            "verdict   {}",
            if r.verdict.is_valid_solid() {
                "valid closed solid"
            } else {
                "DEFECTS FOUND (latvox repair can fix most)"
            }
        );
    }
    Ok(r.verdict.exit_code())
}

/// The file line of a summary, and what reading did.
pub(crate) fn print_header(file: &str, format: Format, facets: u64, r: &Reading) {
    outln!("{file} ({}, {facets} facets read)", format.name());
    let mut notes = Vec::new();
    if r.polygons_split_into_triangles > 0 {
        notes.push(format!(
            "{} polygons split into triangles",
            r.polygons_split_into_triangles
        ));
    }
    if r.faces_with_fewer_than_3_corners_skipped > 0 {
        notes.push(format!(
            "{} faces with fewer than 3 corners skipped",
            r.faces_with_fewer_than_3_corners_skipped
        ));
    }
    if r.vertices_merged_by_tolerance > 0 {
        notes.push(format!(
            "{} vertices merged by tolerance",
            r.vertices_merged_by_tolerance
        ));
    }
    if !notes.is_empty() {
        outln!("reading   {}", notes.join(", "));
    }
    if let Some(b) = &r.beam_lattices {
        outln!(
            "beams     {} beams and {} balls in {} lattice{} meshed as a solid on voxels of {:.4} mm (thinnest radius {:.4} mm){}",
            b.beams,
            b.balls,
            b.lattices,
            if b.lattices == 1 { "" } else { "s" },
            b.voxel,
            b.thinnest_radius,
            if b.short_beams_ignored > 0 {
                format!(
                    "; {} beams shorter than minlength ignored",
                    b.short_beams_ignored
                )
            } else {
                String::new()
            }
        );
    }
}

/// The human-readable summary of a check.
pub(crate) fn print_summary(r: &CheckReport) {
    outln!(
        "mesh      facets {}  vertices {}  edges {}  shells {}",
        r.facets,
        r.vertices,
        r.edges,
        r.shell_count
    );
    outln!(
        "measures  volume {:.4} mm³  area {:.4} mm²",
        r.volume,
        r.area
    );
    let d = r.defects();
    if d.is_empty() {
        outln!("defects   none");
    } else {
        for (k, n) in &d {
            outln!("defect    {n} {k}");
        }
    }
    if let Some(n) = r.normals {
        if n.unset > 0 {
            outln!(
                "note      {} stored normals are unset (zero or not finite)",
                n.unset
            );
        }
    }
    if r.self_intersections.is_none() {
        outln!("note      self-intersections not checked");
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
        outln!(
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
        outln!(
            "…         {} more shells (see --json)",
            r.shells.len() - SHOWN
        );
    }
}
