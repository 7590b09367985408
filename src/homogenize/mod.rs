//! Numerical homogenisation: the effective elasticity tensor of a lattice's periodic unit cell,
//! the stiffness a large block of the lattice has. The cell is voxelised ([`cell`]), each voxel
//! a trilinear hexahedron ([`element`]) weighing its solid share, and the six unit-strain load
//! cases are solved with periodic boundary conditions ([`solver`]); the tensor is the mean
//! strain energy of the responses (Andreassen & Andreasen, "How to determine composite material
//! properties using numerical homogenization", 2014; Dong, Tang & Zhao, "A 149 line
//! homogenization code for three-dimensional cellular materials written in MATLAB", 2019).
//! [`tensor`] reads the engineering constants off it, [`picture`] draws its directional Young's
//! modulus.

pub mod cell;
pub mod element;
pub mod picture;
pub mod solver;
pub mod tensor;

pub use cell::{Cell, Lattice, Voxelization};
pub use solver::SolveStats;
pub use tensor::{Constants, Voigt};

use crate::error::{Error, Result};
use crate::progress::Progress;

/// How much solid the cell holds.
#[derive(Debug, Clone, Copy)]
pub enum Amount {
    /// A relative density, met on the voxels.
    Density(f64),
    /// The level (TPMS) or strut radius (mm) itself.
    Parameter(f64),
}

/// The solid the cell is made of.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Material {
    /// Young's modulus.
    pub young: f64,
    /// Poisson's ratio.
    pub poisson: f64,
    /// Lamé's first constant λ.
    pub lambda: f64,
    /// The shear modulus μ.
    pub mu: f64,
}

impl Material {
    /// The solid of Young's modulus `e` and Poisson's ratio `nu`.
    pub fn from_young(e: f64, nu: f64) -> Result<Material> {
        if !(e > 0.0 && e.is_finite() && nu > -1.0 && nu < 0.5) {
            return Err(Error::invalid(format!(
                "a solid needs E > 0 and −1 < ν < 0.5, got E = {e}, ν = {nu}"
            )));
        }
        let (lambda, mu) = tensor::lame(e, nu);
        Ok(Material {
            young: e,
            poisson: nu,
            lambda,
            mu,
        })
    }

    /// The solid of Lamé constants `lambda`, `mu`.
    pub fn from_lame(lambda: f64, mu: f64) -> Result<Material> {
        if !(mu > 0.0 && 3.0 * lambda + 2.0 * mu > 0.0 && lambda.is_finite() && mu.is_finite()) {
            return Err(Error::invalid(format!(
                "a solid needs μ > 0 and 3λ + 2μ > 0, got λ = {lambda}, μ = {mu}"
            )));
        }
        Ok(Material {
            young: mu * (3.0 * lambda + 2.0 * mu) / (lambda + mu),
            poisson: lambda / (2.0 * (lambda + mu)),
            lambda,
            mu,
        })
    }
}

/// What to homogenise and how.
#[derive(Debug, Clone)]
pub struct Settings {
    /// The unit cell.
    pub cell: Cell,
    /// Its solid's amount.
    pub amount: Amount,
    /// Voxels per axis.
    pub voxels: [usize; 3],
    /// How voxels weigh.
    pub voxelization: Voxelization,
    /// The solid.
    pub material: Material,
    /// Relative residual at which the solver stops.
    pub tolerance: f64,
}

/// The homogenised cell.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Homogenized {
    /// The level (TPMS) or strut radius (mm) the cell was voxelised at.
    pub parameter: f64,
    /// The voxel model's relative density (the weights' mean).
    pub relative_density: f64,
    /// The solid.
    pub material: Material,
    /// Voxels per axis.
    pub voxels: [usize; 3],
    /// How voxels weighed.
    pub voxelization: Voxelization,
    /// The elasticity tensor, Voigt order xx, yy, zz, yz, xz, xy (engineering shears), in the
    /// solid's units.
    pub stiffness: Voigt,
    /// Its inverse.
    pub compliance: Voigt,
    /// Engineering constants.
    pub constants: Constants,
    /// What the solver did.
    pub solver: SolveStats,
    /// Wall time, seconds.
    pub seconds: f64,
}

/// Homogenises the cell `settings` describe.
pub fn homogenize(settings: &Settings, progress: &Progress) -> Result<Homogenized> {
    let start = std::time::Instant::now();
    let n = settings.voxels;
    if n.iter().any(|&c| c < 2) {
        return Err(Error::invalid("a cell needs at least 2 voxels a side"));
    }
    let (parameter, weights) = {
        let _stage = progress.stage("voxelising the cell");
        match settings.amount {
            Amount::Density(d) => {
                if !(d > 0.0 && d <= 1.0) {
                    return Err(Error::invalid(format!(
                        "density must be in (0, 1], got {d}"
                    )));
                }
                settings.cell.at_density(d, n, settings.voxelization)?
            }
            Amount::Parameter(p) => (p, settings.cell.weights(p, n, settings.voxelization)),
        }
    };
    let relative_density = weights.iter().sum::<f64>() / weights.len() as f64;
    if relative_density <= 0.0 {
        return Err(Error::invalid(
            "the cell holds no solid on these voxels: raise the density or the voxels",
        ));
    }
    let h = [0, 1, 2].map(|a| settings.cell.size[a] / n[a] as f64);
    let m = settings.material;
    let solver = solver::Solver::new(n, h, m.lambda, m.mu, weights)?;
    let counter = progress.counter(6, "load cases");
    let (stiffness, stats) = solver.homogenize(settings.tolerance, 2000, |_| counter.inc())?;
    drop(counter);
    // A lattice that falls apart carries no load: its stiffness vanishes to rounding along some
    // strain (a millionth of the solid's at the Voigt bound of its density is far below any
    // lattice that holds together on these voxels).
    let floor = 1e-9 * (m.lambda + 2.0 * m.mu);
    let compliance = tensor::invert(&stiffness, floor).map_err(|_| {
        Error::invalid(format!(
            "the cell carries no load along some strain at {} {:.5}: its solid does not hold together",
            settings.cell.lattice.parameter(),
            parameter
        ))
    })?;
    let constants = Constants::of(&stiffness, &compliance);
    Ok(Homogenized {
        parameter,
        relative_density,
        material: m,
        voxels: n,
        voxelization: settings.voxelization,
        stiffness,
        compliance,
        constants,
        solver: stats,
        seconds: start.elapsed().as_secs_f64(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lattice::strut::UnitCell;
    use std::sync::Arc;

    /// Dong, Tang & Zhao's example: the `grid` cell (the cube's 12 edges), radius 0.1, 40 voxels
    /// a side, voxels solid where their centres are, λ = 115.4, μ = 79.6.
    #[test]
    fn a_power_law_is_found_again() {
        let pts: Vec<(f64, f64)> = [0.1, 0.2, 0.35, 0.5]
            .iter()
            .map(|&r| (r, 0.7 * f64::powf(r, 2.1)))
            .collect();
        let law = PowerLaw::fit(&pts).unwrap();
        assert!(
            (law.c - 0.7).abs() < 1e-12 && (law.n - 2.1).abs() < 1e-12 && law.max_error < 1e-12
        );
        assert!(PowerLaw::fit(&[(0.2, 1.0)]).is_err());
    }

    #[test]
    fn the_published_grid_cell() {
        let settings = Settings {
            cell: Cell {
                lattice: Lattice::Strut(Arc::new(UnitCell::built_in("sc").unwrap())),
                size: [1.0; 3],
            },
            amount: Amount::Parameter(0.1),
            voxels: [40; 3],
            voxelization: Voxelization::Centres,
            material: Material::from_lame(115.4, 79.6).unwrap(),
            tolerance: 1e-8,
        };
        let h = homogenize(&settings, &Progress::hidden()).unwrap();
        let c = h.stiffness;
        eprintln!("{:?} {:?} {}", c, h.solver, h.relative_density);
        for (got, want) in [(c[0][0], 7.1876), (c[0][1], 0.3875), (c[3][3], 0.1489)] {
            assert!((got / want - 1.0).abs() < 0.005, "{got} against {want}");
        }
    }
}

/// A power law `y = c·ρⁿ` fitted to points by least squares on their logarithms (Gibson and
/// Ashby's scaling of a cellular solid's moduli with its relative density).
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct PowerLaw {
    /// The prefactor C.
    pub c: f64,
    /// The exponent n.
    pub n: f64,
    /// The largest relative difference between a point and the law.
    pub max_error: f64,
}

impl PowerLaw {
    /// The law through `(ρ, y)` points (at least two, every value positive).
    pub fn fit(points: &[(f64, f64)]) -> Result<PowerLaw> {
        if points.len() < 2 || points.iter().any(|&(x, y)| !(x > 0.0 && y > 0.0)) {
            return Err(Error::invalid(
                "a power law needs two or more points of positive density and modulus",
            ));
        }
        let k = points.len() as f64;
        let (lx, ly): (Vec<f64>, Vec<f64>) = points.iter().map(|&(x, y)| (x.ln(), y.ln())).unzip();
        let (mx, my) = (lx.iter().sum::<f64>() / k, ly.iter().sum::<f64>() / k);
        let sxx: f64 = lx.iter().map(|x| (x - mx).powi(2)).sum();
        let sxy: f64 = lx.iter().zip(&ly).map(|(x, y)| (x - mx) * (y - my)).sum();
        if sxx <= 0.0 {
            return Err(Error::invalid("a power law needs two different densities"));
        }
        let n = sxy / sxx;
        let c = (my - n * mx).exp();
        let max_error = points
            .iter()
            .map(|&(x, y)| (c * x.powf(n) / y - 1.0).abs())
            .fold(0.0, f64::max);
        Ok(PowerLaw { c, n, max_error })
    }

    /// The law's value at `rho`.
    pub fn at(&self, rho: f64) -> f64 {
        self.c * rho.powf(self.n)
    }
}

/// A cell's moduli over densities, relative to the solid's Young's modulus, and the power laws
/// fitted to them.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Curve {
    /// Each density's homogenised cell.
    pub points: Vec<Homogenized>,
    /// Young's modulus along the axes (their mean) over the solid's, against density.
    pub young: PowerLaw,
    /// The shear modulus on the axes' planes (their mean) over the solid's Young's modulus.
    pub shear: PowerLaw,
    /// Young's modulus averaged over directions, over the solid's.
    pub young_mean: PowerLaw,
}

/// Homogenises the cell of `settings` at each of `densities` and fits the moduli's power laws.
pub fn curve(settings: &Settings, densities: &[f64], progress: &Progress) -> Result<Curve> {
    let counter = progress.counter(densities.len() as u64, "densities");
    let mut points = Vec::with_capacity(densities.len());
    for &d in densities {
        let s = Settings {
            amount: Amount::Density(d),
            ..settings.clone()
        };
        points.push(homogenize(&s, &Progress::hidden())?);
        counter.inc();
    }
    drop(counter);
    let law = |f: &dyn Fn(&Homogenized) -> f64| {
        let pts: Vec<(f64, f64)> = points
            .iter()
            .map(|h| (h.relative_density, f(h) / h.material.young))
            .collect();
        PowerLaw::fit(&pts)
    };
    Ok(Curve {
        young: law(&|h| h.constants.young.iter().sum::<f64>() / 3.0)?,
        shear: law(&|h| h.constants.shear.iter().sum::<f64>() / 3.0)?,
        young_mean: law(&|h| h.constants.young_mean)?,
        points,
    })
}

/// Voxels a side of the cells homogenised for a stiffness table.
pub const TABLE_VOXELS: usize = 24;

/// The densities that give a lattice each relative stiffness: `(E/Es, ρ)` pairs, increasing,
/// with Young's modulus the mean of the cell's along its axes (ν = 0.3), homogenised at 9
/// densities spaced geometrically across the lattice's range (for a TPMS, the densities at which
/// it holds together) on [`TABLE_VOXELS`] voxels a side.
pub fn stiffness_table(cell: &Cell, progress: &Progress) -> Result<Vec<(f64, f64)>> {
    let (lo, hi) = match &cell.lattice {
        Lattice::Tpms(surface, structure) => {
            let r = crate::lattice::tpms::calibrate::feasible(*surface, *structure);
            ((r.min + 0.01).max(0.05), (r.max - 0.01).min(0.8))
        }
        Lattice::Strut(_) => (0.03, 0.6),
    };
    let k = 9;
    let densities: Vec<f64> = (0..k)
        .map(|i| lo * (hi / lo).powf(i as f64 / (k - 1) as f64))
        .collect();
    let settings = Settings {
        cell: cell.clone(),
        amount: Amount::Density(lo),
        voxels: [TABLE_VOXELS; 3],
        voxelization: Voxelization::Fraction,
        material: Material::from_young(1.0, 0.3)?,
        tolerance: 1e-8,
    };
    let _stage = progress.stage("homogenising the cell for its stiffness at each density");
    let c = curve(&settings, &densities, &Progress::hidden())?;
    let table: Vec<(f64, f64)> = c
        .points
        .iter()
        .map(|h| {
            (
                h.constants.young.iter().sum::<f64>() / 3.0,
                h.relative_density,
            )
        })
        .collect();
    if table.windows(2).any(|w| w[1].0 <= w[0].0) {
        return Err(Error::invalid(
            "the cell's stiffness does not rise with its density: it cannot be graded by stiffness",
        ));
    }
    Ok(table)
}
