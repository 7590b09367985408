//! Slicing a mesh file, as `latvox slice` and batch jobs do: read it, check that it is a closed,
//! outward solid (or repair it in memory when asked), place the layers, cut them, and stream the
//! sections to the writers a chunk of layers at a time — memory holds one chunk of sections,
//! never the whole stack.

use super::implicit::ImplicitSlicer;
use super::mesh::{HeightIndex, MeshSlicer};
use super::plan::{plan, Rule};
use super::{Frame, Section, Stack, StackWriter};
use crate::check::{check, CheckOptions};
use crate::error::{Error, Result};
use crate::field::{Aabb, Field, Vec3};
use crate::geom::contour::{grow, merge, EMPTY_BOX};
use crate::geom::Mesh;
use crate::mesh::pieces::Loose;
use crate::mesh::pipeline::PROMISE;
use crate::progress::Progress;
use crate::verify::{verify, Verify};
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// Where the layers go.
#[derive(Debug, Clone, PartialEq)]
pub enum Output {
    /// A Common Layer Interface file (ASCII or binary).
    Cli {
        /// The file.
        path: PathBuf,
        /// Binary rather than ASCII.
        binary: bool,
    },
    /// One SVG file, a group per layer.
    Svg(PathBuf),
    /// A folder of SVG files, one per layer.
    SvgDir(PathBuf),
    /// A folder of PNG masks at a pixel size (mm).
    PngDir {
        /// The folder.
        path: PathBuf,
        /// Pixel size, mm.
        pixel: f64,
    },
    /// A PrusaSlicer SL1 archive.
    Sl1(PathBuf),
}

/// What kind of files a folder output holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum FolderFormat {
    /// PNG masks (DLP/SLA).
    Png,
    /// SVG contours.
    Svg,
}

impl Output {
    /// The output for `path` by its name: `.cli` (binary with `binary`), `.svg`, `.sl1`, or a
    /// folder (a name ending in `/`, an existing folder, or a name without extension) of PNG
    /// masks at `pixel` mm or of SVG files.
    pub fn for_path(path: &Path, binary: bool, pixel: f64, folder: FolderFormat) -> Result<Output> {
        let s = path.to_string_lossy();
        let is_dir = s.ends_with('/') || path.is_dir() || path.extension().is_none();
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        let out = if is_dir {
            let p = PathBuf::from(s.trim_end_matches('/'));
            match folder {
                FolderFormat::Png => Output::PngDir { path: p, pixel },
                FolderFormat::Svg => Output::SvgDir(p),
            }
        } else {
            match ext.as_deref() {
                Some("cli") => Output::Cli {
                    path: path.to_path_buf(),
                    binary,
                },
                Some("svg") => Output::Svg(path.to_path_buf()),
                Some("sl1") => Output::Sl1(path.to_path_buf()),
                Some(e) => {
                    return Err(Error::invalid(format!(
                        "{}: unknown output extension '.{e}' (slices are written as .cli, .svg, .sl1 or a folder of PNG or SVG layers)",
                        path.display()
                    )))
                }
                None => unreachable!(),
            }
        };
        if binary && !matches!(out, Output::Cli { .. }) {
            return Err(Error::invalid(format!(
                "{}: --binary applies to .cli files only",
                path.display()
            )));
        }
        Ok(out)
    }

    /// The file or folder written.
    pub fn path(&self) -> &Path {
        match self {
            Output::Cli { path, .. } | Output::PngDir { path, .. } => path,
            Output::Svg(p) | Output::SvgDir(p) | Output::Sl1(p) => p,
        }
    }

    /// Whether the output is a folder of layer files (the only kind a shard can write).
    pub fn is_folder(&self) -> bool {
        matches!(self, Output::SvgDir(_) | Output::PngDir { .. })
    }

    /// Refuses up front what would fail after the work: a folder that cannot be made, a file
    /// that cannot be written.
    pub fn check_writable(&self) -> Result<()> {
        let p = self.path();
        if self.is_folder() {
            if p.exists() && !p.is_dir() {
                return Err(Error::invalid(format!(
                    "{}: exists and is not a folder",
                    p.display()
                )));
            }
            let parent = match p.parent() {
                Some(d) if !d.as_os_str().is_empty() => d,
                _ => Path::new("."),
            };
            if !parent.is_dir() {
                return Err(Error::invalid(format!(
                    "{}: the folder {} does not exist",
                    p.display(),
                    parent.display()
                )));
            }
            Ok(())
        } else {
            crate::io::atomic::check_writable(p)
        }
    }

    fn writer(&self, stack: &Stack, sharded: bool) -> Result<Box<dyn StackWriter>> {
        Ok(match self {
            Output::Cli { path, binary } => Box::new(super::common_layer::CliWriter::create(
                path, stack, *binary,
            )?),
            Output::Svg(p) => Box::new(super::svg::SvgWriter::create(p, stack)?),
            Output::SvgDir(p) => Box::new(super::svg::SvgDirWriter::create(p, stack, sharded)?),
            Output::PngDir { path, pixel } => Box::new(super::masks::PngDirWriter::create(
                path, stack, *pixel, sharded,
            )?),
            Output::Sl1(p) => Box::new(super::masks::Sl1Writer::create(p, stack)?),
        })
    }
}

/// How to slice.
#[derive(Debug, Clone)]
pub struct SliceOptions {
    /// How the layers are placed.
    pub rule: Rule,
    /// Build direction (any length but zero).
    pub direction: Vec3,
    /// The layer files, if any.
    pub output: Option<Output>,
    /// The per-layer CSV table, if asked.
    pub csv: Option<PathBuf>,
    /// The plot of layer thickness and area against height (PNG), if asked.
    pub plot: Option<PathBuf>,
    /// Slice only shard `index` of `count` (from 0): a contiguous run of layers, written into a
    /// shared folder.
    pub shard: Option<(usize, usize)>,
    /// Repair the mesh in memory first; without it, a mesh that is not a closed, outward solid
    /// is refused.
    pub repair: bool,
    /// How the mesh is checked (and read: vertices within the tolerance merge).
    pub check: CheckOptions,
}

/// What slicing did.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SliceReport {
    /// The input, as named.
    pub input: String,
    /// Facets sliced.
    pub facets: u64,
    /// Whether some facets intersect, when looked for (loops may cross where facets do).
    pub self_intersecting: Option<bool>,
    /// Repairs made in memory (kinds and counts), when asked.
    pub repairs: Vec<(String, u64)>,
    /// The build direction, as a unit vector.
    pub direction: Vec3,
    /// How layers were placed.
    pub rule: Rule,
    /// Layers in the whole stack.
    pub layers: usize,
    /// The layers this run wrote (`first..end`; all unless sharded).
    pub written: (usize, usize),
    /// Thinnest and thickest layer, mm.
    pub thickness: (f64, f64),
    /// Lowest and highest heights of the part along the build direction, mm.
    pub heights: [f64; 2],
    /// Facet–plane crossings (segments) in the layers written.
    pub segments: u64,
    /// Closed loops, holes among them, and chains that could not close, over the layers written.
    pub loops: u64,
    /// Clockwise loops (holes).
    pub holes: u64,
    /// Chains that could not close (only from an invalid mesh).
    pub open_chains: u64,
    /// Layers with an open chain (their first few, by index).
    pub open_layers: Vec<usize>,
    /// For a part file: the TPMS level, or the strut radius (mm), of the solid sliced.
    pub level: Option<f64>,
    /// The mesh's enclosed volume, mm³ (none for an implicit part).
    pub mesh_volume: Option<f64>,
    /// Σ area × thickness over the layers written, mm³ (the whole volume, unsharded: a check of
    /// the slices against the mesh).
    pub layer_volume: f64,
    /// For a part file: the density of what was sliced (Σ area × thickness, as the part's
    /// fraction; none for a shard, which slices part of it).
    pub density: Option<f64>,
    /// For a part file made to a density: the density.
    pub target_density: Option<f64>,
    /// Whether the density sliced is within the promise of the target.
    pub density_met: Option<bool>,
    /// The files written.
    pub outputs: Vec<String>,
}

/// Layers cut and written per round: bounds the sections held at once.
const CHUNK: usize = 64;

/// Reads, checks (or repairs) and slices the mesh file `input`.
pub fn slice_file(input: &Path, opts: &SliceOptions, progress: &Progress) -> Result<SliceReport> {
    validate(opts)?;
    let loaded = crate::check::read_file(input, &opts.check, progress)?;
    let name = input
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "part".into());
    let mut report = slice_mesh(&loaded.mesh, &name, opts, progress).map_err(|e| match e {
        Error::Invalid(m) if m.starts_with("the mesh ") => {
            Error::invalid(format!("{}: {}", input.display(), &m["the mesh ".len()..]))
        }
        e => e,
    })?;
    report.input = input.display().to_string();
    Ok(report)
}

/// Refuses bad settings before any work.
pub fn validate(opts: &SliceOptions) -> Result<()> {
    opts.rule.validate()?;
    Frame::new(opts.direction)?;
    if let Some((k, n)) = opts.shard {
        if k >= n {
            return Err(Error::invalid(format!(
                "shard {} of {n} does not exist",
                k + 1
            )));
        }
        if n > 1 && !opts.output.as_ref().is_some_and(Output::is_folder) {
            return Err(Error::invalid(
                "a shard writes its layers into a folder: give -o DIR/ (PNG or SVG layers)",
            ));
        }
        if n > 1 && opts.csv.is_some() {
            return Err(Error::invalid(
                "--csv covers the whole stack: leave it out of sharded runs (slice unsharded for the table)",
            ));
        }
    }
    if let Some(Output::PngDir { pixel, .. }) = &opts.output {
        if !(*pixel > 0.0 && pixel.is_finite()) {
            return Err(Error::invalid(format!(
                "the pixel size must be a positive length in mm, got {pixel}"
            )));
        }
    }
    if opts.output.is_none() && opts.csv.is_none() && opts.plot.is_none() {
        return Err(Error::invalid(
            "nothing to write: give -o FILE (or a folder), --csv FILE.csv or --plot FILE.png",
        ));
    }
    if let Some(o) = &opts.output {
        o.check_writable()?;
    }
    if let Some(c) = &opts.csv {
        crate::io::atomic::check_writable(c)?;
    }
    if let Some(p) = &opts.plot {
        if !p.extension().is_some_and(|e| e.eq_ignore_ascii_case("png")) {
            return Err(Error::invalid(format!(
                "{}: the plot is a PNG picture (name it .png)",
                p.display()
            )));
        }
        if opts.shard.is_some_and(|(_, n)| n > 1) {
            return Err(Error::invalid(
                "--plot covers the whole stack: leave it out of sharded runs",
            ));
        }
        crate::io::atomic::check_writable(p)?;
    }
    Ok(())
}

/// The defects that keep a mesh from being sliced into closed contours, as "N what" phrases.
fn slicing_defects(r: &crate::check::CheckReport) -> Vec<String> {
    let mut v = Vec::new();
    if r.boundary_edges > 0 {
        v.push(format!(
            "open: {} boundary edges in {} holes",
            r.boundary_edges, r.hole_loops
        ));
    }
    for (n, what) in [
        (r.non_manifold_edges, "non-manifold edges"),
        (r.inconsistent_edges, "inconsistently wound edges"),
        (r.inward_shells, "inward-facing shells"),
        (r.non_orientable_shells, "non-orientable shells"),
        (r.t_junctions, "T-junctions"),
        (r.duplicate_facets, "duplicate facets"),
    ] {
        if n > 0 {
            v.push(format!("{n} {what}"));
        }
    }
    v
}

/// Checks (or repairs) and slices `mesh`, named `name` in the files.
pub fn slice_mesh(
    mesh: &Mesh,
    name: &str,
    opts: &SliceOptions,
    progress: &Progress,
) -> Result<SliceReport> {
    validate(opts)?;
    // The linear-time verification of made parts first; the full check (every defect counted)
    // only to say what is wrong with a mesh that fails it.
    let verified = {
        let _s = progress.stage("checking");
        let how = if opts.check.self_intersections {
            Verify::Full
        } else {
            Verify::Fast
        };
        verify(mesh, how, progress)?
    };
    let defects = if verified.closed && verified.manifold && verified.outward {
        Vec::new()
    } else {
        let _s = progress.stage("counting defects");
        let o = CheckOptions {
            self_intersections: false,
            ..opts.check
        };
        let mut d = slicing_defects(&check(mesh, None, &o)?);
        if d.is_empty() {
            d.push("not closed, manifold and facing out".into());
        }
        d
    };
    let mut repairs = Vec::new();
    let repaired;
    let mesh = if defects.is_empty() {
        mesh
    } else if opts.repair {
        let (m, r) = crate::repair::repair(mesh, &Default::default(), progress)?;
        repairs = r
            .changes
            .iter()
            .map(|c| (c.kind.to_string(), c.count))
            .collect();
        repaired = m;
        &repaired
    } else {
        return Err(Error::invalid(format!(
            "the mesh is not a closed, outward solid ({}): slice it with --repair, or mend it with latvox repair",
            defects.join(", ")
        )));
    };
    let frame = Frame::new(opts.direction)?;
    let slicer = MeshSlicer::new(mesh, frame);
    let Some((lo, hi)) = slicer.range() else {
        return Err(Error::invalid("the mesh has no facets"));
    };
    let layers = {
        let _s = progress.stage("placing layers");
        match opts.rule {
            Rule::Uniform { .. } => plan(&opts.rule, lo, hi, &NoProfile)?,
            Rule::Area { min, .. } | Rule::Cusp { min, .. } => {
                let index = HeightIndex::new(&slicer, min);
                plan(&opts.rule, lo, hi, &index)?
            }
        }
    };
    let stack = Stack {
        layers,
        bounds: in_layer_bounds(mesh, &frame),
        heights: [lo, hi],
        frame,
        name: name.to_string(),
    };
    let (first, end) = shard_range(opts, stack.layers.len());
    let zs: Vec<f64> = stack.layers[first..end].iter().map(|l| l.z).collect();
    let buckets = {
        let _s = progress.stage("bucketing facets");
        slicer.buckets(&zs)
    };
    let tally = write_stack(&stack, opts, progress, |k| {
        slicer.section(stack.layers[k].z, buckets.of(k - first))
    })?;
    Ok(SliceReport {
        input: name.to_string(),
        facets: mesh.triangle_count() as u64,
        self_intersecting: verified
            .self_intersection_checked
            .then_some(verified.self_intersecting),
        repairs,
        segments: buckets.len() as u64,
        mesh_volume: Some(mesh.volume()),
        ..SliceReport::new(&stack, opts, tally)
    })
}

/// The layers shard `opts.shard` writes, of `n`: `first..end`.
fn shard_range(opts: &SliceOptions, n: usize) -> (usize, usize) {
    match opts.shard {
        Some((k, count)) => (n * k / count, n * (k + 1) / count),
        None => (0, n),
    }
}

/// What the layers written held.
#[derive(Debug, Clone, Default)]
struct Tally {
    written: (usize, usize),
    loops: u64,
    holes: u64,
    open_chains: u64,
    open_layers: Vec<usize>,
    layer_volume: f64,
}

impl SliceReport {
    /// Whether the layers keep the part's promises: every loop closed, and (for a part file
    /// made to a density) the density sliced within [`PROMISE`] of it.
    pub fn passed(&self) -> bool {
        self.open_chains == 0 && self.density_met != Some(false)
    }

    /// The report of `stack` sliced as `opts` asked, with what was found; the mesh's own
    /// figures left empty.
    fn new(stack: &Stack, opts: &SliceOptions, t: Tally) -> SliceReport {
        SliceReport {
            input: stack.name.clone(),
            facets: 0,
            self_intersecting: None,
            repairs: Vec::new(),
            direction: stack.frame.d,
            rule: opts.rule,
            layers: stack.layers.len(),
            written: t.written,
            thickness: stack.layers.iter().fold((f64::INFINITY, 0.0f64), |a, l| {
                (a.0.min(l.thickness), a.1.max(l.thickness))
            }),
            heights: stack.heights,
            segments: 0,
            loops: t.loops,
            holes: t.holes,
            open_chains: t.open_chains,
            open_layers: t.open_layers,
            level: None,
            mesh_volume: None,
            layer_volume: t.layer_volume,
            density: None,
            target_density: None,
            density_met: None,
            outputs: opts
                .output
                .iter()
                .map(|o| o.path().display().to_string())
                .chain(opts.csv.iter().map(|c| c.display().to_string()))
                .chain(opts.plot.iter().map(|c| c.display().to_string()))
                .collect(),
        }
    }
}

/// Cuts the layers of this shard with `section` (layer index → its section) a chunk at a time,
/// in parallel, and streams them to the writers `opts` asks for.
fn write_stack(
    stack: &Stack,
    opts: &SliceOptions,
    progress: &Progress,
    section: impl Fn(usize) -> Section + Sync,
) -> Result<Tally> {
    let layers = &stack.layers;
    let (first, end) = shard_range(opts, layers.len());
    let sharded = opts.shard.is_some_and(|(_, n)| n > 1);
    let mut writers: Vec<Box<dyn StackWriter>> = Vec::new();
    if let Some(o) = &opts.output {
        writers.push(o.writer(stack, sharded)?);
    }
    if let Some(c) = &opts.csv {
        writers.push(Box::new(super::csv::CsvWriter::create(c, stack)?));
    }
    let mut t = Tally {
        written: (first, end),
        ..Tally::default()
    };
    let mut areas = Vec::new();
    let counter = progress.counter((end - first) as u64, "layers");
    for start in (first..end).step_by(CHUNK) {
        let stop = (start + CHUNK).min(end);
        let sections: Vec<Section> = (start..stop).into_par_iter().map(&section).collect();
        for (k, s) in (start..stop).zip(&sections) {
            let m = s.measures();
            t.loops += m.loops as u64;
            t.holes += m.holes as u64;
            t.open_chains += m.open as u64;
            if m.open > 0 && t.open_layers.len() < 16 {
                t.open_layers.push(k);
            }
            t.layer_volume += m.area * layers[k].thickness;
            if opts.plot.is_some() {
                areas.push(m.area);
            }
        }
        for w in writers.iter_mut() {
            let encoded: Vec<Result<Vec<u8>>> = (start..stop)
                .into_par_iter()
                .zip(sections.par_iter())
                .map(|(k, s)| w.encode(k, s))
                .collect();
            for (k, e) in (start..stop).zip(encoded) {
                w.put(k, e?)?;
            }
        }
        for _ in start..stop {
            counter.inc();
        }
    }
    drop(counter);
    let _s = progress.stage("writing");
    for w in writers {
        w.finish()?;
    }
    if let Some(p) = &opts.plot {
        super::plot::write_plot(p, layers, &areas)?;
    }
    Ok(t)
}

/// An implicit part to slice: its field, box and sampling, the fragments its mesh drops, and the
/// density it is made to.
pub struct ImplicitPart<'a> {
    /// The solid, negative inside (nothing outside `bounds`).
    pub field: &'a dyn Field,
    /// The box that clips it.
    pub bounds: Aabb,
    /// Sample spacing on each layer's plane, mm (see [`super::implicit`]).
    pub h: f64,
    /// Fragments whose loops are dropped, as the mesh drops them, and the voxel they were
    /// meshed on (mm).
    pub loose: Option<(&'a Loose, f64)>,
    /// The volume fraction the part is made to, if any.
    pub target: Option<f64>,
    /// The part's volume fraction from its volume, mm³ (its share of the box, or of the
    /// region a filled part's lattice fills).
    pub fraction: &'a (dyn Fn(f64) -> f64 + Sync),
}

/// Slices an implicit part, named `name` in the files; the report gives the density of what
/// was sliced (Σ area × thickness, read as the part's fraction) beside the target.
pub fn slice_implicit(
    part: &ImplicitPart,
    name: &str,
    opts: &SliceOptions,
    progress: &Progress,
) -> Result<SliceReport> {
    validate(opts)?;
    let (bounds, h) = (&part.bounds, part.h);
    if !(h > 0.0 && h.is_finite()) {
        return Err(Error::invalid(format!(
            "the sample spacing must be a positive length in mm, got {h}"
        )));
    }
    if matches!(opts.rule, Rule::Cusp { .. }) {
        return Err(Error::invalid(
            "--adaptive cusp reads the slope of a mesh's facets: slice the meshed part, or use --adaptive area",
        ));
    }
    let frame = Frame::new(opts.direction)?;
    let (plane_bounds, heights) = super::implicit::project(bounds, &frame);
    let mut slicer = ImplicitSlicer::new(part.field, bounds, frame, h);
    if let Some((l, voxel)) = part.loose {
        slicer = slicer.dropping(l, voxel);
    }
    let n = slicer.samples_per_layer();
    if n > super::implicit::MAX_SAMPLES || n.is_nan() {
        return Err(Error::invalid(format!(
            "{h} mm samples make {n:.3e} samples a layer (more than {:.0e}): use a larger --sample",
            super::implicit::MAX_SAMPLES
        )));
    }
    let layers = {
        let _s = progress.stage("placing layers");
        plan(&opts.rule, heights[0], heights[1], &slicer)?
    };
    let stack = Stack {
        layers,
        bounds: plane_bounds,
        heights,
        frame,
        name: name.to_string(),
    };
    let tally = write_stack(&stack, opts, progress, |k| {
        slicer.section(stack.layers[k].z)
    })?;
    let mut report = SliceReport::new(&stack, opts, tally);
    // Only the whole stack measures the part.
    if report.written == (0, report.layers) {
        let d = (part.fraction)(report.layer_volume);
        report.density = Some(d);
        report.target_density = part.target;
        report.density_met = part.target.map(|t| (d - t).abs() <= PROMISE);
    }
    Ok(report)
}

/// The part's in-layer bounds, `[u_min, v_min, u_max, v_max]`.
fn in_layer_bounds(mesh: &Mesh, frame: &Frame) -> [f64; 4] {
    mesh.positions
        .par_chunks_exact(3)
        .map(|p| frame.plane([p[0] as f64, p[1] as f64, p[2] as f64]))
        .fold(|| EMPTY_BOX, grow)
        .reduce(|| EMPTY_BOX, merge)
}

/// The profile of uniform layers: they ask nothing.
struct NoProfile;

impl super::plan::Profile for NoProfile {
    fn area(&self, _z: f64) -> f64 {
        0.0
    }
    fn steepest_cos(&self, _z0: f64, _z1: f64) -> f64 {
        0.0
    }
}
