//! Closed (periodic) planar cubic B-spline curves: evaluation, least-squares fitting to ordered
//! points with given knots, and the distance from points to the curve.
//!
//! A periodic cubic with `m` knots `u_0 < … < u_{m−1}` in `[0, L)` and `m` control points:
//! knots repeat with period `L` (`t_{k+m} = t_k + L`), and on the span `[t_j, t_{j+1})` the curve
//! is `Σ N_i(u) P_{i mod m}` over `i = j−3 … j`. The same curve is written to IGES/DXF as an open
//! (unclamped) B-spline with `m + 3` control points (the first three repeated) — see
//! [`Periodic::unwrapped`].

use faer::linalg::solvers::Solve;
use faer::{Mat, Side};

pub type P2 = [f64; 2];

/// A closed cubic B-spline.
#[derive(Debug, Clone)]
pub struct Periodic {
    /// Knots in `[0, period)`, strictly increasing.
    pub knots: Vec<f64>,
    pub period: f64,
    pub points: Vec<P2>,
}

impl Periodic {
    pub fn len(&self) -> usize {
        self.points.len()
    }

    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Knot `t_k` for any integer `k`.
    pub fn t(&self, k: isize) -> f64 {
        let m = self.knots.len() as isize;
        let q = k.div_euclid(m);
        self.knots[k.rem_euclid(m) as usize] + q as f64 * self.period
    }

    /// The span `j` (an integer, `t_j ≤ u < t_{j+1}`) and the four basis values there.
    pub fn basis(&self, u: f64) -> (isize, [f64; 4]) {
        let m = self.knots.len();
        let uu = u.rem_euclid(self.period);
        let q = ((u - uu) / self.period).round() as isize;
        // Last knot ≤ uu.
        let j = match self.knots.binary_search_by(|k| k.total_cmp(&uu)) {
            Ok(i) => i,
            Err(i) => i.max(1) - 1,
        } as isize
            + q * m as isize;
        (j, basis_at(|k| self.t(k), j, u))
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

    /// The parameter nearest to `p`, searched around `guess` within `window`.
    pub fn project(&self, p: P2, guess: f64, window: f64) -> (f64, f64) {
        let d2 = |u: f64| {
            let c = self.eval(u);
            (c[0] - p[0]).powi(2) + (c[1] - p[1]).powi(2)
        };
        let steps = 12;
        let (mut best_u, mut best) = (guess, d2(guess));
        for s in 0..=steps {
            let u = guess - window + 2.0 * window * s as f64 / steps as f64;
            let v = d2(u);
            if v < best {
                best = v;
                best_u = u;
            }
        }
        // Golden-section refinement around the best sample.
        let h = 2.0 * window / steps as f64;
        let (mut a, mut b) = (best_u - h, best_u + h);
        let g = 0.5 * (5f64.sqrt() - 1.0);
        let (mut c, mut d) = (b - g * (b - a), a + g * (b - a));
        let (mut fc, mut fd) = (d2(c), d2(d));
        for _ in 0..40 {
            if fc < fd {
                b = d;
                d = c;
                fd = fc;
                c = b - g * (b - a);
                fc = d2(c);
            } else {
                a = c;
                c = d;
                fc = fd;
                d = a + g * (b - a);
                fd = d2(d);
            }
        }
        let u = 0.5 * (a + b);
        let v = d2(u);
        if v < best {
            (u, v.sqrt())
        } else {
            (best_u, best.sqrt())
        }
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
    let mut curve = Periodic {
        knots,
        period,
        points: vec![[0.0; 2]; m],
    };
    let mut a = Mat::<f64>::zeros(m, m);
    let mut rhs = Mat::<f64>::zeros(m, 2);
    for (p, &u) in pts.iter().zip(params) {
        let (j, n) = curve.basis(u);
        let idx: [usize; 4] =
            [0, 1, 2, 3].map(|r| (j - 3 + r as isize).rem_euclid(m as isize) as usize);
        for r in 0..4 {
            for s in 0..4 {
                a[(idx[r], idx[s])] += n[r] * n[s];
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
                a[(w[r], w[s])] += lambda * c[r] * c[s];
            }
        }
    }
    let sol = match a.as_ref().llt(Side::Lower) {
        Ok(l) => l.solve(&rhs),
        Err(_) => a.as_ref().partial_piv_lu().solve(&rhs),
    };
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
