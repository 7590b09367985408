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

/// A point (x, y) in the plane.
pub type P2 = [f64; 2];

/// A closed cubic B-spline.
#[derive(Debug, Clone)]
pub struct Periodic {
    /// Knots in `[0, period)`, strictly increasing.
    pub knots: Vec<f64>,
    /// Parameter period `L`: one turn around the curve (the points' chord length when fitted).
    pub period: f64,
    /// Control points, one per knot.
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

    /// Number of control points (as many as knots).
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether the curve has no control points.
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

    /// The point at parameter `u` (any real; the curve repeats with the period).
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

    /// Point, first and second derivative at `u`.
    pub fn eval_ders(&self, u: f64) -> [P2; 3] {
        let m = self.knots.len();
        let uu = u.rem_euclid(self.period);
        let j0 = match self.knots.binary_search_by(|k| k.total_cmp(&uu)) {
            Ok(i) => i,
            Err(i) => i.max(1) - 1,
        } as isize;
        let d = ders_at(|k| self.ext[(k + 4) as usize], j0, uu);
        let mut out = [[0.0; 2]; 3];
        for (o, dk) in out.iter_mut().zip(&d) {
            for (r, w) in dk.iter().enumerate() {
                let c = self.points[(j0 - 3 + r as isize).rem_euclid(m as isize) as usize];
                o[0] += w * c[0];
                o[1] += w * c[1];
            }
        }
        out
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

    /// The parameter nearest to `p`, searched around `guess` within `window`: Newton's method on
    /// `(C(u) − p)·C′(u) = 0` from the guess, and from the best of a coarse scan of the window
    /// when that does not settle. Returns `(u, distance)`.
    pub fn project(&self, p: P2, guess: f64, window: f64) -> (f64, f64) {
        let (lo, hi) = (guess - window, guess + window);
        let newton = |mut u: f64| -> (f64, f64, bool) {
            let mut best = f64::INFINITY;
            for _ in 0..8 {
                let [c, d1, d2] = self.eval_ders(u);
                let r = [c[0] - p[0], c[1] - p[1]];
                best = r[0] * r[0] + r[1] * r[1];
                let f = r[0] * d1[0] + r[1] * d1[1];
                let fp = d1[0] * d1[0] + d1[1] * d1[1] + r[0] * d2[0] + r[1] * d2[1];
                if fp <= 0.0 {
                    return (u, best, false);
                }
                let step = f / fp;
                let next = (u - step).clamp(lo, hi);
                if (next - u).abs() < 1e-12 * window.max(1.0) {
                    return (u, best, true);
                }
                u = next;
            }
            (u, best, true)
        };
        let (u, d2, settled) = newton(guess);
        if settled && u > lo && u < hi {
            return (u, d2.sqrt());
        }
        // A coarse scan, then Newton from its best sample.
        let steps = 8;
        let (mut bu, mut bd) = (u, d2);
        for s in 0..=steps {
            let v = lo + 2.0 * window * s as f64 / steps as f64;
            let c = self.eval(v);
            let dv = (c[0] - p[0]).powi(2) + (c[1] - p[1]).powi(2);
            if dv < bd {
                bd = dv;
                bu = v;
            }
        }
        let (u2, d22, _) = newton(bu);
        if d22 < bd {
            (u2, d22.sqrt())
        } else {
            (bu, bd.sqrt())
        }
    }
}

/// Cubic basis values and their first two derivatives on span `j` (The NURBS Book A2.3):
/// `d[k][r]` is the k-th derivative of `N_{j−3+r}` at `u`.
fn ders_at(t: impl Fn(isize) -> f64, j: isize, u: f64) -> [[f64; 4]; 3] {
    const P: usize = 3;
    let mut ndu = [[0.0f64; 4]; 4];
    let mut left = [0.0; 4];
    let mut right = [0.0; 4];
    ndu[0][0] = 1.0;
    for jj in 1..=P {
        left[jj] = u - t(j + 1 - jj as isize);
        right[jj] = t(j + jj as isize) - u;
        let mut saved = 0.0;
        for r in 0..jj {
            ndu[jj][r] = right[r + 1] + left[jj - r];
            let temp = ndu[r][jj - 1] / ndu[jj][r];
            ndu[r][jj] = saved + right[r + 1] * temp;
            saved = left[jj - r] * temp;
        }
        ndu[jj][jj] = saved;
    }
    let mut d = [[0.0; 4]; 3];
    for r in 0..=P {
        d[0][r] = ndu[r][P];
    }
    for r in 0..=P as isize {
        let mut a = [[0.0f64; 4]; 2];
        let (mut s1, mut s2) = (0usize, 1usize);
        a[0][0] = 1.0;
        for k in 1..=2isize {
            let mut dv = 0.0;
            let rk = r - k;
            let pk = P as isize - k;
            if r >= k {
                a[s2][0] = a[s1][0] / ndu[(pk + 1) as usize][rk as usize];
                dv = a[s2][0] * ndu[rk as usize][pk as usize];
            }
            let j1 = if rk >= -1 { 1 } else { -rk };
            let j2 = if r - 1 <= pk { k - 1 } else { P as isize - r };
            for jj in j1..=j2 {
                a[s2][jj as usize] = (a[s1][jj as usize] - a[s1][(jj - 1) as usize])
                    / ndu[(pk + 1) as usize][(rk + jj) as usize];
                dv += a[s2][jj as usize] * ndu[(rk + jj) as usize][pk as usize];
            }
            if r <= pk {
                a[s2][k as usize] = -a[s1][(k - 1) as usize] / ndu[(pk + 1) as usize][r as usize];
                dv += a[s2][k as usize] * ndu[r as usize][pk as usize];
            }
            d[k as usize][r as usize] = dv;
            std::mem::swap(&mut s1, &mut s2);
        }
    }
    let mut f = P as f64;
    for row in d.iter_mut().skip(1) {
        for v in row.iter_mut() {
            *v *= f;
        }
        f *= (P - 1) as f64;
    }
    d
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
    let mut rhs = Mat::<f64>::zeros(m, 2);
    // Per point only four basis functions are nonzero: accumulate the 4 × 4 products in a
    // per-span block (consecutive points share spans), flushed when the span changes.
    let mut block = [[0.0f64; 4]; 4];
    let mut block_span: Option<isize> = None;
    let flush = |span: isize,
                 block: &mut [[f64; 4]; 4],
                 entries: &mut std::collections::HashMap<(usize, usize), f64>| {
        let idx: [usize; 4] =
            [0, 1, 2, 3].map(|r| (span - 3 + r as isize).rem_euclid(m as isize) as usize);
        for r in 0..4 {
            for s in 0..4 {
                if idx[r] >= idx[s] && block[r][s] != 0.0 {
                    *entries.entry((idx[r], idx[s])).or_insert(0.0) += block[r][s];
                }
                block[r][s] = 0.0;
            }
        }
    };
    for (p, &u) in pts.iter().zip(params) {
        let (j, n) = curve.basis(u);
        let j = j.rem_euclid(m as isize);
        if block_span != Some(j) {
            if let Some(b) = block_span {
                flush(b, &mut block, &mut entries);
            }
            block_span = Some(j);
        }
        for r in 0..4 {
            for s in 0..4 {
                block[r][s] += n[r] * n[s];
            }
            let i = (j - 3 + r as isize).rem_euclid(m as isize) as usize;
            rhs[(i, 0)] += n[r] * p[0];
            rhs[(i, 1)] += n[r] * p[1];
        }
    }
    if let Some(b) = block_span {
        flush(b, &mut block, &mut entries);
    }
    let mut add = |r: usize, c: usize, v: f64| {
        if r >= c {
            *entries.entry((r, c)).or_insert(0.0) += v;
        }
    };
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
        // Derivatives agree with finite differences.
        let [_, d1, d2] = c.eval_ders(7.0);
        let h = 1e-4;
        let (a, b, m0) = (c.eval(7.0 - h), c.eval(7.0 + h), c.eval(7.0));
        for k in 0..2 {
            assert!((d1[k] - (b[k] - a[k]) / (2.0 * h)).abs() < 1e-6);
            assert!((d2[k] - (b[k] - 2.0 * m0[k] + a[k]) / (h * h)).abs() < 1e-3);
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
