//! `latvox fill`: a part kept as a solid skin, its core filled with a lattice at an exact
//! density, solids kept whole where asked.

use super::command::{job, parsed, Command, PartKeys};
use super::lattice::{human, print_grading, print_part, triple, GradeArgs, MeshArgs, PartArgs};
use super::out::outln;
use super::part::Part;
use super::tpms::parse_structure;
use super::{parse_density, parse_length0, parse_positive, parse_positive3, parse_unit};
use clap::Args;
use latvox::fill::{FillJob, FillReport, Infilling};
use latvox::io::ReadOptions;
use latvox::strut::cell::BUILT_IN;
use latvox::strut::UnitCell;
use latvox::tpms::{Structure, Surface};
use latvox::{Error, Result};
use std::path::{Path, PathBuf};
use std::sync::Arc;

pub(crate) const EXAMPLES: &str = "\
Examples:
  # A bracket with a 1 mm solid skin, its core a gyroid at 20 % density in 4 mm cells
  latvox fill bracket.stl --skin 1 --lattice gyroid --cell-size 4 --density 0.2 -o filled.stl

  # An octet truss inside, joined to the skin by 0.3 mm fillets, two bosses kept solid
  latvox fill grip.stl --lattice octet --cell-size 5 --density 0.15 --blend 0.3 \\
      --keep boss1.stl --keep boss2.stl -o grip-filled.stl --report grip.json

  # Save the settings (the part's file by its absolute path), then fill it again finer
  latvox fill bracket.stl --skin 1 --cell-size 4 -o filled.stl --save-part bracket.toml
  latvox fill --part bracket.toml --resolution 48 -o filled-fine.stl

  # Two 3 mm escape holes through the skin (lowest and highest point) so powder can get out
  latvox fill bracket.stl --skin 1 --cell-size 4 --drain 3 -o drained.stl

  # Dense near the skin, open inside: 35 % at the skin falling to 15 % 8 mm in (d is the depth
  # below the skin, mm); every cell wholly inside the core meets the field at its centre
  latvox fill bracket.stl --skin 1 --lattice gyroid --cell-size 4 \\
      --density-field 'max(0.15, 0.35 - 0.025*d)' -o graded-fill.stl --report graded-fill.json

  # No skin: the part cut from a sheet gyroid, an open-cell part
  latvox fill implant.stl --no-skin --lattice gyroid --structure sheet --cell-size 3 \\
      --density 0.3 -o implant-open.stl

Lattices: TPMS p, gyroid (g), d, iwp, s, frd, neovius (n), lidinoid (l), split-p, as net or sheet (--structure);
struts sc, bcc, bccz, fcc, fccz, octet, kelvin, diamond, rhombic; a strut cell file (.json); or
voronoi, a random Voronoi net (seeds --spacing apart, --seed, --regularity) that repeats with
the cell, so that a large part is filled as fast as with any strut cell.
The part is read from STL, OBJ, OFF, PLY or 3MF; one that is not closed is mended with latvox's
repair first, or refused when repair cannot close it. --density is the lattice's volume
fraction in the region it fills (the part less its skin and the kept solids): latvox meshes the
part solid and the skin alone to measure that region, then finds the lattice level at which the
written mesh has the density. Lattice pieces the part's surface cuts loose from the rest are
removed (counted in the summary and report), so the part is one piece; the whole written mesh
is verified (--verify).";

/// `latvox fill`.
pub(crate) const COMMAND: Command = Command {
    part: Some(PartKeys {
        own: &[
            "input",
            "skin",
            "no-skin",
            "lattice",
            "structure",
            "cell-size",
            "spacing",
            "seed",
            "regularity",
            "density",
            "density-grade",
            "density-field",
            "stiffness-field",
            "clamp",
            "blend",
            "drain",
            "keep",
        ],
        shared: super::part::MESHING,
    }),
    job: Some(job::<FillArgs>),
    trace: Some(|m, f| {
        Ok(Part::Filled(Box::new(
            parsed::<FillArgs>(m)?.job()?.traced(f)?,
        )))
    }),
    choices: Some(|| {
        let lattices: Vec<&str> = Surface::ALL
            .map(|s| s.name())
            .into_iter()
            .chain(BUILT_IN.iter().copied())
            .collect();
        serde_json::json!({ "lattice": lattices, "structure": ["net", "sheet"] })
    }),
    ..Command::new(
        "fill",
        "Fill a part with a lattice: a solid skin of the part's shape, its core a TPMS or strut lattice at an exact density, solids kept whole where asked",
        EXAMPLES,
        <FillArgs as clap::Args>::augment_args,
        |m, quiet| run(&parsed(m)?, quiet),
    )
};

impl latvox::batch::Task for FillArgs {
    fn outputs(&self) -> Vec<PathBuf> {
        vec![self.mesh.output.clone()]
    }

    fn run(&self) -> Result<latvox::batch::TaskReport> {
        let r = execute(self, &latvox::progress::Progress::hidden())?;
        latvox::batch::TaskReport::new(&r, &r.verdict(), r.part.warnings.clone())
    }
}

#[derive(Args)]
pub struct FillArgs {
    /// The part to fill: a closed mesh (.stl, .obj, .off, .ply, .3mf).
    #[arg(value_name = "PART", required_unless_present = "input_file")]
    pub input: Option<PathBuf>,
    /// The part to fill, as a part file gives it (the PART argument overrides it).
    #[arg(long = "input", value_name = "PART", hide = true)]
    pub input_file: Option<PathBuf>,
    /// Thickness of the solid skin kept inside the part's surface, mm.
    #[arg(long, value_name = "MM", default_value_t = 1.0, value_parser = parse_length0, allow_hyphen_values = true)]
    pub skin: f64,
    /// No skin: the lattice cut by the part's surface (an open-cell part).
    #[arg(long, conflicts_with = "skin")]
    pub no_skin: bool,
    /// The lattice: a TPMS (p, gyroid, d, iwp, s, frd, neovius, lidinoid, split-p), a strut cell (sc, bcc, bccz,
    /// fcc, fccz, octet, kelvin, diamond, rhombic), a strut cell file (.json), or voronoi (a
    /// random Voronoi net that repeats with the cell).
    #[arg(long, value_name = "NAME|FILE.json", default_value = "gyroid")]
    pub lattice: String,
    /// For a Voronoi lattice: the mean spacing of its seeds, mm (the cell holds about
    /// cell³/spacing³ of them; a quarter of the cell when not given).
    #[arg(long, value_name = "MM", value_parser = parse_positive, allow_hyphen_values = true)]
    pub spacing: Option<f64>,
    /// For a Voronoi lattice: the random generator's seed.
    #[arg(long)]
    pub seed: Option<u64>,
    /// For a Voronoi lattice: move its seeds toward the body-centred cubic lattice, 0 random to
    /// 1 the Kelvin foam.
    #[arg(long, value_name = "R", value_parser = parse_unit)]
    pub regularity: Option<f64>,
    /// For a TPMS lattice: net (F ≤ t) or sheet (|F| ≤ t).
    #[arg(long, value_name = "net|sheet", default_value = "net", value_parser = parse_structure)]
    pub structure: Structure,
    /// Cell size in mm: A or AX,AY,AZ (cells start at the lower corner of the part's box).
    #[arg(long, value_name = "MM[,MM,MM]", default_value = "5", value_parser = parse_positive3, allow_hyphen_values = true)]
    pub cell_size: [f64; 3],
    /// The lattice's volume fraction in the region it fills, in (0, 1).
    #[arg(long, short = 'd', default_value_t = 0.2, value_parser = parse_density, allow_hyphen_values = true, conflicts_with_all = ["density_grade", "density_field", "stiffness_field"])]
    pub density: f64,
    /// A density that varies through the part: along an axis of its box, or by a field of x, y,
    /// z and d, the depth below the skin in mm (every cell wholly inside the core meets it).
    #[command(flatten)]
    pub grade: GradeArgs,
    /// Fillet the lattice into the skin (and struts at their joints): smooth minimum over this
    /// many mm (0: a sharp union).
    #[arg(long, value_name = "MM", default_value_t = 0.0, value_parser = parse_length0, allow_hyphen_values = true)]
    pub blend: f64,
    /// Drain holes of this diameter, mm, through the skin at the part's lowest and highest facet
    /// (along z), so that powder or resin can leave the lattice's void, which a skin closes.
    #[arg(long, value_name = "MM", value_parser = parse_positive, conflicts_with = "no_skin", allow_hyphen_values = true)]
    pub drain: Option<f64>,
    /// A solid kept whole (a boss, a flange), unioned with the filled part; repeat for more.
    #[arg(long, value_name = "SOLID")]
    pub keep: Vec<PathBuf>,
    /// Meshing and output.
    #[command(flatten)]
    pub mesh: MeshArgs,
    /// Part files.
    #[command(flatten)]
    pub part_file: PartArgs,
}

/// Reads a mesh file for the job, naming it in errors.
fn read(path: &Path) -> Result<(String, latvox::geom::Mesh)> {
    let loaded = latvox::mesh::part::read(path, &ReadOptions::default())?;
    Ok((path.display().to_string(), loaded.mesh))
}

impl FillArgs {
    /// The lattice the option names: a TPMS, a built-in strut cell, or a cell file.
    fn infilling(&self) -> Result<(Infilling, String)> {
        let name = self.lattice.trim();
        let lower = name.to_ascii_lowercase();
        if lower == "voronoi" {
            return self.voronoi();
        }
        if let Some(flag) = [
            (self.spacing.is_some(), "--spacing"),
            (self.seed.is_some(), "--seed"),
            (self.regularity.is_some(), "--regularity"),
        ]
        .iter()
        .find_map(|(given, flag)| given.then_some(flag))
        {
            return Err(Error::invalid(format!(
                "{flag} sets a Voronoi lattice's seeds: use it with --lattice voronoi"
            )));
        }
        if let Some(surface) = Surface::parse(&lower) {
            let s = Infilling::Tpms {
                surface,
                structure: self.structure,
            };
            return Ok((s, format!("{} {}", surface.name(), self.structure.name())));
        }
        if BUILT_IN.contains(&lower.as_str()) {
            let cell = Arc::new(UnitCell::built_in(&lower)?);
            return Ok((Infilling::Strut { cell }, lower));
        }
        let path = Path::new(name);
        if lower.ends_with(".json") || path.exists() {
            let cell = Arc::new(UnitCell::from_file(path)?);
            return Ok((Infilling::Strut { cell }, name.to_string()));
        }
        Err(Error::invalid(format!(
            "unknown lattice '{name}' (known: p, gyroid, d, iwp, s, frd, neovius, lidinoid, split-p, {}, or a cell file .json)",
            BUILT_IN.join(", ")
        )))
    }

    /// A random Voronoi net that repeats with the cell, as a strut cell.
    fn voronoi(&self) -> Result<(Infilling, String)> {
        if self.structure == Structure::Sheet {
            return Err(Error::invalid(
                "fill takes a Voronoi net (struts); for Voronoi walls make `latvox voronoi --structure sheet`",
            ));
        }
        let shortest = self.cell_size.iter().cloned().fold(f64::INFINITY, f64::min);
        let spacing = self.spacing.unwrap_or(0.25 * shortest);
        let seed = self.seed.unwrap_or(1);
        let merge = shortest / self.mesh.resolution.max(1) as f64;
        let (cell, stats) = latvox::lattice::voronoi::periodic::random_net_cell(
            self.cell_size,
            spacing,
            seed,
            self.regularity.unwrap_or(0.0),
            merge,
        )?;
        Ok((
            Infilling::Strut {
                cell: Arc::new(cell),
            },
            format!(
                "Voronoi net ({} seeds a cell, spacing {} mm, seed {seed})",
                stats.cells,
                human(spacing, 4)
            ),
        ))
    }

    /// The job the options describe.
    pub fn job(&self) -> Result<FillJob> {
        let (lattice, lattice_name) = self.infilling()?;
        let input = self
            .input
            .as_ref()
            .or(self.input_file.as_ref())
            .ok_or_else(|| Error::invalid("name the part to fill"))?;
        let (part_name, part) = read(input)?;
        let keep = self
            .keep
            .iter()
            .map(|k| read(k))
            .collect::<Result<Vec<_>>>()?;
        let bounds = part
            .bounds()
            .ok_or_else(|| Error::invalid(format!("{part_name}: no triangles")))?;
        let grading = self.grade.grading(&bounds, || {
            Ok(latvox::homogenize::Cell {
                lattice: match &lattice {
                    Infilling::Tpms { surface, structure } => {
                        latvox::homogenize::Lattice::Tpms(*surface, *structure)
                    }
                    Infilling::Strut { cell } => latvox::homogenize::Lattice::Strut(cell.clone()),
                },
                size: self.cell_size,
            })
        })?;
        Ok(FillJob {
            part,
            part_name,
            keep,
            skin: if self.no_skin { 0.0 } else { self.skin },
            lattice,
            lattice_name,
            cell: self.cell_size,
            density: self.density,
            blend: self.blend,
            drain: self.drain,
            resolution: self.mesh.resolution,
            auto_resolution: !self.mesh.fixed_resolution,
            options: self.mesh.options(),
            grading,
        })
    }
}

pub fn run(a: &FillArgs, quiet: bool) -> Result<i32> {
    a.mesh.check_report()?;
    let report = execute(a, &latvox::progress::Progress::new(quiet))?;
    let code = a.mesh.finish(&report, &report.part)?;
    print_summary(&report);
    Ok(code)
}

/// Runs the job and writes its mesh atomically; returns the report, for `run` to print and
/// `latvox batch` to record.
pub fn execute(a: &FillArgs, progress: &latvox::progress::Progress) -> Result<FillReport> {
    let job = a.job()?;
    latvox::io::atomic::check_writable(&a.mesh.output)?;
    a.mesh
        .write(|sink| job.run_into(progress, sink), |r| &mut r.part)
}

fn print_summary(r: &FillReport) {
    outln!(
        "{} filled with {} · cells of {} mm · {} voxels/cell ({} mm)",
        r.input,
        r.lattice,
        triple(r.cell_size),
        r.resolution,
        human(r.voxel_size, 4)
    );
    if !r.repair.is_empty() {
        let changes: Vec<String> = r
            .repair
            .iter()
            .map(|c| format!("{} {}", c.count, c.kind))
            .collect();
        outln!("repaired  {}", changes.join(", "));
    }
    outln!(
        "regions   part {:.2} mm³ = skin{} {:.2} mm³ (skin {} mm) + fill {:.2} mm³",
        r.part_volume,
        if r.keep.is_empty() {
            String::new()
        } else {
            format!(
                " and {} kept solid{}",
                r.keep.len(),
                if r.keep.len() == 1 { "" } else { "s" }
            )
        },
        r.skin_volume,
        human(r.skin, 4),
        r.fill_volume
    );
    if !r.drains.is_empty() {
        let at: Vec<String> = r
            .drains
            .iter()
            .map(|d| format!("({})", d.from.map(|x| human(x, 3)).join(", ")))
            .collect();
        outln!(
            "drains    {} holes of {} mm through the skin at {} mm",
            r.drains.len(),
            human(2.0 * r.drains[0].radius, 4),
            at.join(" and ")
        );
    }
    let p = &r.part;
    if let Some(g) = &r.grading {
        print_grading(g, p, "whole cells");
        print_part(p);
        return;
    }
    outln!(
        "density   of the fill: target {:.4}  achieved {:.4}  (error {:+.5}) · level {:.5}",
        p.target_density.unwrap_or(f64::NAN),
        p.achieved_density,
        p.density_error.unwrap_or(f64::NAN),
        r.level
    );
    print_part(p);
}
