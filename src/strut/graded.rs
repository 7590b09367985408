//! Graded strut lattices: a density that varies through the part, met cell by cell by
//! [`crate::mesh::graded`]; here is the cell's side of it: its density → radius map (one cell
//! meshed at the part's own voxel at a handful of densities, the radius found for each by the
//! pipeline's search, the meshing's bias against the radius model interpolated between them)
//! and the lattice whose strut radius varies from point to point — a strut is as thick at a
//! point as the density there asks.

use super::job::{StrutJob, StrutReport};
use crate::error::Result;
use crate::io::sink::MeshSink;
use crate::lattice::strut::graded::calibrate;
use crate::mesh::graded::{self, Feasible, Grading, Mapped, Run};
use crate::mesh::pipeline::Options;
use crate::mesh::report::Timings;
use crate::mesh::resolution::max_resolution;
use crate::progress::Progress;
use std::time::Instant;

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
