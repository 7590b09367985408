//! Graded strut lattices, the cell's side: its density → radius map (one cell meshed at the
//! part's own voxel at a handful of densities, the radius found for each by the pipeline's
//! search, the meshing's bias against the radius model interpolated between them) and the
//! lattice whose strut radius varies from point to point, for [`crate::mesh::graded`] to meet a
//! density that varies through a part cell by cell.

use super::field::StrutField;
use super::{StrutFamily, StrutLattice};
use crate::error::Result;
use crate::field::{numeric_gradient, Aabb, Field, Vec3};
use crate::grid::GridSpec;
use crate::mesh::graded::{self, LevelGrid, LevelMap, Levelled};
use crate::mesh::pipeline::{Options, Solid};

struct GradedStrutField<'a> {
    struts: StrutField,
    levels: &'a LevelGrid,
    offset: f64,
    lipschitz: f64,
}

impl GradedStrutField<'_> {
    #[inline(always)]
    fn radius(&self, p: Vec3) -> f64 {
        (self.levels.at(p).0 + self.offset).max(0.0)
    }
}

impl Field for GradedStrutField<'_> {
    fn value(&self, p: Vec3) -> f64 {
        self.struts.value_at(p, self.radius(p))
    }

    fn clearance(&self, p: Vec3) -> f64 {
        self.value(p).abs() / self.lipschitz
    }

    fn value_and_clearance(&self, p: Vec3) -> (f64, f64) {
        let v = self.value(p);
        (v, v.abs() / self.lipschitz)
    }

    fn implicit_with_gradient(&self, p: Vec3) -> (f64, Vec3) {
        let (t, gt) = self.levels.at(p);
        let r = t + self.offset;
        if r <= 0.0 {
            return (self.value(p), numeric_gradient(|q| self.value(q), p));
        }
        let (d, g, f) = self.struts.gradient_at(p, r);
        (d, [0, 1, 2].map(|a| g[a] - f * gt[a]))
    }

    fn sample_block(&self, origin: Vec3, h: f64, out: &mut [f32; 512]) {
        self.struts.sample_block_at(origin, h, out, |i, j, k| {
            self.levels
                .in_block(origin, h, [i, j, k], self.offset)
                .max(0.0)
        })
    }
}

impl Levelled for StrutFamily {
    fn graded_field<'a>(
        &'a self,
        levels: &'a LevelGrid,
        offset: f64,
        spec: &GridSpec,
    ) -> Box<dyn Field + 'a> {
        let widest = (levels.max + offset).max(1e-9);
        let struts = StrutLattice {
            radius: widest,
            ..self.part.clone()
        }
        .field(spec.half_width * spec.voxel)
        .with_periodic_samples(spec.voxel);
        let factor = self.part.cell.radii.iter().cloned().fold(1.0, f64::max);
        Box::new(GradedStrutField {
            struts,
            levels,
            offset,
            // Each strut's distance less its radius: 1-Lipschitz in the point, and the radius
            // (times its factor) moves with the level's slope.
            lipschitz: 1.0 + factor * levels.lipschitz,
        })
    }

    fn bounds(&self) -> Aabb {
        self.part.bounds
    }

    fn with_bounds(&self, bounds: Aabb) -> Self {
        StrutFamily {
            part: self.part.with_bounds(bounds),
            model: self.model.clone(),
        }
    }

    fn model_fraction(&self, level: f64) -> f64 {
        self.model.fraction(level)
    }

    fn model_level(&self, fraction: f64) -> f64 {
        self.model.radius(fraction)
    }
}

/// The cell's density → radius map over `[lo, hi]` at `voxel`: one cell (a box of one period,
/// which holds exactly the lattice's fraction) meshed at each knot and its radius found by the
/// pipeline's search; whether every search met its density.
pub fn calibrate(
    family: &StrutFamily,
    voxel: f64,
    opts: &Options,
    lo: f64,
    hi: f64,
) -> Result<(LevelMap, bool)> {
    let lattice = &family.part;
    let one = StrutFamily {
        part: lattice.with_bounds(Aabb {
            min: lattice.phase,
            max: [0, 1, 2].map(|a| lattice.phase[a] + lattice.size[a]),
        }),
        model: family.model.clone(),
    };
    let model = family.model.clone();
    graded::calibrate_on(&one, voxel, opts, lo, hi, |f| model.radius(f))
}
