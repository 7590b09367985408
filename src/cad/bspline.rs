//! Closed (periodic) planar cubic B-spline curves: evaluation, least-squares fitting to ordered
//! points with given knots, and the distance from points to the curve.
//!
//! A periodic cubic with `m` knots `u_0 < … < u_{m−1}` in `[0, L)` and `m` control points:
//! knots repeat with period `L` (`t_{k+m} = t_k + L`), and on the span `[t_j, t_{j+1})` the curve
//! is `Σ N_i(u) P_{i mod m}` over `i = j−3 … j`. The same curve is written to IGES/DXF as an open
//! (unclamped) B-spline with `m + 3` control points (the first three repeated) — see
//! [`Periodic::unwrapped`].

use faer::linalg::solvers::Solve;
use faer::sparse::{SparseColMat, Triplet};
use faer::{Mat, Side};

pub type P2 = [f64; 2];

/// A closed cubic B-spline.
#[derive(Debug, Clone)]
pub struct Periodic {
    /// Knots in `[0, period)`, strictly increasing.
    pub knots: Vec<f64>,
    pub period: f64,
    pub points: Vec<P2>,
    /// `t_k` for `k = −4 … m + 4`, at `ext[k + 4]` (evaluation reads knots a lot).
    ext: Vec<f64>,
}

impl Periodic {
    /// A curve with `knots` in `[0, period)` (strictly increasing) and `points`.
    pub fn new(knots: Vec<f64>, period: f64, points: Vec<P2>) -> Periodic {
        let m = knots.len() as isize;
        let ext = (-4..m + 5)
            .map(|k| knots[k.rem_euclid(m) as usize] + k.div_euclid(m) as f64 * period)
            .collect();
        Periodic {
            knots,
            period,
            points,
            ext,
        }
    }

    pub fn len(&self) -> usize {
        self.points.len()
    }

    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Knot `t_k` for any integer `k`.
    pub fn t(&self, k: isize) -> f64 {
        let m = self.knots.len() as isize;
        if (-4..m + 5).contains(&k) {
            return self.ext[(k + 4) as usize];
        }
        let q = k.div_euclid(m);
        self.knots[k.rem_euclid(m) as usize] + q as f64 * self.period
    }

    /// The span `j` (an integer, `t_j ≤ u < t_{j+1}`) and the four basis values there.
    pub fn basis(&self, u: f64) -> (isize, [f64; 4]) {
        let m = self.knots.len();
        let uu = u.rem_euclid(self.period);
        let q = ((u - uu) / self.period).round() as isize;
        // Last knot ≤ uu.
        let j0 = match self.knots.binary_search_by(|k| k.total_cmp(&uu)) {
            Ok(i) => i,
            Err(i) => i.max(1) - 1,
        } as isize;
        // Evaluate in the base period (knots from the cached table), report the true span.
        let n = basis_at(|k| self.ext[(k + 4) as usize], j0, uu);
        (j0 + q * m as isize, n)
    }

    pub fn eval(&self, u: f64) -> P2 {
        let m = self.points.len() as isize;
        let (j, n) = self.basis(u);
        let mut p = [0.0; 2];
        for (r, w) in n.iter().enumerate() {
            let c = self.points[(j - 3 + r as isize).rem_euclid(m) as usize];
            p[0] += w * c[0];
            p[1] += w * c[1];
        }
        p
    }

    /// The open (unclamped) form: control points `P_0 … P_{m−1}, P_0, P_1, P_2` and knots
    /// `t_0 … t_{m+6}`, valid on `[t_3, t_{m+3}]` — for IGES entity 126 and DXF SPLINE.
    pub fn unwrapped(&self) -> (Vec<f64>, Vec<P2>, [f64; 2]) {
        let m = self.points.len();
        let knots = (0..(m + 7) as isize).map(|k| self.t(k)).collect();
        let mut pts = self.points.clone();
        pts.extend_from_slice(&self.points[..3.min(m)]);
        (knots, pts, [self.t(3), self.t(m as isize + 3)])
    }

    /// The parameter nearest to `p`, searched around `guess` within `window`: a coarse scan,
    /// then Newton's method on `(C(u) − p)·C′(u) = 0`. Returns `(u, distance)`.
    pub fn project(&self, p: P2, guess: f64, window: f64) -> (f64, f64) {
        let d2 = |u: f64| {
            let c = self.eval(u);
            (c[0] - p[0]).powi(2) + (c[1] - p[1]).powi(2)
        };
        let steps = 6;
        let (mut u, mut best) = (guess, d2(guess));
        for s in 0..=steps {
            let v = guess - window + 2.0 * window * s as f64 / steps as f64;
            let dv = d2(v);
            if dv < best {
                best = dv;
                u = v;
            }
        }
        let h = 1e-4 * window.max(1e-9);
        let (lo, hi) = (guess - window, guess + window);
        for _ in 0..6 {
            let (a, c, b) = (self.eval(u - h), self.eval(u), self.eval(u + h));
            let d1 = [(b[0] - a[0]) / (2.0 * h), (b[1] - a[1]) / (2.0 * h)];
            let dd = [
                (b[0] - 2.0 * c[0] + a[0]) / (h * h),
                (b[1] - 2.0 * c[1] + a[1]) / (h * h),
            ];
            let r = [c[0] - p[0], c[1] - p[1]];
            let f = r[0] * d1[0] + r[1] * d1[1];
            let fp = d1[0] * d1[0] + d1[1] * d1[1] + r[0] * dd[0] + r[1] * dd[1];
            if fp <= 0.0 {
                break;
            }
            let next = (u - f / fp).clamp(lo, hi);
            let dn = d2(next);
            if dn > best {
                break;
            }
            let done = (next - u).abs() < 1e-10 * window.max(1.0);
            u = next;
            best = dn;
            if done {
                break;
            }
        }
        (u, best.sqrt())
    }
}

/// Cubic basis values `N_{j−3..j}(u)` on span `j` (Cox–de Boor, The NURBS Book A2.2).
fn basis_at(t: impl Fn(isize) -> f64, j: isize, u: f64) -> [f64; 4] {
    let mut n = [0.0; 4];
    let mut left = [0.0; 4];
    let mut right = [0.0; 4];
    n[0] = 1.0;
    for r in 1..=3 {
        left[r] = u - t(j + 1 - r as isize);
        right[r] = t(j + r as isize) - u;
        let mut saved = 0.0;
        for s in 0..r {
            let tmp = n[s] / (right[s + 1] + left[r - s]);
            n[s] = saved + right[s + 1] * tmp;
            saved = left[r - s] * tmp;
        }
        n[r] = saved;
    }
    n
}

/// Least-squares fit of a periodic cubic with `knots` (in `[0, period)`) to `pts` at
/// parameters `params`. A tiny second-difference penalty keeps spans without data determined.
pub fn fit(pts: &[P2], params: &[f64], knots: Vec<f64>, period: f64) -> Periodic {
    let m = knots.len();
    let mut curve = Periodic::new(knots, period, vec![[0.0; 2]; m]);
    // Normal equations: cyclic, seven diagonals. Assembled sparse, solved by sparse Cholesky.
    let mut entries: std::collections::HashMap<(usize, usize), f64> =
        std::collections::HashMap::with_capacity(8 * m);
    let mut add = |r: usize, c: usize, v: f64| {
        if r >= c {
            *entries.entry((r, c)).or_insert(0.0) += v;
        }
    };
    let mut rhs = Mat::<f64>::zeros(m, 2);
    for (p, &u) in pts.iter().zip(params) {
        let (j, n) = curve.basis(u);
        let idx: [usize; 4] =
            [0, 1, 2, 3].map(|r| (j - 3 + r as isize).rem_euclid(m as isize) as usize);
        for r in 0..4 {
            for s in 0..4 {
                add(idx[r], idx[s], n[r] * n[s]);
            }
            rhs[(idx[r], 0)] += n[r] * p[0];
            rhs[(idx[r], 1)] += n[r] * p[1];
        }
    }
    let lambda = 1e-9 * pts.len() as f64 / m as f64;
    for i in 0..m {
        let w = [(i + m - 1) % m, i, (i + 1) % m];
        let c = [1.0, -2.0, 1.0];
        for r in 0..3 {
            for s in 0..3 {
                add(w[r], w[s], lambda * c[r] * c[s]);
            }
        }
    }
    let triplets: Vec<Triplet<usize, usize, f64>> = entries
        .into_iter()
        .map(|((r, c), v)| Triplet::new(r, c, v))
        .collect();
    let sol = SparseColMat::<usize, f64>::try_new_from_triplets(m, m, &triplets)
        .ok()
        .and_then(|a| a.sp_cholesky(Side::Lower).ok())
        .map(|l| l.solve(&rhs))
        .unwrap_or_else(|| Mat::zeros(m, 2));
    for i in 0..m {
        curve.points[i] = [sol[(i, 0)], sol[(i, 1)]];
    }
    curve
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fits_a_circle_and_unwraps_to_the_same_curve() {
        let n = 200;
        let r = 10.0;
        let pts: Vec<P2> = (0..n)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / n as f64;
                [r * a.cos(), r * a.sin()]
            })
            .collect();
        let period = std::f64::consts::TAU * r;
        let params: Vec<f64> = (0..n).map(|k| period * k as f64 / n as f64).collect();
        let m = 12;
        let knots: Vec<f64> = (0..m).map(|k| period * k as f64 / m as f64).collect();
        let c = fit(&pts, &params, knots, period);
        for (p, &u) in pts.iter().zip(&params) {
            let (_, d) = c.project(*p, u, period / 20.0);
            assert!(d < 0.01, "{d}");
        }
        // Partition of unity.
        let (_, b) = c.basis(1.234);
        assert!((b.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        // Open form, evaluated by plain de Boor on its own knot vector, gives the same points.
        let (kn, cp, range) = c.unwrapped();
        for s in 0..50 {
            let u = range[0] + (range[1] - range[0]) * s as f64 / 50.0;
            let j = (3..kn.len() - 4).rev().find(|&j| kn[j] <= u).unwrap();
            let nb = basis_at(|k| kn[k as usize], j as isize, u);
            let mut q = [0.0; 2];
            for r in 0..4 {
                q[0] += nb[r] * cp[j - 3 + r][0];
                q[1] += nb[r] * cp[j - 3 + r][1];
            }
            let e = c.eval(u);
            assert!((q[0] - e[0]).abs() < 1e-9 && (q[1] - e[1]).abs() < 1e-9);
        }
    }
}
