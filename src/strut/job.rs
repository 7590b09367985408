//! One strut-lattice job, start to finish: check the request against what the cell allows
//! (struts at least [`MIN_STRUT_VOXELS`] across, pores that stay open), find the strut radius
//! that gives *this* part its density (or take the radius given), raising the resolution when
//! the struts are too thin for the voxels, mesh, verify, write and report — the meshing is
//! [`crate::mesh::pipeline`]'s, the resolution search [`crate::mesh::resolution`]'s.

use super::{RadiusModel, StrutFamily, StrutLattice, UnitCell};
use crate::error::{Error, Result};
use crate::field::{Aabb, Domain};
use crate::geom::Mesh;
use crate::io::sink::{MeshCollector, MeshSink};
use crate::io::threemf::BeamModel;
use crate::mesh::graded::{Grading, GradingReport};
use crate::mesh::pipeline::{self, Family, Found, Options, Route};
use crate::mesh::report::{LevelSearch, PartReport};
use crate::mesh::resolution::{self, max_resolution, Resolved};
use crate::progress::Progress;
use crate::verify::Verdict;
use std::sync::Arc;
use std::time::Instant;

pub use crate::lattice::strut::MIN_STRUT_VOXELS;

/// How thick the struts are: made to a volume fraction, or given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Sizing {
    /// The radius that gives the written part this volume fraction, in (0, 1).
    Density(f64),
    /// This radius, mm.
    Radius(f64),
}

/// What to build.
#[derive(Debug, Clone)]
pub struct StrutJob {
    /// The unit cell.
    pub cell: Arc<UnitCell>,
    /// Its name, for messages and the report (a built-in name or the cell file).
    pub cell_name: String,
    /// Density or radius.
    pub sizing: Sizing,
    /// Radius of the smooth minimum at the joints, mm (0: a sharp union).
    pub blend: f64,
    /// The box: cell size, overall size and lower corner, mm.
    pub domain: Domain,
    /// Voxels per cell along the cell's shortest axis.
    pub resolution: u32,
    /// Raise the resolution when struts would be thinner than [`MIN_STRUT_VOXELS`] or no
    /// radius on these voxels gives the density.
    pub auto_resolution: bool,
    /// The pipeline's options.
    pub options: Options,
    /// A density that varies through the part, instead of `sizing`.
    pub grading: Option<Grading>,
}

/// The radii (and densities) a cell can be built at.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct StrutRange {
    /// The thinnest struts, at [`MIN_STRUT_VOXELS`] across at the resolution used, mm.
    pub min_radius: f64,
    /// The radius at which the pores close, mm.
    pub max_radius: f64,
    /// The cell's volume fraction at `min_radius` (the radius model's).
    pub min_density: f64,
    /// The cell's volume fraction at `max_radius` (the radius model's).
    pub max_density: f64,
}

/// The JSON report of a strut job.
#[derive(Debug, Clone, serde::Serialize)]
pub struct StrutReport {
    /// The unit cell: a built-in name or the cell file.
    pub cell: String,
    /// Nodes and struts of one period of the cell (each strut once).
    pub cell_nodes: usize,
    /// Struts of one period of the cell.
    pub cell_struts: usize,
    /// The strut radius written, mm (times each node's factor).
    pub radius: f64,
    /// Radius of the smooth minimum at the joints, mm.
    pub blend: f64,
    /// Thinnest strut, voxels across.
    pub thinnest_strut_voxels: f64,
    /// What the cell allows.
    pub feasible_range: StrutRange,
    /// How the radius was found (its levels are radii).
    pub level_search: LevelSearch,
    /// Voxels per cell asked for.
    pub resolution_requested: u32,
    /// Voxels per cell used.
    pub resolution: u32,
    /// Voxel edge, mm.
    pub voxel_size: f64,
    /// Cell size per axis, mm.
    pub cell_size: [f64; 3],
    /// Cells per axis (fractional where the box ends inside a cell).
    pub cells: [f64; 3],
    /// How a graded part met its density field, cell by cell (its `radius` is the mean).
    pub grading: Option<GradingReport>,
    /// The part as written: density, mesh, checks, timings, warnings.
    #[serde(flatten)]
    pub part: PartReport,
}

impl StrutReport {
    /// The part's verdict.
    pub fn verdict(&self) -> Verdict {
        self.part.verdict()
    }
}

/// The JSON report of a strut job written as beams.
#[derive(Debug, Clone, serde::Serialize)]
pub struct BeamsReport {
    /// The unit cell: a built-in name or the cell file.
    pub cell: String,
    /// The beams' radius, mm (times each node's factor).
    pub radius: f64,
    /// The volume fraction asked for (`null` when the radius was given).
    pub target_density: Option<f64>,
    /// The volume fraction of the part meshed at this radius, which the radius was found on
    /// (`null` when the radius was given).
    pub meshed_density: Option<f64>,
    /// Voxels per cell of that meshing.
    pub resolution: Option<u32>,
    /// Beams written.
    pub beams: u64,
    /// Vertices the beams join.
    pub vertices: u64,
    /// What clips the beams: the box, as a clipping mesh.
    pub clipped_by: &'static str,
    /// The part's box, mm.
    #[serde(rename = "box")]
    pub bounds: Aabb,
    /// Cell size per axis, mm.
    pub cell_size: [f64; 3],
    /// Cells per axis (fractional where the box ends inside a cell).
    pub cells: [f64; 3],
    /// Wall time, seconds.
    pub seconds: f64,
    /// The output file, when the command line wrote one.
    pub output: Option<String>,
}

impl BeamsReport {
    /// The beams' verdict: no surface to check (the beams are capsules by definition), so only
    /// whether the meshed part the radius was found on met its density.
    pub fn verdict(&self) -> Verdict {
        Verdict::of_beams(
            self.target_density
                .zip(self.meshed_density)
                .map(|(t, f)| (f - t).abs() <= pipeline::PROMISE),
        )
    }
}

impl StrutJob {
    fn validate(&self) -> Result<()> {
        match self.sizing {
            Sizing::Density(d) => resolution::check_density(d)?,
            Sizing::Radius(r) if !(r > 0.0 && r.is_finite()) => {
                return Err(Error::setting(
                    "radius",
                    format!("radius must be a positive length in mm, got {r}"),
                ))
            }
            _ => {}
        }
        resolution::check_blend(self.blend)?;
        resolution::check_resolution(self.resolution)
    }

    /// Runs the job and returns the mesh with its report.
    pub fn run(&self, progress: &Progress) -> Result<(Mesh, StrutReport)> {
        let mut collector = MeshCollector::default();
        let report = self.run_into(progress, &mut collector)?;
        Ok((collector.mesh, report))
    }

    /// The part as an implicit solid: the radius given, or the one its mesh is made to the
    /// density at (the same search, on the same voxels; in tiles beyond
    /// [`crate::render::MODEL_MEMORY`]), for slices moved so that it encloses the mesh's volume
    /// ([`crate::render::Fidelity`]); with the fragments the mesh drops.
    pub fn model(&self, fidelity: crate::render::Fidelity) -> Result<crate::render::Model> {
        self.validate()?;
        if self.grading.is_some() {
            return Err(Error::invalid(
                "a graded part is drawn and sliced from its mesh: make it with -o part.stl, then render, view or slice part.stl",
            ));
        }
        let (family, _) = self.family();
        let bounded = StrutJob {
            options: crate::render::model_options(&self.options),
            ..self.clone()
        };
        let resolved = bounded.search(&family, &Progress::hidden())?;
        let given = match self.sizing {
            Sizing::Radius(r) => Some(r),
            Sizing::Density(_) => None,
        };
        crate::render::Model::of_struts(&family, &resolved.found, given, self.target(), fidelity)
    }

    /// The voxel edge at `resolution` voxels per cell, mm.
    pub(super) fn voxel(&self, resolution: u32) -> f64 {
        let c = self.domain.cell;
        c[0].min(c[1]).min(c[2]) / resolution as f64
    }

    /// The smallest radius factor: the thinnest strut is the radius times it.
    pub(super) fn thinnest_factor(&self) -> f64 {
        self.cell.thinnest_factor()
    }

    /// The radii and densities the cell allows at `resolution`.
    pub(super) fn range(&self, model: &RadiusModel, resolution: u32) -> StrutRange {
        let min_radius = 0.5 * MIN_STRUT_VOXELS * self.voxel(resolution) / self.thinnest_factor();
        StrutRange {
            min_radius,
            max_radius: model.closing,
            min_density: model.fraction(min_radius),
            max_density: model.fraction(model.closing),
        }
    }

    /// The lattice's family of radii, its model measured (and the seconds that took).
    pub(super) fn family(&self) -> (StrutFamily, f64) {
        let t = Instant::now();
        let bounds = self.domain.bounds();
        let family = StrutFamily::new(StrutLattice {
            cell: self.cell.clone(),
            size: self.domain.cell,
            radius: 0.0,
            blend: self.blend,
            bounds,
            phase: bounds.min,
        });
        (family, t.elapsed().as_secs_f64())
    }

    /// The target density, when the struts are made to one.
    fn target(&self) -> Option<f64> {
        match self.sizing {
            Sizing::Density(d) => Some(d),
            Sizing::Radius(_) => None,
        }
    }

    /// Finds the resolution and radius of the part: the radius given, or the one at which the
    /// part (or a template of its cells) meshes to the target density.
    fn search(&self, family: &StrutFamily, progress: &Progress) -> Result<Resolved<Found>> {
        let r0 = match self.sizing {
            Sizing::Density(d) => family.model_level(d),
            Sizing::Radius(r) => r,
        };
        let thin = self.thin_struts(r0)?;
        self.refuse_closed(&family.model, r0)?;
        let target = self.target();
        let request = resolution::Request {
            part: format!("the {} lattice", self.cell_name),
            setting: self.setting(),
            requested: self.resolution,
            thin,
            density: target,
            auto: self.auto_resolution,
            per: "cell",
        };
        let opts = &self.options;
        resolution::search(&request, &mut |r| {
            let _p = progress.stage(if r == self.resolution {
                "finding the strut radius"
            } else {
                "searching for a resolution that reaches the density"
            });
            let voxel = self.voxel(r);
            let route = Route::choose(&family.at(r0), voxel, opts);
            pipeline::find(family, target, r0, voxel, route, opts)
        })
    }

    /// Runs the job, streaming the part's triangles into `sink`.
    pub fn run_into(&self, progress: &Progress, sink: &mut dyn MeshSink) -> Result<StrutReport> {
        let start = Instant::now();
        self.validate()?;
        if let Some(g) = &self.grading {
            return self.run_graded(g, progress, sink);
        }
        let (family, model_seconds) = self.family();
        let resolved = self.search(&family, progress)?;
        let Found {
            voxel,
            route,
            best,
            tried,
            meshing,
        } = resolved.found;
        let radius = best.level;
        let level_search = LevelSearch::new(&best, route, &tried, resolved.coarser);
        let opts = &self.options;
        let written = pipeline::write(&family, best, voxel, route, opts, progress, sink)?;
        let part = PartReport::after_search(
            self.domain.bounds(),
            self.target(),
            route,
            written,
            meshing,
            model_seconds,
            resolved.raised,
            start,
        );
        Ok(StrutReport {
            cell: self.cell_name.clone(),
            cell_nodes: self.cell.nodes.len(),
            cell_struts: self.cell.struts.len(),
            radius,
            blend: self.blend,
            thinnest_strut_voxels: 2.0 * radius * self.thinnest_factor() / voxel,
            feasible_range: self.range(&family.model, resolved.resolution),
            level_search,
            resolution_requested: self.resolution,
            resolution: resolved.resolution,
            voxel_size: voxel,
            cell_size: self.domain.cell,
            cells: self.domain.counts(),
            grading: None,
            part,
        })
    }

    /// The lattice as beams (the 3MF Beam Lattice extension's): the struts of every cell that
    /// reach into the box, as capsules of the radius given or of the radius at which the meshed
    /// part has the target density, clipped by the box. Joints cannot be blended in beams.
    pub fn beams(&self, progress: &Progress) -> Result<(BeamModel, BeamsReport)> {
        let start = Instant::now();
        self.validate()?;
        if self.grading.is_some() {
            return Err(Error::invalid(
                "a graded lattice is written as a mesh: drop --beams",
            ));
        }
        if self.blend > 0.0 {
            return Err(Error::invalid(
                "blended joints cannot be written as beams (3MF beams are capsules and balls): drop --blend, or write a mesh",
            ));
        }
        let (family, _) = self.family();
        let (radius, measured, resolution) = match self.sizing {
            Sizing::Radius(r) => {
                self.refuse_closed(&family.model, r)?;
                (r, None, None)
            }
            Sizing::Density(_) => {
                let resolved = self.search(&family, progress)?;
                let best = &resolved.found.best;
                (best.level, Some(best.fraction), Some(resolved.resolution))
            }
        };
        let model = {
            let _p = progress.stage("listing the beams");
            super::beams::beams(&family.at(radius))
        };
        let report = BeamsReport {
            cell: self.cell_name.clone(),
            radius,
            target_density: self.target(),
            meshed_density: measured,
            resolution,
            beams: model.beams.len() as u64,
            vertices: model.vertices.len() as u64,
            clipped_by: "box",
            bounds: self.domain.bounds(),
            cell_size: self.domain.cell,
            cells: self.domain.counts(),
            seconds: start.elapsed().as_secs_f64(),
            output: None,
        };
        Ok((model, report))
    }

    /// The resolution struts of radius `r` need, when the requested one leaves them thinner
    /// than [`MIN_STRUT_VOXELS`], and why; refused when even the finest resolution searched
    /// would not do.
    pub(super) fn thin_struts(&self, r: f64) -> Result<Option<(u32, String)>> {
        let req = self.resolution;
        let across = 2.0 * r * self.thinnest_factor() / self.voxel(req);
        if across >= MIN_STRUT_VOXELS {
            return Ok(None);
        }
        let needed = (req as f64 * MIN_STRUT_VOXELS / across).ceil() as u32;
        let why = format!("struts were {across:.2} voxels across at {req} voxels per cell");
        if self.auto_resolution && needed > max_resolution(req) {
            return Err(Error::Resolution {
                requested: req,
                needed: Some(needed),
                message: format!(
                    "the {} lattice at {}: {why}, and would need {needed} voxels per cell; give a larger radius or density (at {req} voxels per cell: radius ≥ {:.4} mm), or --resolution {needed}",
                    self.cell_name,
                    self.setting(),
                    0.5 * MIN_STRUT_VOXELS * self.voxel(req) / self.thinnest_factor(),
                ),
            });
        }
        Ok(Some((needed, why)))
    }

    /// Refuses a radius at which the pores close: the void no longer runs through the lattice.
    fn refuse_closed(&self, model: &RadiusModel, r: f64) -> Result<()> {
        if r < model.closing {
            return Ok(());
        }
        let range = self.range(model, self.resolution);
        Err(Error::Infeasible {
            setting: "radius".into(),
            value: r,
            min: range.min_radius,
            max: range.max_radius,
            message: format!(
                "the {} lattice at {} closes up: its pores close at radius {:.4} mm (density {:.3}), trapping powder or resin; it can be built at radius {:.4} to {:.4} mm, density {:.3} to {:.3} (at {} voxels per cell)",
                self.cell_name,
                self.setting(),
                range.max_radius,
                range.max_density,
                range.min_radius,
                range.max_radius,
                range.min_density,
                range.max_density,
                self.resolution
            ),
        })
    }

    fn setting(&self) -> String {
        match self.sizing {
            Sizing::Density(d) => format!("density {d}"),
            Sizing::Radius(r) => format!("radius {r} mm"),
        }
    }
}
