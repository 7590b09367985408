//! Graded strut lattices: a density that varies through the part, met cell by cell by
//! [`crate::mesh::graded`]; here is the cell's side of it: its density → radius map (one cell
//! meshed at the part's own voxel at a handful of densities, the radius found for each by the
//! pipeline's search, the meshing's bias against the radius model interpolated between them)
//! and the lattice whose strut radius varies from point to point — a strut is as thick at a
//! point as the density there asks.

use super::field::StrutField;
use super::job::{StrutJob, StrutReport};
use super::{StrutFamily, StrutLattice};
use crate::error::Result;
use crate::field::{numeric_gradient, Aabb, Field, Vec3};
use crate::grid::GridSpec;
use crate::io::sink::MeshSink;
use crate::mesh::graded::{self, Feasible, Grading, LevelGrid, LevelMap, Levelled, Mapped, Run};
use crate::mesh::pipeline::{self, Family, Options, Route, Solid};
use crate::mesh::report::Timings;
use crate::mesh::resolution::max_resolution;
use crate::progress::Progress;
use std::time::Instant;

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
pub(crate) fn calibrate(
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
    let opts = Options {
        verify: crate::verify::Verify::None,
        instancing: false,
        keep_fragments: true,
        ..*opts
    };
    let knots = graded::knots(lo, hi);
    let mut bias = Vec::with_capacity(knots.len());
    let mut met = true;
    for &rho in &knots {
        let r0 = one.model.radius(rho);
        let route = Route::choose(&one.at(r0), voxel, &opts);
        let solved = pipeline::solve(&one, rho, r0, voxel, route, &opts)?;
        met &= solved.met;
        bias.push(one.model.fraction(solved.best.level) - rho);
    }
    let model = family.model.clone();
    Ok((
        LevelMap::new(lo, hi, &knots, &bias, |f| model.radius(f)),
        met,
    ))
}

impl StrutJob {
    /// Runs a graded job (see [`crate::mesh::graded`]).
    pub(super) fn run_graded(
        &self,
        grading: &Grading,
        progress: &Progress,
        sink: &mut dyn MeshSink,
    ) -> Result<StrutReport> {
        let start = Instant::now();
        grading.without_skin()?;
        let bounds = self.domain.bounds();
        let cell = self.domain.cell;
        let (family, model_seconds) = self.family();
        let model = family.model.clone();
        // The thinnest struts the finest resolution allowed can hold, and where pores close.
        let finest = if self.auto_resolution {
            max_resolution(self.resolution)
        } else {
            self.resolution
        };
        let range = self.range(&model, finest);
        let feasible = Feasible {
            min: range.min_density,
            max: range.max_density,
            what: format!("{} strut lattice", self.cell_name),
            why: if self.auto_resolution {
                "struts are under 2 voxels across at the finest resolution latvox would try, or the pores close"
            } else {
                "struts are under 2 voxels across, or the pores close"
            },
        };
        let targets = grading.check(&bounds, cell, &|_| Some(0.0), &feasible)?;
        // Struts are thinnest at the lowest density.
        let (resolution, warnings) = graded::raised(
            self.resolution,
            self.thin_struts(model.radius(targets.built[0]))?,
            self.auto_resolution,
            "break",
        )?;
        let voxel = self.voxel(resolution);
        let opts = Options {
            instancing: false,
            ..self.options
        };
        let cal_start = Instant::now();
        let (map, met) = {
            let _p = progress.stage("calibrating the density → radius map");
            calibrate(&family, voxel, &opts, targets.built[0], targets.built[1])?
        };
        let calibrate_seconds = model_seconds + cal_start.elapsed().as_secs_f64();
        let kind = Mapped {
            lattice: family,
            map,
        };
        let lowest = targets.built[0];
        let done = Run {
            grading,
            targets,
            feasible,
            voxel,
            resolution,
            options: opts,
            calibrated: met,
            timings: Timings {
                calibrate: calibrate_seconds,
                ..Timings::default()
            },
            warnings,
            start,
        }
        .in_box(&kind, bounds, cell, progress, sink)?;
        let thinnest = kind.map.level(lowest);
        Ok(StrutReport {
            cell: self.cell_name.clone(),
            cell_nodes: self.cell.nodes.len(),
            cell_struts: self.cell.struts.len(),
            radius: done.mean_level,
            blend: self.blend,
            thinnest_strut_voxels: 2.0 * thinnest * self.thinnest_factor() / voxel,
            feasible_range: self.range(&kind.lattice.model, resolution),
            level_search: done.level_search,
            resolution_requested: self.resolution,
            resolution,
            voxel_size: voxel,
            cell_size: cell,
            cells: self.domain.counts(),
            grading: Some(done.grading),
            part: done.part,
        })
    }
}
