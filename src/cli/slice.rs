//! `latvox slice`: a mesh file cut into layers — CLI, SVG, PNG masks, SL1 — with a per-layer
//! table.

use super::command::{job, parsed, Command};
use super::out::outln;
use super::part::{is_part_file, part_of, Part};
use clap::{Args, ValueEnum};
use latvox::check::CheckOptions;
use latvox::slice::job::{
    slice_file, slice_implicit, validate, FolderFormat, ImplicitPart, Output, SliceOptions,
    SliceReport,
};
use latvox::slice::plan::Rule;
use latvox::Result;
use std::path::PathBuf;

pub(crate) const EXAMPLES: &str = "\
Examples:
  latvox slice part.stl -o part.cli --layer 0.05             # Common Layer Interface, ASCII
  latvox slice part.stl -o part.cli --binary --csv part.csv  # binary CLI and a per-layer table
  latvox slice part.3mf -o layers/ --pixel 0.05              # PNG masks for DLP/SLA + stack.json
  latvox slice part.stl -o part.sl1 --layer 0.05             # PrusaSlicer SL1 archive
  latvox slice part.stl -o part.svg --direction 0,1,1        # SVG stack, tilted build
  latvox slice part.stl --csv p.csv --plot p.png --adaptive area --c 0.1 \\
      --min-layer 0.025 --max-layer 0.2                      # adaptive layers, plotted
  latvox slice part.stl --csv p.csv --adaptive cusp --cusp 0.01
  latvox slice scan.stl -o scan.cli --repair                 # mend an open mesh in memory first
  latvox slice octet.toml -o octet.cli                       # a part file, sliced without a mesh
  latvox slice big.stl -o layers/ --shard 3/8                # one task of a Slurm array

The mesh is checked first: one that is not a closed, outward solid (holes, non-manifold or
inconsistently wound edges, inward shells, T-junctions) is refused with what was found, unless
--repair mends it in memory. Layers are cut at their mid-heights along the build direction;
segments are chained into loops through the mesh's own edges (Minetto et al., Computer-Aided
Design 2017), so a closed solid gives closed loops: outer loops counter-clockwise, holes
clockwise, seen from +direction. In-layer coordinates are x and y for the default +Z build; for
another direction they are two axes across it (stack.json and the JSON report name them).

A part file (.toml, from `latvox tpms|strut|fill --save-part`) is sliced from its implicit solid:
the field is sampled on each layer's plane (every --sample mm, only near the surface) and
contoured by marching squares; nothing is meshed, and a box's sharp cut faces stay sharp. It is
the same part as the mesh `--part FILE -o part.stl` writes: the same level search on the same
voxels finds its level (moved by the slivers the mesh's flat facets cut off the curved surface,
so that it encloses the mesh's volume), and the fragments the box cuts loose, which the mesh
drops, are dropped from every layer. The report gives the density sliced (sum of area times
thickness over the box) beside the part's target.

Outputs by name: .cli (CLI v2.0; z of a layer is its top), .svg (one group per layer), .sl1
(Original Prusa SL1 display, uniform layers only), or a folder (name ending in /, or no
extension): PNG masks at --pixel (or SVG files with --format svg), anti-aliased by exact pixel
coverage. --csv: z (mid-height), thickness, area, perimeter, loops, holes per layer; --plot:
layer thickness and area against height.

Adaptive layers: 'area' keeps a layer while the cross-section area changes by at most C from
the layer below (|S_n - S_n-1| / S_n <= C), halving it otherwise, down to --min-layer; 'cusp'
keeps the stair-step cusp h * |cos(angle between normal and build direction)| under --cusp
(Dolenc and Makela, Computer-Aided Design 1994).

Exit code 0 when every loop closed (and a part file's layers hold its density within 0.002);
1 when some chain could not close (the files are written, the open chains marked: CLI
direction 2, red in SVG) or a part file's layers miss its density (layers too thick for its
cells); 2 on bad input.";

/// `latvox slice`.
pub(crate) const COMMAND: Command = Command {
    job: Some(job::<SliceArgs>),
    ..Command::new(
        "slice",
        "Slice a mesh file, or a part file without meshing it, into layers for printing: CLI (Common Layer Interface), SVG, PNG masks, SL1; uniform or adaptive layers, any build direction",
        EXAMPLES,
        <SliceArgs as clap::Args>::augment_args,
        |m, quiet| run(&parsed(m)?, quiet),
    )
};

impl latvox::batch::Task for SliceArgs {
    fn outputs(&self) -> Vec<PathBuf> {
        outputs(self)
    }

    fn run(&self) -> Result<latvox::batch::TaskReport> {
        let r = execute(self, false, &latvox::progress::Progress::hidden())?;
        Ok(latvox::batch::TaskReport {
            report: serde_json::to_value(&r).map_err(|e| latvox::Error::invalid(e.to_string()))?,
            passed: r.passed(),
            warnings: Vec::new(),
        })
    }
}

/// How adaptive layers are chosen.
#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Adaptive {
    /// By the change of cross-section area between layers (|S_n − S_n−1| / S_n ≤ C).
    Area,
    /// By the stair-step cusp height.
    Cusp,
}

#[derive(Args)]
pub struct SliceArgs {
    /// Mesh file (.stl, .obj, .off, .ply, .3mf), or a part file (.toml, from --save-part):
    /// a part file is sliced from its implicit solid, never meshed.
    #[arg(value_name = "MESH|PART")]
    pub input: PathBuf,
    /// Output: FILE.cli, FILE.svg, FILE.sl1, or a folder (DIR/) of PNG or SVG layers.
    #[arg(short, long, value_name = "PATH")]
    pub output: Option<PathBuf>,
    /// Layer thickness, mm (uniform layers).
    #[arg(long, value_name = "MM", default_value_t = 0.05, value_parser = super::parse_positive)]
    pub layer: f64,
    /// First layer's thickness, mm (uniform layers; default: --layer).
    #[arg(long, value_name = "MM", value_parser = super::parse_positive)]
    pub first_layer: Option<f64>,
    /// Adaptive layers instead of uniform ones.
    #[arg(long, value_enum)]
    pub adaptive: Option<Adaptive>,
    /// Largest relative change of area between layers (--adaptive area).
    #[arg(long, value_name = "C", default_value_t = 0.1, value_parser = super::parse_positive)]
    pub c: f64,
    /// Largest cusp height, mm (--adaptive cusp).
    #[arg(long, value_name = "MM", default_value_t = 0.01, value_parser = super::parse_positive)]
    pub cusp: f64,
    /// Thinnest adaptive layer, mm.
    #[arg(long, value_name = "MM", default_value_t = 0.025, value_parser = super::parse_positive)]
    pub min_layer: f64,
    /// Thickest adaptive layer, mm.
    #[arg(long, value_name = "MM", default_value_t = 0.2, value_parser = super::parse_positive)]
    pub max_layer: f64,
    /// Build direction.
    #[arg(long, value_name = "X,Y,Z", default_value = "0,0,1", value_parser = super::parse_finite3)]
    pub direction: [f64; 3],
    /// Binary CLI rather than ASCII (.cli output).
    #[arg(long)]
    pub binary: bool,
    /// Pixel size of PNG masks, mm (folder output).
    #[arg(long, value_name = "MM", default_value_t = 0.05, value_parser = super::parse_positive)]
    pub pixel: f64,
    /// Sample spacing on each layer for a part file, mm (default: a quarter of the voxel the
    /// part is meshed at, or a 192nd of a cell where that is finer; no coarser than --pixel for
    /// masks).
    #[arg(long, value_name = "MM", value_parser = super::parse_positive)]
    pub sample: Option<f64>,
    /// What a folder output holds.
    #[arg(long, value_enum, default_value = "png")]
    pub format: FolderFormat,
    /// Per-layer table: z, thickness, area, perimeter, loops, holes.
    #[arg(long, value_name = "FILE.csv")]
    pub csv: Option<PathBuf>,
    /// Plot of layer thickness and area against height (PNG).
    #[arg(long, value_name = "FILE.png")]
    pub plot: Option<PathBuf>,
    /// Repair the mesh in memory when it is not a closed, outward solid.
    #[arg(long)]
    pub repair: bool,
    /// Also search for self-intersecting facets (loops cross where facets do).
    #[arg(long)]
    pub self_intersections: bool,
    /// Merge vertices closer than this (mm) when reading.
    #[arg(long, value_name = "MM", default_value_t = 0.0, value_parser = super::parse_length0)]
    pub weld_tolerance: f64,
    /// Slice only this share of the layers, K of N (a folder output; also read from a Slurm
    /// array task's environment).
    #[arg(long, value_name = "K/N")]
    pub shard: Option<String>,
    /// Print the report as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// Also write the JSON report to this file.
    #[arg(long, value_name = "FILE.json")]
    pub report: Option<PathBuf>,
}

impl SliceArgs {
    /// The slicing these arguments ask for; `slurm`: with no --shard, a Slurm array task's
    /// environment names the shard (not for a batch job: the batch shards its jobs).
    pub fn options(&self, slurm: bool) -> Result<SliceOptions> {
        let rule = match self.adaptive {
            None => Rule::Uniform {
                layer: self.layer,
                first: self.first_layer.unwrap_or(self.layer),
            },
            Some(Adaptive::Area) => Rule::Area {
                c: self.c,
                min: self.min_layer,
                max: self.max_layer,
            },
            Some(Adaptive::Cusp) => Rule::Cusp {
                cusp: self.cusp,
                min: self.min_layer,
                max: self.max_layer,
            },
        };
        let output = self
            .output
            .as_deref()
            .map(|p| Output::for_path(p, self.binary, self.pixel, self.format))
            .transpose()?;
        let shard = match &self.shard {
            Some(s) => Some(latvox::batch::shard::Shard::parse(s)?),
            None if slurm => latvox::batch::shard::Shard::from_slurm(|v| std::env::var(v).ok())?,
            None => None,
        };
        Ok(SliceOptions {
            rule,
            direction: self.direction,
            output,
            csv: self.csv.clone(),
            plot: self.plot.clone(),
            shard: shard.map(|s| (s.index, s.count)),
            repair: self.repair,
            check: CheckOptions {
                self_intersections: self.self_intersections,
                tolerance: self.weld_tolerance,
                beam_voxel: None,
            },
        })
    }
}

pub fn run(a: &SliceArgs, quiet: bool) -> Result<i32> {
    let r = execute(a, true, &latvox::progress::Progress::new(quiet))?;
    if !super::emit_json(a.report.as_deref(), a.json, &r)? {
        print_summary(&r);
    }
    Ok(if r.passed() { 0 } else { 1 })
}

/// Slices as `latvox slice` does (the report file written, if asked); `slurm` as for
/// [`SliceArgs::options`].
pub fn execute(
    a: &SliceArgs,
    slurm: bool,
    progress: &latvox::progress::Progress,
) -> Result<SliceReport> {
    let opts = a.options(slurm)?;
    if let Some(r) = &a.report {
        latvox::io::atomic::check_writable(r)?;
    }
    if !is_part_file(&a.input) {
        if a.sample.is_some() {
            return Err(latvox::Error::invalid(
                "--sample is for part files (.toml): a mesh is cut exactly",
            ));
        }
        return slice_file(&a.input, &opts, progress);
    }
    validate(&opts)?;
    let name = a
        .input
        .file_stem()
        .map_or_else(|| "part".into(), |s| s.to_string_lossy().into_owned());
    let spacing = |voxel: f64, cell: f64| {
        a.sample.unwrap_or_else(|| {
            let h = 0.25 * latvox::mesh::pipeline::implicit_step(voxel, cell);
            match &opts.output {
                Some(Output::PngDir { pixel, .. }) => h.min(*pixel),
                Some(Output::Sl1(_)) => h.min(latvox::slice::masks::SL1_DISPLAY.2),
                _ => h,
            }
        })
    };
    let mut r = match part_of(&a.input, latvox::render::Fidelity::Volume)? {
        Part::Block(model) => {
            let field = model.field();
            let volume = model.bounds().volume();
            let part = ImplicitPart {
                field: &*field,
                bounds: model.bounds(),
                h: spacing(model.voxel, model.cell),
                loose: Some((&model.loose, model.voxel)),
                target: model.target,
                fraction: &|v| v / volume,
            };
            let r = slice_implicit(&part, &name, &opts, progress)?;
            SliceReport {
                level: Some(model.level),
                ..r
            }
        }
        Part::Filled(traced) => {
            let lattice = traced.lattice_field();
            let scene = traced.scene(&*lattice, None);
            let part = ImplicitPart {
                field: &scene,
                bounds: traced.bounds,
                h: spacing(traced.voxel, traced.cell),
                loose: Some((&traced.loose, traced.voxel)),
                target: Some(traced.density),
                fraction: &|v| traced.fraction(v),
            };
            let r = slice_implicit(&part, &name, &opts, progress)?;
            SliceReport {
                level: Some(traced.level),
                ..r
            }
        }
    };
    r.input = a.input.display().to_string();
    Ok(r)
}

/// The files a slicing job writes: the layer file (for a folder, its `stack.json`) and the
/// table.
pub fn outputs(a: &SliceArgs) -> Vec<PathBuf> {
    let mut v = Vec::new();
    if let Some(o) = a.options(false).ok().and_then(|o| o.output) {
        v.push(if o.is_folder() {
            o.path().join("stack.json")
        } else {
            o.path().to_path_buf()
        });
    }
    v.extend(a.csv.clone());
    v.extend(a.plot.clone());
    v
}

fn print_summary(r: &SliceReport) {
    let d = r.direction;
    let dir = if d == [0.0, 0.0, 1.0] {
        "+Z".to_string()
    } else {
        format!("({:.4}, {:.4}, {:.4})", d[0], d[1], d[2])
    };
    let (t0, t1) = r.thickness;
    let thick = if (t1 - t0).abs() <= 1e-9 * t1 {
        format!("{t0} mm")
    } else {
        format!("{t0:.4}–{t1:.4} mm")
    };
    outln!(
        "{}: {} facets, {} layers of {thick} along {dir}, heights {:.4} … {:.4} mm",
        r.input,
        r.facets,
        r.layers,
        r.heights[0],
        r.heights[1]
    );
    if !r.repairs.is_empty() {
        let list: Vec<String> = r.repairs.iter().map(|(k, n)| format!("{n} {k}")).collect();
        outln!("repaired  {}", list.join(", "));
    }
    if r.written != (0, r.layers) {
        outln!(
            "shard     layers {} … {} of {}",
            r.written.0,
            r.written.1,
            r.layers
        );
    }
    outln!(
        "loops     {} ({} holes), {} segments{}",
        r.loops,
        r.holes,
        r.segments,
        if r.open_chains > 0 {
            format!(
                "; {} OPEN CHAINS (layers {:?}…): the mesh is not a closed solid there",
                r.open_chains, r.open_layers
            )
        } else {
            String::new()
        }
    );
    if r.self_intersecting == Some(true) {
        outln!("warning   some facets intersect: loops may cross where they do");
    }
    match r.mesh_volume {
        Some(v) if r.written == (0, r.layers) => {
            let rel = (r.layer_volume - v) / v.abs().max(1e-300);
            outln!(
                "volume    Σ area × thickness {:.4} mm³, mesh {v:.4} mm³ ({:+.3} %)",
                r.layer_volume,
                100.0 * rel
            );
        }
        None if r.written == (0, r.layers) => {
            outln!("volume    Σ area × thickness {:.4} mm³", r.layer_volume);
        }
        _ => {}
    }
    match (r.density, r.target_density) {
        (Some(d), Some(t)) => outln!(
            "density   target {t:.4}  sliced {d:.4}  (error {:+.5}{})",
            d - t,
            if r.density_met == Some(false) {
                ", MISSES the promise of ±0.002"
            } else {
                ""
            }
        ),
        (Some(d), None) => outln!("density   sliced {d:.4}"),
        _ => {}
    }
    outln!("wrote     {}", r.outputs.join(", "));
}
