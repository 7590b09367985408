//! One Voronoi-foam job, start to finish: seed the box and a margin round it, compute the
//! diagram (CGAL), refuse a level at which the pores close, find the strut radius or wall
//! thickness that gives *this* part its density (or take the one given) — raising the
//! resolution when members would be under [`MIN_STRUT_VOXELS`] across — then mesh, verify,
//! write and report, with the foam's cells and edges measured. The meshing is
//! [`crate::mesh::pipeline`]'s, the resolution search [`crate::mesh::resolution`]'s.

use crate::error::{Error, Result};
use crate::field::density::DensityField;
use crate::field::{Aabb, Vec3};
use crate::geom::Mesh;
use crate::io::sink::{MeshCollector, MeshSink};
use crate::io::threemf::BeamModel;
use crate::lattice::strut::beams::beams as strut_beams;
use crate::lattice::strut::{StrutFamily, StrutLattice, UnitCell, MIN_STRUT_VOXELS};
use crate::lattice::voronoi::{periodic, seeds, Foam, FoamFamily, FoamStats, Structure};
use crate::mesh::graded::{Grading, GradingReport};
use crate::mesh::instance;
use crate::mesh::pipeline::{self, Family, Found, Options, Route};
use crate::mesh::report::{LevelSearch, PartReport};
use crate::mesh::resolution::{self, max_resolution, Resolved};
use crate::progress::Progress;
use crate::verify::Verdict;
use std::sync::Arc;
use std::time::Instant;

/// How thick the members are: made to a volume fraction, or given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Sizing {
    /// The strut radius or wall thickness that gives the written part this volume fraction.
    Density(f64),
    /// This strut radius (net) or wall thickness (sheet), mm.
    Level(f64),
}

/// The mean spacing of the seeds (the edge of the mean cell), mm.
#[derive(Clone)]
pub enum Spacing {
    /// The same everywhere.
    Uniform(f64),
    /// A field over the box.
    Field(Arc<DensityField>),
}

impl Spacing {
    /// The spacing at `p`.
    pub fn at(&self, p: Vec3) -> f64 {
        match self {
            Spacing::Uniform(s) => *s,
            Spacing::Field(f) => f.at(p, 0.0),
        }
    }
}

/// Where the seeds come from.
#[derive(Clone)]
pub enum Seeding {
    /// Poisson-disk points at a spacing, moved toward the BCC lattice by a regularity.
    Poisson {
        /// The spacing.
        spacing: Spacing,
        /// The generator's seed.
        seed: u64,
        /// 0 (random) to 1 (the Kelvin foam).
        regularity: f64,
    },
    /// The user's points.
    Given(Vec<Vec3>),
}

/// What to build.
#[derive(Clone)]
pub struct VoronoiJob {
    /// Struts or walls.
    pub structure: Structure,
    /// The seeds.
    pub seeding: Seeding,
    /// Density or member size.
    pub sizing: Sizing,
    /// The part's box.
    pub bounds: Aabb,
    /// Voxels per spacing (the smallest, where it varies).
    pub resolution: u32,
    /// The edge of a cell that the foam repeats with, mm, starting at the box's lower corner
    /// (a periodic foam); `None` for a foam random through the whole box.
    pub period: Option<f64>,
    /// A sheet's pores: a round hole through each wall, this fraction (0 to 1) of the wall's
    /// inradius; 0 for closed cells.
    pub pores: f64,
    /// Raise the resolution when members would be too thin for the voxels.
    pub auto_resolution: bool,
    /// A density that varies through the part, met block by block (`sizing` is then not
    /// used); `None` for one density or member size.
    pub grading: Option<Grading>,
    /// The pipeline's options.
    pub options: Options,
}

/// The member sizes (and densities) the foam allows.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct VoronoiRange {
    /// The thinnest members, [`MIN_STRUT_VOXELS`] across at the resolution used: a strut
    /// radius or a wall thickness, mm.
    pub min_level: f64,
    /// The size at which the pores close.
    pub max_level: f64,
    /// The foam's volume fraction at `min_level` (its model's).
    pub min_density: f64,
    /// The foam's volume fraction at `max_level` (its model's).
    pub max_density: f64,
}

/// The JSON report of a Voronoi job.
#[derive(Debug, Clone, serde::Serialize)]
pub struct VoronoiReport {
    /// `net` or `sheet`.
    pub structure: Structure,
    /// Where the seeds came from: `poisson` or `file`.
    pub seeding: &'static str,
    /// The generator's seed (Poisson seeds).
    pub seed: Option<u64>,
    /// How far the seeds were moved toward the BCC lattice, 0 to 1.
    pub regularity: f64,
    /// The mean spacing (edge of the mean cell), least and greatest through the box, mm.
    pub spacing: [f64; 2],
    /// Strut radius of a net, mm.
    pub radius: Option<f64>,
    /// Wall thickness of a sheet, mm.
    pub thickness: Option<f64>,
    /// The members, voxels across.
    pub member_voxels: f64,
    /// What the foam allows.
    pub feasible_range: VoronoiRange,
    /// How the level was found.
    pub level_search: LevelSearch,
    /// Voxels per spacing asked for.
    pub resolution_requested: u32,
    /// Voxels per spacing used.
    pub resolution: u32,
    /// Voxel edge, mm.
    pub voxel_size: f64,
    /// The edge of the cell the foam repeats with, mm (`null`: random through the box).
    pub period: Option<f64>,
    /// The diagram: cells, their sizes, edge lengths (of one repeating cell, for a periodic
    /// foam).
    pub foam: FoamStats,
    /// A graded part's field and its blocks' densities (`cells` lists the blocks).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub grading: Option<GradingReport>,
    /// The blocks a graded foam's density is met in, from the box's lower corner, mm.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub block: Option<Vec3>,
    /// The part as written.
    #[serde(flatten)]
    pub part: PartReport,
    /// The seeds the diagram was made of (box and margin), for `--seeds-out`.
    #[serde(skip)]
    pub seeds: Vec<Vec3>,
    /// A periodic net's cell, as a strut cell.
    #[serde(skip)]
    pub cell: Option<Arc<UnitCell>>,
}

impl VoronoiReport {
    /// The part's verdict.
    pub fn verdict(&self) -> Verdict {
        self.part.verdict()
    }
}

/// The JSON report of a Voronoi net written as beams.
#[derive(Debug, Clone, serde::Serialize)]
pub struct VoronoiBeamsReport {
    /// The beams' radius, mm.
    pub radius: f64,
    /// The volume fraction asked for (`null` when the radius was given).
    pub target_density: Option<f64>,
    /// The volume fraction of the part meshed at this radius, which the radius was found on
    /// (`null` when the radius was given).
    pub meshed_density: Option<f64>,
    /// Voxels per spacing of that meshing.
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
    /// The diagram: cells, their sizes, edge lengths.
    pub foam: FoamStats,
    /// Wall time, seconds.
    pub seconds: f64,
    /// The output file, when the command line wrote one.
    pub output: Option<String>,
    /// The seeds the diagram was made of, for `--seeds-out`.
    #[serde(skip)]
    pub seeds: Vec<Vec3>,
}

impl VoronoiBeamsReport {
    /// The beams' verdict: capsules by definition, so only whether the meshed part the radius
    /// was found on met its density.
    pub fn verdict(&self) -> Verdict {
        Verdict::of_beams(
            self.target_density
                .zip(self.meshed_density)
                .map(|(t, f)| (f - t).abs() <= pipeline::PROMISE),
        )
    }
}

/// Points of the grid the spacing field is checked on, per axis.
const SPACING_PROBES: usize = 17;

impl VoronoiJob {
    fn validate(&self) -> Result<()> {
        match self.sizing {
            Sizing::Density(d) => resolution::check_density(d)?,
            Sizing::Level(l) if !(l > 0.0 && l.is_finite()) => {
                let name = self.structure.level_name();
                return Err(Error::setting(
                    name,
                    format!("{name} must be a positive length in mm, got {l}"),
                ));
            }
            _ => {}
        }
        if let Seeding::Poisson { regularity, .. } = self.seeding {
            if !(0.0..=1.0).contains(&regularity) {
                return Err(Error::setting(
                    "regularity",
                    format!("regularity must be in [0, 1], got {regularity}"),
                ));
            }
        }
        let s = self.bounds.size();
        if !s.iter().all(|x| *x > 0.0 && x.is_finite()) {
            return Err(Error::invalid("the box must have a positive size"));
        }
        if !(0.0..1.0).contains(&self.pores) {
            return Err(Error::setting(
                "pores",
                format!(
                    "pores must be in [0, 1): a fraction of each wall's inradius, got {}",
                    self.pores
                ),
            ));
        }
        if self.pores > 0.0 && self.structure == Structure::Net {
            return Err(Error::invalid(
                "--pores opens a sheet's walls: a net is open already",
            ));
        }
        if let Some(l) = self.period {
            match &self.seeding {
                Seeding::Poisson {
                    spacing: Spacing::Uniform(sp),
                    ..
                } => periodic::check_cell([l; 3], *sp)?,
                Seeding::Poisson { .. } => {
                    return Err(Error::invalid(
                        "a periodic foam has one spacing: drop --spacing-field, or --periodic",
                    ))
                }
                Seeding::Given(points) => {
                    periodic::check_cell([l; 3], (l.powi(3) / points.len() as f64).cbrt())?
                }
            }
        }
        resolution::check_resolution(self.resolution)
    }

    /// The least and greatest spacing through the box.
    fn spacing_range(&self) -> Result<[f64; 2]> {
        match &self.seeding {
            Seeding::Poisson { spacing, .. } => {
                let n = SPACING_PROBES;
                let size = self.bounds.size();
                let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
                for i in 0..n * n * n {
                    let c = [i / (n * n), (i / n) % n, i % n];
                    let p = [0, 1, 2]
                        .map(|k| self.bounds.min[k] + size[k] * c[k] as f64 / (n - 1) as f64);
                    let s = spacing.at(p);
                    if !(s > 0.0 && s.is_finite()) {
                        return Err(Error::setting(
                            "spacing",
                            format!(
                                "the spacing must be a positive length in mm everywhere in the box, got {s} at ({:.3}, {:.3}, {:.3})",
                                p[0], p[1], p[2]
                            ),
                        ));
                    }
                    lo = lo.min(s);
                    hi = hi.max(s);
                }
                Ok([lo, hi])
            }
            Seeding::Given(points) if self.period.is_some() => {
                let s = (self.cell().volume() / points.len() as f64).cbrt();
                Ok([s, s])
            }
            Seeding::Given(points) => {
                let inside = points.iter().filter(|p| self.bounds.contains(**p)).count();
                if inside == 0 {
                    return Err(Error::invalid(
                        "no seed lies in the box: move the box (--origin, --size) onto the seeds",
                    ));
                }
                let s = (self.bounds.volume() / inside as f64).cbrt();
                Ok([s, s])
            }
        }
    }

    /// The seeds: the box and a margin of two spacings round it, so that the cells reaching
    /// into the box are whole.
    fn seeds(&self, spacing: [f64; 2]) -> Result<Vec<Vec3>> {
        if self.period.is_some() {
            let cell = self.cell();
            return Ok(match &self.seeding {
                Seeding::Given(points) => points.iter().map(|&p| seeds::wrap(p, &cell)).collect(),
                Seeding::Poisson {
                    seed, regularity, ..
                } => {
                    let points = seeds::poisson_periodic(&cell, spacing[0], *seed);
                    seeds::regularise(&points, &cell, spacing[0], *regularity, *seed, true)
                }
            });
        }
        match &self.seeding {
            Seeding::Given(points) => Ok(points.clone()),
            Seeding::Poisson {
                spacing: field,
                seed,
                regularity,
            } => {
                let region = self.bounds.grown(2.0 * spacing[1]);
                seeds::check_count(region.volume(), spacing[0])?;
                // Beyond the box the spacing is the nearest point of the box's.
                let clamp =
                    |p: Vec3| [0, 1, 2].map(|k| p[k].clamp(self.bounds.min[k], self.bounds.max[k]));
                let points = seeds::poisson(&region, &|p| field.at(clamp(p)), *seed);
                Ok(match field {
                    Spacing::Uniform(s) if *regularity > 0.0 => {
                        seeds::regularise(&points, &region, *s, *regularity, *seed, false)
                    }
                    _ => points,
                })
            }
        }
    }

    /// The repeating cell of a periodic foam: from the box's lower corner, `period` wide (the
    /// box itself when the foam is not periodic).
    fn cell(&self) -> Aabb {
        match self.period {
            Some(l) => Aabb {
                min: self.bounds.min,
                max: self.bounds.min.map(|x| x + l),
            },
            None => self.bounds,
        }
    }

    /// The voxel edge at `resolution` voxels per spacing: for a periodic foam, rounded down so
    /// that a cell spans whole OpenVDB leaves (the part is then copied from a template).
    pub(super) fn voxel(&self, spacing: [f64; 2], resolution: u32) -> f64 {
        match self.period {
            Some(l) => l / self.cell_voxels(spacing, resolution) as f64,
            None => spacing[0] / resolution as f64,
        }
    }

    /// Voxels across a periodic cell at `resolution` voxels per spacing: whole leaves.
    pub fn cell_voxels(&self, spacing: [f64; 2], resolution: u32) -> u32 {
        let leaf = instance::BLOCK as f64;
        let l = self.period.unwrap_or(spacing[0]);
        ((resolution as f64 * l / spacing[0] / leaf).ceil() * leaf) as u32
    }

    /// The thinnest member (a radius or a thickness), [`MIN_STRUT_VOXELS`] across.
    fn min_level(&self, voxel: f64) -> f64 {
        match self.structure {
            Structure::Net => 0.5 * MIN_STRUT_VOXELS * voxel,
            Structure::Sheet => MIN_STRUT_VOXELS * voxel,
        }
    }

    /// Voxels across a member of `level`.
    pub(super) fn across(&self, level: f64, voxel: f64) -> f64 {
        match self.structure {
            Structure::Net => 2.0 * level / voxel,
            Structure::Sheet => level / voxel,
        }
    }

    /// Where the seeds came from (`poisson` or `file`), the generator's seed and the regularity,
    /// for the report.
    pub(super) fn seeding_report(&self) -> (&'static str, Option<u64>, f64) {
        match self.seeding {
            Seeding::Poisson {
                seed, regularity, ..
            } => ("poisson", Some(seed), regularity),
            Seeding::Given(_) => ("file", None, 0.0),
        }
    }

    pub(super) fn setting(&self) -> String {
        if let Some(g) = &self.grading {
            return format!("density field {}", g.field.source);
        }
        match self.sizing {
            Sizing::Density(d) => format!("density {d}"),
            Sizing::Level(l) => format!("{} {l} mm", self.structure.level_name()),
        }
    }

    pub(super) fn name(&self) -> String {
        format!(
            "the Voronoi {}",
            match self.structure {
                Structure::Net => "net",
                Structure::Sheet => "sheet",
            }
        )
    }

    pub(super) fn range(&self, family: &impl Members, voxel: f64) -> VoronoiRange {
        let min_level = self.min_level(voxel);
        VoronoiRange {
            min_level,
            max_level: family.closing(),
            min_density: family.model_fraction(min_level),
            max_density: family.model_fraction(family.closing()),
        }
    }

    /// Refuses a level or density at which the pores close (or, with none open, any).
    fn refuse_closed(
        &self,
        family: &impl Members,
        level: f64,
        voxel: f64,
        resolution: u32,
    ) -> Result<()> {
        if level < family.closing() {
            return Ok(());
        }
        let range = self.range(family, voxel);
        let name = self.structure.level_name();
        let (setting, value, min, max) = match self.sizing {
            Sizing::Density(d) => ("density", d, range.min_density, range.max_density),
            Sizing::Level(l) => (name, l, range.min_level, range.max_level),
        };
        Err(Error::Infeasible {
            setting: setting.into(),
            value,
            min,
            max,
            message: format!(
                "{} at {} closes its pores: at {name} {:.4} mm (density {:.3}) {}; it can be built at {name} {:.4} to {:.4} mm, density {:.3} to {:.3} (at {resolution} voxels per spacing)",
                self.name(),
                self.setting(),
                range.max_level,
                range.max_density,
                match self.structure {
                    Structure::Net => "half the windows between its cells are shut",
                    Structure::Sheet => "the walls fill over half the void of one cell in ten",
                },
                range.min_level,
                range.max_level,
                range.min_density,
                range.max_density,
            ),
        })
    }

    /// The resolution members of `level` need when the requested one leaves them thinner than
    /// [`MIN_STRUT_VOXELS`], and why; refused when even the finest searched would not do.
    pub(super) fn thin(&self, level: f64, spacing: [f64; 2]) -> Result<Option<(u32, String)>> {
        let req = self.resolution;
        let across = self.across(level, self.voxel(spacing, req));
        if across >= MIN_STRUT_VOXELS {
            return Ok(None);
        }
        let needed = (req as f64 * MIN_STRUT_VOXELS / across).ceil() as u32;
        let why = format!("members were {across:.2} voxels across at {req} voxels per spacing");
        if self.auto_resolution && needed > max_resolution(req) {
            let name = self.structure.level_name();
            return Err(Error::Resolution {
                requested: req,
                needed: Some(needed),
                message: format!(
                    "{} at {}: {why}, and would need {needed} voxels per spacing; give a larger {name} or density (at {req} voxels per spacing: {name} ≥ {:.4} mm), or --resolution {needed}",
                    self.name(),
                    self.setting(),
                    self.min_level(self.voxel(spacing, req)),
                ),
            });
        }
        Ok(Some((needed, why)))
    }

    /// The level the search starts from: the one given, or the model's for the density;
    /// refused (naming the range) where the pores close.
    fn start_level(&self, family: &impl Members, voxel: f64) -> Result<f64> {
        let l0 = match self.sizing {
            Sizing::Density(d) => {
                if d > self.range(family, voxel).max_density {
                    // The model's level would close the pores: refuse naming the range.
                    self.refuse_closed(family, family.closing(), voxel, self.resolution)?;
                }
                family.model_level(d)
            }
            Sizing::Level(l) => l,
        };
        self.refuse_closed(family, l0, voxel, self.resolution)?;
        Ok(l0)
    }

    /// The foam: seeds, diagram and density model.
    pub fn foam(&self, progress: &Progress) -> Result<(Foam, [f64; 2])> {
        self.validate()?;
        let spacing = self.spacing_range()?;
        let seeds = {
            let _p = progress.stage("seeding");
            self.seeds(spacing)?
        };
        let _p = progress.stage("computing the Voronoi diagram");
        let voxel = self.voxel(spacing, self.resolution);
        let foam = match self.period {
            Some(l) => {
                let cell = self.cell();
                let copies = periodic::with_copies(&seeds, &cell);
                Foam::new(self.structure, cell, copies, voxel, spacing[1])?.repeating([l; 3])
            }
            None => Foam::new(self.structure, self.bounds, seeds, voxel, spacing[1])?,
        };
        // Pores narrower than the thinnest member would be a voxel's notch, not a hole.
        let foam = match self.pores {
            f if f > 0.0 => foam.with_pores(f, self.min_level(voxel)),
            _ => foam,
        };
        Ok((foam, spacing))
    }

    /// Runs the job and returns the mesh with its report.
    pub fn run(&self, progress: &Progress) -> Result<(Mesh, VoronoiReport)> {
        let mut collector = MeshCollector::default();
        let report = self.run_into(progress, &mut collector)?;
        Ok((collector.mesh, report))
    }

    /// Runs the job, streaming the part's triangles into `sink`.
    pub fn run_into(&self, progress: &Progress, sink: &mut dyn MeshSink) -> Result<VoronoiReport> {
        let start = Instant::now();
        if let Some(grading) = &self.grading {
            return self.run_graded(grading, progress, sink);
        }
        let (foam, spacing) = self.foam(progress)?;
        match self.net_cell(&foam)? {
            Some(family) => self.make(&family, &foam, spacing, start, progress, sink),
            None => {
                let family = FoamFamily {
                    foam: Arc::new(foam),
                    bounds: self.bounds,
                };
                self.make(&family, &family.foam, spacing, start, progress, sink)
            }
        }
    }

    /// A periodic net as a strut lattice: its cell's edges as a unit cell, repeated from the
    /// box's lower corner (so that drawing, slicing and beams take it as any strut lattice);
    /// `None` for other foams.
    pub fn net_cell(&self, foam: &Foam) -> Result<Option<StrutFamily>> {
        let (Some(l), Structure::Net) = (self.period, self.structure) else {
            return Ok(None);
        };
        Ok(Some(StrutFamily::new(StrutLattice {
            cell: Arc::new(periodic::net_cell(foam)?),
            size: [l; 3],
            radius: 0.0,
            blend: 0.0,
            bounds: self.bounds,
            phase: self.bounds.min,
        })))
    }

    /// Finds the level of `family` (the foam's, or its net's as a strut lattice), meshes,
    /// writes and reports.
    fn make(
        &self,
        family: &impl Members,
        foam: &Foam,
        spacing: [f64; 2],
        start: Instant,
        progress: &Progress,
        sink: &mut dyn MeshSink,
    ) -> Result<VoronoiReport> {
        let model_seconds = start.elapsed().as_secs_f64();
        let voxel0 = self.voxel(spacing, self.resolution);
        let l0 = self.start_level(family, voxel0)?;
        let resolved = self.search(family, l0, spacing, progress)?;
        let Found {
            voxel,
            route,
            best,
            tried,
            meshing,
        } = resolved.found;
        let level = best.level;
        let level_search = LevelSearch::new(&best, route, &tried, resolved.coarser);
        let target = match self.sizing {
            Sizing::Density(d) => Some(d),
            Sizing::Level(_) => None,
        };
        let written = pipeline::write(family, best, voxel, route, &self.options, progress, sink)?;
        let part = PartReport::after_search(
            self.bounds,
            target,
            route,
            written,
            meshing,
            model_seconds,
            resolved.raised,
            start,
        );
        let (seeding, seed, regularity) = self.seeding_report();
        Ok(VoronoiReport {
            structure: self.structure,
            seeding,
            seed,
            regularity,
            spacing,
            radius: (self.structure == Structure::Net).then_some(level),
            thickness: (self.structure == Structure::Sheet).then_some(level),
            member_voxels: self.across(level, voxel),
            feasible_range: self.range(family, voxel),
            level_search,
            resolution_requested: self.resolution,
            resolution: resolved.resolution,
            voxel_size: voxel,
            period: self.period,
            foam: foam.stats,
            grading: None,
            block: None,
            part,
            seeds: foam.own_seeds().to_vec(),
            cell: family.cell(),
        })
    }

    /// A net as beams (the 3MF Beam Lattice extension's): every Voronoi edge that reaches into
    /// the box, a capsule of the radius given or of the radius at which the meshed part has the
    /// target density, the box a clipping mesh.
    pub fn beams(&self, progress: &Progress) -> Result<(BeamModel, VoronoiBeamsReport)> {
        let start = Instant::now();
        if self.structure != Structure::Net {
            return Err(Error::invalid(
                "a sheet's walls cannot be written as beams: drop --beams, or make a net",
            ));
        }
        let (foam, spacing) = self.foam(progress)?;
        match self.net_cell(&foam)? {
            Some(family) => self.beams_of(&family, &foam, spacing, start, progress),
            None => {
                let family = FoamFamily {
                    foam: Arc::new(foam),
                    bounds: self.bounds,
                };
                self.beams_of(&family, &family.foam, spacing, start, progress)
            }
        }
    }

    fn beams_of(
        &self,
        family: &impl Members,
        foam: &Foam,
        spacing: [f64; 2],
        start: Instant,
        progress: &Progress,
    ) -> Result<(BeamModel, VoronoiBeamsReport)> {
        let voxel0 = self.voxel(spacing, self.resolution);
        let (radius, measured, resolution, target) = match self.sizing {
            Sizing::Level(r) => {
                self.start_level(family, voxel0)?;
                (r, None, None, None)
            }
            Sizing::Density(d) => {
                let l0 = self.start_level(family, voxel0)?;
                let resolved = self.search(family, l0, spacing, progress)?;
                let best = &resolved.found.best;
                (
                    best.level,
                    Some(best.fraction),
                    Some(resolved.resolution),
                    Some(d),
                )
            }
        };
        let model = family.beam_model(radius);
        let report = VoronoiBeamsReport {
            radius,
            target_density: target,
            meshed_density: measured,
            resolution,
            beams: model.beams.len() as u64,
            vertices: model.vertices.len() as u64,
            clipped_by: "box",
            bounds: self.bounds,
            foam: foam.stats,
            seconds: start.elapsed().as_secs_f64(),
            output: None,
            seeds: foam.own_seeds().to_vec(),
        };
        Ok((model, report))
    }

    /// The part as an implicit solid, for drawing and slicing from its settings: the strut
    /// radius or wall thickness given, or the one its mesh is made to the density at (the same
    /// search, on the same voxels; in tiles beyond [`crate::render::MODEL_MEMORY`]), for slices
    /// moved so that it encloses the mesh's volume, with the fragments the mesh drops. A
    /// periodic net is its strut lattice.
    pub fn model(&self, fidelity: crate::render::Fidelity) -> Result<crate::render::Model> {
        let (foam, spacing) = self.foam(&Progress::hidden())?;
        let bounded = VoronoiJob {
            options: crate::render::model_options(&self.options),
            ..self.clone()
        };
        let (given, target) = match self.sizing {
            Sizing::Level(r) => (Some(r), None),
            Sizing::Density(d) => (None, Some(d)),
        };
        let voxel0 = self.voxel(spacing, self.resolution);
        if let Some(family) = self.net_cell(&foam)? {
            let l0 = self.start_level(&family, voxel0)?;
            let resolved = bounded.search(&family, l0, spacing, &Progress::hidden())?;
            return crate::render::Model::of_struts(
                &family,
                &resolved.found,
                given,
                target,
                fidelity,
            );
        }
        let family = FoamFamily {
            foam: Arc::new(foam),
            bounds: self.bounds,
        };
        let l0 = self.start_level(&family, voxel0)?;
        let resolved = bounded.search(&family, l0, spacing, &Progress::hidden())?;
        // The level's integration on the part's own voxels (extrapolated, it is within 0.1 % on
        // struts two voxels across): a foam is integrated whole, not a template cell.
        crate::render::Model::of(
            &family,
            &resolved.found,
            given,
            target,
            fidelity,
            [spacing[0], resolved.found.voxel],
            |f, level| crate::render::Lattice::Foam(f.at(level)),
        )
    }

    /// Finds the resolution and level of the part: the level given, or the one at which the
    /// part meshes to the target density.
    fn search(
        &self,
        family: &impl Members,
        l0: f64,
        spacing: [f64; 2],
        progress: &Progress,
    ) -> Result<Resolved<Found>> {
        let target = match self.sizing {
            Sizing::Density(d) => Some(d),
            Sizing::Level(_) => None,
        };
        let request = resolution::Request {
            part: self.name(),
            setting: self.setting(),
            requested: self.resolution,
            thin: self.thin(l0, spacing)?,
            density: target,
            auto: self.auto_resolution,
            per: "spacing",
        };
        let opts = &self.options;
        resolution::search(&request, &mut |r| {
            let _p = progress.stage(if r == self.resolution {
                "finding the member size"
            } else {
                "searching for a resolution that reaches the density"
            });
            let voxel = self.voxel(spacing, r);
            let route = Route::choose(&family.at(l0), voxel, opts);
            pipeline::find(family, target, l0, voxel, route, opts)
        })
    }
}

/// What the job needs of a foam's family besides the pipeline's: the size at which its pores
/// close, its beams, and, for a periodic net, its strut cell.
pub(super) trait Members: Family {
    /// The largest level at which the pores stay open.
    fn closing(&self) -> f64;
    /// The net at `radius` as 3MF beams, the box clipping them.
    fn beam_model(&self, radius: f64) -> BeamModel;
    /// The strut cell, when the family is a periodic net's.
    fn cell(&self) -> Option<Arc<UnitCell>> {
        None
    }
}

impl Members for FoamFamily {
    fn closing(&self) -> f64 {
        self.foam.closing
    }

    fn beam_model(&self, radius: f64) -> BeamModel {
        self.foam.beam_model(radius)
    }
}

impl Members for StrutFamily {
    fn closing(&self) -> f64 {
        self.model.closing
    }

    fn beam_model(&self, radius: f64) -> BeamModel {
        strut_beams(&self.at(radius))
    }

    fn cell(&self) -> Option<Arc<UnitCell>> {
        Some(self.part.cell.clone())
    }
}
