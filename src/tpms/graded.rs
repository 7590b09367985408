//! Graded TPMS lattices: a density that varies through the part, met cell by cell by
//! [`crate::mesh::graded`]; here is the type's side of it: its density → level map (the unit
//! cell calibrated at the part's own voxel by [`calibrate::calibrate`] at a handful of densities,
//! the bias interpolated between them) and the lattice at a level that varies from point to
//! point.

use super::blend::BlendMapped;
use super::calibrate::{self, Calibration};
use super::job::TpmsJob;
use super::{Lattice, Structure, Surface, TpmsField, TpmsReport};
use crate::error::Result;
use crate::field::{Aabb, Field, Vec3};
use crate::grid::GridSpec;
use crate::io::sink::MeshSink;
use crate::mesh::graded::{self, Feasible, Grading, LevelGrid, LevelMap, Levelled, Mapped, Run};
use crate::mesh::report::Timings;

/// Times a graded part whose cells miss the field is meshed again on finer voxels.
const MAX_RAISES: u32 = 2;
/// How much finer each time.
const RAISE: f64 = 1.25;
use crate::progress::Progress;
use std::time::Instant;

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

impl TpmsJob {
    /// Runs a graded job (see [`crate::mesh::graded`]).
    pub(super) fn run_graded(
        &self,
        grading: &Grading,
        progress: &Progress,
        sink: &mut dyn MeshSink,
    ) -> Result<TpmsReport> {
        let start = Instant::now();
        let (s, st) = (self.surface, self.structure);
        grading.without_skin()?;
        let bounds = self.domain.bounds();
        let cell = self.domain.cell;
        let range = calibrate::feasible(s, st);
        // A blend must be feasible as either type.
        let (range, what) = match &self.blend {
            None => (range, format!("{} {}", s.name(), st.name())),
            Some(b) => {
                let other = calibrate::feasible(b.to, st);
                (
                    calibrate::FeasibleRange {
                        min: range.min.max(other.min),
                        max: range.max.min(other.max),
                    },
                    format!("{} {} blended to {}", s.name(), st.name(), b.to.name()),
                )
            }
        };
        let feasible = Feasible {
            min: range.min,
            max: range.max,
            what,
            why: "the solid falls apart",
        };
        let targets = grading.check(&bounds, cell, &|_| Some(0.0), &feasible)?;
        // Sheet walls are thinnest at the lowest density (the thinner of the two types').
        let thin = |surface: Surface| {
            let job = TpmsJob {
                surface,
                ..self.clone()
            };
            job.thin_walls(calibrate::analytic_level(surface, st, targets.built[0]))
        };
        let thinnest = std::iter::once(s)
            .chain(self.blend.as_ref().map(|b| b.to))
            .filter_map(thin)
            .max_by_key(|(r, _)| *r);
        let (mut resolution, mut warnings) =
            graded::raised(self.resolution, thinnest, self.auto_resolution, "perforate")?;
        let opts = self.options(false, false);
        // Members too thin for the voxels break loose, and the cells they leave miss the field:
        // such a part is meshed again on finer voxels (twice at most) before it is written.
        let mut raises = 0;
        let (done, calibrated, voxel) = loop {
            let voxel = cell.iter().cloned().fold(f64::INFINITY, f64::min) / resolution as f64;
            let cal_start = Instant::now();
            let (lo, hi) = (targets.built[0], targets.built[1]);
            let calibrate = |surface: Surface| {
                Calibrated::build(surface, st, cell, voxel, self.adaptivity, lo, hi)
            };
            let (calibrated, other) = {
                let _p = progress.stage("calibrating the density → level map");
                (
                    calibrate(s)?,
                    self.blend.as_ref().map(|b| calibrate(b.to)).transpose()?,
                )
            };
            let calibrate_seconds = cal_start.elapsed().as_secs_f64();
            let lattice = Lattice {
                surface: s,
                structure: st,
                level: calibrated.middle.level,
                cell,
                bounds,
                phase: bounds.min,
            };
            let run = Run {
                grading,
                targets,
                feasible: feasible.clone(),
                voxel,
                resolution,
                options: opts,
                calibrated: calibrated.converged && other.as_ref().is_none_or(|o| o.converged),
                timings: Timings {
                    calibrate: calibrate_seconds,
                    ..Timings::default()
                },
                warnings: warnings.clone(),
                start,
            };
            let hold_back = self.auto_resolution && raises < MAX_RAISES;
            let done = match (&self.blend, &other) {
                (Some(blend), Some(other)) => {
                    let margin = (crate::mesh::pipeline::HALF_WIDTH + 2.0) * voxel;
                    let kind =
                        BlendMapped::new(lattice, blend, margin, (lo, hi), &calibrated, other);
                    run.try_in_box(&kind, bounds, cell, hold_back, progress, sink)?
                }
                _ => {
                    let kind = Mapped {
                        lattice,
                        map: calibrated.map.clone(),
                    };
                    run.try_in_box(&kind, bounds, cell, hold_back, progress, sink)?
                }
            };
            if let Some(done) = done {
                break (done, calibrated, voxel);
            }
            let raised = (resolution as f64 * RAISE).ceil() as u32;
            warnings.push(format!(
                "cells missed the field at {resolution} voxels per cell: the resolution was raised to {raised} (finer voxels keep thin members from breaking loose and follow the field more closely)"
            ));
            resolution = raised;
            raises += 1;
        };
        Ok(TpmsReport {
            surface: s,
            structure: st,
            level: done.mean_level,
            calibration: calibrated.middle,
            level_search: done.level_search,
            feasible_range: range,
            connectivity: calibrate::Connectivity {
                solid: true,
                void: true,
            },
            resolution_requested: self.resolution,
            resolution,
            voxel_size: voxel,
            thinnest_wall_voxels: None,
            cell_size: cell,
            cells: self.domain.counts(),
            grading: Some(done.grading),
            blend: self.blend.as_ref().map(|b| super::blend::BlendReport {
                to: b.to,
                weight: b.weight.source.clone(),
            }),
            cell_map: None,
            part: done.part,
        })
    }
}
