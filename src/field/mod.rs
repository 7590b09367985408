//! Fields: implicit solids as functions of space.
//!
//! A [`Field`] gives a signed value at a point — negative inside, close to the signed distance in
//! millimetres near the surface — and a *clearance*: a radius around the point that the surface
//! provably does not enter. Sampling uses the clearance to skip whole 8³ blocks; because the
//! clearance never overestimates, a skipped block can never hide a piece of surface (a skipped
//! block that the surface crossed would be a hole in the mesh).

pub mod beams;
pub mod cellmap;
pub mod density;
pub mod domain;
pub mod nodes;
pub mod periodic;
pub mod sizing;
pub mod volume;

pub use domain::Domain;

pub use crate::geom::{Aabb, Vec3};

/// An implicit solid: `value < 0` inside.
pub trait Field: Sync {
    /// Signed value at `p`; approximately the signed distance near the surface.
    fn value(&self, p: Vec3) -> f64;

    /// A lower bound on the distance from `p` to the surface `value = 0`.
    fn clearance(&self, p: Vec3) -> f64;

    /// [`Field::value`] and [`Field::clearance`] at one point, for callers that need both (a
    /// sphere tracer's step); fields that compute both from the same evaluation override it.
    fn value_and_clearance(&self, p: Vec3) -> (f64, f64) {
        (self.value(p), self.clearance(p))
    }

    /// The implicit function and its gradient at `p`: any function with the same zero set and
    /// sign as `value`, smooth near the surface (used for Newton projection onto the surface).
    /// The default differentiates `value` numerically.
    fn implicit_with_gradient(&self, p: Vec3) -> (f64, Vec3) {
        (self.value(p), numeric_gradient(|q| self.value(q), p))
    }

    /// Whether the surface is smooth within `reach` of `p`, so that a vertex there may be
    /// snapped onto it: not where two surfaces meet at an edge that Newton steps do not follow
    /// (a lattice cut by a curved wall). True by default.
    fn smooth_near(&self, _p: Vec3, _reach: f64) -> bool {
        true
    }

    /// Values at `points` (a small, compact set: a block of samples), into `out`. Fields whose
    /// work can be shared across nearby points (a test done once for the whole block) override
    /// it.
    fn values(&self, points: &[Vec3], out: &mut [f64]) {
        for (p, o) in points.iter().zip(out.iter_mut()) {
            *o = self.value(*p);
        }
    }

    /// Values at the 8³ points `origin + h·(i, j, k)`, `i, j, k ∈ 0..8`, stored at
    /// `out[(i·8 + j)·8 + k]` (OpenVDB's leaf order). Fields with separable structure override
    /// this to share work along each axis.
    fn sample_block(&self, origin: Vec3, h: f64, out: &mut [f32; 512]) {
        for i in 0..8 {
            for j in 0..8 {
                for k in 0..8 {
                    let p = [
                        origin[0] + h * i as f64,
                        origin[1] + h * j as f64,
                        origin[2] + h * k as f64,
                    ];
                    out[(i * 8 + j) * 8 + k] = self.value(p) as f32;
                }
            }
        }
    }
}

impl<T: Field + ?Sized> Field for &T {
    fn value(&self, p: Vec3) -> f64 {
        (**self).value(p)
    }
    fn clearance(&self, p: Vec3) -> f64 {
        (**self).clearance(p)
    }
    fn value_and_clearance(&self, p: Vec3) -> (f64, f64) {
        (**self).value_and_clearance(p)
    }
    fn implicit_with_gradient(&self, p: Vec3) -> (f64, Vec3) {
        (**self).implicit_with_gradient(p)
    }
    fn smooth_near(&self, p: Vec3, reach: f64) -> bool {
        (**self).smooth_near(p, reach)
    }
    fn sample_block(&self, origin: Vec3, h: f64, out: &mut [f32; 512]) {
        (**self).sample_block(origin, h, out)
    }
    fn values(&self, points: &[Vec3], out: &mut [f64]) {
        (**self).values(points, out)
    }
}

/// The gradient of `f` at `p` by central differences, with a step relative to `p`'s size.
pub fn numeric_gradient(f: impl Fn(Vec3) -> f64, p: Vec3) -> Vec3 {
    let e = 1e-6 * (1.0 + p.iter().fold(0.0f64, |m, x| m.max(x.abs())));
    [0, 1, 2].map(|a| {
        let (mut up, mut dn) = (p, p);
        up[a] += e;
        dn[a] -= e;
        (f(up) - f(dn)) / (2.0 * e)
    })
}

/// Quilez's polynomial smooth minimum of radius `k > 0`: `min(a, b)` where they differ by more
/// than `k`, below it by up to `k/4` where they meet; 1-Lipschitz when `a` and `b` are.
pub fn smooth_min(a: f64, b: f64, k: f64) -> f64 {
    let h = (k - (a - b).abs()).max(0.0) / k;
    a.min(b) - 0.25 * h * h * k
}

/// The clearance of `max(a, b)` from the operands' values and clearances: its surface lies on
/// `a`'s or `b`'s and inside both, so from a point outside either operand, that operand's
/// clearance alone is a valid bound.
pub fn intersection_clearance(a: f64, ca: f64, b: f64, cb: f64) -> f64 {
    let mut c = ca.min(cb);
    if a > 0.0 {
        c = c.max(ca);
    }
    if b > 0.0 {
        c = c.max(cb);
    }
    c
}

/// The clearance of `min(a, b)`: its surface lies on `a`'s or `b`'s and outside both, so from
/// inside either operand, that operand's clearance alone is a valid bound.
pub fn union_clearance(a: f64, ca: f64, b: f64, cb: f64) -> f64 {
    intersection_clearance(-a, ca, -b, cb)
}

impl Field for Aabb {
    fn value(&self, p: Vec3) -> f64 {
        let mut outside = 0.0f64;
        let mut inside = f64::NEG_INFINITY;
        for (a, &pa) in p.iter().enumerate() {
            let d = (self.min[a] - pa).max(pa - self.max[a]);
            outside += d.max(0.0).powi(2);
            inside = inside.max(d);
        }
        if outside > 0.0 {
            outside.sqrt()
        } else {
            inside
        }
    }

    fn clearance(&self, p: Vec3) -> f64 {
        self.value(p).abs()
    }
}

/// The intersection of two solids (`max` of the values). The clip of a lattice by its box.
pub struct Intersection<A, B> {
    /// The first solid.
    pub a: A,
    /// The second solid.
    pub b: B,
}

impl<A: Field, B: Field> Field for Intersection<A, B> {
    fn value(&self, p: Vec3) -> f64 {
        self.a.value(p).max(self.b.value(p))
    }

    fn clearance(&self, p: Vec3) -> f64 {
        self.value_and_clearance(p).1
    }

    fn value_and_clearance(&self, p: Vec3) -> (f64, f64) {
        let (a, ca) = self.a.value_and_clearance(p);
        let (b, cb) = self.b.value_and_clearance(p);
        (a.max(b), intersection_clearance(a, ca, b, cb))
    }

    fn sample_block(&self, origin: Vec3, h: f64, out: &mut [f32; 512]) {
        let mut other = [0.0f32; 512];
        self.a.sample_block(origin, h, out);
        self.b.sample_block(origin, h, &mut other);
        for (o, b) in out.iter_mut().zip(other.iter()) {
            *o = o.max(*b);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_distance_is_exact_outside_and_inside() {
        let b = Aabb {
            min: [0.0; 3],
            max: [2.0, 4.0, 6.0],
        };
        assert!((b.value([1.0, 2.0, 3.0]) + 1.0).abs() < 1e-12);
        assert!((b.value([-3.0, -4.0, 3.0]) - 5.0).abs() < 1e-12);
        assert!((b.value([2.5, 2.0, 3.0]) - 0.5).abs() < 1e-12);
    }
}
