//! Geometry every stage shares: points and boxes, rays, the triangle mesh with its measures
//! ([`Mesh`]) and topology ([`topology`]), polygon triangulation ([`triangulate`]), a bounding
//! volume hierarchy over triangles for ray casts, distances and inside tests ([`bvh`]), and
//! closed contours in a plane with marching squares ([`contour`]). It depends on nothing else in
//! latvox: every other stage builds on it.

pub mod bvh;
pub mod contour;
mod mesh;
pub mod topology;
pub mod triangulate;
pub mod winding;

pub use mesh::*;

/// A point or a vector, mm.
pub type Vec3 = [f64; 3];

/// An axis-aligned box `[min, max]` (a signed distance field too: `crate::field`).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Aabb {
    /// Lower corner, mm.
    pub min: Vec3,
    /// Upper corner, mm.
    pub max: Vec3,
}

impl Aabb {
    /// Edge lengths along x, y, z, mm.
    pub fn size(&self) -> Vec3 {
        [
            self.max[0] - self.min[0],
            self.max[1] - self.min[1],
            self.max[2] - self.min[2],
        ]
    }

    /// Volume, mm³.
    pub fn volume(&self) -> f64 {
        let s = self.size();
        s[0] * s[1] * s[2]
    }

    /// The centre, mm.
    pub fn centre(&self) -> Vec3 {
        [0, 1, 2].map(|a| 0.5 * (self.min[a] + self.max[a]))
    }

    /// Whether `p` lies in the box (faces included).
    pub fn contains(&self, p: Vec3) -> bool {
        (0..3).all(|a| p[a] >= self.min[a] && p[a] <= self.max[a])
    }

    /// The smallest box holding both.
    pub fn union(&self, o: &Aabb) -> Aabb {
        Aabb {
            min: [0, 1, 2].map(|k| self.min[k].min(o.min[k])),
            max: [0, 1, 2].map(|k| self.max[k].max(o.max[k])),
        }
    }

    /// The box grown by `m` on every side.
    pub fn grown(&self, m: f64) -> Aabb {
        Aabb {
            min: self.min.map(|x| x - m),
            max: self.max.map(|x| x + m),
        }
    }
}

/// A ray: `origin + t·dir`, `dir` of unit length.
#[derive(Debug, Clone, Copy)]
pub struct Ray {
    /// Where it starts, mm.
    pub origin: Vec3,
    /// Its direction, unit length.
    pub dir: Vec3,
}

impl Ray {
    /// The point at distance `t`.
    #[inline]
    pub fn at(&self, t: f64) -> Vec3 {
        [
            self.origin[0] + t * self.dir[0],
            self.origin[1] + t * self.dir[1],
            self.origin[2] + t * self.dir[2],
        ]
    }

    /// The part of the ray inside `b`, as `(t_enter, t_exit)` with `t_enter ≥ 0`, if any.
    pub fn clip(&self, b: &Aabb) -> Option<(f64, f64)> {
        let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
        for a in 0..3 {
            let inv = 1.0 / self.dir[a];
            let (mut lo, mut hi) = (
                (b.min[a] - self.origin[a]) * inv,
                (b.max[a] - self.origin[a]) * inv,
            );
            if lo > hi {
                std::mem::swap(&mut lo, &mut hi);
            }
            // NaN (a ray in the plane of a face) keeps the other bounds.
            if lo > t0 {
                t0 = lo;
            }
            if hi < t1 {
                t1 = hi;
            }
        }
        (t0 <= t1).then_some((t0, t1))
    }
}

/// `a` scaled to unit length (unchanged if zero).
pub(crate) fn normalized(a: Vec3) -> Vec3 {
    let n = norm(a);
    if n > 0.0 {
        a.map(|x| x / n)
    } else {
        a
    }
}

/// The block at position `i` of the `n` blocks from `lo` (x slowest, z fastest).
pub(crate) fn block_at(lo: [i64; 3], n: [i64; 3], i: usize) -> [i64; 3] {
    let (i, [_, ny, nz]) = (i as i64, n);
    [lo[0] + i / (ny * nz), lo[1] + (i / nz) % ny, lo[2] + i % nz]
}

/// The position of block `b` among the `n` blocks from `lo`, if it is one of them.
pub(crate) fn block_index(lo: [i64; 3], n: [i64; 3], b: [i64; 3]) -> Option<usize> {
    let r = [0, 1, 2].map(|a| b[a] - lo[a]);
    if (0..3).any(|a| r[a] < 0 || r[a] >= n[a]) {
        return None;
    }
    Some(((r[0] * n[1] + r[1]) * n[2] + r[2]) as usize)
}
