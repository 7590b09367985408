//! `latvox homogenize`: the effective elasticity tensor of a lattice's periodic unit cell and
//! the engineering constants read off it.

use super::command::{parsed, Command};
use super::out::outln;
use super::tpms::{parse_structure, parse_surface};
use super::{emit_json, parse_density, parse_f64, parse_positive, parse_positive3};
use clap::{Args, ValueEnum};
use latvox::homogenize::{
    self, Amount, Cell, Homogenized, Lattice, Material, Settings, Voxelization,
};
use latvox::lattice::tpms::{Structure, Surface};
use latvox::{Error, Result};
use std::path::PathBuf;
use std::sync::Arc;

pub(crate) const EXAMPLES: &str = "\
Examples:
  # A gyroid net at 20 % of the solid, E and ν relative to the solid's
  latvox homogenize --type gyroid --structure net --density 0.2

  # Dong, Tang & Zhao's grid cell: voxels solid where their centres are, Lamé constants
  latvox homogenize --cell sc --radius 0.1 --voxels 40 --voxelization centres --lame 115.4,79.6

  # An octet cell of Ti-6Al-4V (E = 110 GPa, ν = 0.34, in MPa), the report as JSON
  latvox homogenize --cell octet --density 0.3 --young 110000 --poisson 0.34 --report octet.json

  # The directional Young's modulus of a BCC cell as a picture
  latvox homogenize --cell bcc --density 0.2 --plot bcc-young.png

  # Moduli from 10 % to 50 % and Gibson and Ashby's law fitted to them
  latvox homogenize --type gyroid --structure sheet --densities 0.1:0.5:5 --voxels 32

The tensor is in Voigt order xx, yy, zz, yz, xz, xy with engineering shear strains (γ = 2ε), in
the units of --young. Young's moduli E, shear moduli G and Poisson's ratios ν (ν_xy: strain along y
under stress along x) come from its inverse; Zener's ratio 2·C44/(C11 − C12) is 1 for an isotropic
cubic cell. The cell is voxelised with N voxels along each axis; each voxel is a trilinear
hexahedron of the solid weighing the share of it the solid fills (--voxelization fraction) or 1
where its centre is solid (centres, the published codes' rule); --density is met on the voxels.";

/// `latvox homogenize`.
pub(crate) const COMMAND: Command = Command::new(
    "homogenize",
    "The effective elasticity tensor of a lattice's unit cell (numerical homogenisation)",
    EXAMPLES,
    <HomogenizeArgs as clap::Args>::augment_args,
    |m, quiet| run(&parsed(m)?, quiet),
);

#[derive(Clone, Copy, ValueEnum)]
pub enum VoxelizationArg {
    Fraction,
    Centres,
}

#[derive(Args)]
pub struct HomogenizeArgs {
    /// TPMS surface: p, gyroid (g), d, iwp, s, frd, neovius (n), lidinoid (l), split-p (a
    /// gyroid when neither --type nor --cell is given).
    #[arg(long = "type", short = 't', value_name = "TYPE", value_parser = parse_surface, conflicts_with = "cell")]
    pub surface: Option<Surface>,
    /// Solid side of the TPMS: net (F ≤ t) or sheet (|F| ≤ t).
    #[arg(long, value_name = "net|sheet", default_value = "net", value_parser = parse_structure)]
    pub structure: Structure,
    /// Which labyrinth of a net is solid: first (F ≤ t) or other (−F ≤ t).
    #[arg(long, value_name = "first|other", default_value = "first", value_parser = ["first", "other"])]
    pub side: String,
    /// Strut cell: a built-in name (sc, bcc, bccz, fcc, fccz, octet, kelvin, diamond, rhombic)
    /// or a cell file (.json); struts are capsules (sharp joints).
    #[arg(long, value_name = "NAME|FILE.json")]
    pub cell: Option<String>,
    /// Relative density, in (0, 1], met on the voxels (0.2 when neither --level nor --radius is
    /// given).
    #[arg(long, short = 'd', value_parser = parse_density, allow_hyphen_values = true, conflicts_with_all = ["level", "radius"])]
    pub density: Option<f64>,
    /// Densities to tabulate the moduli over, and fit Gibson and Ashby's law E/Es = C·ρⁿ (and
    /// G) to: A:B:K (K densities from A to B) or a list D1,D2,….
    #[arg(long, value_name = "A:B:K", value_parser = parse_densities, conflicts_with_all = ["density", "level", "radius", "plot"])]
    pub densities: Option<Densities>,
    /// The TPMS level t instead of a density.
    #[arg(long, value_name = "T", value_parser = parse_f64, allow_hyphen_values = true, conflicts_with = "radius")]
    pub level: Option<f64>,
    /// The strut radius in mm (times each node's factor) instead of a density.
    #[arg(long, value_name = "MM", value_parser = parse_positive, allow_hyphen_values = true)]
    pub radius: Option<f64>,
    /// The cell's size in mm: A or AX,AY,AZ.
    #[arg(long, value_name = "MM[,MM,MM]", default_value = "1", value_parser = parse_positive3, allow_hyphen_values = true)]
    pub cell_size: [f64; 3],
    /// Voxels along each axis of the cell.
    #[arg(long, short = 'r', value_name = "N", default_value_t = 40, value_parser = clap::value_parser!(u32).range(4..=512))]
    pub voxels: u32,
    /// How a voxel weighs: the share of it the solid fills, or 1 where its centre is solid.
    #[arg(long, value_enum, default_value = "fraction", value_name = "HOW")]
    pub voxelization: VoxelizationArg,
    /// The solid's Young's modulus (the tensor comes in its units; 1: relative to the solid).
    #[arg(long, value_name = "E", default_value_t = 1.0, value_parser = parse_positive, allow_hyphen_values = true)]
    pub young: f64,
    /// The solid's Poisson's ratio.
    #[arg(long, value_name = "NU", default_value_t = 0.3, value_parser = parse_f64, allow_hyphen_values = true)]
    pub poisson: f64,
    /// The solid's Lamé constants λ,μ instead of --young and --poisson.
    #[arg(long, value_name = "LAMBDA,MU", value_parser = parse_lame, allow_hyphen_values = true, conflicts_with_all = ["young", "poisson"])]
    pub lame: Option<[f64; 2]>,
    /// A picture of the directional Young's modulus (the surface E(d)·d: a sphere for an
    /// isotropic cell) from the iso view, the front and the top (PNG).
    #[arg(long, value_name = "FILE.png")]
    pub plot: Option<PathBuf>,
    /// JSON report: the settings, the tensor, its inverse, the constants and the solver's work.
    #[arg(long, value_name = "FILE.json")]
    pub report: Option<PathBuf>,
    /// Print the report as JSON instead of the summary.
    #[arg(long)]
    pub json: bool,
}

/// Densities to tabulate over.
#[derive(Clone, Debug)]
pub struct Densities(pub Vec<f64>);

fn parse_densities(s: &str) -> std::result::Result<Densities, String> {
    let bad = || format!("'{s}' is not A:B:K (K densities from A to B) or a list D1,D2,…");
    let in_range = |d: f64| d > 0.0 && d <= 1.0;
    let parts: Vec<&str> = s.split(':').collect();
    let v: Vec<f64> = if parts.len() == 3 {
        let a: f64 = parts[0].trim().parse().map_err(|_| bad())?;
        let b: f64 = parts[1].trim().parse().map_err(|_| bad())?;
        let k: usize = parts[2].trim().parse().map_err(|_| bad())?;
        if !(2..=100).contains(&k) {
            return Err(format!("'{s}': K must be from 2 to 100"));
        }
        (0..k)
            .map(|i| a + (b - a) * i as f64 / (k - 1) as f64)
            .collect()
    } else {
        s.split(',')
            .map(|x| x.trim().parse::<f64>().map_err(|_| bad()))
            .collect::<std::result::Result<_, _>>()?
    };
    if v.len() < 2 || v.iter().any(|&d| !in_range(d)) {
        return Err(format!("'{s}': two or more densities, each in (0, 1]"));
    }
    Ok(Densities(v))
}

fn parse_lame(s: &str) -> std::result::Result<[f64; 2], String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| {
            x.trim()
                .parse::<f64>()
                .map_err(|_| format!("'{s}' is not λ,μ (two numbers)"))
        })
        .collect::<std::result::Result<_, _>>()?;
    match v[..] {
        [l, m] if l.is_finite() && m.is_finite() => Ok([l, m]),
        _ => Err(format!("'{s}' is not λ,μ (two numbers)")),
    }
}

/// A report: the lattice and its cell beside what was computed (one cell or a curve).
#[derive(serde::Serialize)]
struct Report<T> {
    lattice: String,
    cell_size: [f64; 3],
    parameter_name: &'static str,
    voigt_order: &'static str,
    #[serde(flatten)]
    result: T,
}

impl<T> Report<T> {
    fn of(name: &str, a: &HomogenizeArgs, settings: &Settings, result: T) -> Report<T> {
        Report {
            lattice: name.to_string(),
            cell_size: a.cell_size,
            parameter_name: settings.cell.lattice.parameter(),
            voigt_order: "xx, yy, zz, yz, xz, xy (engineering shears)",
            result,
        }
    }
}

impl HomogenizeArgs {
    /// The settings the options describe, and the lattice's name.
    fn settings(&self) -> Result<(Settings, String)> {
        let (lattice, name) = match &self.cell {
            Some(c) => {
                if self.level.is_some() {
                    return Err(Error::invalid(
                        "--level is a TPMS's; a strut cell takes --radius",
                    ));
                }
                let (cell, name) = super::strut::unit_cell(c)?;
                let lattice = Lattice::Strut(Arc::new(cell));
                let label = lattice.name(Some(&name));
                (lattice, label)
            }
            None => {
                if self.radius.is_some() {
                    return Err(Error::invalid(
                        "--radius is a strut cell's; a TPMS takes --level",
                    ));
                }
                let structure = match (self.structure, self.side.as_str()) {
                    (Structure::Net, "other") => Structure::NetOther,
                    (s, _) => s,
                };
                let lattice = Lattice::Tpms(self.surface.unwrap_or(Surface::Gyroid), structure);
                let label = lattice.name(None);
                (lattice, label)
            }
        };
        let amount = match (self.density, self.level.or(self.radius)) {
            (Some(d), _) => Amount::Density(d),
            (None, Some(p)) => Amount::Parameter(p),
            (None, None) => Amount::Density(0.2),
        };
        let material = match self.lame {
            Some([l, m]) => Material::from_lame(l, m)?,
            None => Material::from_young(self.young, self.poisson)?,
        };
        let n = self.voxels as usize;
        Ok((
            Settings {
                cell: Cell {
                    lattice,
                    size: self.cell_size,
                },
                amount,
                voxels: [n; 3],
                voxelization: match self.voxelization {
                    VoxelizationArg::Fraction => Voxelization::Fraction,
                    VoxelizationArg::Centres => Voxelization::Centres,
                },
                material,
                tolerance: 1e-8,
            },
            name,
        ))
    }
}

pub fn run(a: &HomogenizeArgs, quiet: bool) -> Result<i32> {
    let (settings, name) = a.settings()?;
    for f in [&a.report, &a.plot].into_iter().flatten() {
        latvox::io::atomic::check_writable(f)?;
    }
    let progress = latvox::progress::Progress::new(quiet || a.json);
    if let Some(Densities(densities)) = &a.densities {
        let curve = homogenize::curve(&settings, densities, &progress)?;
        if !emit_json(
            a.report.as_deref(),
            a.json,
            &Report::of(&name, a, &settings, &curve),
        )? {
            print_curve(&name, &settings, &curve);
        }
        return Ok(0);
    }
    let h = homogenize::homogenize(&settings, &progress)?;
    if let Some(p) = &a.plot {
        homogenize::picture::write_picture(&h.compliance, p, 400)?;
    }
    if emit_json(
        a.report.as_deref(),
        a.json,
        &Report::of(&name, a, &settings, &h),
    )? {
        return Ok(0);
    }
    print_summary(&name, &settings, &h);
    Ok(0)
}

fn print_summary(name: &str, s: &Settings, h: &Homogenized) {
    let size = s.cell.size;
    let m = h.material;
    outln!(
        "{name}, cell {} × {} × {} mm on {} voxels a side ({}): relative density {:.4} ({} {:.5})",
        size[0],
        size[1],
        size[2],
        h.voxels[0],
        match h.voxelization {
            Voxelization::Fraction => "voxels weigh their solid share",
            Voxelization::Centres => "voxels solid where their centres are",
        },
        h.relative_density,
        s.cell.lattice.parameter(),
        h.parameter
    );
    outln!(
        "solid: E = {}, ν = {:.4} (λ = {:.6}, μ = {:.6})",
        m.young,
        m.poisson,
        m.lambda,
        m.mu
    );
    outln!("stiffness C, Voigt order xx yy zz yz xz xy (engineering shears):");
    for row in &h.stiffness {
        let cells: Vec<String> = row.iter().map(|v| format!("{:>12}", sig(*v))).collect();
        outln!("  {}", cells.join(" "));
    }
    let k = &h.constants;
    let rel = |v: f64| v / m.young;
    outln!(
        "Young's moduli   Ex {}  Ey {}  Ez {}   (E/Es {:.5} {:.5} {:.5})",
        sig(k.young[0]),
        sig(k.young[1]),
        sig(k.young[2]),
        rel(k.young[0]),
        rel(k.young[1]),
        rel(k.young[2])
    );
    outln!(
        "shear moduli     Gyz {}  Gxz {}  Gxy {}",
        sig(k.shear[0]),
        sig(k.shear[1]),
        sig(k.shear[2])
    );
    outln!(
        "Poisson's ratios νxy {:.4}  νxz {:.4}  νyz {:.4}",
        k.poisson[0][1],
        k.poisson[0][2],
        k.poisson[1][2]
    );
    outln!(
        "Zener anisotropy {:.4} (1: isotropic)   bulk modulus {}",
        k.zener,
        sig(k.bulk)
    );
    let dir = |d: [f64; 3]| format!("[{:.3}, {:.3}, {:.3}]", d[0], d[1], d[2]);
    outln!(
        "Young's modulus by direction: max {} along {}, min {} along {}; [110] {}, [111] {}, mean {}",
        sig(k.young_max.0),
        dir(k.young_max.1),
        sig(k.young_min.0),
        dir(k.young_min.1),
        sig(k.young_110),
        sig(k.young_111),
        sig(k.young_mean)
    );
    outln!(
        "solver: {} conjugate-gradient iterations at most (multigrid, {} grids), residual {:.1e}, {} unknowns, {:.2} s",
        h.solver.iterations,
        h.solver.levels,
        h.solver.residual,
        h.solver.unknowns,
        h.seconds
    );
}

fn print_curve(name: &str, s: &Settings, c: &homogenize::Curve) {
    outln!(
        "{name}, cell {} × {} × {} mm on {} voxels a side: moduli over the solid's Young's modulus",
        s.cell.size[0],
        s.cell.size[1],
        s.cell.size[2],
        s.voxels[0]
    );
    outln!(
        "{:>8} {:>10} {:>10} {:>10} {:>8} {:>8} {:>10}",
        "density",
        s.cell.lattice.parameter(),
        "E/Es",
        "G/Es",
        "νxy",
        "Zener",
        "mean E/Es"
    );
    for h in &c.points {
        let k = &h.constants;
        let es = h.material.young;
        outln!(
            "{:>8.4} {:>10.5} {:>10} {:>10} {:>8.4} {:>8.4} {:>10}",
            h.relative_density,
            h.parameter,
            sig(k.young.iter().sum::<f64>() / 3.0 / es),
            sig(k.shear.iter().sum::<f64>() / 3.0 / es),
            k.poisson[0][1],
            k.zener,
            sig(k.young_mean / es)
        );
    }
    outln!("Gibson–Ashby fits, modulus/Es = C·ρⁿ (largest miss of a point):");
    for (what, law) in [
        ("E along the axes", c.young),
        ("G on the axes' planes", c.shear),
        ("E over all directions", c.young_mean),
    ] {
        outln!(
            "  {what:<22} C {:.4}  n {:.3}  ({:.1} %)",
            law.c,
            law.n,
            100.0 * law.max_error
        );
    }
}

/// `v` to 5 significant digits.
fn sig(v: f64) -> String {
    if v == 0.0 || v.abs() < 1e-12 {
        return "0".into();
    }
    let digits = (4 - v.abs().log10().floor() as i32).max(0) as usize;
    format!("{v:.digits$}")
}
