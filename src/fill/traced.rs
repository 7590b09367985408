//! A filled part traced from its meshes, with no distance grid: the augmented sphere tracing of
//! shell-lattices (Guo and Li, Computer-Aided Design 184, 2025). The part's surface and the
//! solids kept whole are triangle meshes under BVHs; a ray is cast at them to find where it
//! enters the part (or a kept solid), and only inside the part is the lattice sphere-traced,
//! joined to the skin by the distance to the part's surface — asked of the BVH only where it can
//! matter (within the skin, the blend and the lattice field's reach of the surface), and capped
//! there. Memory is the meshes' and one unit cell's, whatever the number of cells; nothing is
//! sampled on voxels.

use super::job::{closed_parts, FillJob, Found, Infilling, Then};
use super::shape::{skin_or_lattice, Drain};
use crate::error::Result;
use crate::field::{intersection_clearance, union_clearance, Aabb, Field, Vec3};
use crate::geom::bvh::Bvh;
use crate::geom::{norm, sub};
use crate::grid::GridSpec;
use crate::lattice::strut::StrutLattice;
use crate::lattice::tpms::Lattice as Tpms;
use crate::mesh::pieces::Loose;
use crate::mesh::pipeline::Family;
use crate::mesh::resolution::Resolved;
use crate::progress::Progress;
use crate::render::camera::{dot, Ray};
use crate::render::trace::{
    field_normal, field_openness, mesh_hit, sphere_trace, Hit, Scene, Section, Tolerance,
};
use crate::render::view::scene::{Fill, Scene as EditorScene, Triangles};
use crate::render::Lattice;

/// A filled part as meshes and a lattice, ready to trace.
pub struct Traced {
    part: Bvh,
    keep: Vec<Bvh>,
    drains: Vec<Drain>,
    skin: f64,
    blend: f64,
    lattice: Lattice,
    /// The box of the part and the kept solids.
    pub bounds: Aabb,
    /// The voxel meshing would use, mm.
    pub voxel: f64,
    /// The shortest cell side, mm.
    pub cell: f64,
    /// The lattice's TPMS level, or its strut radius (mm).
    pub level: f64,
    /// The density the lattice fills the part to.
    pub density: f64,
    /// The fragments the part's mesh drops.
    pub loose: Loose,
    /// Volume of the part's skin and kept solids alone, and of the region the lattice fills,
    /// as the part's meshing measured them, mm³.
    regions: (f64, f64),
}

impl FillJob {
    /// The filled part for tracing: the part's and the kept solids' meshes (closed first, as
    /// for meshing) and the lattice: for slices, at the level (or radius) its mesh is written
    /// at, found by the same search on the same voxels (in tiles beyond
    /// [`crate::render::MODEL_MEMORY`]) and moved so that it encloses the mesh's volume, with the
    /// fragments the mesh drops; for pictures, at the level its unit cell gives for the density
    /// (the part's own search meshes the whole part, whatever its number of cells).
    pub fn traced(&self, fidelity: crate::render::Fidelity) -> Result<Traced> {
        if self.grading.is_some() {
            return Err(crate::error::Error::invalid(
                "a graded part is drawn and sliced from its mesh: make it with -o part.stl, then render, view or slice part.stl",
            ));
        }
        let (part, keep, _) = closed_parts(self, &Progress::hidden())?;
        let settled = match fidelity {
            // The part's own search meshes the whole part, whatever its number of cells: a
            // picture takes the lattice's level from its unit cell.
            crate::render::Fidelity::Look => self.unit_cell_level(),
            crate::render::Fidelity::Volume => {
                let bounded = FillJob {
                    options: crate::render::model_options(&self.options),
                    ..self.clone()
                };
                bounded.with_lattice(&part, &keep, &Progress::hidden(), Settle)?
            }
        };
        let keep: Vec<Bvh> = keep.iter().map(Bvh::new).collect();
        let voxel = settled.voxel;
        let drains = match (self.drain, self.skin > 0.0) {
            (Some(d), true) => {
                self.check_drain(&part, d)?;
                Drain::at_ends(&part, d, self.skin + self.blend + voxel)
            }
            _ => Vec::new(),
        };
        let part = Bvh::new(&part);
        let mut bounds = part.bounds().expect("a closed part has triangles");
        for k in &keep {
            let b = k.bounds().expect("a kept solid has triangles");
            bounds.min = [0, 1, 2].map(|a| bounds.min[a].min(b.min[a]));
            bounds.max = [0, 1, 2].map(|a| bounds.max[a].max(b.max[a]));
        }
        let (lattice, level) = match &self.lattice {
            Infilling::Tpms { surface, structure } => {
                let level = settled.level;
                let solid = Tpms {
                    surface: *surface,
                    structure: *structure,
                    level,
                    cell: self.cell,
                    bounds,
                    phase: bounds.min,
                };
                (Lattice::Tpms(solid), level)
            }
            Infilling::Strut { cell } => {
                let radius = settled.level;
                let solid = StrutLattice {
                    cell: cell.clone(),
                    size: self.cell,
                    radius,
                    blend: self.blend,
                    bounds,
                    phase: bounds.min,
                };
                (Lattice::Struts(solid), radius)
            }
        };
        Ok(Traced {
            part,
            keep,
            drains,
            skin: self.skin,
            blend: self.blend,
            lattice,
            bounds,
            voxel,
            cell: self.min_cell(),
            level,
            density: self.density,
            loose: settled.loose,
            regions: settled.regions,
        })
    }
}

impl FillJob {
    /// The lattice's level (or radius) its unit cell's model gives for the density, on the
    /// voxels the part is meshed at, with no fragments and the regions of a box of lattice.
    fn unit_cell_level(&self) -> Settled {
        let level = match &self.lattice {
            Infilling::Tpms { surface, structure } => {
                crate::lattice::tpms::calibrate::analytic_level(*surface, *structure, self.density)
            }
            Infilling::Strut { cell } => {
                crate::lattice::strut::RadiusModel::new(cell, self.cell).radius(self.density)
            }
        };
        Settled {
            level,
            voxel: self.min_cell() / self.resolution as f64,
            loose: Loose::default(),
            regions: (0.0, 1.0),
        }
    }
}

/// The level a fill's mesh is written at, and what tracing needs of its meshing.
struct Settled {
    level: f64,
    voxel: f64,
    loose: Loose,
    regions: (f64, f64),
}

/// Keeps the level found, moved for slices ([`crate::render::Fidelity::Volume`]).
struct Settle;

impl Then for Settle {
    type Out = Settled;

    fn then<F: Family>(
        self,
        job: &FillJob,
        resolved: Resolved<Found<F>>,
        _: std::time::Instant,
        _: &Progress,
    ) -> Result<Settled>
    where
        F::Solid: Clone,
    {
        use crate::mesh::pipeline::{implicit_level, implicit_step};
        let f = resolved.found;
        let step = implicit_step(f.voxel, job.min_cell());
        Ok(Settled {
            level: implicit_level(&f.family, &f.best, &f.tried, f.voxel, step),
            voxel: f.voxel,
            loose: crate::mesh::pipeline::loose(&f.family, &f.best, f.voxel)?,
            regions: (f.family.base_volume, f.family.fill_volume),
        })
    }
}

impl Traced {
    /// The lattice's share of the region it fills, for a part of `volume` mm³ (the measure
    /// its mesh's density is given in).
    pub fn fraction(&self, volume: f64) -> f64 {
        (volume - self.regions.0) / self.regions.1
    }

    /// The browser editor's scene of the filled part: the lattice inside, the part's surface,
    /// its skin, drains and kept solids.
    pub fn editor_scene(&self) -> EditorScene {
        let mut scene = EditorScene::of_lattice(
            self.lattice(),
            self.level,
            self.reach(),
            self.bounds,
            self.voxel,
            self.cell,
        );
        let keep: Vec<[Vec3; 3]> = self
            .keep()
            .iter()
            .flat_map(|k| k.triangles().iter().copied())
            .collect();
        let (skin, blend) = self.skin_and_blend();
        scene.fill = Some(Fill {
            part: Triangles::of(self.part()),
            keep: Triangles::of(&Bvh::over(keep)),
            drains: self
                .drains()
                .iter()
                .map(|d| {
                    let (a, b) = (d.from, d.to);
                    [a[0], a[1], a[2], b[0], b[1], b[2], d.radius]
                })
                .collect(),
            skin,
            blend,
            cap: skin + blend + self.reach() + self.voxel,
        });
        scene
    }

    /// The distance up to which the lattice's field is exact (see [`crate::render::Model`]).
    pub fn reach(&self) -> f64 {
        0.15 * self.cell
    }

    /// The part's surface.
    pub fn part(&self) -> &Bvh {
        &self.part
    }

    /// The solids kept whole.
    pub fn keep(&self) -> &[Bvh] {
        &self.keep
    }

    /// The drain holes.
    pub fn drains(&self) -> &[Drain] {
        &self.drains
    }

    /// The skin's thickness and the blend radius between skin and lattice, mm.
    pub fn skin_and_blend(&self) -> (f64, f64) {
        (self.skin, self.blend)
    }

    /// The lattice that fills the part.
    pub fn lattice(&self) -> &Lattice {
        &self.lattice
    }

    /// The lattice's field, unclipped, exact up to the reach.
    pub fn lattice_field(&self) -> Box<dyn Field + '_> {
        let spec = GridSpec::covering(
            &self.bounds,
            self.voxel,
            (self.reach() / self.voxel).max(1.0),
        );
        self.lattice.solid().field(&spec)
    }

    /// The scene to render, its lattice read from `field` (from [`Traced::lattice_field`]).
    pub fn scene<'a>(&'a self, field: &'a dyn Field, section: Option<Section>) -> FilledScene<'a> {
        FilledScene {
            traced: self,
            lattice: field,
            section,
        }
    }
}

/// A filled part, cut by a section plane where asked.
pub struct FilledScene<'a> {
    traced: &'a Traced,
    lattice: &'a dyn Field,
    section: Option<Section>,
}

/// The filled part as an implicit solid (negative inside): the skin or lattice inside the part,
/// less the drain holes, with the kept solids. What slicing samples; one BVH parity test per
/// point decides inside the part.
impl Field for FilledScene<'_> {
    fn value(&self, p: Vec3) -> f64 {
        self.value_and_clearance(p).0
    }

    fn clearance(&self, p: Vec3) -> f64 {
        self.value_and_clearance(p).1
    }

    /// A block of points shares its tests: when the part's surface is farther from the block's
    /// centre than the block reaches, one parity test places the whole block, and where it is
    /// deeper inside than the skin and lattice look, no point asks for its depth.
    fn values(&self, points: &[Vec3], out: &mut [f64]) {
        let t = self.traced;
        let n = points.len() as f64;
        let c = points
            .iter()
            .fold([0.0; 3], |a, p| [0, 1, 2].map(|k| a[k] + p[k] / n));
        let reach = points.iter().map(|p| norm(sub(*p, c))).fold(0.0, f64::max);
        let cap = t.skin + t.blend + t.reach() + t.voxel;
        let d = t.part.distance(c, cap + reach);
        if !t.keep.is_empty() || d <= reach {
            for (p, o) in points.iter().zip(out.iter_mut()) {
                *o = self.value(*p);
            }
            return;
        }
        let inside = t.part.contains(c);
        for (p, o) in points.iter().zip(out.iter_mut()) {
            let lower = d - norm(sub(*p, c));
            *o = if !inside {
                lower.max(1e-12)
            } else if lower >= cap {
                self.inside_at(*p, cap).0
            } else {
                self.inside_at(*p, self.depth(*p)).0
            };
        }
    }

    fn value_and_clearance(&self, p: Vec3) -> (f64, f64) {
        let t = self.traced;
        let surface = self.depth(p);
        let (v, c) = if t.part.contains(p) {
            let (v, c) = self.inside_at(p, surface);
            (v, c.min(surface))
        } else {
            (surface.max(1e-12), surface)
        };
        let cap = t.skin + t.blend + t.reach() + t.voxel;
        t.keep.iter().fold((v, c), |(v, c), k| {
            let d = k.distance(p, cap);
            let dk = if k.contains(p) { -d } else { d };
            (v.min(dk), union_clearance(v, c, dk, d))
        })
    }
}

/// A small step past a surface a ray was cast to, mm (relative to the part's size).
fn nudge(b: &Aabb) -> f64 {
    1e-7 * (1.0 + b.size().iter().cloned().fold(0.0, f64::max))
}

impl FilledScene<'_> {
    /// The distance to the part's surface from a point inside it, capped where the skin and
    /// the lattice no longer depend on it.
    fn depth(&self, x: Vec3) -> f64 {
        let t = self.traced;
        let cap = t.skin + t.blend + t.reach() + t.voxel;
        t.part.distance(x, cap)
    }

    /// The solid inside the part at `x` (the skin or the lattice, less the drain holes): value
    /// and clearance.
    fn inside(&self, x: Vec3) -> (f64, f64) {
        // Without a skin the lattice alone fills the part, whatever the depth.
        let d = if self.traced.skin > 0.0 {
            self.depth(x)
        } else {
            0.0
        };
        self.inside_at(x, d)
    }

    /// [`FilledScene::inside`] at `x`, `d` its (capped) depth in the part.
    fn inside_at(&self, x: Vec3, d: f64) -> (f64, f64) {
        let t = self.traced;
        let core = d - t.skin;
        let (v, c) = skin_or_lattice(
            (core, core.abs()),
            self.lattice.value_and_clearance(x),
            t.skin,
            t.blend,
        );
        t.drains.iter().fold((v, c), |(v, c), h| {
            let dh = -h.distance(x);
            (v.max(dh), intersection_clearance(v, c, dh, dh.abs()))
        })
    }

    /// The first hit of the solid inside the part along `ray` on `(t0, t1)`, where the ray is
    /// inside the part throughout.
    fn trace_inside(&self, ray: &Ray, t0: f64, t1: f64, tol: Tolerance) -> Option<f64> {
        sphere_trace(|p| self.inside(p), ray, t0, t1, tol)
    }

    /// The nearest hit of the filled part (without the kept solids) on `(t0, t1)`; `outside`:
    /// the ray is known to start outside the part.
    fn part_hit(
        &self,
        ray: &Ray,
        (t0, t1): (f64, f64),
        outside: bool,
        tol: Tolerance,
    ) -> Option<Hit> {
        let part = &self.traced.part;
        let eps = nudge(&self.traced.bounds);
        let mut t = t0;
        let mut inside = !outside && part.contains(ray.at(t0));
        while t < t1 {
            let mut surface = None;
            if !inside {
                let from = Ray {
                    origin: ray.at(t),
                    dir: ray.dir,
                };
                let h = part.hit(&from, t1 - t)?;
                t += h.t;
                surface = Some(h.normal);
            }
            let exit = part
                .hit(
                    &Ray {
                        origin: ray.at(t + eps),
                        dir: ray.dir,
                    },
                    t1 - t,
                )
                .map_or(t1, |h| t + eps + h.t);
            if let Some(th) = self.trace_inside(ray, t, exit, tol) {
                let p = ray.at(th);
                let normal = match (th == t, surface) {
                    (true, Some(n)) => {
                        if dot(n, ray.dir) > 0.0 {
                            n.map(|x| -x)
                        } else {
                            n
                        }
                    }
                    (true, None) => match self.cut_at(p) {
                        Some(normal) => {
                            return Some(Hit {
                                t: th,
                                normal,
                                cap: true,
                            })
                        }
                        None => self.normal(p),
                    },
                    _ => self.normal(p),
                };
                return Some(Hit {
                    t: th,
                    normal,
                    cap: false,
                });
            }
            // Out of the part (through a drain hole, or at the end of the ray's span).
            t = exit + eps;
            inside = false;
        }
        None
    }

    /// The section plane's normal, if `p` lies on it (where a ray starts on the cut).
    fn cut_at(&self, p: Vec3) -> Option<Vec3> {
        let eps = 1e-6 * self.traced.cell;
        self.section
            .filter(|s| s.distance(p).abs() <= eps)
            .map(|s| s.normal)
    }

    /// The outward normal of the solid inside the part at `p`.
    fn normal(&self, p: Vec3) -> Vec3 {
        field_normal(|q| self.inside(q).0, p, 0.1 * self.traced.voxel)
    }
}

impl Scene for FilledScene<'_> {
    fn hit(&self, ray: &Ray, tol: Tolerance) -> Option<Hit> {
        let b = self.traced.bounds.grown(nudge(&self.traced.bounds));
        let (entry, exit) = ray.clip(&b)?;
        let (t0, t1) = match &self.section {
            Some(s) => s.keep(ray, entry, exit)?,
            None => (entry, exit),
        };
        // A ray that starts on the box (grown past the part), not on the cut nor inside the box
        // (the camera there), starts outside the part.
        let outside = t0 == entry && entry > 0.0;
        let mut best: Option<Hit> = None;
        for k in &self.traced.keep {
            let start = ray.at(t0);
            let hit = if let Some(normal) = self.cut_at(start).filter(|_| k.contains(start)) {
                Some(Hit {
                    t: t0,
                    normal,
                    cap: true,
                })
            } else {
                mesh_hit(k, ray, t0, t1)
            };
            if let Some(h) = hit {
                if best.is_none_or(|b| h.t < b.t) {
                    best = Some(h);
                }
            }
        }
        let limit = best.map_or(t1, |h| h.t);
        match self.part_hit(ray, (t0, limit), outside, tol) {
            Some(h) if best.is_none_or(|b| h.t < b.t) => Some(h),
            _ => best,
        }
    }

    fn bounds(&self) -> Aabb {
        self.traced.bounds
    }

    /// Ambient occlusion from the solid inside the part (five samples along the normal; none
    /// on the part's outer surface).
    fn openness(&self, p: Vec3, n: Vec3) -> f64 {
        if self.depth(p) < 0.5 * self.traced.voxel {
            return 1.0;
        }
        let cut = |q: Vec3| self.section.map_or(f64::NEG_INFINITY, |s| s.distance(q));
        field_openness(
            |q| self.inside(q).0.max(cut(q)),
            p,
            n,
            self.traced.cell / 6.0,
        )
    }
}
