//! Graded TPMS lattices, the type's side: its density → level map (the unit cell calibrated at
//! the part's own voxel by [`calibrate::calibrate`] at a handful of densities, the bias
//! interpolated between them) and the lattice at a level that varies from point to point, for
//! [`crate::mesh::graded`] to meet a density that varies through a part cell by cell.

use super::calibrate::{self, Calibration};
use super::{Lattice, Structure, Surface, TpmsField};
use crate::error::Result;
use crate::field::{Aabb, Field, Vec3};
use crate::grid::GridSpec;
use crate::mesh::graded::{self, LevelGrid, LevelMap, Levelled};

/// A type's calibrated density → level map at one voxel size.
pub struct Calibrated {
    /// The map.
    pub map: LevelMap,
    /// The calibration at the middle of the range (for the report).
    pub middle: Calibration,
    /// Whether every calibration converged.
    pub converged: bool,
    /// The meshing's bias at each knot of [`graded::knots`] over the range: the model's
    /// fraction at the calibrated level less the knot's density.
    pub bias: Vec<f64>,
}

impl Calibrated {
    /// Calibrates the unit cell at densities spanning `[lo, hi]` on voxels of `voxel`.
    pub fn build(
        surface: Surface,
        structure: Structure,
        cell: Vec3,
        voxel: f64,
        adaptivity: f64,
        lo: f64,
        hi: f64,
    ) -> Result<Calibrated> {
        let knots = graded::knots(lo, hi);
        let mut bias = Vec::with_capacity(knots.len());
        let mut middle = None;
        let mut converged = true;
        for (i, &rho) in knots.iter().enumerate() {
            // An interior cell: the part's faces are met by the per-cell correction.
            let cal =
                calibrate::calibrate(surface, structure, rho, cell, voxel, [1e6; 3], adaptivity)?;
            converged &= cal.converged;
            bias.push(calibrate::analytic_fraction(surface, structure, cal.level) - rho);
            if i == knots.len() / 2 {
                middle = Some(cal);
            }
        }
        Ok(Calibrated {
            map: LevelMap::new(lo, hi, &knots, &bias, |f| {
                calibrate::analytic_level(surface, structure, f)
            }),
            middle: middle.expect("at least one knot"),
            converged,
            bias,
        })
    }
}

struct GradedField<'a> {
    tpms: TpmsField,
    levels: &'a LevelGrid,
    offset: f64,
    lipschitz: f64,
}

impl GradedField<'_> {
    #[inline(always)]
    fn level(&self, p: Vec3) -> (f64, Vec3) {
        let (t, g) = self.levels.at(p);
        (t + self.offset, g)
    }
}

impl Field for GradedField<'_> {
    fn value(&self, p: Vec3) -> f64 {
        let (f, g) = self.tpms.eval_at(p);
        self.tpms.distance_at(f, g, self.level(p).0)
    }

    fn clearance(&self, p: Vec3) -> f64 {
        self.value_and_clearance(p).1
    }

    fn value_and_clearance(&self, p: Vec3) -> (f64, f64) {
        let (f, g) = self.tpms.eval_at(p);
        let t = self.level(p).0;
        (
            self.tpms.distance_at(f, g, t),
            self.tpms.implicit_at(f, t).abs() / self.lipschitz,
        )
    }

    fn implicit_with_gradient(&self, p: Vec3) -> (f64, Vec3) {
        let (f, g) = self.tpms.eval_at(p);
        let (t, gt) = self.level(p);
        let sign = match self.tpms.structure {
            Structure::Net => 1.0,
            Structure::Sheet => f.signum(),
            Structure::NetOther => -1.0,
        };
        (
            self.tpms.implicit_at(f, t),
            [0, 1, 2].map(|a| sign * g[a] / self.tpms.cell[a] - gt[a]),
        )
    }

    fn sample_block(&self, origin: Vec3, h: f64, out: &mut [f32; 512]) {
        self.tpms.sample_block_at(origin, h, out, |i, j, k| {
            self.levels.in_block(origin, h, [i, j, k], self.offset)
        })
    }
}

impl Levelled for Lattice {
    fn graded_field<'a>(
        &'a self,
        levels: &'a LevelGrid,
        offset: f64,
        spec: &GridSpec,
    ) -> Box<dyn Field + 'a> {
        let tpms = self
            .field(spec.half_width * spec.voxel)
            .with_periodic_samples(spec.voxel);
        Box::new(GradedField {
            lipschitz: tpms.lipschitz() + levels.lipschitz,
            tpms,
            levels,
            offset,
        })
    }

    fn bounds(&self) -> Aabb {
        self.bounds
    }

    fn with_bounds(&self, bounds: Aabb) -> Self {
        Lattice { bounds, ..*self }
    }

    fn model_fraction(&self, level: f64) -> f64 {
        calibrate::analytic_fraction(self.surface, self.structure, level)
    }

    fn model_level(&self, fraction: f64) -> f64 {
        calibrate::analytic_level(self.surface, self.structure, fraction)
    }
}
