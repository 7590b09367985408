//! `latvox fgm`: functionally graded material from distance fields — a scan (or a mesh) to a
//! signed distance grid, material fractions graded by the distance to features, and the files a
//! multi-material printer or a simulation takes.

use super::command::{job, parsed, Command, PartKeys};
use super::out::outln;
use super::{cgal_findings, parse_positive, write_json};
use clap::Args;
use latvox::fgm::material::{Composition, Feature, Features, Law};
use latvox::fgm::stack::{StackReport, StackSpec};
use latvox::fgm::{FgmJob, Geometry, Sign};
use latvox::io::ReadOptions;
use latvox::progress::Progress;
use latvox::verify::Verify;
use latvox::{Error, Result};
use std::path::{Path, PathBuf};

pub(crate) const EXAMPLES: &str = "\
Examples:
  # A scanned part (x y z per line, normals estimated), its surface hard and its core soft:
  # the first material follows the law (none at the skin, all of it 4 mm in), the last takes
  # the rest: Rigid at the skin, Flexible inside, a smooth step between; a .vdb for simulation
  # and a coloured mesh to look at
  latvox fgm --points scan.xyz --voxel 0.2 --feature skin --materials Flexible,Rigid \\
      --law step:0:4 --vdb part.vdb -o part.ply

  # The same as PolyJet slices (600 × 300 dpi, 27 µm layers), one material per pixel
  latvox fgm --points scan.xyz --voxel 0.2 --feature skin --materials Flexible,Rigid \\
      --law step:0:4 --png-stack slices --palette '#f0c000,#00a0e0'

  # Graded from a point (a load), three materials, from a mesh: Tough growing by a square law
  # away from the point, Hard fading out over 6 mm from it (a table: rows d, fraction, here
  # 0,1 and 6,0), Soft the rest
  latvox fgm --mesh bracket.stl --voxel 0.25 --feature point:10,0,5 --materials Tough,Hard,Soft \\
      --law power:2 --law table:near.csv --vdb bracket.vdb

  # The inside told by line scans, as the implicit FGM literature does (clean scans only)
  latvox fgm --points clean.ply --voxel 0.5 --sign scan -o part.ply

  # In the plane: a cam's measured profile (x y per line) to a signed distance image (CSV
  # matrix), its outline (SVG) and a picture graded linearly from the profile inward
  latvox fgm --2d --points cam.csv --voxel 0.5 --feature skin -o cam.csv --svg cam.svg \
      --preview cam.png

Geometry: --points reads .xyz/.txt/.csv/.asc/.pts (x y z per line; x y z nx ny nz gives normals)
or .ply (vertex x y z, with nx ny nz when present). Missing normals are estimated by local PCA
and oriented by a minimum spanning tree (Hoppe et al. 1992). Near the scan the signed distance is
the implicit moving-least-squares distance to the points' tangent planes; away from it the sign
is the generalised winding number of the oriented points (Barill et al., \"Fast winding numbers
for soups and clouds\", 2018), which closes holes in a scan instead of leaking (--sign scan:
boundary cells and line scans instead). --mesh takes a closed mesh through OpenVDB's
mesh-to-level-set.

Material: the distance d to the features (the nearest, or the --weights mean); materials but the
last follow their --law, the last takes the rest, so fractions sum to 1 and every iso-surface of
d has one composition. Laws: linear, power:P ((d/dmax)^P, dmax by default the largest d in the
part), step:FROM:TO (a smooth step between two distances, mm), table:FILE.csv (rows d, fraction).

Outputs: -o FILE mesh of the part (.ply with vertex colours mixed from --palette; .3mf with the
Materials extension's composite materials per vertex over base materials; .stl, .obj, .off
geometry only), checked closed and free of self-intersections; --vdb FILE with grids
sdf, distance and one fog grid per material; --png-stack DIR one RGBA picture per layer, each
pixel one material (error diffusion), outside transparent, with stack.json; --preview FILE.png a
section (--preview-z, default mid-height) coloured by composition, with a legend.

--2d: the points are a closed contour in a plane (x y per line; x y nx ny with normals): the
same field in the plane, sampled at the nodes x0 + i·h, y0 + j·h. Outputs: -o FILE.csv the
signed distance image (one row per line, lowest y first), --svg the outline (the zero
iso-line, by marching squares), --preview the image coloured by composition; features
point:X,Y, curve:FILE (x y per line) and skin.";

/// `latvox fgm`.
pub(crate) const COMMAND: Command = Command {
    part: Some(PartKeys {
        own: &[
            "points",
            "2d",
            "mesh",
            "voxel",
            "tolerance",
            "sign",
            "feature",
            "weights",
            "materials",
            "law",
            "dmax",
            "palette",
            "dpi",
            "layer",
        ],
        shared: &[],
    }),
    job: Some(job::<FgmArgs>),
    ..Command::new(
        "fgm",
        "Functionally graded material from distance fields: a scanned point cloud (or a mesh) to a signed distance grid, material fractions graded by the distance to features, and .vdb grids, a coloured mesh and voxel-print PNG stacks",
        EXAMPLES,
        <FgmArgs as clap::Args>::augment_args,
        |m, quiet| run(&parsed(m)?, quiet),
    )
};

impl latvox::batch::Task for FgmArgs {
    fn outputs(&self) -> Vec<PathBuf> {
        outputs(self)
    }

    fn run(&self) -> Result<latvox::batch::TaskReport> {
        if self.two_d {
            let r = execute_plane(self, &Progress::hidden())?;
            return Ok(latvox::batch::TaskReport {
                report: serde_json::to_value(&r).map_err(|e| Error::invalid(e.to_string()))?,
                passed: true,
                warnings: Vec::new(),
            });
        }
        let r = execute(self, &Progress::hidden())?;
        let verdict = r.checks.verdict();
        latvox::batch::TaskReport::new(&r, &verdict, Vec::new())
    }
}

/// Default colours, one per material in order.
const PALETTE: [[u8; 3]; 6] = [
    [0, 160, 224],
    [240, 192, 0],
    [220, 40, 80],
    [40, 40, 40],
    [245, 245, 245],
    [60, 180, 90],
];

#[derive(Args)]
pub struct FgmArgs {
    /// The part as a scanned point cloud: .xyz, .txt, .csv, .asc, .pts or .ply.
    #[arg(
        long,
        value_name = "FILE",
        required_unless_present = "mesh",
        conflicts_with = "mesh"
    )]
    pub points: Option<PathBuf>,
    /// The points are a closed contour in a plane (x y per line): a signed distance image.
    #[arg(long = "2d", requires = "points")]
    pub two_d: bool,
    /// The part as a closed mesh (.stl, .obj, .off, .ply, .3mf).
    #[arg(long, value_name = "FILE")]
    pub mesh: Option<PathBuf>,
    /// Voxel edge, mm (default: the part's longest side / 128).
    #[arg(long, value_name = "MM", value_parser = parse_positive, allow_hyphen_values = true)]
    pub voxel: Option<f64>,
    /// Simplify the part's mesh within this distance of its surface, mm (of the input mesh with
    /// --mesh; of the surface meshed from a scan's distance field): large triangles where it is
    /// flat, the volume kept, the deviation measured and reported. Default: the uniform mesh,
    /// two triangles per voxel the surface crosses.
    #[arg(long, value_name = "MM", value_parser = parse_positive, allow_hyphen_values = true)]
    pub tolerance: Option<f64>,
    /// How a scan's inside is told from its outside away from the points.
    #[arg(long, value_enum, default_value = "winding")]
    pub sign: Sign,
    /// A feature the composition is graded from: point:X,Y,Z, curve:FILE.csv (a polyline),
    /// surface:FILE.stl, or skin (the part's surface); repeat for several.
    #[arg(long, value_name = "KIND[:ARG]", default_values_t = vec!["skin".to_string()])]
    pub feature: Vec<String>,
    /// One weight per feature: the distance is their weighted mean (default: the nearest).
    #[arg(long, value_name = "W,W,…")]
    pub weights: Option<String>,
    /// The materials' names, comma-separated (they name the .vdb grids).
    #[arg(long, value_name = "A,B[,C…]", default_value = "A,B")]
    pub materials: String,
    /// A material's law, in the materials' order (the last material takes the rest): linear,
    /// power:P, step:FROM:TO or table:FILE.csv; repeat per material.
    #[arg(long, value_name = "LAW", default_values_t = vec!["linear".to_string()])]
    pub law: Vec<String>,
    /// The distance at which a power law reaches 1, mm (default: the largest in the part).
    #[arg(long, value_name = "MM", value_parser = parse_positive, allow_hyphen_values = true)]
    pub dmax: Option<f64>,
    /// Colours per material, #RRGGBB comma-separated (meshes' vertex colours, PNG stacks).
    #[arg(long, value_name = "#RGB,#RGB,…")]
    pub palette: Option<String>,
    /// The part's mesh: .ply (vertex colours), .3mf (composite materials per vertex), .stl,
    /// .obj or .off, or its level set alone, .vdb [default: fgm.ply]; with --2d, the signed distance image, .csv [default:
    /// fgm.csv].
    #[arg(long, short = 'o', value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// With --2d: the outline (the zero iso-line) as SVG.
    #[arg(long, value_name = "FILE.svg", requires = "two_d")]
    pub svg: Option<PathBuf>,
    /// A .vdb with grids sdf, distance and one per material.
    #[arg(long, value_name = "FILE.vdb")]
    pub vdb: Option<PathBuf>,
    /// A folder of voxel-print PNG layers (replaced whole).
    #[arg(long, value_name = "DIR")]
    pub png_stack: Option<PathBuf>,
    /// Resolution of the PNG layers, dots per inch: X or XxY.
    #[arg(long, value_name = "X[xY]", default_value = "600x300")]
    pub dpi: String,
    /// Layer thickness of the PNG stack, mm.
    #[arg(long, value_name = "MM", default_value_t = 0.027, value_parser = parse_positive, allow_hyphen_values = true)]
    pub layer: f64,
    /// A picture: a horizontal section coloured by composition, with a legend.
    #[arg(long, value_name = "FILE.png")]
    pub preview: Option<PathBuf>,
    /// The preview's section height, mm (default: the part's mid-height).
    #[arg(long, value_name = "Z", allow_hyphen_values = true)]
    pub preview_z: Option<f64>,
    /// How the part's mesh is verified: full, fast, none or cgal.
    #[arg(long, value_enum, default_value = "full", value_name = "HOW")]
    pub verify: Verify,
    /// Write a JSON report.
    #[arg(long, value_name = "FILE.json")]
    pub report: Option<PathBuf>,
    /// Print the report as JSON instead of the summary.
    #[arg(long)]
    pub json: bool,
    /// Part files.
    #[command(flatten)]
    pub part_file: super::lattice::PartArgs,
}

/// The report of an `fgm` run.
#[derive(serde::Serialize)]
pub struct FgmReport {
    input: String,
    geometry: latvox::fgm::job::GeometryReport,
    features: Vec<&'static str>,
    composition: Composition,
    dmax: f64,
    shares: Vec<f64>,
    triangles: usize,
    vertices: usize,
    volume: Option<f64>,
    /// The part mesh's verification (the job's verdict).
    pub checks: latvox::verify::cgal::Verification,
    simplified: Option<latvox::mesh::simplify::Simplified>,
    stack: Option<StackReport>,
    outputs: Vec<String>,
    timings: serde_json::Map<String, serde_json::Value>,
}

fn parse_palette(s: &str) -> Result<Vec<[u8; 3]>> {
    s.split(',')
        .map(|c| {
            let h = c.trim().trim_start_matches('#');
            let ok = h.len() == 6 && h.chars().all(|c| c.is_ascii_hexdigit());
            if !ok {
                return Err(Error::invalid(format!(
                    "palette colour '{c}' is not #RRGGBB"
                )));
            }
            let v = |i: usize| u8::from_str_radix(&h[i..i + 2], 16).unwrap_or(0);
            Ok([v(0), v(2), v(4)])
        })
        .collect()
}

fn parse_dpi(s: &str) -> Result<[f64; 2]> {
    let parts: Vec<&str> = s.split(['x', 'X']).collect();
    let v: Vec<f64> = parts
        .iter()
        .map(|p| {
            p.trim()
                .parse::<f64>()
                .ok()
                .filter(|v| *v > 0.0 && v.is_finite())
        })
        .collect::<Option<_>>()
        .ok_or_else(|| Error::invalid(format!("--dpi '{s}': give X or XxY dots per inch")))?;
    match v.as_slice() {
        [x] => Ok([*x, *x]),
        [x, y] => Ok([*x, *y]),
        _ => Err(Error::invalid(format!(
            "--dpi '{s}': give X or XxY dots per inch"
        ))),
    }
}

impl FgmArgs {
    fn features(&self) -> Result<Features> {
        let list = self
            .feature
            .iter()
            .map(|f| Feature::parse(f, self.two_d))
            .collect::<Result<Vec<_>>>()?;
        let weights = match &self.weights {
            None => None,
            Some(w) => {
                let v: Vec<f64> = w
                    .split(',')
                    .map(|x| {
                        x.trim()
                            .parse::<f64>()
                            .ok()
                            .filter(|v| *v >= 0.0 && v.is_finite())
                    })
                    .collect::<Option<_>>()
                    .ok_or_else(|| Error::invalid(format!("--weights '{w}': give numbers ≥ 0")))?;
                if v.len() != list.len() || v.iter().sum::<f64>() <= 0.0 {
                    return Err(Error::invalid(format!(
                        "--weights: {} weights (not all 0) for {} features",
                        v.len(),
                        list.len()
                    )));
                }
                Some(v)
            }
        };
        Ok(Features { list, weights })
    }

    /// The job the options describe (reads the input files).
    pub fn job(&self) -> Result<FgmJob> {
        let materials: Vec<String> = self
            .materials
            .split(',')
            .map(|m| m.trim().to_string())
            .collect();
        let laws = self
            .law
            .iter()
            .map(|l| Law::parse(l))
            .collect::<Result<Vec<_>>>()?;
        let composition = Composition::new(materials, laws)?;
        let features = self.features()?;
        let (geometry, input_name, bounds) = match (&self.points, &self.mesh) {
            (Some(p), _) => {
                let cloud = match self.two_d {
                    true => latvox::io::points::read_plane(p)?,
                    false => latvox::io::points::read(p)?,
                };
                if cloud.points.is_empty() {
                    return Err(Error::invalid(format!("{}: no points", p.display())));
                }
                let mut lo = [f64::INFINITY; 3];
                let mut hi = [f64::NEG_INFINITY; 3];
                for q in &cloud.points {
                    for a in 0..3 {
                        lo[a] = lo[a].min(q[a]);
                        hi[a] = hi[a].max(q[a]);
                    }
                }
                let geometry = match self.two_d {
                    true => Geometry::Contour(cloud),
                    false => Geometry::Points(cloud),
                };
                (geometry, p.display().to_string(), (lo, hi))
            }
            (None, Some(m)) => {
                let mesh = latvox::mesh::part::read(m, &ReadOptions::default())?.mesh;
                let b = mesh
                    .bounds()
                    .ok_or_else(|| Error::invalid(format!("{}: no triangles", m.display())))?;
                (
                    Geometry::Mesh(mesh),
                    m.display().to_string(),
                    (b.min, b.max),
                )
            }
            (None, None) => {
                return Err(Error::invalid(
                    "give the part: --points FILE or --mesh FILE",
                ))
            }
        };
        let longest = (0..3)
            .map(|a| bounds.1[a] - bounds.0[a])
            .fold(0.0, f64::max);
        let voxel = self.voxel.unwrap_or(longest / 128.0);
        if voxel.is_nan() || voxel <= 0.0 {
            return Err(Error::invalid("the part has no extent: give --voxel"));
        }
        Ok(FgmJob {
            geometry,
            input_name,
            voxel,
            sign: self.sign,
            features,
            composition,
            dmax: self.dmax,
            verify: self.verify,
            tolerance: self.tolerance,
        })
    }

    fn palette(&self, n: usize) -> Result<Vec<[u8; 3]>> {
        let p = match &self.palette {
            Some(s) => parse_palette(s)?,
            None => PALETTE.iter().cycle().take(n).copied().collect(),
        };
        if p.len() != n {
            return Err(Error::invalid(format!(
                "--palette: {} colours for {n} materials",
                p.len()
            )));
        }
        Ok(p)
    }
}

/// Writes `mesh` with its composition: vertex colours in PLY, composite materials in 3MF,
/// geometry alone in the other formats (`.vdb`: the level set at the job's voxels).
fn write_mesh(
    path: &Path,
    fgm: &latvox::fgm::Fgm,
    job: &FgmJob,
    palette: &[[u8; 3]],
) -> Result<()> {
    use latvox::io::Format;
    use latvox::mesh::output::{MeshFile, Written};
    let file = MeshFile::new(path, false)?.with_voxel(job.voxel);
    match file.written {
        Written::Mesh(Format::Ply) => latvox::io::atomic::write_atomic(path, |w| {
            let colours: Vec<[u8; 3]> = fgm
                .vertex_fractions(&job.features)
                .iter()
                .map(|f| latvox::fgm::job::mix(f, palette))
                .collect();
            latvox::io::ply::write_coloured(&fgm.mesh, &colours, w)
        }),
        Written::Mesh(Format::ThreeMf) => latvox::io::atomic::write_atomic(path, |w| {
            let fractions = fgm.vertex_fractions(&job.features);
            let c = latvox::io::threemf::Composites {
                names: &fgm.composition.materials,
                colours: palette,
                fractions: &fractions,
            };
            latvox::io::threemf::write_composites(&fgm.mesh, &c, w)
        }),
        _ => file.save(&fgm.mesh),
    }
}

impl FgmArgs {
    /// The main output: `-o`, or its default.
    pub fn output(&self) -> PathBuf {
        let default = if self.two_d { "fgm.csv" } else { "fgm.ply" };
        self.output.clone().unwrap_or_else(|| default.into())
    }
}

/// The files a run writes.
pub fn outputs(a: &FgmArgs) -> Vec<PathBuf> {
    let mut v = vec![a.output()];
    v.extend(a.svg.clone());
    v.extend(a.vdb.clone());
    v.extend(a.png_stack.clone());
    v.extend(a.preview.clone());
    v
}

pub fn run(a: &FgmArgs, quiet: bool) -> Result<i32> {
    let progress = Progress::new(quiet || a.json);
    if let Some(r) = &a.report {
        latvox::io::atomic::check_writable(r)?;
    }
    if a.two_d {
        let report = execute_plane(a, &progress)?;
        if let Some(r) = &a.report {
            write_json(r, &report)?;
        }
        match a.json {
            true => super::out::json(&report),
            false => print_plane_summary(&report),
        }
        return Ok(0);
    }
    let report = execute(a, &progress)?;
    if let Some(r) = &a.report {
        write_json(r, &report)?;
    }
    if a.json {
        super::out::json(&report);
    } else {
        print_summary(&report);
    }
    Ok(report.checks.verdict().exit_code())
}

/// The report of an `fgm --2d` run.
#[derive(serde::Serialize)]
pub struct PlaneReport {
    input: String,
    geometry: latvox::fgm::job::GeometryReport,
    /// Nodes of the signed distance image along x and y.
    image: [usize; 2],
    /// The node (0, 0), mm.
    origin: [f64; 2],
    features: Vec<&'static str>,
    composition: Composition,
    dmax: f64,
    shares: Vec<f64>,
    /// The outline's loops and the area they enclose, mm².
    loops: usize,
    area: f64,
    outputs: Vec<String>,
    timings: serde_json::Map<String, serde_json::Value>,
}

/// Makes a plane contour's signed distance image and writes its files.
pub fn execute_plane(a: &FgmArgs, progress: &Progress) -> Result<PlaneReport> {
    let output = a.output();
    let ext = output
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    if ext.as_deref() != Some("csv") {
        return Err(Error::invalid(format!(
            "{}: with --2d, -o is the signed distance image, a .csv (the outline: --svg)",
            output.display()
        )));
    }
    for (given, what) in [
        (a.vdb.is_some(), "--vdb"),
        (a.png_stack.is_some(), "--png-stack"),
        (a.preview_z.is_some(), "--preview-z"),
    ] {
        if given {
            return Err(Error::invalid(format!(
                "{what} makes no sense for a plane contour (--2d)"
            )));
        }
    }
    latvox::io::atomic::check_writable(&output)?;
    for p in a.svg.iter().chain(&a.preview) {
        latvox::io::atomic::check_writable(p)?;
    }
    let job = a.job()?;
    let palette = a.palette(job.composition.materials.len())?;
    let part = job.run_plane(progress)?;
    let mut timings = serde_json::Map::new();
    for (k, v) in &part.timings {
        timings.insert(k.to_string(), (*v).into());
    }
    let t = std::time::Instant::now();
    latvox::io::atomic::write_atomic(&output, |w| part.write_csv(w))?;
    let mut outputs = vec![output.display().to_string()];
    if let Some(p) = &a.svg {
        latvox::io::atomic::write_atomic(p, |w| part.write_svg(w))?;
        outputs.push(p.display().to_string());
    }
    if let Some(p) = &a.preview {
        part.write_preview(p, &palette)?;
        outputs.push(p.display().to_string());
    }
    timings.insert("write".into(), t.elapsed().as_secs_f64().into());
    Ok(PlaneReport {
        input: job.input_name.clone(),
        geometry: part.geometry.clone(),
        image: part.size,
        origin: part.origin,
        features: job.features.list.iter().map(|f| f.name()).collect(),
        composition: part.composition.clone(),
        dmax: part.dmax,
        shares: part.shares(),
        loops: part.loops.len(),
        area: part.area(),
        outputs,
        timings,
    })
}

/// The summary's material line: the features, d_max and each material's share (by `by`).
fn print_material(features: &[&str], c: &Composition, dmax: f64, shares: &[f64], by: &str) {
    let shares: Vec<String> = c
        .materials
        .iter()
        .zip(shares)
        .map(|(m, s)| format!("{m} {:.1} %", 100.0 * s))
        .collect();
    outln!(
        "material  graded from {} · d_max {dmax:.4} mm · by {by} {}",
        features.join(" + "),
        shares.join(", ")
    );
}

fn print_plane_summary(r: &PlaneReport) {
    let g = &r.geometry;
    outln!(
        "{}: contour of {} points, spacing {:.4} mm, normals {} · inside by {}",
        r.input,
        g.points.unwrap_or(0),
        g.point_spacing.unwrap_or(0.0),
        if g.normals_estimated == Some(true) {
            "estimated"
        } else {
            "from the file"
        },
        match g.sign {
            Some(Sign::Scan) => "line scans",
            _ => "winding numbers",
        }
    );
    outln!(
        "image     {} × {} nodes, h = {} mm, from ({:.4}, {:.4})",
        r.image[0],
        r.image[1],
        g.voxel,
        r.origin[0],
        r.origin[1]
    );
    print_material(&r.features, &r.composition, r.dmax, &r.shares, "area");
    outln!("outline   {} loop(s), area {:.3} mm²", r.loops, r.area);
    for o in &r.outputs {
        outln!("wrote     {o}");
    }
}

/// Makes the part and writes its files; returns the report, for `run` to print and `latvox
/// batch` to record.
pub fn execute(a: &FgmArgs, progress: &Progress) -> Result<FgmReport> {
    let output = a.output();
    if a.svg.is_some() {
        return Err(Error::invalid(
            "--svg is the outline of a plane contour (--2d)",
        ));
    }
    latvox::io::atomic::check_writable(&output)?;
    // The output's extension is refused before the work, not after.
    latvox::mesh::output::MeshFile::new(&output, false)?;
    for p in a.vdb.iter().chain(&a.preview) {
        latvox::io::atomic::check_writable(p)?;
    }
    if let Some(dir) = &a.png_stack {
        if dir.exists() && !dir.is_dir() {
            return Err(Error::invalid(format!(
                "{}: exists and is not a folder",
                dir.display()
            )));
        }
        // The folder is filled beside where it goes, then renamed: its parent must take files.
        latvox::io::atomic::check_writable(&dir.with_extension("latvox-probe"))?;
    }
    let dpi = parse_dpi(&a.dpi)?;
    let job = a.job()?;
    let palette = a.palette(job.composition.materials.len())?;
    let fgm = job.run(progress)?;
    let mut outputs = Vec::new();
    let mut timings = serde_json::Map::new();
    for (k, v) in &fgm.timings {
        timings.insert(k.to_string(), (*v).into());
    }
    // Whatever can be refused is refused before the first file is made.
    let spec = StackSpec {
        dpi,
        layer: a.layer,
        palette: palette.clone(),
    };
    if a.png_stack.is_some() {
        latvox::fgm::stack::plan(&fgm, &spec)?;
    }
    if a.preview.is_some() {
        latvox::fgm::preview::section_height(&fgm, a.preview_z)?;
    }
    let t = std::time::Instant::now();
    if let Some(p) = &a.preview {
        latvox::fgm::preview::write(&fgm, p, &palette, a.preview_z)?;
    }
    write_mesh(&output, &fgm, &job, &palette)?;
    outputs.push(output.display().to_string());
    if let Some(v) = &a.vdb {
        let _s = progress.stage("write .vdb");
        fgm.write_vdb(v)?;
        outputs.push(v.display().to_string());
    }
    outputs.extend(a.preview.iter().map(|p| p.display().to_string()));
    timings.insert("write".into(), t.elapsed().as_secs_f64().into());
    let stack = match &a.png_stack {
        Some(dir) => {
            let t = std::time::Instant::now();
            let r = latvox::fgm::stack::write(&fgm, dir, &spec, progress)?;
            timings.insert("png stack".into(), t.elapsed().as_secs_f64().into());
            outputs.push(dir.display().to_string());
            Some(r)
        }
        None => None,
    };
    let report = FgmReport {
        input: job.input_name.clone(),
        geometry: fgm.geometry.clone(),
        features: job.features.list.iter().map(|f| f.name()).collect(),
        composition: fgm.composition.clone(),
        dmax: fgm.dmax,
        shares: fgm.shares(),
        triangles: fgm.mesh.triangle_count(),
        vertices: fgm.mesh.vertex_count(),
        volume: fgm.checks.volume,
        checks: fgm.checks,
        simplified: fgm.simplified,
        stack,
        outputs,
        timings,
    };
    Ok(report)
}

fn print_summary(r: &FgmReport) {
    let g = &r.geometry;
    match g.points {
        Some(n) => outln!(
            "{}: {} points, spacing {:.4} mm, normals {}{} · inside by {}",
            r.input,
            n,
            g.point_spacing.unwrap_or(0.0),
            if g.normals_estimated == Some(true) {
                "estimated"
            } else {
                "from the file"
            },
            if g.normals_flipped == Some(true) {
                " (flipped outward)"
            } else {
                ""
            },
            match g.sign {
                Some(Sign::Scan) => "line scans",
                _ => "winding numbers",
            }
        ),
        None => outln!("{}: mesh", r.input),
    }
    outln!(
        "grid      voxel {} mm · narrow band {} voxels ({:.1} MB)",
        g.voxel,
        g.band_voxels,
        g.grid_bytes as f64 / 1e6
    );
    print_material(&r.features, &r.composition, r.dmax, &r.shares, "volume");
    outln!(
        "mesh      {} triangles, volume {:.2} mm³",
        r.triangles,
        r.volume.unwrap_or(f64::NAN)
    );
    if let Some(s) = &r.simplified {
        let from = match r.geometry.source {
            "mesh" => "the input mesh",
            _ => "the uniform mesh",
        };
        super::out::simplified(s, "uniform mesh", from);
    }
    outln!(
        "verified  {}  (by {})",
        cgal_findings(&r.checks),
        r.checks.checked_by
    );
    if let Some(s) = &r.stack {
        outln!(
            "stack     {} layers of {} × {} px ({:.4} × {:.4} mm, {} mm layers) · worst layer share error {:.3} %",
            s.layers,
            s.width,
            s.height,
            s.pixel_mm[0],
            s.pixel_mm[1],
            s.layer_mm,
            100.0 * s.worst_layer_error
        );
    }
    for o in &r.outputs {
        outln!("wrote     {o}");
    }
}
