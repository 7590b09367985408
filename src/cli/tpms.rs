//! `latvox tpms`: a closed TPMS lattice at an exact volume fraction.

use super::command::{job, parsed, Command, PartKeys};
use super::lattice::{
    human, print_grading, print_part, triple, BoxArgs, GradeArgs, MeshArgs, PartArgs,
};
use super::out::outln;
use super::parse_density;
use super::part::Part;
use clap::Args;
use latvox::tpms::{Structure, Surface, TpmsJob, TpmsReport};
use latvox::Result;

pub(crate) const EXAMPLES: &str = "\
Examples:
  # 4×4×4 gyroid cells of 5 mm, network solid at exactly 30 % density
  latvox tpms --type gyroid --structure net --density 0.3 --cells 4 --cell-size 5 -o gyroid.stl

  # Diamond sheet, 4×4×2 cells of 6 mm, finer voxels, JSON report
  latvox tpms --type d --structure sheet --density 0.2 --cells 4,4,2 --cell-size 6 \\
      --resolution 48 -o diamond.stl --report diamond.json

  # A 50×30×10 mm block filled with 10 mm Schwarz-P cells (partial cells at the far sides)
  latvox tpms --type p --density 0.35 --size 50,30,10 --cell-size 10 -o p-block.stl

  # 30×30×30 cells (27,000): periodic cells are copies of a meshed template, streamed to the
  # STL, so memory stays flat whatever the cell count (name it .3mf for a 3MF package, which
  # holds an index per distinct vertex while it is written)
  latvox tpms --type gyroid --density 0.3 --cells 30 --cell-size 5 --resolution 16 -o big.stl

  # The whole part meshed in tiles that fit a 1 GB budget, streamed to the file (the path taken
  # when cells cannot be copied — a cell that is not a whole number of 8-voxel blocks — or with
  # --no-instancing)
  latvox tpms --type d --density 0.25 --cells 20 --cell-size 6 --no-instancing --memory 1G -o d.stl

  # A gyroid net graded from 10 % density at the bottom to 40 % at the top: each whole cell's
  # density, measured on the written mesh, is the grade at its centre within ±0.01 (the report
  # lists every cell)
  latvox tpms --type gyroid --density-grade z:0.1:0.4 --cells 6 --cell-size 5 -o graded.stl \\
      --report graded.json

  # Dense at the rim of a 40 mm disc of cells, open at its centre (an expression in x, y, z)
  latvox tpms --type d --cells 8,8,2 --cell-size 5 \\
      --density-field '0.35 - 0.2*exp(-((x-20)^2 + (y-20)^2)/100)' -o rim.stl

  # A gyroid net turning into a diamond net along x, 30 % in every cell through the blend
  latvox tpms --type gyroid --blend-to d --blend-field x:0:1 --density 0.3 --cells 6,2,2 -o blend.stl

  # An F-RD net at 30 %: its first labyrinth falls apart there, its other one holds together
  latvox tpms --type frd --density 0.3 --side other --cells 3 -o frd.stl

  # A tube (a stent's or a heat exchanger's wall): 12 gyroid cells around a 10 mm bore, one
  # through the 4 mm wall, 4 along; whole cells around, every cell at 30 %
  latvox tpms --type gyroid --cell-map cylindrical --bore 10 --cells 12,1,4 --cell-size 4 -o tube.stl

  # A spherical shell (a cubed sphere: six faces of 4×4 cells, no poles) around a 12 mm bore,
  # two cells through the wall, every cell whole
  latvox tpms --type d --density 0.25 --cell-map spherical --bore 12 --cells 4 --layers 2 -o ball.stl

  # Cells 3 mm at the bottom of a 40 mm block growing to 8 mm at its top, each one whole
  latvox tpms --type gyroid --size 20,20,40 --cell-size 5 --cell-size-grade z:3:8 -o grown.stl

  # Cells sized by a field: 3 mm along the axis of a 40 mm block growing to 7 mm at its sides
  latvox tpms --type gyroid --size 40,40,20 --cell-size-field '3 + 0.2*sqrt((x-20)^2 + (y-20)^2)' \\
      -o sized.stl

  # Save the part's settings as a part file; make it again, here with finer voxels
  latvox tpms --type d --density 0.25 --cells 4 -o d.stl --save-part d.toml
  latvox tpms --part d.toml --resolution 48 -o d-fine.stl

Types: p (Schwarz primitive), g|gyroid, d (Schwarz diamond), iwp (Schoen I-WP),
       s (Fischer–Koch S), frd (Schoen F-RD), n|neovius, l|lidinoid, split-p (Schoen's split P).
Structures: net (solid on one side of F = t; --side other for the other labyrinth),
            sheet (solid where |F| ≤ t).
The level t is found by latvox so that the written mesh has the requested volume fraction;
the report gives the target, the fraction measured on the written mesh, and its checks
(--verify: closed, manifold, outward and no self-intersection by default).";

/// `latvox tpms`.
pub(crate) const COMMAND: Command = Command {
    part: Some(PartKeys {
        own: &[
            "type",
            "structure",
            "side",
            "density",
            "density-grade",
            "density-field",
            "stiffness-field",
            "clamp",
            "blend-to",
            "blend-field",
            "cell-map",
            "bore",
            "layers",
            "cell-size-grade",
            "cell-size-field",
            "allow-islands",
        ],
        shared: super::part::LATTICE_BOX,
    }),
    job: Some(job::<TpmsArgs>),
    trace: Some(|m, f| {
        Ok(Part::Block(Box::new(
            parsed::<TpmsArgs>(m)?.job()?.model(f)?,
        )))
    }),
    choices: Some(|| {
        serde_json::json!({
            "type": Surface::ALL.map(|s| s.name()),
            "structure": ["net", "sheet"],
        })
    }),
    ..Command::new(
        "tpms",
        "Generate a closed TPMS lattice at an exact volume fraction",
        EXAMPLES,
        <TpmsArgs as clap::Args>::augment_args,
        |m, quiet| run(&parsed(m)?, quiet),
    )
};

impl latvox::batch::Task for TpmsArgs {
    fn outputs(&self) -> Vec<std::path::PathBuf> {
        vec![self.mesh.output.clone()]
    }

    fn run(&self) -> Result<latvox::batch::TaskReport> {
        let r = execute(self, &latvox::progress::Progress::hidden())?;
        latvox::batch::TaskReport::new(&r, &r.verdict(), r.part.warnings.clone())
    }
}

#[derive(Args)]
pub struct TpmsArgs {
    /// Surface: p, gyroid (g), d, iwp, s, frd, neovius (n), lidinoid (l), split-p.
    #[arg(long = "type", short = 't', value_name = "TYPE", default_value = "gyroid", value_parser = parse_surface)]
    pub surface: Surface,
    /// Solid side: net (F ≤ t) or sheet (|F| ≤ t).
    #[arg(long, value_name = "net|sheet", default_value = "net", value_parser = parse_structure)]
    pub structure: Structure,
    /// Which labyrinth of a net is solid: first (F ≤ t) or other (−F ≤ t, the complementary
    /// labyrinth, for nets whose two sides differ: F-RD, I-WP, Neovius, …).
    #[arg(long, value_name = "first|other", default_value = "first", value_parser = ["first", "other"])]
    pub side: String,
    /// Target volume fraction of solid, in (0, 1).
    #[arg(long, short = 'd', default_value_t = 0.3, value_parser = parse_density, allow_hyphen_values = true, conflicts_with_all = ["density_grade", "density_field", "stiffness_field"])]
    pub density: f64,
    /// A density that varies through the part.
    #[command(flatten)]
    pub grade: GradeArgs,
    /// Blend the type into a second one (p, gyroid, d, …) by --blend-field: the solid where
    /// (1 − w)·F/s + w·F₂/s₂ is below the level (s: each surface's RMS), each cell at its
    /// density.
    #[arg(long, value_name = "TYPE", value_parser = parse_surface, requires = "blend_field")]
    pub blend_to: Option<Surface>,
    /// The weight w of --blend-to at each point, held to [0, 1]: AXIS:A:B (linear along x, y or
    /// z across the box, as x:0:1) or a field as --density-field takes.
    #[arg(
        long,
        value_name = "AXIS:A:B|EXPR|FILE",
        requires = "blend_to",
        allow_hyphen_values = true
    )]
    pub blend_field: Option<String>,
    /// Wrap the cells around an axis or a centre. cylindrical: a tube about the z axis through
    /// --origin (its lower end's centre); --cells gives the cells around, through the wall and
    /// along the axis (12,1,4 by default), --cell-size the cell's size through the wall and
    /// along the axis (5 mm by default), --bore the inner radius; whole cells around, none cut at
    /// the seam. spherical: a shell about --origin made of a cube's six faces (a cubed sphere,
    /// no poles); --cells N gives the cells along each face's edge at the bore (4 by default),
    /// --layers the cells through the wall (1), --cell-size the cell's size through the wall
    /// (by default πR/2N, cubes at the faces' middles); every cell whole. Towards the cube's
    /// corners the cells are about half as wide: --resolution counts voxels across those.
    #[arg(long, value_name = "cylindrical|spherical", value_parser = ["cylindrical", "spherical"], requires = "bore")]
    pub cell_map: Option<String>,
    /// Cells through the wall of a --cell-map spherical shell (1 by default).
    #[arg(long, value_name = "K", value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub layers: Option<u32>,
    /// Grade the cell size along an axis: AXIS:A:B, cells A mm at the box's lower face growing
    /// to B mm at its upper one (as z:3:6), scaled a little so that whole cells span the box
    /// (the cell size along the other axes from --cell-size); no cell is torn.
    #[arg(long, value_name = "AXIS:A:B", conflicts_with = "cell_map")]
    pub cell_size_grade: Option<String>,
    /// Size the cells by a field: the cell size in mm at each point, an expression in x, y, z
    /// (as "3 + 0.1*sqrt((x-20)^2 + (y-20)^2)"), a .npy array spanning the box or a .vdb's
    /// float grid. Every line of cells along an axis holds the same whole number of cells,
    /// each stretched to the field's size along the line; no cell is torn. Where the field
    /// varies across a line, the line's cells lean and keep its count (the report gives how
    /// far each axis' cells came from the field).
    #[arg(
        long,
        value_name = "EXPR|FILE.npy|FILE.vdb",
        allow_hyphen_values = true,
        conflicts_with_all = ["cell_map", "cell_size_grade"]
    )]
    pub cell_size_field: Option<String>,
    /// Inner radius of a --cell-map tube or shell, mm.
    #[arg(
        long,
        value_name = "MM",
        requires = "cell_map",
        allow_hyphen_values = true
    )]
    pub bore: Option<f64>,
    /// The box of cells.
    #[command(flatten)]
    pub domain: BoxArgs,
    /// Build even when the solid falls apart into islands at this density.
    #[arg(long)]
    pub allow_islands: bool,
    /// Meshing and output.
    #[command(flatten)]
    pub mesh: MeshArgs,
    /// Part files.
    #[command(flatten)]
    pub part_file: PartArgs,
}

pub(crate) fn parse_surface(s: &str) -> std::result::Result<Surface, String> {
    Surface::parse(s).ok_or_else(|| {
        format!("unknown TPMS type '{s}' (known: p, gyroid, d, iwp, s, frd, neovius, lidinoid, split-p)")
    })
}

pub(crate) fn parse_structure(s: &str) -> std::result::Result<Structure, String> {
    match s.to_ascii_lowercase().as_str() {
        "net" | "network" | "solid" => Ok(Structure::Net),
        "sheet" | "shell" => Ok(Structure::Sheet),
        "net-other" => Ok(Structure::NetOther),
        _ => Err(format!("unknown structure '{s}' (known: net, sheet)")),
    }
}

pub fn run(a: &TpmsArgs, quiet: bool) -> Result<i32> {
    a.mesh.check_report()?;
    let report = execute(a, &latvox::progress::Progress::new(quiet))?;
    let code = a.mesh.finish(&report, &report.part)?;
    print_tpms_summary(&report);
    Ok(code)
}

/// Runs the job and writes its mesh atomically; returns the report (output and write time
/// filled in), for `run` to print and `latvox batch` to record.
pub fn execute(a: &TpmsArgs, progress: &latvox::progress::Progress) -> Result<TpmsReport> {
    let job = a.job()?;
    a.mesh
        .write(|sink| job.run_into(progress, sink), |r| &mut r.part)
}

impl TpmsArgs {
    /// The box: from --size alone when a field sizes the cells.
    fn domain(&self) -> Result<latvox::field::Domain> {
        let d = &self.domain;
        if self.cell_size_field.is_none() {
            return d.domain();
        }
        match (d.size, d.cells, d.cell_size) {
            (Some(s), None, None) => latvox::field::Domain::from_size_and_cell(s, s, d.origin),
            (None, _, _) => Err(latvox::Error::invalid(
                "--cell-size-field sizes the cells of a box: give the box with --size",
            )),
            _ => Err(latvox::Error::invalid(
                "--cell-size-field gives the cells' size and count: --cells and --cell-size are not used",
            )),
        }
    }

    /// The tube of a --cell-map part: cells around, through the wall and along from --cells
    /// (12,1,4 by default), their size through the wall and along from --cell-size (5 mm).
    fn cell_map(&self) -> Result<Option<latvox::field::cellmap::Mapping>> {
        use latvox::field::cellmap::{GradedCells, Mapping};
        if let Some(f) = &self.cell_size_field {
            let bounds = self.domain()?.bounds();
            let field = super::lattice::named_field(f, &bounds, "cell-size")?;
            if field.uses_distance() {
                return Err(latvox::Error::invalid(
                    "a cell-size field is in x, y and z: d (the depth below a filled part's skin) has no meaning here",
                ));
            }
            return latvox::field::sizing::SizedCells::new(
                bounds,
                |p| field.at(p, 0.0),
                field.source.clone(),
            )
            .map(|m| Some(Mapping::Sized(m)));
        }
        if let Some(g) = &self.cell_size_grade {
            let bad = || {
                latvox::Error::invalid(format!(
                    "a cell-size grade is AXIS:A:B, as z:3:6 (cells 3 mm at the lower face growing to 6 mm), got '{g}'"
                ))
            };
            let parts: Vec<&str> = g.split(':').collect();
            let [axis, a, b] = parts[..] else {
                return Err(bad());
            };
            let axis = ["x", "y", "z"]
                .iter()
                .position(|x| x.eq_ignore_ascii_case(axis))
                .ok_or_else(bad)?;
            let (a, b): (f64, f64) = (
                a.trim().parse().map_err(|_| bad())?,
                b.trim().parse().map_err(|_| bad())?,
            );
            let d = self.domain.domain()?;
            return GradedCells::new(d.bounds(), axis, a, b, d.cell)
                .map(|m| Some(Mapping::Graded(m)));
        }
        let (Some(kind), Some(bore)) = (&self.cell_map, self.bore) else {
            if self.layers.is_some() {
                return Err(latvox::Error::invalid(
                    "--layers counts the cells through a --cell-map spherical shell's wall",
                ));
            }
            return Ok(None);
        };
        let d = &self.domain;
        if d.size.is_some() {
            return Err(latvox::Error::invalid(format!(
                "--cell-map makes a {} from --cells, --cell-size and --bore: --size is not used",
                if kind == "spherical" { "shell" } else { "tube" }
            )));
        }
        let one_size = |default: Option<f64>, what: &str| match d.cell_size {
            None => Ok(default),
            Some([a, b, c]) if a == b && b == c => Ok(Some(a)),
            Some(_) => Err(latvox::Error::invalid(format!(
                "with --cell-map, --cell-size is one size ({what})"
            ))),
        };
        if kind == "spherical" {
            let n = match d.cells {
                None => 4,
                Some([a, b, c]) if a == b && b == c => a,
                Some(_) => {
                    return Err(latvox::Error::invalid(
                        "a spherical shell's --cells is one count, the cells along each face's edge at the bore (--layers counts those through the wall)",
                    ))
                }
            };
            let cell = one_size(None, "through the wall")?;
            return latvox::field::cellmap::Spherical::new(
                d.origin,
                bore,
                [n, self.layers.unwrap_or(1)],
                cell,
            )
            .map(|m| Some(Mapping::Spherical(m)));
        }
        if self.layers.is_some() {
            return Err(latvox::Error::invalid(
                "a tube's layers are the second of --cells (around, through, along); --layers is for a spherical shell",
            ));
        }
        let cells = d.cells.unwrap_or([12, 1, 4]);
        let a = one_size(
            Some(5.0),
            "through the wall and along the axis; the cells around follow from --cells and --bore",
        )?
        .unwrap_or(5.0);
        latvox::field::cellmap::Cylindrical::new(d.origin, bore, cells, [a, a])
            .map(|m| Some(Mapping::Cylindrical(m)))
    }

    /// The job the options describe.
    pub fn job(&self) -> Result<TpmsJob> {
        let m = &self.mesh;
        let o = m.options();
        let cell_map = self.cell_map()?;
        let domain = self.domain()?;
        let bounds = domain.bounds();
        let structure =
            match (self.structure, self.side.as_str()) {
                (Structure::Net, "other") => Structure::NetOther,
                (Structure::Sheet, "other") => return Err(latvox::Error::invalid(
                    "--side other picks a net's other labyrinth: a sheet is the wall between both",
                )),
                (st, _) => st,
            };
        let grading = self.grade.grading(&bounds, || {
            Ok(latvox::homogenize::Cell {
                lattice: latvox::homogenize::Lattice::Tpms(self.surface, structure),
                size: domain.cell,
            })
        })?;
        Ok(TpmsJob {
            surface: self.surface,
            structure,
            density: self.density,
            domain,
            resolution: m.resolution,
            adaptivity: o.adaptivity,
            tolerance: o.tolerance,
            allow_islands: self.allow_islands,
            auto_resolution: !m.fixed_resolution,
            verify: o.verify,
            instancing: o.instancing,
            tile: o.tile,
            memory: o.memory,
            keep_fragments: o.keep_fragments,
            grading,
            cell_map,
            blend: match (self.blend_to, &self.blend_field) {
                (Some(to), Some(f)) => Some(latvox::tpms::blend::Blend {
                    to,
                    weight: std::sync::Arc::new(if f.contains(':') {
                        latvox::field::density::DensityField::grade(f, &bounds)?
                    } else {
                        super::lattice::field(f, &bounds)?
                    }),
                }),
                _ => None,
            },
        })
    }
}

fn print_tpms_summary(r: &TpmsReport) {
    let cells = r.cells.map(|x| human(x, 2)).join("×");
    let blend = match &r.blend {
        Some(b) => format!(" blended to {} by {}", b.to.name(), b.weight),
        None => String::new(),
    };
    use latvox::tpms::mapped::CellMapReport;
    let (blend, cells) = match &r.cell_map {
        Some(CellMapReport::Cylindrical {
            map,
            outer_radius,
            length,
            ..
        }) => (
            format!(
                "{blend} tube, bore {} mm, outer radius {} mm, {} mm long",
                human(map.bore, 4),
                human(*outer_radius, 4),
                human(*length, 4)
            ),
            format!("{cells} (around × through × along)"),
        ),
        Some(CellMapReport::Spherical {
            map,
            outer_radius,
            total_cells,
            ..
        }) => (
            format!(
                "{blend} spherical shell, bore {} mm, outer radius {} mm",
                human(map.bore, 4),
                human(*outer_radius, 4)
            ),
            format!(
                "{total_cells} ({n}×{n} on each of 6 faces at the bore, {} through)",
                map.cells[1],
                n = map.cells[0]
            ),
        ),
        Some(CellMapReport::Sized { field, fit, .. }) => (
            format!(
                "{blend}, cells sized by {field} ({} to {} mm)",
                human(fit.asked[0], 4),
                human(fit.asked[1], 4)
            ),
            cells,
        ),
        Some(CellMapReport::Graded { map, .. }) => (
            format!(
                "{blend}, cells growing along {} from {} to {} mm",
                ["x", "y", "z"][map.axis],
                human(map.ends[0], 4),
                human(map.ends[1], 4)
            ),
            cells,
        ),
        None => (blend, cells),
    };
    outln!(
        "{} {}{blend} · {cells} cells of {} mm · {} voxels/cell ({} mm)",
        r.surface.name(),
        r.structure.name(),
        triple(r.cell_size),
        r.resolution,
        human(r.voxel_size, 4)
    );
    let p = &r.part;
    if let Some(g) = &r.grading {
        print_grading(g, p, "whole cells");
        print_part(p);
        return;
    }
    outln!(
        "density   target {:.4}  achieved {:.4}  (error {:+.5}, level t = {:.5})",
        p.target_density.unwrap_or(f64::NAN),
        p.achieved_density,
        p.density_error.unwrap_or(f64::NAN),
        r.level
    );
    let layer_densities = match &r.cell_map {
        Some(CellMapReport::Cylindrical {
            layer_densities, ..
        })
        | Some(CellMapReport::Spherical {
            layer_densities, ..
        }) => Some(layer_densities).filter(|l| l.len() > 1),
        _ => None,
    };
    if let Some(layer_densities) = layer_densities {
        let layers: Vec<String> = layer_densities.iter().map(|d| format!("{d:.4}")).collect();
        outln!("layers    {} (bore outwards)", layers.join("  "));
    }
    print_part(p);
}
