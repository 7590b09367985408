//! A lattice's periodic unit cell as voxel weights: the share of each voxel the solid fills
//! (integrated on the field, [`crate::field::volume::inside`], to a quarter of a voxel with the
//! share of the last boxes read off the field's plane) or, as in the published reference codes,
//! 1 where the voxel's centre is solid and 0 elsewhere. A density is met on the voxels
//! themselves: the level or radius is moved until the weights' mean is the density.

use crate::error::{Error, Result};
use crate::field::{volume, Aabb, Field, Vec3};
use crate::lattice::strut::{RadiusModel, StrutField, UnitCell};
use crate::lattice::tpms::{calibrate, Structure, Surface, TpmsField};
use rayon::prelude::*;
use std::sync::Arc;

/// Which lattice fills the cell.
#[derive(Debug, Clone)]
pub enum Lattice {
    /// A TPMS: its surface and which side is solid.
    Tpms(Surface, Structure),
    /// A strut cell with capsule struts (radius times each node's factor).
    Strut(Arc<UnitCell>),
}

impl Lattice {
    /// The lattice's name in reports: "gyroid net", "bcc struts".
    pub fn name(&self, cell: Option<&str>) -> String {
        match self {
            Lattice::Tpms(s, st) => format!("{} {}", s.name(), st.name()),
            Lattice::Strut(_) => format!("{} struts", cell.unwrap_or("strut")),
        }
    }

    /// The parameter's name: the level `t` of a TPMS, the strut radius (mm).
    pub fn parameter(&self) -> &'static str {
        match self {
            Lattice::Tpms(..) => "level",
            Lattice::Strut(_) => "radius",
        }
    }
}

/// How voxels weigh.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Voxelization {
    /// The share of the voxel the solid fills.
    Fraction,
    /// 1 where the voxel's centre is solid.
    Centres,
}

/// A parameter and its density's miss, in the search for a density.
type Point = (f64, f64);

/// A periodic unit cell of a lattice.
#[derive(Debug, Clone)]
pub struct Cell {
    /// The lattice.
    pub lattice: Lattice,
    /// The cell's size per axis, mm.
    pub size: Vec3,
}

impl Cell {
    /// The solid at `parameter` (level or radius) as a field, exact within `reach` mm of its
    /// surface.
    fn field(&self, parameter: f64, reach: f64) -> Box<dyn Field + '_> {
        match &self.lattice {
            Lattice::Tpms(surface, structure) => Box::new(TpmsField::new(
                *surface, *structure, parameter, self.size, [0.0; 3], reach,
            )),
            Lattice::Strut(cell) => Box::new(StrutField::new(
                cell,
                self.size,
                [0.0; 3],
                parameter,
                0.0,
                reach + parameter,
            )),
        }
    }

    /// The level or radius of the exact (not voxelised) cell at `density`.
    fn first_guess(&self, density: f64) -> f64 {
        match &self.lattice {
            Lattice::Tpms(surface, structure) => {
                calibrate::analytic_level(*surface, *structure, density)
            }
            Lattice::Strut(cell) => RadiusModel::new(cell, self.size).radius(density),
        }
    }

    /// The voxel weights on `n` voxels per axis at `parameter`, indexed `i + n₀(j + n₁k)`.
    pub fn weights(&self, parameter: f64, n: [usize; 3], rule: Voxelization) -> Vec<f64> {
        let h = [0, 1, 2].map(|a| self.size[a] / n[a] as f64);
        let reach = 2.0 * h.iter().fold(0.0f64, |m, x| m.max(*x));
        let field = self.field(parameter, reach);
        (0..n[0] * n[1] * n[2])
            .into_par_iter()
            .map(|e| {
                let c = [e % n[0], (e / n[0]) % n[1], e / (n[0] * n[1])];
                let b = Aabb {
                    min: [0, 1, 2].map(|a| c[a] as f64 * h[a]),
                    max: [0, 1, 2].map(|a| (c[a] + 1) as f64 * h[a]),
                };
                match rule {
                    Voxelization::Centres => {
                        let centre = [0, 1, 2].map(|a| (c[a] as f64 + 0.5) * h[a]);
                        if field.value(centre) <= 0.0 {
                            1.0
                        } else {
                            0.0
                        }
                    }
                    Voxelization::Fraction => {
                        (volume::inside(&*field, &b, 2) / b.volume()).clamp(0.0, 1.0)
                    }
                }
            })
            .collect()
    }

    /// The level or radius at which the voxel weights' mean is `density` (to 1e-5, or to one
    /// voxel's share where the voxels' centres decide), and the weights.
    pub fn at_density(
        &self,
        density: f64,
        n: [usize; 3],
        rule: Voxelization,
    ) -> Result<(f64, Vec<f64>)> {
        if let Lattice::Tpms(surface, structure) = &self.lattice {
            let range = calibrate::feasible(*surface, *structure);
            if !(density >= range.min && density <= range.max) {
                return Err(Error::invalid(format!(
                    "the {} holds together at densities from {:.3} to {:.3}, not at {density}",
                    self.lattice.name(None),
                    range.min,
                    range.max
                )));
            }
        }
        let voxels = (n[0] * n[1] * n[2]) as f64;
        let tol = match rule {
            Voxelization::Fraction => 1e-5,
            Voxelization::Centres => (1.0 / voxels).max(1e-5),
        };
        let mean = |w: &[f64]| w.iter().sum::<f64>() / voxels;
        let mut a = self.first_guess(density);
        let wa = self.weights(a, n, rule);
        let mut fa = mean(&wa) - density;
        if fa.abs() <= tol {
            return Ok((a, wa));
        }
        // A second point a little way towards the density, then secant steps kept within the
        // bracket once one is found (bisection where a step leaves it).
        let scale = match &self.lattice {
            Lattice::Tpms(..) => 0.05,
            Lattice::Strut(_) => 0.05 * self.size.iter().fold(f64::INFINITY, |m, x| m.min(*x)),
        };
        let (mut lo, mut hi): (Option<Point>, Option<Point>) = (None, None);
        let record = |p: f64, f: f64, lo: &mut Option<Point>, hi: &mut Option<Point>| {
            if f < 0.0 {
                *lo = Some((p, f));
            } else {
                *hi = Some((p, f));
            }
        };
        record(a, fa, &mut lo, &mut hi);
        let mut b = a - fa.signum() * scale * 0.2;
        for _ in 0..40 {
            let wb = self.weights(b, n, rule);
            let fb = mean(&wb) - density;
            if fb.abs() <= tol {
                return Ok((b, wb));
            }
            record(b, fb, &mut lo, &mut hi);
            let mut next = if fb != fa {
                b - fb * (b - a) / (fb - fa)
            } else {
                b + scale
            };
            match (lo, hi) {
                (Some((l, _)), Some((h, _))) => {
                    let (l, h) = (l.min(h), l.max(h));
                    if !(next > l && next < h) {
                        next = 0.5 * (l + h);
                    }
                }
                (Some(_), None) => next = next.max(b + 0.1 * scale).min(b + 4.0 * scale),
                (None, Some(_)) => next = next.min(b - 0.1 * scale).max(b - 4.0 * scale),
                (None, None) => unreachable!(),
            }
            (a, fa) = (b, fb);
            b = next;
        }
        Err(Error::invalid(format!(
            "no {} gives a voxelised density of {density} on {}×{}×{} voxels",
            self.lattice.parameter(),
            n[0],
            n[1],
            n[2]
        )))
    }
}
