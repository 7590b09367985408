//! `latvox strut`: a closed strut (beam) lattice at an exact volume fraction or strut radius.

use super::command::{job, parsed, Command, PartKeys};
use super::lattice::{
    human, print_density, print_grading, print_part, triple, BoxArgs, GradeArgs, MeshArgs, PartArgs,
};
use super::out::outln;
use super::part::Part;
use super::{parse_density, parse_length0, parse_positive, write_json};
use clap::Args;
use latvox::strut::cell::BUILT_IN;
use latvox::strut::{BeamsReport, Sizing, StrutJob, StrutReport, UnitCell};
use latvox::Result;
use std::path::Path;
use std::sync::Arc;

pub(crate) const EXAMPLES: &str = "\
Examples:
  # 4×4×4 octet-truss cells of 5 mm at exactly 20 % density, with a JSON report
  latvox strut --cell octet --density 0.2 --cells 4 --cell-size 5 -o octet.stl --report octet.json

  # BCC struts of radius 0.4 mm, joints filleted over 0.3 mm, in a 42×30×12 mm block (partial
  # cells at the far sides, fragments the box cuts loose removed)
  latvox strut --cell bcc --radius 0.4 --blend 0.3 --size 42,30,12 --cell-size 6 -o bcc.stl

  # A cell of your own: nodes in unit-cell coordinates, struts as node pairs, and optionally a
  # radius factor per node (struts between nodes of different factors are tapered); here the
  # centre joined to four corners, a tetrahedral net, thick at the centre
  echo '{\"nodes\": [[0.5,0.5,0.5],[0,0,0],[1,0,0],[0,1,0],[0,0,1]],
         \"struts\": [[0,1],[0,2],[0,3],[0,4]], \"radii\": [1.5,0.8,0.8,0.8,0.8]}' > cell.json
  latvox strut --cell cell.json --density 0.15 --cells 5 --cell-size 4 -o custom.stl

  # The same lattice as 3MF beams (each strut a beam, the box a clipping mesh): kilobytes
  latvox strut --cell octet --density 0.2 --cells 10 --cell-size 5 --beams -o octet-beams.3mf

  # Save the part's settings, then make it again with 8 cells a side
  latvox strut --cell octet --density 0.2 --cells 4 -o octet.stl --save-part octet.toml
  latvox strut --part octet.toml --cells 8 -o octet-8.stl

  # BCC struts graded from 10 % density at the bottom to 40 % at the top: the radius varies
  # with the height, and each whole cell's density, measured on the written mesh, is the grade
  # at its centre within ±0.01 (the report lists every cell)
  latvox strut --cell bcc --density-grade z:0.1:0.4 --cells 6 --cell-size 5 -o bcc-graded.stl \\
      --report bcc-graded.json

  # 30×30×30 cells: copies of a meshed template streamed to the file, memory flat
  latvox strut --cell kelvin --density 0.1 --cells 30 --cell-size 3 --resolution 16 -o big.stl

Cells: sc (simple cubic), bcc, bccz (bcc with vertical struts), fcc, fccz, octet (octet truss),
       kelvin (edges of the truncated octahedron), diamond, rhombic (rhombic dodecahedron);
       or a cell file (.json).
A strut is a capsule (a cone with rounded ends where its two nodes' radius factors differ). With
--density, latvox finds the radius at which the written mesh has that volume fraction; the
report gives the radius, the fraction measured on the written mesh, and its checks. Radii at
which struts would be under 2 voxels across raise the resolution; radii at which the pores
between struts close are refused, with the range the cell allows.";

/// `latvox strut`.
pub(crate) const COMMAND: Command = Command {
    part: Some(PartKeys {
        own: &[
            "cell",
            "density",
            "radius",
            "density-grade",
            "density-field",
            "stiffness-field",
            "clamp",
            "blend",
        ],
        shared: super::part::LATTICE_BOX,
    }),
    job: Some(job::<StrutArgs>),
    trace: Some(|m, f| Ok(Part::Block(Box::new(parsed::<StrutArgs>(m)?.job()?.model(f)?)))),
    choices: Some(|| serde_json::json!({ "cell": BUILT_IN })),
    ..Command::new(
        "strut",
        "Generate a closed strut (beam) lattice — BCC, octet, Kelvin or a cell of your own — at an exact volume fraction or strut radius",
        EXAMPLES,
        <StrutArgs as clap::Args>::augment_args,
        |m, quiet| run(&parsed(m)?, quiet),
    )
};

impl latvox::batch::Task for StrutArgs {
    fn outputs(&self) -> Vec<std::path::PathBuf> {
        vec![self.mesh.output.clone()]
    }

    fn run(&self) -> Result<latvox::batch::TaskReport> {
        execute(self, &latvox::progress::Progress::hidden())?.task_report()
    }
}

#[derive(Args)]
pub struct StrutArgs {
    /// Unit cell: a built-in name (sc, bcc, bccz, fcc, fccz, octet, kelvin, diamond, rhombic)
    /// or a cell file (.json: nodes, struts, optional radii).
    #[arg(long, value_name = "NAME|FILE.json", default_value = "bcc")]
    pub cell: String,
    /// Target volume fraction of solid, in (0, 1): the strut radius is found for it (0.2 when
    /// neither --density nor --radius is given).
    #[arg(long, short = 'd', value_parser = parse_density, allow_hyphen_values = true, conflicts_with_all = ["radius", "density_grade", "density_field", "stiffness_field"])]
    pub density: Option<f64>,
    /// Strut radius in mm (times each node's factor), instead of a density.
    #[arg(long, value_name = "MM", value_parser = parse_positive, allow_hyphen_values = true, conflicts_with_all = ["density_grade", "density_field", "stiffness_field"])]
    pub radius: Option<f64>,
    /// A density that varies through the part (the strut radius varies with it).
    #[command(flatten)]
    pub grade: GradeArgs,
    /// Fillet the joints: smooth minimum over this many mm (0: a sharp union).
    #[arg(long, value_name = "MM", default_value_t = 0.0, value_parser = parse_length0, allow_hyphen_values = true)]
    pub blend: f64,
    /// Write the lattice as beams (3MF Beam Lattice extension: each strut a beam with its
    /// radii, the box a clipping mesh) instead of a mesh: kilobytes instead of gigabytes, for
    /// printers and tools that read beams. The output must be .3mf; joints cannot be blended.
    #[arg(long)]
    pub beams: bool,
    /// The box of cells.
    #[command(flatten)]
    pub domain: BoxArgs,
    /// Meshing and output.
    #[command(flatten)]
    pub mesh: MeshArgs,
    /// Part files.
    #[command(flatten)]
    pub part_file: PartArgs,
}

/// The cell `name` names: a built-in cell, or else a cell file; and its name for reports.
pub(crate) fn unit_cell(name: &str) -> Result<(UnitCell, String)> {
    let name = name.trim();
    let lower = name.to_ascii_lowercase();
    if BUILT_IN.contains(&lower.as_str()) {
        return Ok((UnitCell::built_in(&lower)?, lower));
    }
    let path = Path::new(name);
    if lower.ends_with(".json") || path.exists() {
        return Ok((UnitCell::from_file(path)?, name.to_string()));
    }
    // Neither: the built-in cell's error, which lists them.
    Ok((UnitCell::built_in(&lower)?, lower))
}

impl StrutArgs {
    /// The job the options describe.
    pub fn job(&self) -> Result<StrutJob> {
        let (cell, cell_name) = unit_cell(&self.cell)?;
        let cell = Arc::new(cell);
        let domain = self.domain.domain()?;
        Ok(StrutJob {
            grading: self.grade.grading(&domain.bounds(), || {
                Ok(latvox::homogenize::Cell {
                    lattice: latvox::homogenize::Lattice::Strut(cell.clone()),
                    size: domain.cell,
                })
            })?,
            cell,
            cell_name,
            sizing: match (self.radius, self.density) {
                (Some(r), _) => Sizing::Radius(r),
                (None, d) => Sizing::Density(d.unwrap_or(0.2)),
            },
            blend: self.blend,
            domain,
            resolution: self.mesh.resolution,
            auto_resolution: !self.mesh.fixed_resolution,
            options: self.mesh.options(),
        })
    }
}

/// What a strut run made: a meshed part, or beams.
pub enum Made {
    /// The part as a mesh.
    Mesh(Box<StrutReport>),
    /// The lattice as 3MF beams.
    Beams(Box<BeamsReport>),
}

impl Made {
    /// The report, its verdict and its warnings, for `latvox batch`.
    pub fn task_report(&self) -> Result<latvox::batch::TaskReport> {
        match self {
            Made::Mesh(r) => {
                latvox::batch::TaskReport::new(r, &r.verdict(), r.part.warnings.clone())
            }
            Made::Beams(r) => latvox::batch::TaskReport::new(r, &r.verdict(), Vec::new()),
        }
    }
}

pub fn run(a: &StrutArgs, quiet: bool) -> Result<i32> {
    a.mesh.check_report()?;
    match execute(a, &latvox::progress::Progress::new(quiet))? {
        Made::Mesh(report) => {
            let code = a.mesh.finish(&report, &report.part)?;
            print_summary(&report);
            Ok(code)
        }
        Made::Beams(report) => {
            if let Some(r) = &a.mesh.report {
                write_json(r, &report)?;
            }
            print_beams_summary(&report);
            Ok(report.verdict().exit_code())
        }
    }
}

/// Runs the job and writes its mesh (or beams) atomically; returns the report, for `run` to
/// print and `latvox batch` to record.
pub fn execute(a: &StrutArgs, progress: &latvox::progress::Progress) -> Result<Made> {
    let job = a.job()?;
    if !a.beams {
        let report = a
            .mesh
            .write(|sink| job.run_into(progress, sink), |r| &mut r.part)?;
        return Ok(Made::Mesh(Box::new(report)));
    }
    let out = &a.mesh.output;
    let mut report = super::lattice::write_beams(out, || job.beams(progress))?;
    report.output = Some(out.display().to_string());
    Ok(Made::Beams(Box::new(report)))
}

fn print_beams_summary(r: &BeamsReport) {
    let cells = r.cells.map(|x| human(x, 2)).join("×");
    outln!(
        "{} beams · {cells} cells of {} mm",
        r.cell,
        triple(r.cell_size)
    );
    outln!(
        "beams     {} beams of radius {:.4} mm between {} vertices, clipped by the box",
        r.beams,
        r.radius,
        r.vertices
    );
    if let (Some(t), Some(f), Some(res)) = (r.target_density, r.meshed_density, r.resolution) {
        outln!("density   target {t:.4}  meshed at this radius {f:.4}  ({res} voxels per cell)");
    }
    outln!("time      {:.3} s", r.seconds);
    if let Some(o) = &r.output {
        outln!("wrote     {o}");
    }
}

pub(crate) fn print_summary(r: &StrutReport) {
    let cells = r.cells.map(|x| human(x, 2)).join("×");
    outln!(
        "{} struts · {cells} cells of {} mm · {} voxels/cell ({} mm)",
        r.cell,
        triple(r.cell_size),
        r.resolution,
        human(r.voxel_size, 4)
    );
    outln!(
        "struts    radius {:.4} mm ({:.2} voxels across at the thinnest), blend {} mm · cell of {} nodes, {} struts",
        r.radius,
        r.thinnest_strut_voxels,
        human(r.blend, 4),
        r.cell_nodes,
        r.cell_struts
    );
    let p = &r.part;
    if let Some(g) = &r.grading {
        print_grading(g, p, "whole cells");
        print_part(p);
        return;
    }
    print_density(p);
    print_part(p);
}
