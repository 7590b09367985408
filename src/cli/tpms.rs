//! `latvox tpms`: a closed TPMS lattice at an exact volume fraction.

use super::out::outln;
use super::{
    cgal_findings, parse_counts, parse_density, parse_finite3, parse_positive3, parse_size,
    parse_tile, parse_unit, write_json,
};
use clap::Args;
use latvox::io::sink::MeshFile;
use latvox::tpms::{Domain, Structure, Surface, TpmsJob, TpmsReport};
use latvox::{Error, Result};
use std::path::PathBuf;

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

Types: p (Schwarz primitive), g|gyroid, d (Schwarz diamond), iwp (Schoen I-WP),
       s (Fischer–Koch S), frd (Schoen F-RD), n|neovius.
Structures: net (solid on one side of F = t), sheet (solid where |F| ≤ t).
The level t is found by latvox so that the written mesh has the requested volume fraction;
the report gives the target, the fraction CGAL measures on the mesh, and the CGAL checks.";

#[derive(Args)]
pub struct TpmsArgs {
    /// Surface: p, gyroid (g), d, iwp, s, frd, neovius (n).
    #[arg(long = "type", short = 't', value_name = "TYPE", default_value = "gyroid", value_parser = parse_surface)]
    pub surface: Surface,
    /// Solid side: net (F ≤ t) or sheet (|F| ≤ t).
    #[arg(long, value_name = "net|sheet", default_value = "net", value_parser = parse_structure)]
    pub structure: Structure,
    /// Target volume fraction of solid, in (0, 1).
    #[arg(long, short = 'd', default_value_t = 0.3, value_parser = parse_density, allow_hyphen_values = true)]
    pub density: f64,
    /// Cells per axis: N or NX,NY,NZ.
    #[arg(long, value_name = "N[,NY,NZ]", value_parser = parse_counts, allow_hyphen_values = true)]
    pub cells: Option<[u32; 3]>,
    /// Cell size in mm: A or AX,AY,AZ.
    #[arg(long, value_name = "MM[,MM,MM]", value_parser = parse_positive3, allow_hyphen_values = true)]
    pub cell_size: Option<[f64; 3]>,
    /// Overall box size in mm (with --cells or --cell-size): S or SX,SY,SZ.
    #[arg(long, value_name = "MM[,MM,MM]", value_parser = parse_positive3, allow_hyphen_values = true)]
    pub size: Option<[f64; 3]>,
    /// Lower corner of the box in mm (lattice phase starts there).
    #[arg(long, value_name = "X,Y,Z", default_value = "0,0,0", value_parser = parse_finite3, allow_hyphen_values = true)]
    pub origin: [f64; 3],
    /// Voxels per cell along the cell's shortest side.
    #[arg(long, short = 'r', default_value_t = 32, value_parser = clap::value_parser!(u32).range(4..=4096))]
    pub resolution: u32,
    /// OpenVDB mesh adaptivity: 0 keeps uniform triangles, up to 1 merges flat regions.
    #[arg(long, default_value_t = 0.0, value_parser = parse_unit)]
    pub adaptivity: f64,
    /// Output mesh, in the format its extension names: .stl (binary, ASCII with --ascii) or
    /// .3mf, streamed to the file as it is made; .obj, .off or .ply (binary, ASCII with
    /// --ascii), written once the part is whole.
    #[arg(
        long,
        short = 'o',
        value_name = "FILE.stl|.3mf|.obj|.off|.ply",
        default_value = "lattice.stl"
    )]
    pub output: PathBuf,
    /// Write ASCII STL (or ASCII PLY) instead of binary.
    #[arg(long)]
    pub ascii: bool,
    /// Write a JSON report (type, level, densities, mesh counts, CGAL checks, timings).
    #[arg(long, value_name = "FILE.json")]
    pub report: Option<PathBuf>,
    /// Build even when the solid falls apart into islands at this density.
    #[arg(long)]
    pub allow_islands: bool,
    /// Fail instead of raising the resolution when sheet walls would be under 1.25 voxels.
    #[arg(long)]
    pub fixed_resolution: bool,
    /// Skip CGAL's self-intersection test (the slowest check) on very large meshes.
    #[arg(long)]
    pub no_self_intersection_check: bool,
    /// Mesh the whole part at once instead of copying its periodic cells from a meshed
    /// 3×3×3-cell template (slower, same solid; CGAL then checks the whole part).
    #[arg(long)]
    pub no_instancing: bool,
    /// Memory budget while meshing, e.g. 2G or 512M: a part whose grid would not fit is meshed
    /// in tiles sized from it and streamed to the file (default 4G).
    #[arg(long, value_name = "SIZE", value_parser = parse_size)]
    pub memory: Option<u64>,
    /// Mesh in tiles of this many voxels a side (a multiple of 8, at least 16), whatever the
    /// part's size; the tiled part is the same solid as the untiled one.
    #[arg(long, value_name = "VOXELS", value_parser = parse_tile)]
    pub tile: Option<i64>,
    /// Keep the pieces the box cuts loose from the lattice (by default they are removed, so
    /// that the part is one piece; the summary and report count them either way).
    #[arg(long)]
    pub keep_fragments: bool,
}

pub(crate) fn parse_surface(s: &str) -> std::result::Result<Surface, String> {
    Surface::parse(s).ok_or_else(|| {
        format!("unknown TPMS type '{s}' (known: p, gyroid, d, iwp, s, frd, neovius)")
    })
}

pub(crate) fn parse_structure(s: &str) -> std::result::Result<Structure, String> {
    match s.to_ascii_lowercase().as_str() {
        "net" | "network" | "solid" => Ok(Structure::Net),
        "sheet" | "shell" => Ok(Structure::Sheet),
        _ => Err(format!("unknown structure '{s}' (known: net, sheet)")),
    }
}

fn domain(a: &TpmsArgs) -> Result<Domain> {
    match (a.cells, a.cell_size, a.size) {
        (Some(n), Some(c), None) => Domain::from_cells(n, c, a.origin),
        (Some(n), None, Some(s)) => Domain::from_size_and_cells(s, n, a.origin),
        (None, Some(c), Some(s)) => Domain::from_size_and_cell(s, c, a.origin),
        (Some(n), None, None) => Domain::from_cells(n, [5.0; 3], a.origin),
        (None, Some(c), None) => Domain::from_cells([4; 3], c, a.origin),
        (None, None, None) => Domain::from_cells([4; 3], [5.0; 3], a.origin),
        (None, None, Some(_)) => Err(Error::invalid("--size needs --cells or --cell-size")),
        (Some(_), Some(_), Some(_)) => Err(Error::invalid(
            "give two of --cells, --cell-size, --size, not all three",
        )),
    }
}

pub fn run(a: &TpmsArgs, quiet: bool) -> Result<i32> {
    // Fail on an unwritable destination before the work, not after.
    if let Some(r) = &a.report {
        latvox::io::atomic::check_writable(r)?;
    }
    let report = execute(a, &latvox::progress::Progress::new(quiet))?;
    if let Some(r) = &a.report {
        write_json(r, &report)?;
    }
    for w in &report.warnings {
        eprintln!("latvox: warning: {w}");
    }
    print_tpms_summary(&report);
    Ok(report.verdict().exit_code())
}

/// Runs the job and writes its mesh atomically; returns the report (output and write time
/// filled in), for `run` to print and `latvox batch` to record.
pub fn execute(a: &TpmsArgs, progress: &latvox::progress::Progress) -> Result<TpmsReport> {
    let job = TpmsJob {
        surface: a.surface,
        structure: a.structure,
        density: a.density,
        domain: domain(a)?,
        resolution: a.resolution,
        adaptivity: a.adaptivity,
        allow_islands: a.allow_islands,
        auto_resolution: !a.fixed_resolution,
        self_intersection: !a.no_self_intersection_check,
        instancing: !a.no_instancing,
        tile: a.tile,
        memory: a.memory,
        keep_fragments: a.keep_fragments,
    };
    latvox::io::atomic::check_writable(&a.output)?;
    // The part goes to a temporary file that becomes the output only once the job is done.
    let mut sink = MeshFile::new(&a.output, a.ascii)?.sink()?;
    let mut report = job.run_into(progress, &mut sink)?;
    sink.commit()?;
    report.output = Some(a.output.display().to_string());
    Ok(report)
}

/// A number for people: at most `digits` decimals, trailing zeros dropped.
fn human(x: f64, digits: usize) -> String {
    let s = format!("{x:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

fn print_tpms_summary(r: &latvox::tpms::TpmsReport) {
    let triple = |v: [f64; 3]| {
        if v[0] == v[1] && v[1] == v[2] {
            human(v[0], 3)
        } else {
            v.map(|x| human(x, 3)).join("×")
        }
    };
    let cells = r.cells.map(|x| human(x, 2)).join("×");
    outln!(
        "{} {} · {cells} cells of {} mm · {} voxels/cell ({} mm)",
        r.surface.name(),
        r.structure.name(),
        triple(r.cell_size),
        r.resolution,
        human(r.voxel_size, 4)
    );
    outln!(
        "density   target {:.4}  achieved {:.4}  (error {:+.5}, level t = {:.5})",
        r.target_density,
        r.achieved_density,
        r.density_error,
        r.level
    );
    outln!(
        "mesh      {} triangles, {} vertices, area {:.2} mm², volume {:.2} mm³",
        r.triangles,
        r.vertices,
        r.area,
        r.volume.unwrap_or(f64::NAN)
    );
    if let Some(b) = r.bounding_box {
        outln!(
            "bounds    [{:.3}, {:.3}, {:.3}] – [{:.3}, {:.3}, {:.3}] mm",
            b.min[0],
            b.min[1],
            b.min[2],
            b.max[0],
            b.max[1],
            b.max[2]
        );
    }
    let f = &r.fragments;
    outln!(
        "pieces    {}",
        match r.one_piece {
            None => "not checked (meshed in tiles without a template of its cells)".to_string(),
            Some(true) if f.count == 0 => "one".to_string(),
            Some(true) => format!(
                "one ({} fragment{} cut loose by the box removed, {:.3} mm³)",
                f.count,
                if f.count == 1 { "" } else { "s" },
                f.volume
            ),
            Some(false) => format!(
                "{} ({} fragment{} kept, {:.3} mm³)",
                f.count + 1,
                f.count,
                if f.count == 1 { "" } else { "s" },
                f.volume
            ),
        }
    );
    outln!("CGAL      {}", cgal_findings(&r.checks));
    let t = &r.timings;
    outln!(
        "time      {:.3} s (calibrate {:.3}, sample {:.3}, mesh {:.3}, snap {:.3}, verify {:.3}, write {:.3})",
        t.total, t.calibrate, t.sample, t.mesh, t.snap, t.verify, t.write
    );
    if let Some(o) = &r.output {
        outln!("wrote     {o}");
    }
}
