//! What the lattice commands (`tpms`, `strut`) share: the box of cells, the meshing and output
//! options, writing the part atomically with its report, and the summary of the part written.

use super::out::outln;
use super::{
    cgal_findings, parse_counts, parse_finite3, parse_positive3, parse_size, parse_tile,
    parse_unit, write_json,
};
use clap::Args;
use latvox::field::density::DensityField;
use latvox::field::Domain;
use latvox::io::sink::MeshSink;
use latvox::mesh::graded::{Grading, GradingReport};
use latvox::mesh::output::MeshFile;
use latvox::mesh::pipeline::{Options, Tolerance};
use latvox::mesh::report::PartReport;
use latvox::verify::Verify;
use latvox::{Error, Result};
use std::path::PathBuf;

/// A density that varies through the part.
#[derive(Args, Clone)]
pub struct GradeArgs {
    /// Grade the density linearly along an axis across the box: AXIS:A:B (as z:0.1:0.4); every
    /// whole cell meets the grade at its centre within ±0.01.
    #[arg(long, value_name = "AXIS:A:B", conflicts_with = "density_field")]
    pub density_grade: Option<String>,
    /// Grade the density by a field: an expression in x, y, z (mm; as "0.15 + 0.1*sin(PI*x/20)";
    /// for fill also d, the depth below the skin), a .npy array of shape (NX, NY, NZ) sampled
    /// over the box, corners on its corners, or a .vdb's float grid (named density, or the
    /// first) in the part's coordinates, read between its voxels' centres.
    #[arg(
        long,
        value_name = "EXPR|FILE.npy|FILE.vdb",
        allow_hyphen_values = true
    )]
    pub density_field: Option<String>,
    /// Grade by stiffness: a field (as --density-field takes) of the Young's modulus wanted,
    /// relative to the solid's (E/Es, the mean along the axes); each point's density is the one
    /// at which the lattice's unit cell, homogenised (`latvox homogenize`), is that stiff. With
    /// --clamp, stiffnesses beyond those of the densities homogenised (TPMS: 0.05 or the least
    /// that holds together to 0.8; struts 0.03 to 0.6) take those densities.
    #[arg(
        long,
        value_name = "EXPR|FILE.npy|FILE.vdb",
        allow_hyphen_values = true,
        conflicts_with_all = ["density_grade", "density_field"]
    )]
    pub stiffness_field: Option<String>,
    /// Hold a density field to the type's feasible range instead of refusing it (reported).
    #[arg(long)]
    pub clamp: bool,
}

impl GradeArgs {
    /// Whether a grading is asked for.
    pub fn is_graded(&self) -> bool {
        self.density_grade.is_some()
            || self.density_field.is_some()
            || self.stiffness_field.is_some()
    }

    /// The grading asked for over `bounds`, if any; `cell` is the lattice's unit cell, for a
    /// stiffness field.
    pub fn grading(
        &self,
        bounds: &latvox::field::Aabb,
        cell: impl FnOnce() -> Result<latvox::homogenize::Cell>,
    ) -> Result<Option<Grading>> {
        let field = match (&self.density_grade, &self.density_field, &self.stiffness_field) {
            (Some(g), _, _) => DensityField::grade(g, bounds)?,
            (None, Some(f), _) => field(f, bounds)?,
            (None, None, Some(f)) => {
                let stiffness = named_field(f, bounds, "stiffness")?;
                let cell = cell()?;
                let table = latvox::homogenize::stiffness_table(
                    &cell,
                    &latvox::progress::Progress::hidden(),
                )?;
                let source = format!(
                    "stiffness {} (E/Es) through the homogenised {}'s stiffness at densities {:.3} to {:.3}{}",
                    stiffness.source,
                    cell.lattice.name(None),
                    table[0].1,
                    table[table.len() - 1].1,
                    if self.clamp { ", held to them" } else { "" }
                );
                DensityField::through(stiffness, table, self.clamp, source)?
            }
            (None, None, None) if self.clamp => {
                return Err(Error::invalid(
                    "--clamp holds a density field (--density-grade, --density-field or --stiffness-field) to the feasible range: give one",
                ))
            }
            (None, None, None) => return Ok(None),
        };
        Ok(Some(Grading {
            field: std::sync::Arc::new(field),
            clamp: self.clamp,
        }))
    }
}

/// A field over `bounds`: an expression, a `.npy` array spanning it, or a `.vdb`'s grid.
pub(crate) fn field(spec: &str, bounds: &latvox::field::Aabb) -> Result<DensityField> {
    named_field(spec, bounds, "density")
}

/// [`field`] for a field that gives `noun` (a density, a cell size), named so in messages.
pub(crate) fn named_field(
    spec: &str,
    bounds: &latvox::field::Aabb,
    noun: &str,
) -> Result<DensityField> {
    if spec.to_ascii_lowercase().ends_with(".vdb") {
        let (nodes, name) = latvox::grid::read_values(std::path::Path::new(spec))?;
        return Ok(DensityField::nodes(
            nodes,
            format!("grid '{name}' of {spec}"),
        ));
    }
    DensityField::parse_named(spec, bounds, noun)
}

/// The density line of a graded part's summary; `cells` names what the density is met in
/// ("whole cells").
pub fn print_grading(g: &GradingReport, p: &PartReport, cells: &str) {
    outln!(
        "density   {} ({:.3} to {:.3}) · {} {cells} {} (largest error {:.4}) · part {:.4}",
        g.field,
        g.range[0],
        g.range[1],
        g.whole_cells,
        if g.cells_met {
            "within their promise"
        } else {
            "NOT all within their promise"
        },
        g.max_cell_error,
        p.achieved_density
    );
}

/// The box: two of cells, cell size and overall size, and the lower corner.
#[derive(Args, Clone)]
pub struct BoxArgs {
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
}

impl BoxArgs {
    /// The box the options give (4×4×4 cells of 5 mm by default).
    pub fn domain(&self) -> Result<Domain> {
        let o = self.origin;
        match (self.cells, self.cell_size, self.size) {
            (Some(n), Some(c), None) => Domain::from_cells(n, c, o),
            (Some(n), None, Some(s)) => Domain::from_size_and_cells(s, n, o),
            (None, Some(c), Some(s)) => Domain::from_size_and_cell(s, c, o),
            (Some(n), None, None) => Domain::from_cells(n, [5.0; 3], o),
            (None, Some(c), None) => Domain::from_cells([4; 3], c, o),
            (None, None, None) => Domain::from_cells([4; 3], [5.0; 3], o),
            (None, None, Some(_)) => Err(Error::invalid("--size needs --cells or --cell-size")),
            (Some(_), Some(_), Some(_)) => Err(Error::invalid(
                "give two of --cells, --cell-size, --size, not all three",
            )),
        }
    }
}

/// Part files: the settings of a part saved, or given back.
#[derive(Args, Clone)]
pub struct PartArgs {
    /// Save the settings that define this part (all but where its files go) to a TOML part
    /// file, once the part is made.
    #[arg(long, value_name = "FILE.toml")]
    pub save_part: Option<PathBuf>,
    /// Make the part a part file describes (options given here override the file's).
    #[arg(long, value_name = "FILE.toml")]
    pub part: Option<PathBuf>,
}

/// How the part is meshed, checked and written.
#[derive(Args, Clone)]
pub struct MeshArgs {
    /// Voxels per cell along the cell's shortest side.
    #[arg(long, short = 'r', default_value_t = 32, value_parser = clap::value_parser!(u32).range(4..=4096))]
    pub resolution: u32,
    /// Fail instead of raising the resolution when the lattice's members would be too thin
    /// for the voxels.
    #[arg(long)]
    pub fixed_resolution: bool,
    /// Kept for older scripts: simplify within this many voxels, 0 to 1 (0.5: half a voxel);
    /// --tolerance says it in millimetres and wins over it.
    #[arg(long, default_value_t = 0.0, value_parser = parse_unit)]
    pub adaptivity: f64,
    /// Simplify the mesh: the largest distance allowed between it and the exact surface, mm, or
    /// auto. Flat regions get large triangles, curved ones small; every vertex stays on the
    /// surface, the density is kept, and the deviation is measured and reported. Without it
    /// the mesh is uniform (two triangles per voxel the surface crosses): its deviation is
    /// about half a voxel at the box's cut edges and where struts meet. auto keeps to that:
    /// half a voxel (cell / resolution / 2, 0.078 mm for 5 mm cells at 32), or the deviation
    /// measured on the uniform mesh where larger, with 7–30× fewer triangles. A tolerance under
    /// the uniform mesh's deviation meshes the part on voxels up to half as large first. The
    /// part is then meshed whole (not copied cell by cell, nor in tiles).
    #[arg(long, value_name = "MM|auto", value_parser = Tolerance::parse, allow_hyphen_values = true)]
    pub tolerance: Option<Tolerance>,
    /// Output mesh, in the format its extension names: .stl (binary, ASCII with --ascii) or
    /// .3mf, streamed to the file as it is made; .obj, .off or .ply (binary, ASCII with
    /// --ascii), written once the part is whole; .vdb, the part's level set at its voxels
    /// (OpenVDB, a grid named sdf).
    #[arg(
        long,
        short = 'o',
        value_name = "FILE.stl|.3mf|.obj|.off|.ply|.vdb",
        default_value = "lattice.stl"
    )]
    pub output: PathBuf,
    /// Write ASCII STL (or ASCII PLY) instead of binary.
    #[arg(long)]
    pub ascii: bool,
    /// Write a JSON report (settings, densities, mesh counts, checks, timings).
    #[arg(long, value_name = "FILE.json")]
    pub report: Option<PathBuf>,
    /// How the part is verified: full (closed, manifold, outward and no self-intersection, exact,
    /// on the whole written part), fast (no self-intersection search), none, or cgal (CGAL's own
    /// checks, an independent second opinion, several times slower)
    #[arg(long, value_enum, default_value = "full", value_name = "HOW")]
    pub verify: Verify,
    /// The same as --verify fast.
    #[arg(long, hide = true)]
    pub no_self_intersection_check: bool,
    /// Mesh the whole part at once instead of copying its periodic cells from a meshed
    /// 3×3×3-cell template (slower, same solid; the whole part is then verified).
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

impl MeshArgs {
    /// The pipeline's options.
    pub fn options(&self) -> Options {
        Options {
            adaptivity: self.adaptivity,
            tolerance: self.tolerance,
            verify: if self.no_self_intersection_check && self.verify == Verify::Full {
                Verify::Fast
            } else {
                self.verify
            },
            instancing: !self.no_instancing,
            tile: self.tile,
            memory: self.memory,
            keep_fragments: self.keep_fragments,
        }
    }

    /// Fails on an unwritable report before the work, not after.
    pub fn check_report(&self) -> Result<()> {
        match &self.report {
            Some(r) => latvox::io::atomic::check_writable(r),
            None => Ok(()),
        }
    }

    /// Runs `job` into the output file: a temporary file that becomes the output only once the
    /// job is done; `part` gives the job's report's part, to note the output in.
    pub fn write<R>(
        &self,
        job: impl FnOnce(&mut dyn MeshSink) -> Result<R>,
        part: impl FnOnce(&mut R) -> &mut PartReport,
    ) -> Result<R> {
        latvox::io::atomic::check_writable(&self.output)?;
        let mut sink = MeshFile::new(&self.output, self.ascii)?.sink()?;
        let mut report = job(&mut sink)?;
        let written = part(&mut report);
        sink.set_voxel(written.meshing.voxel_size);
        sink.commit()?;
        written.output = Some(self.output.display().to_string());
        Ok(report)
    }

    /// Writes the JSON report (when asked for) and the warnings; returns the exit code.
    pub fn finish(&self, report: &impl serde::Serialize, part: &PartReport) -> Result<i32> {
        if let Some(r) = &self.report {
            write_json(r, report)?;
        }
        for w in &part.warnings {
            super::out::warning(w);
        }
        Ok(part.verdict().exit_code())
    }
}

/// A number for people: at most `digits` decimals, trailing zeros dropped.
pub(crate) fn human(x: f64, digits: usize) -> String {
    let s = format!("{x:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// A size per axis for people: one number when the three agree.
pub(crate) fn triple(v: [f64; 3]) -> String {
    if v[0] == v[1] && v[1] == v[2] {
        human(v[0], 3)
    } else {
        v.map(|x| human(x, 3)).join("×")
    }
}

/// The summary's lines on the part written: mesh, bounds, pieces, checks, time, file.
/// Writes beams to `out` atomically, after checking it is a writable .3mf: `make` gives the
/// beams once the output is known to be good.
pub(crate) fn write_beams<R>(
    out: &std::path::Path,
    make: impl FnOnce() -> Result<(latvox::io::threemf::BeamModel, R)>,
) -> Result<R> {
    if !out
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("3mf"))
    {
        return Err(latvox::Error::invalid(format!(
            "{}: beams are written to 3MF only: name the output .3mf",
            out.display()
        )));
    }
    latvox::io::atomic::check_writable(out)?;
    let (model, report) = make()?;
    latvox::io::atomic::write_atomic(out, |w| latvox::io::threemf::write_beams(&model, w))?;
    Ok(report)
}

/// The density line of a part made to a density (or with one measured).
pub(crate) fn print_density(p: &PartReport) {
    match p.target_density {
        Some(t) => outln!(
            "density   target {t:.4}  achieved {:.4}  (error {:+.5})",
            p.achieved_density,
            p.density_error.unwrap_or(f64::NAN)
        ),
        None => outln!("density   {:.4}", p.achieved_density),
    }
}

pub(crate) fn print_part(r: &PartReport) {
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
    if let Some(s) = &r.simplified {
        let st = &s.stats;
        outln!(
            "simplified {} of the uniform mesh's {} triangles ({:.1}× fewer); deviation {:.4} mm measured, tolerance {}{}",
            st.triangles_after,
            s.uniform_triangles,
            s.uniform_triangles as f64 / st.triangles_after.max(1) as f64,
            s.deviation,
            if s.auto {
                format!("{:.4} mm (auto)", st.tolerance)
            } else {
                format!("{} mm", st.tolerance)
            },
            if st.gave_up {
                " — not simplified within it: the uniform mesh was written".to_string()
            } else if s.voxel < r.meshing.voxel_size {
                format!(" (meshed on {:.4} mm voxels first)", s.voxel)
            } else {
                String::new()
            }
        );
    }
    let f = &r.fragments;
    let plural = if f.count == 1 { "" } else { "s" };
    outln!(
        "pieces    {}",
        match r.one_piece {
            None => "not checked".to_string(),
            Some(true) if f.count == 0 => "one".to_string(),
            Some(true) => format!(
                "one ({} fragment{plural} cut loose removed, {:.3} mm³)",
                f.count, f.volume
            ),
            Some(false) => format!(
                "{} ({} fragment{plural} kept, {:.3} mm³)",
                f.count + 1,
                f.count,
                f.volume
            ),
        }
    );
    outln!(
        "verified  {}  (by {})",
        cgal_findings(&r.checks),
        r.checks.checked_by
    );
    let t = &r.timings;
    outln!(
        "time      {:.3} s (calibrate {:.3}, sample {:.3}, mesh {:.3}, snap {:.3}{}, verify {:.3}, write {:.3})",
        t.total,
        t.calibrate,
        t.sample,
        t.mesh,
        t.snap,
        if r.simplified.is_some() {
            format!(", simplify {:.3}", t.simplify)
        } else {
            String::new()
        },
        t.verify,
        t.write
    );
    if let Some(o) = &r.output {
        outln!("wrote     {o}");
    }
}
