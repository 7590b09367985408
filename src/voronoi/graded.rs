//! Graded Voronoi foams: a density that varies through the part, met block by block by
//! [`crate::mesh::graded`] — the strut radius (net) or wall thickness (sheet) varies from point
//! to point ([`crate::lattice::voronoi::graded`]), calibrated on a block of the foam at the
//! part's own voxel. A foam has no repeating cell, so its density is promised over blocks of
//! about [`BLOCK_SPACINGS`] spacings that split the box evenly: each holds a few cells, whose
//! sizes vary as a random foam's do, and the correction meets the field in each.

use super::job::{VoronoiJob, VoronoiReport};
use crate::error::{Error, Result};
use crate::field::{Aabb, Vec3};
use crate::io::sink::MeshSink;
use crate::lattice::voronoi::graded::calibrate;
use crate::lattice::voronoi::{FoamFamily, Structure};
use crate::mesh::graded::{self, Feasible, Grading, Mapped, Run};
use crate::mesh::pipeline::{Family, Options};
use crate::mesh::report::Timings;
use crate::mesh::resolution::max_resolution;
use crate::progress::Progress;
use std::sync::Arc;
use std::time::Instant;

/// A graded foam's blocks are about this many (smallest) spacings wide.
pub const BLOCK_SPACINGS: f64 = 2.0;

/// The calibration region's edge, in (smallest) spacings at most: some 30 cells, enough for the
/// meshing's bias at each density (the correction meets each block's).
const CALIBRATION_SPACINGS: f64 = 3.0;

impl VoronoiJob {
    /// The blocks a graded foam's density is met in: about [`BLOCK_SPACINGS`] spacings wide, a
    /// whole number of them across the box.
    pub fn grading_block(&self, spacing: [f64; 2]) -> Vec3 {
        let size = self.bounds.size();
        size.map(|s| s / (s / (BLOCK_SPACINGS * spacing[0])).round().max(1.0))
    }

    /// Runs a graded job (see [`crate::mesh::graded`]).
    pub(super) fn run_graded(
        &self,
        grading: &Grading,
        progress: &Progress,
        sink: &mut dyn MeshSink,
    ) -> Result<VoronoiReport> {
        let start = Instant::now();
        grading.without_skin()?;
        if self.period.is_some() {
            return Err(Error::invalid(match self.structure {
                Structure::Net => "a graded periodic net is graded as a strut lattice, cell by repeating cell: make it with latvox voronoi",
                Structure::Sheet => "a periodic sheet cannot be graded: drop --periodic (a random sheet is graded block by block), or give one --density",
            }));
        }
        let (foam, spacing) = self.foam(progress)?;
        let family = FoamFamily {
            foam: Arc::new(foam),
            bounds: self.bounds,
        };
        let model_seconds = start.elapsed().as_secs_f64();
        // The thinnest members the finest resolution allowed can hold, and where pores close.
        let finest = if self.auto_resolution {
            max_resolution(self.resolution)
        } else {
            self.resolution
        };
        let range = self.range(&family, self.voxel(spacing, finest));
        let feasible = Feasible {
            min: range.min_density,
            max: range.max_density,
            what: self.name().trim_start_matches("the ").to_string(),
            why: if self.auto_resolution {
                "members are under 2 voxels across at the finest resolution latvox would try, or the pores close"
            } else {
                "members are under 2 voxels across, or the pores close"
            },
        };
        let block = self.grading_block(spacing);
        let targets = grading.check(&self.bounds, block, &|_| Some(0.0), &feasible)?;
        // Members are thinnest at the lowest density.
        let (resolution, warnings) = graded::raised(
            self.resolution,
            self.thin(family.model_level(targets.built[0]), spacing)?,
            self.auto_resolution,
            "break",
        )?;
        let voxel = self.voxel(spacing, resolution);
        let opts = Options {
            instancing: false,
            ..self.options
        };
        let cal_start = Instant::now();
        let (map, met) = {
            let _p = progress.stage("calibrating the density → size map");
            calibrate(
                &family,
                self.calibration_region(spacing),
                voxel,
                &opts,
                targets.built[0],
                targets.built[1],
            )?
        };
        let calibrate_seconds = model_seconds + cal_start.elapsed().as_secs_f64();
        let kind = Mapped {
            lattice: family,
            map,
        };
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
        .in_box(&kind, self.bounds, block, progress, sink)?;
        let level = done.mean_level;
        let foam = &kind.lattice.foam;
        let (seeding, seed, regularity) = self.seeding_report();
        Ok(VoronoiReport {
            structure: self.structure,
            seeding,
            seed,
            regularity,
            spacing,
            radius: (self.structure == Structure::Net).then_some(level),
            thickness: (self.structure == Structure::Sheet).then_some(level),
            member_voxels: self.across(kind.map.level(targets.built[0]), voxel),
            feasible_range: self.range(&kind.lattice, voxel),
            level_search: done.level_search,
            resolution_requested: self.resolution,
            resolution,
            voxel_size: voxel,
            period: None,
            foam: foam.stats,
            grading: Some(done.grading),
            block: Some(block),
            part: done.part,
            seeds: foam.own_seeds().to_vec(),
            cell: None,
        })
    }

    /// The part of the box the foam is calibrated on: [`CALIBRATION_SPACINGS`] a side at most,
    /// about the box's middle.
    fn calibration_region(&self, spacing: [f64; 2]) -> Aabb {
        let size = self.bounds.size();
        let c = [0, 1, 2].map(|a| 0.5 * (self.bounds.min[a] + self.bounds.max[a]));
        let half = [0, 1, 2].map(|a| 0.5 * size[a].min(CALIBRATION_SPACINGS * spacing[0]));
        Aabb {
            min: [0, 1, 2].map(|a| c[a] - half[a]),
            max: [0, 1, 2].map(|a| c[a] + half[a]),
        }
    }
}
