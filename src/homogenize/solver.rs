//! Periodic linear elasticity on a voxel grid: the six unit-strain load cases of numerical
//! homogenisation (Andreassen & Andreasen 2014; Dong, Tang & Zhao 2019), solved by conjugate
//! gradients preconditioned with a geometric multigrid V-cycle.
//!
//! Every voxel is one trilinear hexahedron whose stiffness is the solid's times the voxel's
//! weight (its solid fraction, 0 for void), and the grid wraps around on every axis: node
//! `(i, j, k)` is node `(i mod n₀, j mod n₁, k mod n₂)`, so displacements are periodic. Nodes
//! that no solid voxel touches carry no unknowns. The operator is applied voxel by voxel
//! (matrix-free), each node gathering from its eight voxels, in parallel over z-slabs.
//!
//! The preconditioner coarsens the grid by two on every axis while the counts stay even: a
//! coarse voxel's weight is the mean of its eight children's, its stiffness that of a box twice
//! as large (the coarse operator of a uniform solid is then exactly the Galerkin product of the
//! trilinear transfer), damped Jacobi smooths on every level, and the coarsest is solved by a
//! dense Cholesky factorisation where it is small. The solution is unique up to rigid
//! translations, which are projected out of every iterate.

// Index loops read as the formulas they transcribe.
#![allow(clippy::needless_range_loop)]

use super::element;
use crate::error::{Error, Result};
use rayon::prelude::*;

/// Jacobi damping of the smoother.
const OMEGA: f64 = 0.6;
/// Smoothing sweeps before and after each coarse correction.
const SWEEPS: usize = 2;
/// The largest coarsest grid (unknowns) factorised densely; a larger one is only smoothed.
const DENSE: usize = 1600;

/// One grid of the hierarchy.
struct Level {
    n: [usize; 3],
    ke: Box<[f64; 576]>,
    /// Weight of each voxel, indexed as its lower corner node.
    w: Vec<f64>,
    /// Whether a solid voxel touches the node.
    active: Vec<bool>,
    /// How many nodes are active.
    active_count: usize,
    /// Inverse of the operator's diagonal (0 on inactive nodes), 3 per node.
    inv_diag: Vec<f64>,
}

/// Node index of grid coordinates.
#[inline(always)]
fn index(n: [usize; 3], i: usize, j: usize, k: usize) -> usize {
    i + n[0] * (j + n[1] * k)
}

/// `c + 1` and `c − 1` on a periodic axis of `n`.
#[inline(always)]
fn next(c: usize, n: usize) -> usize {
    if c + 1 == n {
        0
    } else {
        c + 1
    }
}
#[inline(always)]
fn prev(c: usize, n: usize) -> usize {
    if c == 0 {
        n - 1
    } else {
        c - 1
    }
}

impl Level {
    fn new(n: [usize; 3], h: [f64; 3], lambda: f64, mu: f64, w: Vec<f64>) -> Level {
        let ke = Box::new(element::stiffness(h, lambda, mu));
        let nodes = n[0] * n[1] * n[2];
        let mut level = Level {
            n,
            ke,
            w,
            active: vec![false; nodes],
            active_count: 0,
            inv_diag: vec![0.0; 3 * nodes],
        };
        let (active, inv_diag): (Vec<bool>, Vec<[f64; 3]>) = (0..nodes)
            .into_par_iter()
            .map(|p| {
                let mut d = [0.0; 3];
                let mut any = false;
                level.for_voxels(p, |a, e| {
                    let w = level.w[e];
                    if w > 0.0 {
                        any = true;
                        for (r, d) in d.iter_mut().enumerate() {
                            *d += w * level.ke[(3 * a + r) * 25];
                        }
                    }
                });
                (any, if any { d.map(|d| 1.0 / d) } else { [0.0; 3] })
            })
            .unzip();
        level.active_count = active.iter().filter(|&&a| a).count();
        level.active = active;
        level.inv_diag = inv_diag.into_iter().flatten().collect();
        level
    }

    fn nodes(&self) -> usize {
        self.n[0] * self.n[1] * self.n[2]
    }

    /// Calls `f(a, e)` for each of the eight voxels `e` around node `p`, `a` being the node's
    /// corner in it.
    #[inline(always)]
    fn for_voxels(&self, p: usize, mut f: impl FnMut(usize, usize)) {
        let n = self.n;
        let (i, j, k) = (p % n[0], (p / n[0]) % n[1], p / (n[0] * n[1]));
        let xs = [i, prev(i, n[0])];
        let ys = [j, prev(j, n[1])];
        let zs = [k, prev(k, n[2])];
        for a in 0..8 {
            f(a, index(n, xs[a & 1], ys[a >> 1 & 1], zs[a >> 2 & 1]));
        }
    }

    /// The eight nodes of voxel `e`, in element order.
    #[inline(always)]
    fn corners(&self, e: usize) -> [usize; 8] {
        let n = self.n;
        let (i, j, k) = (e % n[0], (e / n[0]) % n[1], e / (n[0] * n[1]));
        let xs = [i, next(i, n[0])];
        let ys = [j, next(j, n[1])];
        let zs = [k, next(k, n[2])];
        std::array::from_fn(|b| index(n, xs[b & 1], ys[b >> 1 & 1], zs[b >> 2 & 1]))
    }

    /// `y = A x`.
    fn apply(&self, x: &[f64], y: &mut [f64]) {
        let slab = self.n[0] * self.n[1];
        y.par_chunks_mut(3 * slab).enumerate().for_each(|(k, out)| {
            for q in 0..slab {
                let p = q + k * slab;
                let mut acc = [0.0; 3];
                if self.active[p] {
                    self.for_voxels(p, |a, e| {
                        let w = self.w[e];
                        if w == 0.0 {
                            return;
                        }
                        let rows = &self.ke[72 * a..72 * a + 72];
                        for (b, node) in self.corners(e).into_iter().enumerate() {
                            let xb = &x[3 * node..3 * node + 3];
                            for (r, acc) in acc.iter_mut().enumerate() {
                                let row = &rows[24 * r + 3 * b..24 * r + 3 * b + 3];
                                *acc += w * (row[0] * xb[0] + row[1] * xb[1] + row[2] * xb[2]);
                            }
                        }
                    });
                }
                out[3 * q..3 * q + 3].copy_from_slice(&acc);
            }
        });
    }

    /// `z += ω D⁻¹ (r − A z)`, `sweeps` times (`scratch` the size of `z`).
    fn smooth(&self, r: &[f64], z: &mut [f64], scratch: &mut [f64], sweeps: usize) {
        for _ in 0..sweeps {
            self.apply(z, scratch);
            z.par_iter_mut()
                .zip(scratch.par_iter())
                .zip(r.par_iter().zip(self.inv_diag.par_iter()))
                .for_each(|((z, az), (r, d))| *z += OMEGA * d * (r - az));
        }
    }

    /// The coarse level: voxels of twice the size, each weighing the mean of its children.
    fn coarsen(&self, h: [f64; 3], lambda: f64, mu: f64) -> Level {
        let n = self.n;
        let nc = n.map(|c| c / 2);
        let w: Vec<f64> = (0..nc[0] * nc[1] * nc[2])
            .into_par_iter()
            .map(|e| {
                let (i, j, k) = (e % nc[0], (e / nc[0]) % nc[1], e / (nc[0] * nc[1]));
                (0..8)
                    .map(|b| {
                        self.w[index(n, 2 * i + (b & 1), 2 * j + (b >> 1 & 1), 2 * k + (b >> 2))]
                    })
                    .sum::<f64>()
                    / 8.0
            })
            .collect();
        Level::new(nc, h, lambda, mu, w)
    }

    /// The fine residual `r` restricted to the coarse level `c` (the transpose of
    /// [`Level::prolong`]).
    fn restrict(&self, c: &Level, r: &[f64]) -> Vec<f64> {
        let (n, nc) = (self.n, c.n);
        let mut out = vec![0.0; 3 * c.nodes()];
        out.par_chunks_mut(3).enumerate().for_each(|(p, o)| {
            if !c.active[p] {
                return;
            }
            let (i, j, k) = (p % nc[0], (p / nc[0]) % nc[1], p / (nc[0] * nc[1]));
            let axis =
                |c: usize, n: usize| [(prev(2 * c, n), 0.5), (2 * c, 1.0), (next(2 * c, n), 0.5)];
            for (x, wx) in axis(i, n[0]) {
                for (y, wy) in axis(j, n[1]) {
                    for (z, wz) in axis(k, n[2]) {
                        let q = index(n, x, y, z);
                        let wt = wx * wy * wz;
                        for a in 0..3 {
                            o[a] += wt * r[3 * q + a];
                        }
                    }
                }
            }
        });
        out
    }

    /// Adds the coarse correction `zc` of level `c`, interpolated trilinearly, to `z`.
    fn prolong(&self, c: &Level, zc: &[f64], z: &mut [f64]) {
        let (n, nc) = (self.n, c.n);
        z.par_chunks_mut(3).enumerate().for_each(|(p, o)| {
            if !self.active[p] {
                return;
            }
            let (i, j, k) = (p % n[0], (p / n[0]) % n[1], p / (n[0] * n[1]));
            let axis = |c: usize, n: usize| -> [(usize, f64); 2] {
                if c.is_multiple_of(2) {
                    [(c / 2, 1.0), (0, 0.0)]
                } else {
                    [(c / 2, 0.5), (next(c / 2, n), 0.5)]
                }
            };
            for (x, wx) in axis(i, nc[0]) {
                for (y, wy) in axis(j, nc[1]) {
                    for (zz, wz) in axis(k, nc[2]) {
                        let wt = wx * wy * wz;
                        if wt == 0.0 {
                            continue;
                        }
                        let q = index(nc, x, y, zz);
                        for a in 0..3 {
                            o[a] += wt * zc[3 * q + a];
                        }
                    }
                }
            }
        });
    }

    /// The operator as a dense symmetric matrix (inactive unknowns given a unit diagonal), made
    /// definite by a small shift against rigid translations.
    fn dense(&self) -> faer::Mat<f64> {
        let m = 3 * self.nodes();
        let mut a = faer::Mat::<f64>::zeros(m, m);
        for e in 0..self.nodes() {
            let w = self.w[e];
            if w == 0.0 {
                continue;
            }
            let nodes = self.corners(e);
            for r in 0..24 {
                for c in 0..24 {
                    let (gr, gc) = (3 * nodes[r / 3] + r % 3, 3 * nodes[c / 3] + c % 3);
                    a[(gr, gc)] += w * self.ke[r * 24 + c];
                }
            }
        }
        let scale = (0..m).map(|i| a[(i, i)]).fold(0.0f64, f64::max);
        for i in 0..m {
            if self.active[i / 3] {
                a[(i, i)] += 1e-9 * scale;
            } else {
                a[(i, i)] = 1.0;
            }
        }
        a
    }
}

/// The hierarchy and the coarsest factorisation.
pub struct Solver {
    levels: Vec<Level>,
    coarsest: Option<faer::linalg::solvers::Llt<f64>>,
    /// Voxel edges of the finest level.
    h: [f64; 3],
}

/// What a solve did.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct SolveStats {
    /// Conjugate-gradient iterations, the most over the load cases.
    pub iterations: usize,
    /// Relative residual ‖b − A x‖/‖b‖ at the end, the largest over the load cases.
    pub residual: f64,
    /// Grids in the multigrid hierarchy.
    pub levels: usize,
    /// Unknowns of the finest grid (3 per node a solid voxel touches).
    pub unknowns: usize,
}

impl Solver {
    /// The solver for voxels of edges `h` on a periodic grid of `n` voxels per axis, each
    /// weighing `w` (indexed `i + n₀(j + n₁k)`), of a solid with Lamé constants `lambda`, `mu`.
    pub fn new(n: [usize; 3], h: [f64; 3], lambda: f64, mu: f64, w: Vec<f64>) -> Result<Solver> {
        if w.len() != n[0] * n[1] * n[2] || n.iter().any(|&c| c < 2) {
            return Err(Error::invalid(
                "the voxel grid needs at least 2 voxels a side",
            ));
        }
        let mut levels = vec![Level::new(n, h, lambda, mu, w)];
        let mut hc = h;
        loop {
            let last = levels.last().unwrap();
            if last.n.iter().any(|&c| c % 2 == 1 || c / 2 < 3) {
                break;
            }
            hc = hc.map(|x| 2.0 * x);
            let coarse = last.coarsen(hc, lambda, mu);
            levels.push(coarse);
        }
        let last = levels.last().unwrap();
        let coarsest = if levels.len() > 1 && 3 * last.nodes() <= DENSE {
            Some(
                last.dense()
                    .llt(faer::Side::Lower)
                    .map_err(|_| Error::invalid("the coarsest grid's operator is not definite"))?,
            )
        } else {
            None
        };
        Ok(Solver {
            levels,
            coarsest,
            h,
        })
    }

    /// Unknowns of the finest grid.
    pub fn unknowns(&self) -> usize {
        3 * self.levels[0].active_count
    }

    /// The preconditioner: one V-cycle from level `l` on the residual `r`.
    fn vcycle(&self, l: usize, r: &[f64]) -> Vec<f64> {
        let lev = &self.levels[l];
        let mut z = vec![0.0; r.len()];
        if l + 1 == self.levels.len() {
            match &self.coarsest {
                Some(llt) => {
                    use faer::linalg::solvers::Solve;
                    let x = llt.solve(faer::Mat::from_fn(r.len(), 1, |i, _| r[i]));
                    for (i, z) in z.iter_mut().enumerate() {
                        if lev.active[i / 3] {
                            *z = x[(i, 0)];
                        }
                    }
                }
                None => {
                    let mut scratch = vec![0.0; r.len()];
                    lev.smooth(r, &mut z, &mut scratch, 4 * SWEEPS);
                }
            }
            return z;
        }
        let mut scratch = vec![0.0; r.len()];
        lev.smooth(r, &mut z, &mut scratch, SWEEPS);
        lev.apply(&z, &mut scratch);
        scratch
            .par_iter_mut()
            .zip(r.par_iter())
            .for_each(|(s, r)| *s = r - *s);
        let coarse = &self.levels[l + 1];
        let rc = lev.restrict(coarse, &scratch);
        let zc = self.vcycle(l + 1, &rc);
        lev.prolong(coarse, &zc, &mut z);
        lev.smooth(r, &mut z, &mut scratch, SWEEPS);
        z
    }

    /// Removes the rigid translation from `x`: the mean of each component over the active nodes.
    fn project(&self, x: &mut [f64]) {
        let lev = &self.levels[0];
        let count = lev.active_count.max(1) as f64;
        let mut mean = [0.0; 3];
        for (p, a) in lev.active.iter().enumerate() {
            if *a {
                for c in 0..3 {
                    mean[c] += x[3 * p + c];
                }
            }
        }
        let mean = mean.map(|m| m / count);
        x.par_chunks_mut(3)
            .zip(lev.active.par_iter())
            .for_each(|(x, a)| {
                if *a {
                    for c in 0..3 {
                        x[c] -= mean[c];
                    }
                }
            });
    }

    /// Solves `A x = b` by preconditioned conjugate gradients to `tol` relative residual; the
    /// solution, iterations and relative residual.
    pub fn solve(
        &self,
        b: &[f64],
        tol: f64,
        max_iterations: usize,
    ) -> Result<(Vec<f64>, usize, f64)> {
        let lev = &self.levels[0];
        let mut r = b.to_vec();
        self.project(&mut r);
        let norm_b = dot(&r, &r).sqrt();
        let mut x = vec![0.0; b.len()];
        if norm_b == 0.0 {
            return Ok((x, 0, 0.0));
        }
        let mut z = self.vcycle(0, &r);
        self.project(&mut z);
        let mut p = z.clone();
        let mut rz = dot(&r, &z);
        let mut ap = vec![0.0; b.len()];
        for it in 1..=max_iterations {
            lev.apply(&p, &mut ap);
            let pap = dot(&p, &ap);
            if pap.is_nan() || pap <= 0.0 {
                return Err(Error::invalid(
                    "the cell's stiffness is not positive: the solid does not hold together",
                ));
            }
            let alpha = rz / pap;
            x.par_iter_mut()
                .zip(p.par_iter())
                .for_each(|(x, p)| *x += alpha * p);
            r.par_iter_mut()
                .zip(ap.par_iter())
                .for_each(|(r, ap)| *r -= alpha * ap);
            let rel = dot(&r, &r).sqrt() / norm_b;
            if rel <= tol {
                return Ok((x, it, rel));
            }
            z = self.vcycle(0, &r);
            self.project(&mut z);
            let rz_new = dot(&r, &z);
            let beta = rz_new / rz;
            rz = rz_new;
            p.par_iter_mut()
                .zip(z.par_iter())
                .for_each(|(p, z)| *p = z + beta * *p);
        }
        let rel = dot(&r, &r).sqrt() / norm_b;
        Err(Error::invalid(format!(
            "the solver did not converge in {max_iterations} iterations (residual {rel:.2e})"
        )))
    }

    /// The homogenised elasticity tensor (6 × 6, Voigt order `xx, yy, zz, yz, xz, xy`): for each
    /// pair of unit strains, the mean strain energy density of the periodic fluctuation's
    /// response, after solving the six load cases to `tol`.
    pub fn homogenize(
        &self,
        tol: f64,
        max_iterations: usize,
        mut progress: impl FnMut(usize),
    ) -> Result<([[f64; 6]; 6], SolveStats)> {
        let lev = &self.levels[0];
        let chi0: [[f64; 24]; 6] = std::array::from_fn(|c| element::unit_strain(c, self.h));
        let mut chi = Vec::with_capacity(6);
        let (mut iterations, mut residual) = (0, 0.0f64);
        for (case, u0) in chi0.iter().enumerate() {
            // b = Σ_e w_e Ke χ0: the loads of the unit strain on the voxels.
            let mut ke_u0 = [0.0; 24];
            for (r, v) in ke_u0.iter_mut().enumerate() {
                *v = (0..24).map(|c| lev.ke[r * 24 + c] * u0[c]).sum();
            }
            let mut b = vec![0.0; 3 * lev.nodes()];
            b.par_chunks_mut(3).enumerate().for_each(|(p, o)| {
                if !lev.active[p] {
                    return;
                }
                lev.for_voxels(p, |a, e| {
                    for c in 0..3 {
                        o[c] += lev.w[e] * ke_u0[3 * a + c];
                    }
                });
            });
            let (x, it, rel) = self.solve(&b, tol, max_iterations)?;
            iterations = iterations.max(it);
            residual = residual.max(rel);
            chi.push(x);
            progress(case + 1);
        }
        let slab = lev.n[0] * lev.n[1];
        let parts: Vec<[[f64; 6]; 6]> = (0..lev.n[2])
            .into_par_iter()
            .map(|k| {
                let mut c = [[0.0; 6]; 6];
                for e in k * slab..(k + 1) * slab {
                    let w = lev.w[e];
                    if w == 0.0 {
                        continue;
                    }
                    let nodes = lev.corners(e);
                    let d: [[f64; 24]; 6] = std::array::from_fn(|i| {
                        std::array::from_fn(|r| chi0[i][r] - chi[i][3 * nodes[r / 3] + r % 3])
                    });
                    for j in 0..6 {
                        let kd: [f64; 24] = std::array::from_fn(|r| {
                            (0..24).map(|s| lev.ke[r * 24 + s] * d[j][s]).sum()
                        });
                        for i in 0..=j {
                            c[i][j] += w * (0..24).map(|r| d[i][r] * kd[r]).sum::<f64>();
                        }
                    }
                }
                c
            })
            .collect();
        let volume = lev.nodes() as f64 * self.h.iter().product::<f64>();
        let mut c = [[0.0; 6]; 6];
        for part in &parts {
            for i in 0..6 {
                for j in i..6 {
                    c[i][j] += part[i][j];
                }
            }
        }
        for i in 0..6 {
            for j in i..6 {
                c[i][j] /= volume;
                c[j][i] = c[i][j];
            }
        }
        let stats = SolveStats {
            iterations,
            residual,
            levels: self.levels.len(),
            unknowns: self.unknowns(),
        };
        Ok((c, stats))
    }
}

/// `a · b`, summed in a fixed order (slabs of 4096 in parallel, then in sequence), so that a
/// result does not depend on the threads.
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let parts: Vec<f64> = a
        .par_chunks(4096)
        .zip(b.par_chunks(4096))
        .map(|(a, b)| a.iter().zip(b).map(|(x, y)| x * y).sum())
        .collect();
    parts.iter().sum()
}
