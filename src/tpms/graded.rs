//! Graded TPMS lattices: a density that varies through the part, met cell by cell by
//! [`crate::mesh::graded`]; here is the type's side of it: its density → level map (the unit
//! cell calibrated at the part's own voxel by [`calibrate::calibrate`] at a handful of densities,
//! the bias interpolated between them) and the lattice at a level that varies from point to
//! point.

use super::blend::BlendMapped;
use super::job::TpmsJob;
use super::TpmsReport;
use crate::error::Result;
use crate::io::sink::MeshSink;
use crate::lattice::tpms::graded::Calibrated;
use crate::lattice::tpms::{calibrate, Lattice, Surface};
use crate::mesh::graded::{self, Feasible, Grading, Mapped, Run};
use crate::mesh::report::Timings;

/// Times a graded part whose cells miss the field is meshed again on finer voxels.
const MAX_RAISES: u32 = 2;
/// How much finer each time.
const RAISE: f64 = 1.25;
use crate::progress::Progress;
use std::time::Instant;

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
