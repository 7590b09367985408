//! Sections of an implicit solid, without a mesh: the field sampled on the layer's plane and
//! contoured by marching squares ([`crate::geom::contour::iso_loops`]). The plane is covered by blocks
//! of 8 × 8 samples; a block whose centre's clearance (a distance within which the field keeps
//! its sign) exceeds its half-diagonal lies wholly inside or outside and is not sampled further,
//! so the work follows the length of the contours, not the area of the layer. Loops come out
//! with the solid on the left, like a mesh's sections, and go to the same writers.
//!
//! Where the part's meshing dropped fragments the box cuts loose ([`Loose`]), the deepest
//! sample of each loop's region is tested against the fragments' shells, and the loop is
//! dropped when it lies in one: the slices hold what the mesh holds.
//!
//! The error is marching squares' own — the contour is linear between samples a spacing `h`
//! apart — and shrinks as h²: nothing is lost at a box's cut faces, where a mesh's sharp edges
//! are rounded by its voxels.

use super::Frame;
use crate::field::{intersection_clearance, Aabb, Field, Vec3};
use crate::geom::contour::{iso_loops, Section};
use crate::mesh::pieces::Loose;

/// Samples per block side.
const BLOCK: usize = 8;

/// Most samples one layer's plane may hold (1.6 GB of values).
pub const MAX_SAMPLES: f64 = 2e8;

/// An implicit solid prepared for slicing along one direction.
pub struct ImplicitSlicer<'a> {
    field: &'a dyn Field,
    /// The box the solid is clipped to.
    clip: Aabb,
    frame: Frame,
    /// In-layer bounds of the solid, `[u_min, v_min, u_max, v_max]`.
    bounds: [f64; 4],
    /// Sample spacing, mm.
    h: f64,
    /// Fragments whose loops are dropped.
    loose: Option<&'a Loose>,
    /// How far outside a fragment's shell a loop's deepest point may lie and still be the
    /// fragment's (its voxels round the fragment's thin ends off), mm.
    reach: f64,
}

impl<'a> ImplicitSlicer<'a> {
    /// Slices `field` (negative inside) clipped to `bounds` along `frame.d`, sampling every
    /// `h` mm.
    pub fn new(field: &'a dyn Field, bounds: &Aabb, frame: Frame, h: f64) -> Self {
        let (b, _) = project(bounds, &frame);
        ImplicitSlicer {
            field,
            clip: *bounds,
            frame,
            bounds: b,
            h,
            loose: None,
            reach: 0.0,
        }
    }

    /// The slicer, dropping the loops of the fragments `loose` holds, meshed on voxels of
    /// `voxel` mm.
    pub fn dropping(self, loose: &'a Loose, voxel: f64) -> Self {
        ImplicitSlicer {
            loose: (!loose.is_empty()).then_some(loose),
            reach: voxel,
            ..self
        }
    }

    /// Samples on one layer's plane (the grid and its margin).
    pub fn samples_per_layer(&self) -> f64 {
        let b = self.bounds;
        (((b[2] - b[0]) / self.h).ceil() + 3.0) * (((b[3] - b[1]) / self.h).ceil() + 3.0)
    }

    /// The clipped solid's value and clearance at `p`: the field's, cut by the box (whose
    /// slab distance is exact inside and a lower bound outside).
    fn sample(&self, p: Vec3) -> (f64, f64) {
        let bv = self.box_value(p);
        let (v, c) = self.field.value_and_clearance(p);
        (v.max(bv), intersection_clearance(v, c, bv, bv.abs()))
    }

    /// The clipping box's slab distance at `p` (negative inside).
    fn box_value(&self, p: Vec3) -> f64 {
        let b = &self.clip;
        (0..3)
            .map(|a| (b.min[a] - p[a]).max(p[a] - b.max[a]))
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// The section at height `z`.
    pub fn section(&self, z: f64) -> Section {
        let h = self.h;
        let b = self.bounds;
        // One sample of margin all round: the margin lies outside the solid, so loops close.
        let (u0, v0) = (b[0] - h, b[1] - h);
        let nu = ((b[2] - b[0]) / h).ceil() as usize + 3;
        let nv = ((b[3] - b[1]) / h).ceil() as usize + 3;
        let f = &self.frame;
        let at = |i: f64, j: f64| -> Vec3 {
            let (u, v) = (u0 + i * h, v0 + j * h);
            [0, 1, 2].map(|a| u * f.u[a] + v * f.v[a] + z * f.d[a])
        };
        let mut vals = vec![f64::NAN; nu * nv];
        let (bu, bv) = (nu.div_ceil(BLOCK), nv.div_ceil(BLOCK));
        let mut near = Vec::new();
        for bj in 0..bv {
            for bi in 0..bu {
                let (i0, j0) = (bi * BLOCK, bj * BLOCK);
                let (i1, j1) = ((i0 + BLOCK).min(nu - 1), (j0 + BLOCK).min(nv - 1));
                let c = at(0.5 * (i0 + i1) as f64, 0.5 * (j0 + j1) as f64);
                let half = 0.5 * h * (((i1 - i0).pow(2) + (j1 - j0).pow(2)) as f64).sqrt();
                let (v, cl) = self.sample(c);
                if cl > half * (1.0 + 1e-9) && v != 0.0 {
                    for j in j0..=j1 {
                        for i in i0..=i1 {
                            if vals[j * nu + i].is_nan() {
                                vals[j * nu + i] = v;
                            }
                        }
                    }
                } else {
                    near.push((i0, j0, i1, j1));
                }
            }
        }
        // Blocks near the surface: every sample (shared edges evaluated again, exactly), the
        // block's points given to the field at once.
        let mut points = Vec::with_capacity((BLOCK + 1) * (BLOCK + 1));
        let mut out = Vec::with_capacity((BLOCK + 1) * (BLOCK + 1));
        for (i0, j0, i1, j1) in near {
            points.clear();
            for j in j0..=j1 {
                for i in i0..=i1 {
                    points.push(at(i as f64, j as f64));
                }
            }
            out.resize(points.len(), 0.0);
            self.field.values(&points, &mut out);
            let mut k = 0;
            for j in j0..=j1 {
                for i in i0..=i1 {
                    vals[j * nu + i] = out[k].max(self.box_value(points[k]));
                    k += 1;
                }
            }
        }
        let mut loops = iso_loops([nu, nv], |i, j| -vals[j * nu + i], 0.0, -1.0);
        if let Some(loose) = self.loose {
            loops.retain(|l| {
                let (i, j) = deepest_in(l, &vals, nu, nv);
                !loose.holds(at(i as f64, j as f64), self.reach)
            });
        }
        let loops = loops
            .into_iter()
            .map(|l| {
                l.into_iter()
                    .map(|p| [u0 + p[0] * h, v0 + p[1] * h])
                    .collect()
            })
            .collect();
        Section {
            loops,
            open: Vec::new(),
        }
    }
}

/// The deepest solid sample of the region a loop (in grid units, on the sample grid's edges)
/// bounds, within the loop's bounds: the region's samples are reached from the solid end of the
/// edge the loop's first point is on, through the grid's edges (two solid samples an edge apart
/// are in one region), and the one farthest (in steps along the grid) from the region's edge is
/// taken — the middle of a strut's or a wall's section, where a shell meshed on voxels surely
/// holds it. (The values cannot tell: they are flat where a box's face parallel to the layer
/// clips them.)
fn deepest_in(l: &[[f64; 2]], vals: &[f64], nu: usize, nv: usize) -> (usize, usize) {
    let solid = |i: usize, j: usize| vals[j * nu + i] <= 0.0;
    let p = l[0];
    let (a, b) = if p[0].fract() != 0.0 {
        ((p[0].floor(), p[1]), (p[0].floor() + 1.0, p[1]))
    } else {
        ((p[0], p[1].floor()), (p[0], p[1].floor() + 1.0))
    };
    let index = |q: (f64, f64)| -> Option<(usize, usize)> {
        (q.0 >= 0.0 && q.1 >= 0.0 && (q.0 as usize) < nu && (q.1 as usize) < nv)
            .then_some((q.0 as usize, q.1 as usize))
            .filter(|&(i, j)| solid(i, j))
    };
    let Some(start) = index(a).or_else(|| index(b)) else {
        return (0, 0);
    };
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for q in l {
        lo = [lo[0].min(q[0]), lo[1].min(q[1])];
        hi = [hi[0].max(q[0]), hi[1].max(q[1])];
    }
    let i0 = lo[0].floor().max(0.0) as usize;
    let j0 = lo[1].floor().max(0.0) as usize;
    let i1 = (hi[0].ceil() as usize).min(nu - 1);
    let j1 = (hi[1].ceil() as usize).min(nv - 1);
    let w = i1 + 1 - i0;
    let at = |i: usize, j: usize| (j - j0) * w + i - i0;
    let neighbours = |i: usize, j: usize| {
        [
            (i > i0).then(|| (i - 1, j)),
            (i < i1).then(|| (i + 1, j)),
            (j > j0).then(|| (i, j - 1)),
            (j < j1).then(|| (i, j + 1)),
        ]
    };
    // The region, by a flood fill.
    let mut inside = vec![false; w * (j1 + 1 - j0)];
    let mut region = vec![start];
    inside[at(start.0, start.1)] = true;
    let mut k = 0;
    while k < region.len() {
        let (i, j) = region[k];
        k += 1;
        for (ni, nj) in neighbours(i, j).into_iter().flatten() {
            if !inside[at(ni, nj)] && solid(ni, nj) {
                inside[at(ni, nj)] = true;
                region.push((ni, nj));
            }
        }
    }
    // Steps from the region's edge, breadth first from the samples on it.
    let mut steps = vec![u32::MAX; inside.len()];
    let mut queue = std::collections::VecDeque::new();
    for &(i, j) in &region {
        let edge = neighbours(i, j).iter().filter(|n| n.is_some()).count() < 4
            || neighbours(i, j)
                .into_iter()
                .flatten()
                .any(|(ni, nj)| !inside[at(ni, nj)]);
        if edge {
            steps[at(i, j)] = 0;
            queue.push_back((i, j));
        }
    }
    let mut best = start;
    while let Some((i, j)) = queue.pop_front() {
        let s = steps[at(i, j)];
        if s > steps[at(best.0, best.1)] {
            best = (i, j);
        }
        for (ni, nj) in neighbours(i, j).into_iter().flatten() {
            if inside[at(ni, nj)] && steps[at(ni, nj)] == u32::MAX {
                steps[at(ni, nj)] = s + 1;
                queue.push_back((ni, nj));
            }
        }
    }
    best
}

impl super::plan::Profile for ImplicitSlicer<'_> {
    fn area(&self, z: f64) -> f64 {
        self.section(z).measures().area
    }

    /// Not known without facets: adaptive cusp layers are for meshes.
    fn steepest_cos(&self, _z0: f64, _z1: f64) -> f64 {
        1.0
    }
}

/// In-layer bounds `[u_min, v_min, u_max, v_max]` and height range of a box along a frame.
pub fn project(b: &Aabb, frame: &Frame) -> ([f64; 4], [f64; 2]) {
    let mut out = crate::geom::contour::EMPTY_BOX;
    let mut hs = [f64::INFINITY, f64::NEG_INFINITY];
    for k in 0..8 {
        let p = [0, 1, 2].map(|a| if k >> a & 1 == 1 { b.max[a] } else { b.min[a] });
        out = crate::geom::contour::grow(out, frame.plane(p));
        let h = frame.height(p);
        hs = [hs[0].min(h), hs[1].max(h)];
    }
    (out, hs)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::contour::signed_area;

    /// A ball of radius 3 minus a ball of radius 1.5 (a hollow sphere), as a distance field.
    struct Shell;
    impl Field for Shell {
        fn value(&self, p: Vec3) -> f64 {
            let r = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
            (r - 3.0).max(1.5 - r)
        }
        fn clearance(&self, p: Vec3) -> f64 {
            self.value(p).abs()
        }
    }

    #[test]
    fn a_hollow_ball_slices_into_rings_of_the_right_area() {
        let b = Aabb {
            min: [-3.0; 3],
            max: [3.0; 3],
        };
        for dir in [[0.0, 0.0, 1.0], [1.0, 2.0, -0.5]] {
            let s = ImplicitSlicer::new(&Shell, &b, Frame::new(dir).unwrap(), 0.01);
            for z in [0.3, 1.0, 2.0] {
                let sec = s.section(z);
                let exact = std::f64::consts::PI * ((9.0 - z * z) - (2.25 - z * z).max(0.0));
                let area: f64 = sec.loops.iter().map(|l| signed_area(l)).sum();
                assert!(
                    (area - exact).abs() / exact < 1e-4,
                    "{dir:?} z={z}: {area} vs {exact}"
                );
                assert_eq!(sec.loops.len(), if z < 1.5 { 2 } else { 1 });
            }
        }
    }
}
