//! `latvox voronoi`: a Voronoi foam — struts along the edges or walls along the faces of the
//! Voronoi diagram of random seeds — at an exact volume fraction, strut radius or wall thickness.

use super::command::{job, parsed, Command, PartKeys};
use super::lattice::{
    human, named_field, print_density, print_grading, print_part, triple, GradeArgs, MeshArgs,
    PartArgs,
};
use super::out::outln;
use super::part::Part;
use super::{
    parse_density, parse_finite3, parse_positive, parse_positive3, parse_unit, write_json,
};
use clap::{Args, ValueEnum};
use latvox::field::Aabb;
use latvox::voronoi::{
    seeds, Seeding, Sizing, Spacing, Structure, VoronoiBeamsReport, VoronoiJob, VoronoiReport,
};
use latvox::Result;
use std::path::PathBuf;
use std::sync::Arc;

pub(crate) const EXAMPLES: &str = "\
Examples:
  # A 20 mm cube of Voronoi struts, cells of 3 mm on average, at exactly 15 % density
  latvox voronoi --spacing 3 --density 0.15 --size 20 -o foam.stl --report foam.json

  # Walls 0.3 mm thick along the Voronoi faces, in a 30×20×10 mm plate; with --pores 0.5,
  # a round hole through each wall half its inradius wide, so that the cells drain
  latvox voronoi --structure sheet --spacing 4 --thickness 0.3 --size 30,20,10 -o walls.stl
  latvox voronoi --structure sheet --spacing 4 --thickness 0.3 --pores 0.5 --size 20 -o open.stl

  # Cells graded from 2 mm at x = 0 to 5 mm at x = 30 (the spacing is an expression in x, y, z)
  latvox voronoi --spacing-field '2 + x/10' --density 0.2 --size 30,10,10 -o graded.stl

  # Halfway between a random foam and the Kelvin foam (regularity 1: BCC seeds, Kelvin
  # cells); the same --seed gives the same file, byte for byte
  latvox voronoi --spacing 3 --regularity 0.5 --seed 7 --density 0.15 -o half.stl

  # The same net as 3MF beams (each Voronoi edge a beam, the box a clipping mesh): kilobytes
  latvox voronoi --spacing 3 --density 0.15 -r 12 --beams -o foam-beams.3mf

  # A foam that repeats every 12 mm (random inside each cell, no seam between cells): a part
  # of any size is copied from a few meshed cells; the net's cell saved as a strut cell
  latvox voronoi --spacing 3 --periodic 12 --density 0.15 --size 48 -r 10 -o big.stl --cell-out foam-cell.json
  latvox strut --cell foam-cell.json --cell-size 12 --density 0.2 --size 24 -r 40 -o denser.stl

  # A periodic net graded from 10 % at z = 0 to 30 % at z = 36, cell by repeating cell
  latvox voronoi --spacing 3 --periodic 9 --density-grade z:0.1:0.3 --size 18,18,36 -r 10 -o graded-net.stl

  # Your own seeds (x,y,z per line, mm), and the seeds a run used written out
  latvox voronoi --spacing 3 --density 0.15 --seeds-out seeds.csv -o a.stl
  latvox voronoi --seeds-in seeds.csv --density 0.2 -o b.stl

The spacing is the edge of the mean cell: a box of volume V holds about V/spacing³ cells. Seeds
are Poisson-disk points (Bridson's sampling) in the box and a margin of two spacings round it;
their Voronoi diagram is CGAL's (the dual of its Delaunay triangulation), its edges shorter
than a voxel merged. With --density, latvox finds the strut radius (net) or wall thickness
(sheet) at which the written mesh has that volume fraction; members under 2 voxels across
raise the resolution (--resolution counts voxels per spacing, the smallest where it varies);
sizes at which one pore in ten closes are refused, with the range the foam allows. A sheet's
cells are closed, each a void of its own, unless --pores opens a hole through each wall. With --periodic, the seeds fill one cell (from the
box's lower corner) measured with their copies in the cells round it, so the foam tiles space;
a periodic net is a strut lattice whose cell --cell-out writes (for strut, fill, homogenize).";

/// `latvox voronoi`.
pub(crate) const COMMAND: Command = Command {
    part: Some(PartKeys {
        own: &[
            "structure",
            "spacing",
            "spacing-field",
            "seed",
            "regularity",
            "seeds-in",
            "periodic",
            "density",
            "density-grade",
            "density-field",
            "stiffness-field",
            "clamp",
            "radius",
            "thickness",
            "pores",
            "size",
            "origin",
        ],
        shared: super::part::MESHING,
    }),
    job: Some(job::<VoronoiArgs>),
    trace: Some(|m, f| {
        let a = parsed::<VoronoiArgs>(m)?;
        if a.grade.is_graded() {
            return Err(latvox::Error::invalid(
                "a graded part is drawn and sliced from its mesh: make it with -o part.stl, then render, view or slice part.stl",
            ));
        }
        Ok(Part::Block(Box::new(a.job()?.model(f)?)))
    }),
    choices: Some(|| serde_json::json!({ "structure": ["net", "sheet"] })),
    ..Command::new(
        "voronoi",
        "Generate a Voronoi foam — struts along the edges or walls along the faces of a random (or graded, or partly regular) Voronoi diagram — at an exact volume fraction",
        EXAMPLES,
        <VoronoiArgs as clap::Args>::augment_args,
        |m, quiet| run(&parsed(m)?, quiet),
    )
};

/// Struts or walls.
#[derive(Clone, Copy, ValueEnum)]
pub enum StructureArg {
    /// Struts along the Voronoi edges.
    Net,
    /// Walls along the Voronoi faces.
    Sheet,
}

#[derive(Args)]
pub struct VoronoiArgs {
    /// Struts along the Voronoi edges (net) or walls along its faces (sheet).
    #[arg(long, value_enum, default_value = "net")]
    pub structure: StructureArg,
    /// Mean spacing of the seeds, mm: the edge of the mean cell.
    #[arg(long, value_name = "MM", default_value_t = 3.0, value_parser = parse_positive, allow_hyphen_values = true)]
    pub spacing: f64,
    /// A spacing that varies through the box (instead of --spacing): an expression in x, y, z
    /// (mm), a .npy array spanning the box, or a .vdb grid.
    #[arg(
        long,
        value_name = "EXPR|FILE.npy|FILE.vdb",
        conflicts_with = "seeds_in"
    )]
    pub spacing_field: Option<String>,
    /// The random generator's seed: the same seed gives the same foam, byte for byte.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Move the seeds toward the body-centred cubic lattice: 0 random, 1 the Kelvin foam.
    #[arg(long, value_name = "R", default_value_t = 0.0, value_parser = parse_unit, conflicts_with_all = ["spacing_field", "seeds_in"])]
    pub regularity: f64,
    /// Your own seeds: a CSV file of x,y,z per line, mm (they should fill the box and a margin
    /// of a cell or two round it).
    #[arg(long, value_name = "FILE.csv")]
    pub seeds_in: Option<PathBuf>,
    /// Write the seeds used (box and margin; a periodic foam's cell) to a CSV file.
    #[arg(long, value_name = "FILE.csv")]
    pub seeds_out: Option<PathBuf>,
    /// Make a foam that repeats with a cube of this edge, mm (at least two spacings), from
    /// the box's lower corner: random inside the cell, seamless across cells, meshed once and
    /// copied through a large box.
    #[arg(long, value_name = "MM", value_parser = parse_positive, allow_hyphen_values = true, conflicts_with = "spacing_field")]
    pub periodic: Option<f64>,
    /// Write a periodic net's cell as a strut cell (JSON: nodes in unit-cell coordinates,
    /// struts), for `strut --cell`, `fill --cell` and `homogenize --cell`.
    #[arg(long, value_name = "FILE.json", requires = "periodic")]
    pub cell_out: Option<PathBuf>,
    /// Target volume fraction of solid, in (0, 1) (0.15 when no size is given).
    #[arg(long, short = 'd', value_parser = parse_density, allow_hyphen_values = true, conflicts_with_all = ["radius", "thickness", "density_grade", "density_field", "stiffness_field"])]
    pub density: Option<f64>,
    /// A density that varies through the part: a periodic net's met cell by repeating cell, as
    /// for strut lattices; a random foam's block by block, in blocks of about two spacings.
    #[command(flatten)]
    pub grade: GradeArgs,
    /// Strut radius of a net, mm, instead of a density.
    #[arg(long, value_name = "MM", value_parser = parse_positive, allow_hyphen_values = true, conflicts_with = "thickness")]
    pub radius: Option<f64>,
    /// Wall thickness of a sheet, mm, instead of a density.
    #[arg(long, value_name = "MM", value_parser = parse_positive, allow_hyphen_values = true)]
    pub thickness: Option<f64>,
    /// Open a sheet's cells: a round pore through the middle of each wall, this fraction of the
    /// wall's inradius (0 to 1; walls too small for a pore two voxels across keep none).
    #[arg(long, value_name = "F", default_value_t = 0.0, value_parser = parse_unit)]
    pub pores: f64,
    /// Write the net as beams (3MF Beam Lattice extension: each Voronoi edge a beam of the
    /// radius, the box a clipping mesh) instead of a mesh. The output must be .3mf.
    #[arg(long)]
    pub beams: bool,
    /// Box size in mm: S or SX,SY,SZ.
    #[arg(long, value_name = "MM[,MM,MM]", default_value = "20", value_parser = parse_positive3, allow_hyphen_values = true)]
    pub size: [f64; 3],
    /// Lower corner of the box in mm.
    #[arg(long, value_name = "X,Y,Z", default_value = "0,0,0", value_parser = parse_finite3, allow_hyphen_values = true)]
    pub origin: [f64; 3],
    /// Meshing and output.
    #[command(flatten)]
    pub mesh: MeshArgs,
    /// Part files.
    #[command(flatten)]
    pub part_file: PartArgs,
}

impl latvox::batch::Task for VoronoiArgs {
    fn outputs(&self) -> Vec<PathBuf> {
        let mut out = vec![self.mesh.output.clone()];
        out.extend(self.seeds_out.clone());
        out.extend(self.cell_out.clone());
        out
    }

    fn run(&self) -> Result<latvox::batch::TaskReport> {
        match execute(self, &latvox::progress::Progress::hidden())? {
            Made::Mesh(r) => {
                latvox::batch::TaskReport::new(&r, &r.verdict(), r.part.warnings.clone())
            }
            Made::Beams(r) => latvox::batch::TaskReport::new(&r, &r.verdict(), Vec::new()),
            Made::Graded(r) => {
                latvox::batch::TaskReport::new(&r, &r.verdict(), r.part.warnings.clone())
            }
        }
    }
}

impl VoronoiArgs {
    /// The job the options describe.
    pub fn job(&self) -> Result<VoronoiJob> {
        let bounds = Aabb {
            min: self.origin,
            max: [0, 1, 2].map(|k| self.origin[k] + self.size[k]),
        };
        let structure = match self.structure {
            StructureArg::Net => Structure::Net,
            StructureArg::Sheet => Structure::Sheet,
        };
        let level = match structure {
            Structure::Net => {
                if self.thickness.is_some() {
                    return Err(latvox::Error::invalid(
                        "--thickness sizes a sheet's walls: a net's struts take --radius",
                    ));
                }
                self.radius
            }
            Structure::Sheet => {
                if self.radius.is_some() {
                    return Err(latvox::Error::invalid(
                        "--radius sizes a net's struts: a sheet's walls take --thickness",
                    ));
                }
                self.thickness
            }
        };
        let seeding = match (&self.seeds_in, &self.spacing_field) {
            (Some(path), _) => Seeding::Given(seeds::read_csv(path)?),
            (None, Some(f)) => Seeding::Poisson {
                spacing: Spacing::Field(Arc::new(named_field(f, &bounds, "spacing")?)),
                seed: self.seed,
                regularity: self.regularity,
            },
            (None, None) => Seeding::Poisson {
                spacing: Spacing::Uniform(self.spacing),
                seed: self.seed,
                regularity: self.regularity,
            },
        };
        // A periodic net is graded as a strut lattice, cell by repeating cell (see `graded`);
        // other foams block by block, by the job itself.
        let grading = match (self.periodic, structure) {
            (Some(_), Structure::Net) => None,
            _ if self.grade.stiffness_field.is_some() => {
                return Err(latvox::Error::invalid(
                    "--stiffness-field grades by the homogenised stiffness of a repeating cell: give --periodic with a net, or grade the foam by --density-field",
                ))
            }
            _ => self.grade.grading(&bounds, || {
                unreachable!("a stiffness field is refused above")
            })?,
        };
        if grading.is_some() && self.beams {
            return Err(latvox::Error::invalid(
                "a graded foam is written as a mesh: drop --beams, or give one --density or --radius",
            ));
        }
        Ok(VoronoiJob {
            structure,
            seeding,
            sizing: match (level, self.density) {
                (Some(l), _) => Sizing::Level(l),
                (None, d) => Sizing::Density(d.unwrap_or(0.15)),
            },
            bounds,
            period: self.periodic,
            pores: self.pores,
            resolution: self.mesh.resolution,
            auto_resolution: !self.mesh.fixed_resolution,
            grading,
            options: self.mesh.options(),
        })
    }
}

/// What a run made: a meshed part, or beams.
pub enum Made {
    /// The part as a mesh.
    Mesh(Box<VoronoiReport>),
    /// A graded periodic net, made as a graded strut lattice.
    Graded(Box<latvox::strut::StrutReport>),
    /// The net as 3MF beams.
    Beams(Box<VoronoiBeamsReport>),
}

pub fn run(a: &VoronoiArgs, quiet: bool) -> Result<i32> {
    a.mesh.check_report()?;
    match execute(a, &latvox::progress::Progress::new(quiet))? {
        Made::Mesh(report) => {
            let code = a.mesh.finish(&report, &report.part)?;
            print_summary(a, &report);
            Ok(code)
        }
        Made::Graded(report) => {
            let code = a.mesh.finish(&report, &report.part)?;
            super::strut::print_summary(&report);
            Ok(code)
        }
        Made::Beams(report) => {
            if let Some(r) = &a.mesh.report {
                write_json(r, &report)?;
            }
            outln!(
                "Voronoi net as beams · box {} mm · {} beams of radius {:.4} mm between {} vertices, clipped by the box",
                triple(a.size),
                report.beams,
                report.radius,
                report.vertices
            );
            if let (Some(t), Some(f), Some(res)) = (
                report.target_density,
                report.meshed_density,
                report.resolution,
            ) {
                outln!(
                    "density   target {t:.4}  meshed at this radius {f:.4}  ({res} voxels per spacing)"
                );
            }
            outln!("time      {:.3} s", report.seconds);
            if let Some(o) = &report.output {
                outln!("wrote     {o}");
            }
            Ok(report.verdict().exit_code())
        }
    }
}

/// Writes the seeds a run used, when asked.
fn write_seeds(a: &VoronoiArgs, seeds: &[latvox::field::Vec3]) -> Result<()> {
    if let Some(s) = &a.seeds_out {
        let csv = seeds::to_csv(seeds);
        latvox::io::atomic::write_atomic(s, |w| w.write_all(csv.as_bytes()))?;
    }
    Ok(())
}

/// Runs the job and writes its mesh or beams (and seeds) atomically; returns the report.
pub fn execute(a: &VoronoiArgs, progress: &latvox::progress::Progress) -> Result<Made> {
    let job = a.job()?;
    for s in a.seeds_out.iter().chain(&a.cell_out) {
        latvox::io::atomic::check_writable(s)?;
    }
    if a.cell_out.is_some() && matches!(a.structure, StructureArg::Sheet) {
        return Err(latvox::Error::invalid(
            "--cell-out writes a periodic net's struts: a sheet's walls are not a strut cell",
        ));
    }
    if let Some(r) = graded(a, &job, progress)? {
        return Ok(Made::Graded(Box::new(r)));
    }
    if a.beams {
        if matches!(a.structure, StructureArg::Sheet) {
            return Err(latvox::Error::invalid(
                "a sheet's walls cannot be written as beams: drop --beams, or make a net",
            ));
        }
        let out = &a.mesh.output;
        let mut report = super::lattice::write_beams(out, || job.beams(progress))?;
        report.output = Some(out.display().to_string());
        write_seeds(a, &report.seeds)?;
        return Ok(Made::Beams(Box::new(report)));
    }
    let report = a
        .mesh
        .write(|sink| job.run_into(progress, sink), |r| &mut r.part)?;
    write_seeds(a, &report.seeds)?;
    if let (Some(path), Some(cell)) = (&a.cell_out, &report.cell) {
        let json = cell.to_json();
        latvox::io::atomic::write_atomic(path, |w| w.write_all(json.as_bytes()))?;
    }
    Ok(Made::Mesh(Box::new(report)))
}

/// A graded periodic net: its cell made as a strut lattice graded cell by repeating cell (the
/// strut job's grading); `None` when no grading is asked for or the foam is not a periodic net
/// (the job grades those itself).
fn graded(
    a: &VoronoiArgs,
    job: &VoronoiJob,
    progress: &latvox::progress::Progress,
) -> Result<Option<latvox::strut::StrutReport>> {
    let g = &a.grade;
    let (true, Some(period), StructureArg::Net) = (g.is_graded(), a.periodic, a.structure) else {
        return Ok(None);
    };
    if a.beams {
        return Err(latvox::Error::invalid(
            "a graded foam is written as a mesh: drop --beams, or give one --density or --radius",
        ));
    }
    let (foam, spacing) = job.foam(progress)?;
    let cell = Arc::new(latvox::lattice::voronoi::periodic::net_cell(&foam)?);
    let grading = g.grading(&job.bounds, || {
        Ok(latvox::homogenize::Cell {
            lattice: latvox::homogenize::Lattice::Strut(cell.clone()),
            size: [period; 3],
        })
    })?;
    let strut = latvox::strut::StrutJob {
        cell: cell.clone(),
        cell_name: format!("periodic Voronoi net ({} seeds a cell)", foam.stats.cells),
        sizing: latvox::strut::Sizing::Density(0.5),
        blend: 0.0,
        domain: latvox::field::Domain::from_size_and_cell(a.size, [period; 3], a.origin)?,
        resolution: job.cell_voxels(spacing, job.resolution),
        auto_resolution: job.auto_resolution,
        options: job.options,
        grading,
    };
    let report = a
        .mesh
        .write(|sink| strut.run_into(progress, sink), |r| &mut r.part)?;
    write_seeds(a, foam.own_seeds())?;
    if let Some(path) = &a.cell_out {
        let json = cell.to_json();
        latvox::io::atomic::write_atomic(path, |w| w.write_all(json.as_bytes()))?;
    }
    Ok(Some(report))
}

fn print_summary(a: &VoronoiArgs, r: &VoronoiReport) {
    let mean = if r.grading.is_some() {
        " on average"
    } else {
        ""
    };
    let (kind, level) = match (r.radius, r.thickness) {
        (Some(l), _) => ("net", format!("strut radius {l:.4} mm{mean}")),
        (_, Some(l)) => ("sheet", format!("wall thickness {l:.4} mm{mean}")),
        _ => ("foam", String::new()),
    };
    let spacing = if r.spacing[0] == r.spacing[1] {
        format!("{} mm", human(r.spacing[0], 4))
    } else {
        format!("{}–{} mm", human(r.spacing[0], 4), human(r.spacing[1], 4))
    };
    outln!(
        "Voronoi {kind} · box {} mm · spacing {spacing} · {} voxels/spacing ({} mm)",
        triple(a.size),
        r.resolution,
        human(r.voxel_size, 4)
    );
    let f = &r.foam;
    let cells = match r.period {
        Some(l) => format!("{} per repeating cell of {} mm", f.cells, human(l, 4)),
        None => format!("{} in the box ({} seeds with the margin)", f.cells, f.seeds),
    };
    outln!(
        "cells     {cells} · cell diameter {:.3} mm (5–95 %: {:.3}–{:.3})",
        f.cell_diameter.mean,
        f.cell_diameter.p5,
        f.cell_diameter.p95
    );
    outln!(
        "members   {level} ({:.2} voxels across) · edges {:.3} mm on average (5–95 %: {:.3}–{:.3})",
        r.member_voxels,
        f.edge_length.mean,
        f.edge_length.p5,
        f.edge_length.p95
    );
    if a.pores > 0.0 {
        outln!(
            "pores     {} walls in the box opened by a round pore ({} of the wall's inradius)",
            f.pores,
            human(a.pores, 3)
        );
    }
    let p = &r.part;
    match &r.grading {
        Some(g) => {
            let block = r
                .block
                .map_or(String::new(), |b| format!(" of {} mm", triple(b)));
            print_grading(g, p, &format!("blocks{block}"))
        }
        None => print_density(p),
    }
    print_part(p);
    if let Some(s) = &a.seeds_out {
        outln!("seeds     {} written to {}", r.seeds.len(), s.display());
    }
    if let (Some(c), Some(cell)) = (&a.cell_out, &r.cell) {
        outln!(
            "cell      {} struts between {} nodes written to {}",
            cell.struts.len(),
            cell.nodes.len(),
            c.display()
        );
    }
}
