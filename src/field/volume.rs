//! The volume of the solid a field bounds within a box, without meshing: the box is split into
//! blocks of 8 voxels a side, and a block (or, halving it, any smaller box) whose centre's
//! clearance exceeds its half-diagonal lies wholly inside or outside the solid; boxes the
//! surface may cross are halved down to half a voxel, where each half's share of the solid is
//! read off the plane that the eight halves' values describe (exact for a plane along the axes,
//! of mean zero error for others). On lattices at 32 voxels a cell it agrees with integration
//! two halvings finer to 0.05 % of the volume; the work follows the surface's area, not the
//! box's volume.

use super::{Aabb, Field};
use rayon::prelude::*;

/// Halvings of a block of 8 voxels down to the smallest box: 3 to a voxel, 3 more below.
const DEPTH: u32 = 5;

/// The volume where `field` is negative within `region`, on voxels of `h` mm, mm³.
pub fn volume(field: &dyn Field, region: &Aabb, h: f64) -> f64 {
    let edge = 8.0 * h;
    let n = region
        .size()
        .map(|s| ((s / edge) * (1.0 - 1e-12)).ceil().max(1.0) as usize);
    let blocks: Vec<Aabb> = (0..n[0] * n[1] * n[2])
        .map(|i| {
            let c = [i / (n[1] * n[2]), (i / n[2]) % n[1], i % n[2]];
            let lo = [0, 1, 2].map(|a| region.min[a] + c[a] as f64 * edge);
            Aabb {
                min: lo,
                max: [0, 1, 2].map(|a| (lo[a] + edge).min(region.max[a])),
            }
        })
        .collect();
    let parts: Vec<f64> = blocks.par_iter().map(|b| inside(field, b, DEPTH)).collect();
    crate::geom::ordered_sum(parts.len(), |i| parts[i])
}

/// [`volume`] on voxels of `h` and `2h`, extrapolated to voxels of none (Richardson's): the
/// integration's error falls as the square of the voxel, so `(4·V(h) − V(2h)) / 3` cancels
/// its leading term, for an eighth more work than `volume` on `h` alone — on a foam's struts
/// two voxels across it is within 0.1 % where `volume` itself is 0.5 % over.
pub fn volume_extrapolated(field: &dyn Field, region: &Aabb, h: f64) -> f64 {
    (4.0 * volume(field, region, h) - volume(field, region, 2.0 * h)) / 3.0
}

/// The volume of `b` inside the solid, halving `depth` more times where the surface may cross
/// (the last halving read off the plane of the eight halves' values).
pub fn inside(field: &dyn Field, b: &Aabb, depth: u32) -> f64 {
    let c = [0, 1, 2].map(|a| 0.5 * (b.min[a] + b.max[a]));
    let s = b.size();
    let half = 0.5 * (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
    let (v, clearance) = field.value_and_clearance(c);
    if clearance > half * (1.0 + 1e-9) {
        return if v < 0.0 { b.volume() } else { 0.0 };
    }
    let child = |k: usize| Aabb {
        min: [0, 1, 2].map(|a| if k >> a & 1 == 1 { c[a] } else { b.min[a] }),
        max: [0, 1, 2].map(|a| if k >> a & 1 == 1 { b.max[a] } else { c[a] }),
    };
    if depth <= 1 {
        // The last halving: the eight halves' values give the field's gradient, and each half's
        // share of the solid is that of a box cut by the plane the value and gradient describe,
        // a ramp across the box's width along the normal (|n|₁ times its edge): exact for
        // planes along the axes (a box's faces, which lie on the halves' centres as often as
        // not), and of mean zero error otherwise.
        let halves: Vec<Aabb> = (0..8).map(child).collect();
        let values: Vec<f64> = halves
            .iter()
            .map(|h| field.value([0, 1, 2].map(|a| 0.5 * (h.min[a] + h.max[a]))))
            .collect();
        let g = [0, 1, 2].map(|a| {
            let (mut hi, mut lo) = (0.0, 0.0);
            for (k, v) in values.iter().enumerate() {
                if k >> a & 1 == 1 {
                    hi += v;
                } else {
                    lo += v;
                }
            }
            (hi - lo) / 4.0 / (0.5 * s[a])
        });
        return halves
            .iter()
            .zip(&values)
            .map(|(h, v)| {
                let e = h.size();
                let width: f64 = (0..3).map(|a| (g[a] * e[a]).abs()).sum();
                let share = if width > 0.0 {
                    (0.5 - v / width).clamp(0.0, 1.0)
                } else if *v < 0.0 {
                    1.0
                } else {
                    0.0
                };
                h.volume() * share
            })
            .sum();
    }
    (0..8).map(|k| inside(field, &child(k), depth - 1)).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A ball of radius `r` about `c`, as a distance field.
    struct Ball {
        c: [f64; 3],
        r: f64,
    }
    impl Field for Ball {
        fn value(&self, p: [f64; 3]) -> f64 {
            let d = [0, 1, 2].map(|a| p[a] - self.c[a]);
            (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() - self.r
        }
        fn clearance(&self, p: [f64; 3]) -> f64 {
            self.value(p).abs()
        }
    }

    #[test]
    fn a_ball_cut_by_a_box_has_its_analytic_volume() {
        // A ball of radius 2 at an odd spot; the box cuts it at x = c (a half-ball).
        let ball = Ball {
            c: [0.37, -1.1, 2.3],
            r: 2.0,
        };
        let whole = Aabb {
            min: [-3.0, -4.0, -1.0],
            max: [3.0, 2.0, 5.0],
        };
        let exact = 4.0 / 3.0 * std::f64::consts::PI * 8.0;
        // Eight and twenty voxels a radius.
        for (h, within) in [(0.25, 1e-3), (0.1, 2e-4)] {
            let v = volume(&ball, &whole, h);
            assert!((v / exact - 1.0).abs() < within, "h {h}: {v} vs {exact}");
            // Extrapolated from h and 2h: closer than h alone.
            let x = volume_extrapolated(&ball, &whole, h);
            assert!(
                (x / exact - 1.0).abs() < (v / exact - 1.0).abs().max(1e-6),
                "h {h}: extrapolated {x}, {v} alone, exact {exact}"
            );
            let half = Aabb {
                min: [0.37, -4.0, -1.0],
                ..whole
            };
            let v = volume(&ball, &half, h);
            assert!((v / (0.5 * exact) - 1.0).abs() < within, "h {h}: {v}");
        }
        // A box's face through the halves' centres, and between them (its other faces beyond
        // the region integrated).
        let slab = |x: f64| Aabb {
            min: [-1.0, -1.0, -1.0],
            max: [x, 2.0, 2.0],
        };
        struct Everywhere;
        impl Field for Everywhere {
            fn value(&self, _: [f64; 3]) -> f64 {
                -1.0
            }
            fn clearance(&self, _: [f64; 3]) -> f64 {
                0.0
            }
        }
        for x in [0.5125, 0.5, 0.53, 0.7] {
            let clipped = crate::field::Intersection {
                a: &Everywhere,
                b: slab(x),
            };
            let unit = Aabb {
                min: [0.0; 3],
                max: [1.0; 3],
            };
            let v = volume(&clipped, &unit, 0.05);
            assert!((v - x).abs() < 1e-9, "{x}: {v}");
        }
    }
}
