//! Graded Voronoi foams, the foam's side: a net whose strut radius, or a sheet whose wall
//! thickness, varies from point to point (read off a level grid), and the foam's density →
//! level map, calibrated on a block of the foam at the part's own voxel, for
//! [`crate::mesh::graded`] to meet a density that varies through the part block by block.
//!
//! **Net.** At each point every strut is as thick as the level there, so the union's distance
//! is the distance to the nearest Voronoi edge (a skeleton of zero radius) less that level:
//! `|∇| ≤ 1 + |∇level|`.
//!
//! **Sheet.** The distance to the nearest face less half the level there (the uniform sheet's
//! field with a varying half thickness): `|∇| ≤ 1 + |∇level| / 2`.

use super::foam::{FoamFamily, Half, SheetField, Structure};
use crate::error::Result;
use crate::field::beams::BeamField;
use crate::field::{Aabb, Field, Vec3};
use crate::grid::GridSpec;
use crate::lattice::model::LevelModel;
use crate::mesh::graded::{self, LevelGrid, LevelMap, Levelled};
use crate::mesh::pipeline::{Family, Options};

/// A net whose strut radius at each point is the grid's level there.
struct GradedNet<'a> {
    /// The Voronoi edges at radius 0, exact up to the reach plus the thickest radius.
    skeleton: BeamField,
    levels: &'a LevelGrid,
    offset: f64,
    reach: f64,
    lipschitz: f64,
}

impl GradedNet<'_> {
    fn radius(&self, p: Vec3) -> f64 {
        (self.levels.at(p).0 + self.offset).max(0.0)
    }
}

impl Field for GradedNet<'_> {
    fn value(&self, p: Vec3) -> f64 {
        (self.skeleton.value(p) - self.radius(p)).min(self.reach)
    }

    fn clearance(&self, p: Vec3) -> f64 {
        self.value(p).abs() / self.lipschitz
    }

    fn sample_block(&self, origin: Vec3, h: f64, out: &mut [f32; 512]) {
        self.skeleton.sample_block(origin, h, out);
        for i in 0..8 {
            for j in 0..8 {
                for k in 0..8 {
                    let o = &mut out[(i * 8 + j) * 8 + k];
                    let r = self.levels.in_block(origin, h, [i, j, k], self.offset);
                    *o = (*o as f64 - r.max(0.0)).min(self.reach) as f32;
                }
            }
        }
    }
}

impl Levelled for FoamFamily {
    fn graded_field<'a>(
        &'a self,
        levels: &'a LevelGrid,
        offset: f64,
        spec: &GridSpec,
    ) -> Box<dyn Field + 'a> {
        let reach = spec.half_width * spec.voxel;
        let most = (levels.max + offset).max(0.0);
        match self.foam.structure {
            Structure::Net => Box::new(GradedNet {
                skeleton: self.foam.net_field(0.0, reach + most),
                levels,
                offset,
                reach,
                lipschitz: 1.0 + levels.lipschitz,
            }),
            Structure::Sheet => Box::new(SheetField {
                foam: &self.foam,
                half: Half::Graded { levels, offset },
                reach,
                lipschitz: 1.0 + 0.5 * levels.lipschitz,
            }),
        }
    }

    fn bounds(&self) -> Aabb {
        self.bounds
    }

    fn with_bounds(&self, bounds: Aabb) -> Self {
        FoamFamily {
            foam: self.foam.clone(),
            bounds,
        }
    }

    fn model_fraction(&self, level: f64) -> f64 {
        self.foam.model().fraction(level)
    }

    fn model_level(&self, fraction: f64) -> f64 {
        self.foam.model().level(fraction)
    }
}

/// A block of a foam with the density model of that block.
struct Block {
    family: FoamFamily,
    model: LevelModel,
}

impl Family for Block {
    type Solid = <FoamFamily as Family>::Solid;

    fn at(&self, level: f64) -> Self::Solid {
        self.family.at(level)
    }

    fn model_fraction(&self, level: f64) -> f64 {
        self.model.fraction(level)
    }

    fn model_level(&self, fraction: f64) -> f64 {
        self.model.level(fraction)
    }
}

/// The foam's density → level map over `[lo, hi]` at `voxel`: the block `region` of it (its
/// own density model measured there) meshed at each knot and its level found by the
/// pipeline's search, the meshing's bias against the model interpolated between the knots and
/// read off the whole foam's model; whether every search met its density.
pub fn calibrate(
    family: &FoamFamily,
    region: Aabb,
    voxel: f64,
    opts: &Options,
    lo: f64,
    hi: f64,
) -> Result<(LevelMap, bool)> {
    let block = Block {
        family: family.with_bounds(region),
        model: family.foam.model_in(&region),
    };
    graded::calibrate_on(&block, voxel, opts, lo, hi, |f| {
        Family::model_level(family, f)
    })
}
