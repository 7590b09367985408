//! What a ray meets: an implicit solid by sphere tracing, or a triangle mesh through its BVH.
//!
//! **Sphere tracing** (Hart 1996): from a point outside the solid, a field's clearance is a
//! radius the surface does not enter, so the ray may advance by it without passing through
//! anything. Steps are never shorter than a tolerance (a quarter of the pixel at that
//! distance), so a ray near the surface crosses it within a step or grazes past; a crossing
//! (the value turning negative) is refined by false position, so a hit is where the ray enters
//! the solid, not merely where it came close. The clearance of every latvox field is a true
//! lower bound on the distance — for a TPMS the implicit over its Lipschitz bound, for a strut
//! lattice the distance to the struts of the augmented cell (every strut of the cell and every
//! copy from the neighbouring cells within the field's reach) capped at that reach: a strut not
//! in the augmented cell is farther than the reach from any point of the cell, so the capped
//! per-cell distance is a safe step across cell boundaries as well (the guarantee a stop on the
//! cell boundary gives in Guo and Li's augmented sphere tracing, without the extra stop). No
//! step can therefore tunnel through a strut or sheet thicker than the tolerance.

use super::camera::{dot, Ray};
use crate::field::{intersection_clearance, Aabb, Field, Vec3};
use crate::geom::bvh::Bvh;
use crate::mesh::pieces::Loose;

/// Where a ray meets the scene.
#[derive(Debug, Clone, Copy)]
pub struct Hit {
    /// Distance along the ray, mm.
    pub t: f64,
    /// Unit normal, facing out of the solid.
    pub normal: Vec3,
    /// The hit is on the face the section plane cut.
    pub cap: bool,
}

/// The shortest step a trace takes: `absolute + per_distance · t` mm at distance `t` (a camera
/// passes a quarter of its pixel's width per millimetre of distance). Nothing thinner than it
/// can be stepped over.
#[derive(Debug, Clone, Copy)]
pub struct Tolerance {
    /// At the ray's origin, mm.
    pub absolute: f64,
    /// Growth per mm along the ray.
    pub per_distance: f64,
}

/// Anything rays can be cast at.
pub trait Scene: Sync {
    /// The nearest hit along `ray`, stopping within `tol`.
    fn hit(&self, ray: &Ray, tol: Tolerance) -> Option<Hit>;
    /// A box holding everything visible.
    fn bounds(&self) -> Aabb;
    /// How open the surroundings of a hit are, in [0, 1] (1: nothing near occludes it).
    fn openness(&self, _p: Vec3, _n: Vec3) -> f64 {
        1.0
    }
}

/// The first distance in `(t0, t1)` along `ray` at which a solid — `field(p)` its value and
/// clearance — is met, by sphere tracing from `t0` (a hit at `t0` where it starts inside).
pub fn sphere_trace(
    field: impl Fn(Vec3) -> (f64, f64),
    ray: &Ray,
    t0: f64,
    t1: f64,
    tol: Tolerance,
) -> Option<f64> {
    let mut t = t0;
    let mut before = (t0, f64::NAN);
    for _ in 0..MAX_STEPS {
        if t > t1 {
            return None;
        }
        let (v, c) = field(ray.at(t));
        if v <= 0.0 {
            if t == t0 {
                return Some(t);
            }
            return Some(refine(|p| field(p).0, ray, before, (t, v)));
        }
        // Steps never shorter than the tolerance: a ray that comes that close to the surface
        // crosses it within a step (and the crossing is refined) or grazes past; only
        // something thinner than the tolerance can be stepped over.
        let eps = tol.absolute + tol.per_distance * t;
        before = (t, v);
        t += c.max(eps);
    }
    None
}

/// The crossing between `out` (outside, its value) and `inside`: a step of at most the
/// tolerance (a longer one cannot cross the surface), narrowed by three steps of false
/// position.
fn refine(
    value: impl Fn(Vec3) -> f64,
    ray: &Ray,
    mut out: (f64, f64),
    mut inside: (f64, f64),
) -> f64 {
    let weight = |a: f64, b: f64| {
        if a.is_finite() && a > b {
            a / (a - b)
        } else {
            0.5
        }
    };
    for _ in 0..3 {
        let w = weight(out.1, inside.1).clamp(0.05, 0.95);
        let m = out.0 + w * (inside.0 - out.0);
        let v = value(ray.at(m));
        if v <= 0.0 {
            inside = (m, v);
        } else {
            out = (m, v);
        }
    }
    out.0 + weight(out.1, inside.1) * (inside.0 - out.0)
}

/// The outward unit normal of the zero set of `value` at `p`: its gradient from four samples at
/// the corners of a tetrahedron of size `h` (their weighted sum is the central difference along
/// each axis).
pub fn field_normal(value: impl Fn(Vec3) -> f64, p: Vec3, h: f64) -> Vec3 {
    let mut g = [0.0; 3];
    for k in [
        [1.0, -1.0, -1.0],
        [-1.0, -1.0, 1.0],
        [-1.0, 1.0, -1.0],
        [1.0, 1.0, 1.0],
    ] {
        let v = value([p[0] + h * k[0], p[1] + h * k[1], p[2] + h * k[2]]);
        g = [0, 1, 2].map(|a| g[a] + k[a] * v);
    }
    let n = dot(g, g).sqrt();
    if n > 0.0 {
        g.map(|x| x / n)
    } else {
        [0.0, 0.0, 1.0]
    }
}

/// Ambient occlusion from a field (Quilez's five samples along the normal `n`, out to `reach`
/// mm): 1 where nothing near occludes `p`.
pub fn field_openness(value: impl Fn(Vec3) -> f64, p: Vec3, n: Vec3, reach: f64) -> f64 {
    let mut occ = 0.0;
    let mut weight = 1.0;
    for k in 1..=5 {
        let h = 0.2 * reach * k as f64;
        let q = [0, 1, 2].map(|a| p[a] + h * n[a]);
        occ += weight * (h - value(q)).max(0.0) / h;
        weight *= 0.6;
    }
    (1.0 - 0.45 * occ).clamp(0.0, 1.0)
}

/// The nearest triangle of `bvh` along `ray` on `(t0, t1)`, its normal turned to face the ray.
pub fn mesh_hit(bvh: &Bvh, ray: &Ray, t0: f64, t1: f64) -> Option<Hit> {
    let start = Ray {
        origin: ray.at(t0),
        dir: ray.dir,
    };
    let h = bvh.hit(&start, t1 - t0)?;
    Some(Hit {
        t: t0 + h.t,
        normal: if dot(h.normal, ray.dir) > 0.0 {
            h.normal.map(|x| -x)
        } else {
            h.normal
        },
        cap: false,
    })
}

/// A half-space `normal · p ≤ offset`: what a section keeps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Section {
    /// Unit normal, pointing into the part cut away.
    pub normal: Vec3,
    /// Offset along the normal, mm.
    pub offset: f64,
}

impl Section {
    /// The signed distance to the plane, positive on the side cut away.
    pub fn distance(&self, p: Vec3) -> f64 {
        dot(self.normal, p) - self.offset
    }

    /// The part of `(t0, t1)` along the ray on the side kept, if any.
    pub fn keep(&self, ray: &Ray, t0: f64, t1: f64) -> Option<(f64, f64)> {
        let d0 = self.distance(ray.origin);
        let rate = dot(self.normal, ray.dir);
        if rate.abs() < 1e-300 {
            return (d0 <= 0.0).then_some((t0, t1));
        }
        let t = -d0 / rate;
        let (lo, hi) = if rate > 0.0 {
            (t0, t1.min(t))
        } else {
            (t0.max(t), t1)
        };
        (lo <= hi).then_some((lo, hi))
    }
}

/// The most steps one ray takes through an implicit solid: a ray still short of the surface
/// after them is taken to have missed it (it only happens along grazing rays).
pub const MAX_STEPS: usize = 4096;

/// An implicit solid: a field clipped by a box and, where asked, a section plane; less, where
/// asked, the fragments its mesh drops.
pub struct Implicit<'a> {
    field: &'a dyn Field,
    bounds: Aabb,
    section: Option<Section>,
    /// The step normals are differentiated over, mm.
    step: f64,
    /// The distance over which openness is measured, mm.
    reach: f64,
    /// The fragments left out, and how far beyond their meshes' shells they reach, mm.
    loose: Option<(&'a Loose, f64)>,
}

impl<'a> Implicit<'a> {
    /// `field` clipped by `bounds` and `section`, its finest features about `voxel` mm across
    /// and its cells `cell` mm (normals are differentiated over a tenth of a voxel, openness
    /// measured over a sixth of a cell).
    pub fn new(
        field: &'a dyn Field,
        bounds: Aabb,
        section: Option<Section>,
        voxel: f64,
        cell: f64,
    ) -> Implicit<'a> {
        Implicit {
            field,
            bounds,
            section,
            step: 0.1 * voxel,
            reach: cell / 6.0,
            loose: None,
        }
    }

    /// The solid less the fragments `loose` holds (meshed on voxels of `voxel` mm), as its
    /// mesh is: near or inside the solid, a point within a voxel of a fragment's shell (the
    /// mesh's chords lie within a voxel of the surface) is outside it, and a ray crosses a
    /// fragment in steps of half a voxel (fragments lie apart from the part, by definition).
    pub fn dropping(self, loose: &'a Loose, voxel: f64) -> Implicit<'a> {
        Implicit {
            loose: (!loose.is_empty()).then_some((loose, voxel)),
            ..self
        }
    }

    /// The solid's value and clearance at `p`, unclipped: the field's, outside the fragments
    /// left out.
    fn unclipped(&self, p: Vec3) -> (f64, f64) {
        let (f, cf) = self.field.value_and_clearance(p);
        match self.loose {
            Some((loose, voxel)) if f < voxel && loose.holds(p, voxel) => {
                (0.5 * voxel, 0.5 * voxel)
            }
            _ => (f, cf),
        }
    }

    /// The clipped solid's value and clearance at `p`.
    pub fn value_and_clearance(&self, p: Vec3) -> (f64, f64) {
        let (f, cf) = self.unclipped(p);
        let b = self.bounds.value(p);
        let (mut v, mut c) = (f.max(b), intersection_clearance(f, cf, b, b.abs()));
        if let Some(s) = &self.section {
            let d = s.distance(p);
            c = intersection_clearance(v, c, d, d.abs());
            v = v.max(d);
        }
        (v, c)
    }

    /// The clipped solid's value at `p`.
    pub fn value(&self, p: Vec3) -> f64 {
        self.value_and_clearance(p).0
    }

    /// The first distance along `ray` at which it meets the clipped solid, by sphere tracing.
    pub fn first_hit(&self, ray: &Ray, tol: Tolerance) -> Option<f64> {
        let (t0, t1) = ray.clip(&self.bounds)?;
        let (t0, t1) = match &self.section {
            Some(s) => s.keep(ray, t0, t1)?,
            None => (t0, t1),
        };
        sphere_trace(|p| self.value_and_clearance(p), ray, t0, t1, tol)
    }

    /// The outward unit normal at `p`, from the clipped field's gradient.
    pub fn normal(&self, p: Vec3) -> Vec3 {
        field_normal(|q| self.value(q), p, self.step)
    }
}

impl Scene for Implicit<'_> {
    fn hit(&self, ray: &Ray, tol: Tolerance) -> Option<Hit> {
        let t = self.first_hit(ray, tol)?;
        let p = ray.at(t);
        let cap = self.section.is_some_and(|s| {
            let d = s.distance(p);
            d.abs() < self.step + 2.0 * (tol.absolute + tol.per_distance * t)
                && self.unclipped(p).0 <= d + self.step
        });
        let normal = match (&self.section, cap) {
            (Some(s), true) => s.normal,
            _ => self.normal(p),
        };
        Some(Hit { t, normal, cap })
    }

    fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// Ambient occlusion from the field.
    fn openness(&self, p: Vec3, n: Vec3) -> f64 {
        field_openness(|q| self.value(q), p, n, self.reach)
    }
}

/// A triangle mesh, hit through its BVH, cut by a section plane where asked (the cut is not
/// capped: a mesh has no inside to fill it with).
pub struct Triangles<'a> {
    /// The hierarchy over the triangles.
    pub bvh: &'a Bvh,
    /// The half-space kept.
    pub section: Option<Section>,
}

impl Scene for Triangles<'_> {
    fn hit(&self, ray: &Ray, _tol: Tolerance) -> Option<Hit> {
        let b = self.bvh.bounds()?;
        let (t0, t1) = ray.clip(&b.grown(1e-9 * (1.0 + b.size()[0].abs())))?;
        let (t0, t1) = match &self.section {
            Some(s) => s.keep(ray, t0, t1)?,
            None => (t0, t1),
        };
        mesh_hit(self.bvh, ray, t0, t1)
    }

    fn bounds(&self) -> Aabb {
        self.bvh.bounds().unwrap_or(Aabb {
            min: [0.0; 3],
            max: [0.0; 3],
        })
    }
}
