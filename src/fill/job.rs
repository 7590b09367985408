//! One fill job, start to finish: close the part (latvox's repair, or a refusal naming what
//! stays open), build its distance grid, measure the region the lattice fills (the whole part
//! less the skin and the kept solids), find the lattice level at which the lattice fills that
//! region to the target density — on the filled part itself, loose fragments removed — raising
//! the resolution where the lattice or the skin is too thin for the voxels, then mesh, verify,
//! write and report. The meshing is [`crate::mesh::pipeline`]'s, the resolution search
//! [`crate::mesh::resolution`]'s.

use super::shape::{Drain, FillFamily, FillSolid, Infill, Shape};
use crate::error::{Error, Result};
use crate::field::{Aabb, Vec3};
use crate::geom::Mesh;
use crate::io::sink::{MeshCollector, MeshSink};
use crate::lattice::strut::MIN_STRUT_VOXELS;
use crate::lattice::strut::{RadiusModel, StrutFamily, StrutLattice, UnitCell};
use crate::lattice::tpms::MIN_WALL_VOXELS;
use crate::lattice::tpms::{calibrate, Lattice, LatticeFamily, Structure, Surface};
use crate::mesh::graded::{Grading, GradingReport};
use crate::mesh::pipeline::{self, Family, Measured, MeshingStats, Options, Route};
use crate::mesh::report::{LevelSearch, PartReport, Timings};
use crate::mesh::resolution::{self, Resolved};
use crate::progress::Progress;
use crate::repair::{repair, Change, RepairOptions};
use crate::verify::Verdict;
use std::sync::Arc;
use std::time::Instant;

/// A skin thinner than this many voxels is not represented faithfully (samples miss it and it
/// perforates): the resolution is raised to keep it this thick.
pub const MIN_SKIN_VOXELS: f64 = 2.0;

/// The lattice that fills the part.
#[derive(Debug, Clone)]
pub enum Infilling {
    /// A triply periodic minimal surface lattice.
    Tpms {
        /// Which surface.
        surface: Surface,
        /// Net or sheet.
        structure: Structure,
    },
    /// A strut lattice.
    Strut {
        /// Its unit cell.
        cell: Arc<UnitCell>,
    },
}

/// What to build.
#[derive(Debug, Clone)]
pub struct FillJob {
    /// The part: a closed triangle mesh (an open one is repaired first, or refused).
    pub part: Mesh,
    /// The part's name, for messages and the report (its file).
    pub part_name: String,
    /// Solids kept whole (bosses, flanges), with their names.
    pub keep: Vec<(String, Mesh)>,
    /// Skin thickness, mm (0: no skin, an open-cell part).
    pub skin: f64,
    /// The lattice.
    pub lattice: Infilling,
    /// Its name, for messages and the report.
    pub lattice_name: String,
    /// Cell size per axis, mm.
    pub cell: Vec3,
    /// The lattice's volume fraction in the region it fills, in (0, 1).
    pub density: f64,
    /// Radius of the smooth minimum joining the lattice to the skin (and struts at their
    /// joints), mm.
    pub blend: f64,
    /// Diameter of the drain holes through the skin, mm (none when not given).
    pub drain: Option<f64>,
    /// Voxels per cell along the cell's shortest axis.
    pub resolution: u32,
    /// Raise the resolution when the lattice or the skin would be too thin for the voxels.
    pub auto_resolution: bool,
    /// The pipeline's options.
    pub options: Options,
    /// A density that varies through the part (of `x, y, z` and `d`, the depth below the
    /// skin), instead of `density`.
    pub grading: Option<Grading>,
}

/// The JSON report of a fill job.
#[derive(Debug, Clone, serde::Serialize)]
pub struct FillReport {
    /// The part filled (its file).
    pub input: String,
    /// What latvox's repair changed to close the part (empty for a closed part).
    pub repair: Vec<Change>,
    /// The solids kept whole (their files).
    pub keep: Vec<String>,
    /// Skin thickness, mm (0: no skin).
    pub skin: f64,
    /// The lattice: a TPMS name or a strut cell.
    pub lattice: String,
    /// Net or sheet, for a TPMS lattice.
    pub structure: Option<Structure>,
    /// Cell size per axis, mm.
    pub cell_size: Vec3,
    /// The lattice's level: the TPMS level `t`, or the strut radius in mm.
    pub level: f64,
    /// Radius of the smooth minimum at the lattice's joins, mm.
    pub blend: f64,
    /// Drain holes through the skin (empty when none were asked for).
    pub drains: Vec<Drain>,
    /// Volume of the whole part (and kept solids) meshed solid, mm³.
    pub part_volume: f64,
    /// Volume of the skin and kept solids alone, mm³.
    pub skin_volume: f64,
    /// Volume of the region the lattice fills (`part_volume − skin_volume`), mm³: the
    /// density (`achieved_density`) is the lattice's share of it.
    pub fill_volume: f64,
    /// How the level was found (fractions of the fill region).
    pub level_search: LevelSearch,
    /// Voxels per cell asked for.
    pub resolution_requested: u32,
    /// Voxels per cell used.
    pub resolution: u32,
    /// Voxel edge, mm.
    pub voxel_size: f64,
    /// Memory of the part's distance grids, bytes.
    pub distance_grid_bytes: u64,
    /// How a graded fill met its density field, cell by cell (the cells wholly inside the core
    /// are promised); its `level` is the mean.
    pub grading: Option<GradingReport>,
    /// The part as written: `target_density` and `achieved_density` are the lattice's share of
    /// the fill region; mesh, checks, fragments (lattice pieces the part's surface cut loose,
    /// removed), timings, warnings.
    #[serde(flatten)]
    pub part: PartReport,
}

impl FillReport {
    /// The part's verdict.
    pub fn verdict(&self) -> Verdict {
        self.part.verdict()
    }
}

/// A resolution at which the filled part reaches its density.
pub(super) struct Found<F: Family> {
    pub(super) voxel: f64,
    pub(super) route: Route,
    /// The pipeline's options, the budget less the distance grid.
    pub(super) options: Options,
    pub(super) family: FillFamily<F>,
    pub(super) best: Measured,
    pub(super) tried: Vec<(f64, f64)>,
    pub(super) meshing: MeshingStats,
    pub(super) grid_bytes: u64,
}

/// The job's part and kept solids, closed, and what closing the part changed.
pub(super) fn closed_parts(
    job: &FillJob,
    progress: &Progress,
) -> Result<(Mesh, Vec<Mesh>, Vec<Change>)> {
    let (part, changes) = {
        let _p = progress.stage("checking the part is closed");
        closed(&job.part, &job.part_name)?
    };
    let keep = job
        .keep
        .iter()
        .map(|(name, m)| closed(m, name).map(|(m, _)| m))
        .collect::<Result<Vec<_>>>()?;
    Ok((part, keep, changes))
}

/// Closes `mesh` with latvox's repair, or refuses it naming what stays open.
pub fn closed(mesh: &Mesh, name: &str) -> Result<(Mesh, Vec<Change>)> {
    if mesh.triangle_count() == 0 {
        return Err(Error::invalid(format!("{name}: no triangles")));
    }
    let (m, report) = repair(mesh, &RepairOptions::default(), &Progress::new(true))?;
    if !report.open_shells.is_empty() || report.non_orientable_shells > 0 {
        let edges: u64 = report.open_shells.iter().map(|s| s.boundary_edges).sum();
        return Err(Error::invalid(format!(
            "{name}: not a closed solid, and repair could not close it ({} open shell{}, {edges} boundary edges, {} one-sided shells); mend it with `latvox repair` or another tool first",
            report.open_shells.len(),
            if report.open_shells.len() == 1 { "" } else { "s" },
            report.non_orientable_shells,
        )));
    }
    let volume = m.volume();
    if volume.is_nan() || volume <= 0.0 {
        return Err(Error::invalid(format!("{name}: encloses no volume")));
    }
    Ok((m, report.changes))
}

impl FillJob {
    /// The part's and the kept solids' distance grids at `voxel` mm, with the drain holes.
    pub(super) fn shape(&self, part: &Mesh, keep: &[Mesh], voxel: f64) -> Result<Arc<Shape>> {
        let mut depth = self.skin + self.blend;
        if self
            .grading
            .as_ref()
            .is_some_and(|g| g.field.uses_distance())
        {
            // The field reads the depth below the skin everywhere: the grid is exact through
            // the whole part (no point lies deeper than half its smallest extent).
            let b = part.bounds().expect("a part has triangles");
            let least = (0..3)
                .map(|a| b.max[a] - b.min[a])
                .fold(f64::INFINITY, f64::min);
            depth = depth.max(0.5 * least + voxel);
        }
        let mut shape = Shape::new(part, keep, voxel, depth)?;
        if let (Some(d), true) = (self.drain, self.skin > 0.0) {
            self.check_drain(part, d)?;
            shape.drains = Drain::at_ends(part, d, self.skin + self.blend + voxel);
        }
        Ok(Arc::new(shape))
    }

    /// The pipeline's options beside `shape`'s distance grid, which is held throughout: the
    /// meshing gets the rest of the budget.
    pub(super) fn beside(&self, shape: &Shape, opts: &Options) -> Options {
        Options {
            memory: Some(
                opts.memory
                    .unwrap_or(pipeline::DEFAULT_MEMORY)
                    .saturating_sub(shape.memory_bytes()),
            ),
            ..*opts
        }
    }

    /// The volume of the whole part and of its skin and kept solids alone on `voxel`, mm³, and
    /// the meshings that measured them; refused when the skin leaves no room for a lattice.
    pub(super) fn regions(
        &self,
        shape: &Arc<Shape>,
        keep: &[Mesh],
        voxel: f64,
        opts: &Options,
        progress: &Progress,
    ) -> Result<(f64, f64, MeshingStats)> {
        let solid = |infill| FillSolid::<crate::lattice::tpms::Lattice> {
            shape: shape.clone(),
            skin: self.skin,
            blend: self.blend,
            infill,
        };
        let route = Route::choose(&solid(Infill::Full), voxel, opts);
        let (whole, mut meshing) = {
            let _p = progress.stage("measuring the part");
            pipeline::solid_volume(&solid(Infill::Full), voxel, route)?
        };
        let base = if self.skin == 0.0 && keep.is_empty() {
            0.0
        } else {
            let _p = progress.stage("measuring the skin");
            let (v, m) = pipeline::solid_volume(&solid(Infill::Empty), voxel, route)?;
            meshing.add(&m);
            v
        };
        let fill = whole - base;
        if fill.is_nan() || fill <= 1e-6 * whole {
            return Err(Error::invalid(format!(
                "a skin of {} mm leaves no room for a lattice in {}: it is thicker than half the part",
                self.skin, self.part_name
            )));
        }
        Ok((whole, base, meshing))
    }

    /// Refuses a drain hole wider than half the part's smallest extent.
    pub(super) fn check_drain(&self, part: &Mesh, d: f64) -> Result<()> {
        let b = part.bounds().expect("a part has triangles");
        let least = (0..3)
            .map(|a| b.max[a] - b.min[a])
            .fold(f64::INFINITY, f64::min);
        if d > 0.5 * least {
            return Err(Error::invalid(format!(
                "a drain hole of {d} mm is too wide for {}: at most half its smallest extent, {} mm",
                self.part_name,
                0.5 * least
            )));
        }
        Ok(())
    }

    fn validate(&self) -> Result<()> {
        resolution::check_density(self.density)?;
        if !(self.skin >= 0.0 && self.skin.is_finite()) {
            return Err(Error::invalid(format!(
                "skin must be a thickness ≥ 0 mm, got {}",
                self.skin
            )));
        }
        resolution::check_blend(self.blend)?;
        if let Some(c) = self.cell.iter().find(|c| !(**c > 0.0 && c.is_finite())) {
            return Err(Error::invalid(format!(
                "cell size must be a positive length in mm, got {c}"
            )));
        }
        resolution::check_resolution(self.resolution)
    }

    /// Runs the job and returns the mesh with its report.
    pub fn run(&self, progress: &Progress) -> Result<(Mesh, FillReport)> {
        let mut collector = MeshCollector::default();
        let report = self.run_into(progress, &mut collector)?;
        Ok((collector.mesh, report))
    }

    /// The shortest cell side, mm.
    pub(super) fn min_cell(&self) -> f64 {
        self.cell.iter().cloned().fold(f64::INFINITY, f64::min)
    }

    /// Runs the job, streaming the filled part's triangles into `sink`.
    pub fn run_into(&self, progress: &Progress, sink: &mut dyn MeshSink) -> Result<FillReport> {
        let start = Instant::now();
        self.validate()?;
        if let Some(g) = &self.grading {
            return self.run_graded(g, progress, sink);
        }
        let (part, keep, changes) = closed_parts(self, progress)?;
        self.with_lattice(
            &part,
            &keep,
            progress,
            Write {
                changes,
                start,
                sink,
            },
        )
    }

    /// Finds the lattice's resolution and level for the closed `part` and `keep` as the mesh
    /// is made at, and hands them to `then` (which writes the part, or keeps its level).
    pub(super) fn with_lattice<T: Then>(
        &self,
        part: &Mesh,
        keep: &[Mesh],
        progress: &Progress,
        then: T,
    ) -> Result<T::Out> {
        match &self.lattice {
            Infilling::Tpms { surface, structure } => {
                let (s, st) = (*surface, *structure);
                let t0 = calibrate::analytic_level(s, st, self.density);
                let walls = (st == Structure::Sheet).then(|| {
                    (
                        calibrate::thinnest_sheet_wall(s, t0) * self.resolution as f64,
                        MIN_WALL_VOXELS,
                        "sheet walls",
                    )
                });
                let make = |bounds: Aabb, phase: Vec3| LatticeFamily {
                    part: Lattice {
                        surface: s,
                        structure: st,
                        level: t0,
                        cell: self.cell,
                        bounds,
                        phase,
                    },
                };
                let searched = Instant::now();
                let found = self.search_with(part, keep, make, t0, walls, progress)?;
                then.then(self, found, searched, progress)
            }
            Infilling::Strut { cell } => {
                let model = Arc::new(RadiusModel::new(cell, self.cell));
                let r0 = model.radius(self.density);
                if r0 >= model.closing {
                    return Err(Error::invalid(format!(
                        "the {} lattice at density {} closes up: its pores close at radius {:.4} mm (density {:.3}), trapping powder or resin; give a lower density",
                        self.lattice_name,
                        self.density,
                        model.closing,
                        model.fraction(model.closing),
                    )));
                }
                let factor = cell.thinnest_factor();
                let across = 2.0 * r0 * factor * self.resolution as f64 / self.min_cell();
                let make = |bounds: Aabb, phase: Vec3| StrutFamily {
                    part: StrutLattice {
                        cell: cell.clone(),
                        size: self.cell,
                        radius: r0,
                        blend: self.blend,
                        bounds,
                        phase,
                    },
                    model: model.clone(),
                };
                let members = Some((across, MIN_STRUT_VOXELS, "struts"));
                let searched = Instant::now();
                let found = self.search_with(part, keep, make, r0, members, progress)?;
                then.then(self, found, searched, progress)
            }
        }
    }

    /// The resolution the lattice's members (`members`: their width in voxels at the requested
    /// resolution, the least they need, and what they are) and the skin need, when the
    /// requested one falls short, and why.
    pub(super) fn thin(&self, members: Option<(f64, f64, &str)>) -> Option<(u32, String)> {
        let r = self.resolution;
        let mut needs: Vec<(u32, String)> = Vec::new();
        if let Some((w, min, what)) = members.filter(|(w, min, _)| w < min) {
            needs.push((
                (r as f64 * min / w).ceil() as u32,
                format!("{what} were {w:.2} voxels across at {r} voxels per cell"),
            ));
        }
        let skin_voxels = self.skin * r as f64 / self.min_cell();
        if self.skin > 0.0 && skin_voxels < MIN_SKIN_VOXELS {
            needs.push((
                (r as f64 * MIN_SKIN_VOXELS / skin_voxels).ceil() as u32,
                format!("the skin was {skin_voxels:.2} voxels thick at {r} voxels per cell"),
            ));
        }
        needs.into_iter().max_by_key(|(n, _)| *n)
    }

    /// The resolution search of the part filled with the lattices `make` gives (for a box and
    /// the cells' corner), from the level `start_level`.
    fn search_with<F: Family>(
        &self,
        part: &Mesh,
        keep: &[Mesh],
        make: impl Fn(Aabb, Vec3) -> F,
        start_level: f64,
        members: Option<(f64, f64, &str)>,
        progress: &Progress,
    ) -> Result<Resolved<Found<F>>>
    where
        F::Solid: Clone,
    {
        let opts = &self.options;
        let request = resolution::Request {
            part: format!(
                "the {} lattice filling {}",
                self.lattice_name, self.part_name
            ),
            setting: format!("density {}", self.density),
            requested: self.resolution,
            thin: self.thin(members),
            density: Some(self.density),
            auto: self.auto_resolution,
            per: "cell",
        };
        resolution::search(&request, &mut |r| {
            let voxel = self.min_cell() / r as f64;
            let shape = {
                let _p = progress.stage("building the part's distance field");
                self.shape(part, keep, voxel)?
            };
            let lattice = make(shape.bounds, shape.corner);
            let solid = |infill| FillSolid {
                shape: shape.clone(),
                skin: self.skin,
                blend: self.blend,
                infill,
            };
            let opts = &self.beside(&shape, opts);
            let (whole, base, mut meshing) = self.regions(&shape, keep, voxel, opts, progress)?;
            let fill = whole - base;
            let family = FillFamily {
                lattice,
                part: solid(Infill::Empty),
                base_volume: base,
                fill_volume: fill,
            };
            // Tiles are sized for the lattice's surface, not the bare part's.
            let route = Route::choose(&family.at(start_level), voxel, opts);
            let solved = {
                let _p = progress.stage(if r == self.resolution {
                    "finding the lattice's level"
                } else {
                    "searching for a resolution that reaches the density"
                });
                pipeline::solve(&family, self.density, start_level, voxel, route, opts)?
            };
            if !solved.met {
                return Ok(Err(solved.best.fraction));
            }
            meshing.add(&solved.meshing);
            Ok(Ok(Found {
                voxel,
                route,
                options: *opts,
                grid_bytes: shape.memory_bytes(),
                family,
                best: solved.best,
                tried: solved.tried,
                meshing,
            }))
        })
    }
}

/// What is done with the lattice's level once found (the search began at `searched`): the part
/// written, or its level kept.
pub(super) trait Then {
    type Out;
    fn then<F: Family>(
        self,
        job: &FillJob,
        found: Resolved<Found<F>>,
        searched: Instant,
        progress: &Progress,
    ) -> Result<Self::Out>
    where
        F::Solid: Clone;
}

/// The part written to a sink and reported.
struct Write<'a> {
    changes: Vec<Change>,
    start: Instant,
    sink: &'a mut dyn MeshSink,
}

impl Then for Write<'_> {
    type Out = FillReport;

    fn then<F: Family>(
        self,
        job: &FillJob,
        resolved: Resolved<Found<F>>,
        searched: Instant,
        progress: &Progress,
    ) -> Result<FillReport>
    where
        F::Solid: Clone,
    {
        let Write {
            changes,
            start,
            sink,
        } = self;
        // The lattice's model was made by the time the search began.
        let model_seconds = searched.duration_since(start).as_secs_f64();
        let Found {
            voxel,
            route,
            options,
            family,
            best,
            tried,
            meshing,
            grid_bytes,
        } = resolved.found;
        let level = best.level;
        let level_search = LevelSearch::new(&best, route, &tried, resolved.coarser);
        let written = pipeline::write(&family, best, voxel, route, &options, progress, sink)?;
        let bounds = family.part.shape.bounds;
        let mut report = PartReport::new(
            bounds,
            None,
            route,
            written,
            meshing,
            Timings {
                calibrate: model_seconds,
                ..Timings::default()
            },
        );
        let volume = report.volume.unwrap_or(f64::NAN);
        report.density_against(job.density, family.fraction(volume, &bounds));
        let mut warnings: Vec<String> = resolved.raised.into_iter().collect();
        warnings.append(&mut report.warnings);
        report.warnings = warnings;
        report.timings.total = start.elapsed().as_secs_f64();
        Ok(job.report(
            changes,
            family.part.shape.drains.clone(),
            grid_bytes,
            Filled {
                level,
                level_search,
                part_volume: family.base_volume + family.fill_volume,
                skin_volume: family.base_volume,
                resolution: resolved.resolution,
                voxel,
                grading: None,
                part: report,
            },
        ))
    }
}

/// What a fill's meshing found, for its report.
pub(super) struct Filled {
    pub level: f64,
    pub level_search: LevelSearch,
    pub part_volume: f64,
    pub skin_volume: f64,
    pub resolution: u32,
    pub voxel: f64,
    pub grading: Option<GradingReport>,
    pub part: PartReport,
}

impl FillJob {
    /// The job's report: its settings, the repairs made to its input and what the meshing found.
    pub(super) fn report(
        &self,
        repair: Vec<Change>,
        drains: Vec<Drain>,
        grid_bytes: u64,
        f: Filled,
    ) -> FillReport {
        FillReport {
            input: self.part_name.clone(),
            repair,
            keep: self.keep.iter().map(|(n, _)| n.clone()).collect(),
            skin: self.skin,
            lattice: self.lattice_name.clone(),
            structure: match &self.lattice {
                Infilling::Tpms { structure, .. } => Some(*structure),
                Infilling::Strut { .. } => None,
            },
            cell_size: self.cell,
            level: f.level,
            blend: self.blend,
            drains,
            part_volume: f.part_volume,
            skin_volume: f.skin_volume,
            fill_volume: f.part_volume - f.skin_volume,
            level_search: f.level_search,
            resolution_requested: self.resolution,
            resolution: f.resolution,
            voxel_size: f.voxel,
            distance_grid_bytes: grid_bytes,
            grading: f.grading,
            part: f.part,
        }
    }
}
