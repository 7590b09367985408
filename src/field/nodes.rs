//! Values at the nodes of a regular grid, read trilinearly between them: a sampled density
//! field, the level of a graded lattice, a per-cell correction read between the cells' centres.

use super::Vec3;

/// Values at the nodes `origin + (i, j, k) · step`, `i < n[0]`, …, stored `(i·n₁ + j)·n₂ + k`.
/// Points beyond the outer nodes read the outer nodes' values (the reading is held there); an
/// axis of one node is constant along it.
#[derive(Debug, Clone)]
pub struct Nodes {
    /// The first node, mm.
    pub origin: Vec3,
    /// Spacing along each axis, mm.
    pub step: Vec3,
    /// Nodes per axis (each at least 1).
    pub n: [usize; 3],
    /// The values.
    pub values: Vec<f64>,
}

impl Nodes {
    /// `value(p)` at every node, in parallel.
    pub fn sample(
        origin: Vec3,
        step: Vec3,
        n: [usize; 3],
        value: impl Fn(Vec3) -> f64 + Sync,
    ) -> Nodes {
        use rayon::prelude::*;
        let values = (0..n[0] * n[1] * n[2])
            .into_par_iter()
            .map(|i| {
                let c = [i / (n[1] * n[2]), i / n[2] % n[1], i % n[2]];
                value([0, 1, 2].map(|a| origin[a] + c[a] as f64 * step[a]))
            })
            .collect();
        Nodes {
            origin,
            step,
            n,
            values,
        }
    }

    /// `value(p)` at nodes `step` apart over `bounds` grown by `margin`, a node on its lower
    /// corner.
    pub fn covering(
        bounds: &super::Aabb,
        step: Vec3,
        margin: f64,
        value: impl Fn(Vec3) -> f64 + Sync,
    ) -> Nodes {
        let origin = [0, 1, 2].map(|a| bounds.min[a] - (margin / step[a]).ceil() * step[a]);
        let n =
            [0, 1, 2].map(|a| ((bounds.max[a] + margin - origin[a]) / step[a]).ceil() as usize + 1);
        Nodes::sample(origin, step, n, value)
    }

    /// The value at `p`.
    #[inline(always)]
    pub fn at(&self, p: Vec3) -> f64 {
        self.with_gradient(p).0
    }

    /// The value at `p` and its gradient.
    #[inline(always)]
    pub fn with_gradient(&self, p: Vec3) -> (f64, Vec3) {
        let n = self.n;
        let mut i0 = [0usize; 3];
        let mut d = [0usize; 3];
        let mut w = [0.0; 3];
        for a in 0..3 {
            if n[a] > 1 {
                let u = ((p[a] - self.origin[a]) / self.step[a]).clamp(0.0, (n[a] - 1) as f64);
                i0[a] = (u as usize).min(n[a] - 2);
                w[a] = u - i0[a] as f64;
                d[a] = 1;
            }
        }
        let base = (i0[0] * n[1] + i0[1]) * n[2] + i0[2];
        let c = |x: usize, y: usize, z: usize| {
            self.values[base + (x * d[0] * n[1] + y * d[1]) * n[2] + z * d[2]]
        };
        let lerp = |a: f64, b: f64, w: f64| a + (b - a) * w;
        let (c00, c01) = (
            lerp(c(0, 0, 0), c(0, 0, 1), w[2]),
            lerp(c(0, 1, 0), c(0, 1, 1), w[2]),
        );
        let (c10, c11) = (
            lerp(c(1, 0, 0), c(1, 0, 1), w[2]),
            lerp(c(1, 1, 0), c(1, 1, 1), w[2]),
        );
        let (c0, c1) = (lerp(c00, c01, w[1]), lerp(c10, c11, w[1]));
        let slope = |a: usize, v: f64| if d[a] == 1 { v / self.step[a] } else { 0.0 };
        let gx = slope(0, c1 - c0);
        let gy = slope(1, lerp(c01 - c00, c11 - c10, w[0]));
        let dz = |y: usize| lerp(c(0, y, 1) - c(0, y, 0), c(1, y, 1) - c(1, y, 0), w[0]);
        let gz = slope(2, lerp(dz(0), dz(1), w[1]));
        (lerp(c0, c1, w[0]), [gx, gy, gz])
    }

    /// A bound on the gradient's length anywhere (exact for the trilinear reading: along each
    /// axis its slope is a blend of the slopes between neighbouring nodes).
    pub fn lipschitz(&self) -> f64 {
        let n = self.n;
        let mut slope = [0.0f64; 3];
        let at = |x: usize, y: usize, z: usize| self.values[(x * n[1] + y) * n[2] + z];
        for x in 0..n[0] {
            for y in 0..n[1] {
                for z in 0..n[2] {
                    let v = at(x, y, z);
                    if x + 1 < n[0] {
                        slope[0] = slope[0].max((at(x + 1, y, z) - v).abs() / self.step[0]);
                    }
                    if y + 1 < n[1] {
                        slope[1] = slope[1].max((at(x, y + 1, z) - v).abs() / self.step[1]);
                    }
                    if z + 1 < n[2] {
                        slope[2] = slope[2].max((at(x, y, z + 1) - v).abs() / self.step[2]);
                    }
                }
            }
        }
        (slope[0].powi(2) + slope[1].powi(2) + slope[2].powi(2)).sqrt()
    }

    /// The smallest and largest value.
    pub fn range(&self) -> [f64; 2] {
        self.values
            .iter()
            .fold([f64::INFINITY, f64::NEG_INFINITY], |[a, b], v| {
                [a.min(*v), b.max(*v)]
            })
    }

    /// The mean value.
    pub fn mean(&self) -> f64 {
        self.values.iter().sum::<f64>() / self.values.len() as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A linear function is read exactly, with its slope, inside the nodes; held beyond them;
    /// an axis of one node is constant; the Lipschitz bound is the slope's length.
    #[test]
    fn reads_linear_functions_exactly() {
        let f = |p: Vec3| 1.0 + 2.0 * p[0] - 0.5 * p[1];
        let g = Nodes::sample([0.5, -1.0, 3.0], [0.25, 0.5, 1.0], [5, 4, 1], f);
        for p in [[0.6, -0.8, 3.0], [1.4, 0.4, 7.0], [0.5, -1.0, 3.0]] {
            let (v, d) = g.with_gradient(p);
            assert!((v - f(p)).abs() < 1e-12, "{p:?}");
            assert!((d[0] - 2.0).abs() < 1e-12 && (d[1] + 0.5).abs() < 1e-12 && d[2] == 0.0);
        }
        assert!((g.at([9.0, 9.0, 9.0]) - f([1.5, 0.5, 0.0])).abs() < 1e-12);
        assert!((g.lipschitz() - (4.0f64 + 0.25).sqrt()).abs() < 1e-12);
        assert_eq!(g.range(), [f([0.5, 0.5, 0.0]), f([1.5, -1.0, 0.0])]);
    }
}
