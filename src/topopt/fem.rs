//! Finite-element analysis for the optimiser: assembles `K = Σ E_e·KE` over the free DOFs and
//! solves `K u = f` with faer's sparse Cholesky (supernodal LLᵀ).
//!
//! The sparsity pattern and its symbolic factorisation (fill-reducing ordering, elimination
//! tree) are computed once per problem; each iteration only refills the values and factors
//! numerically.

use super::problem::Problem;
use crate::error::{Error, Result};
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{Pair, SparseColMat, SymbolicSparseColMat};
use faer::{Mat, Side};

/// A problem's assembly pattern and symbolic factorisation, reused across iterations.
pub struct Fem {
    /// Element matrix, row-major, `m × m`.
    pub ke: Vec<f64>,
    /// DOFs per element (8 for Q4, 24 for H8).
    pub m: usize,
    /// Element DOFs, `m` per element.
    pub edofs: Vec<usize>,
    /// For each stored lower-triangle contribution: (element, index into `ke`).
    contrib: Vec<(u32, u32)>,
    symbolic: SymbolicSparseColMat<usize>,
    argsort: faer::sparse::Argsort<usize>,
    llt: SymbolicLlt<usize>,
    /// Free DOFs in order; `free_index[d]` is `usize::MAX` for a fixed DOF.
    free: Vec<usize>,
    free_index: Vec<usize>,
    /// Load vector over all DOFs.
    pub f: Vec<f64>,
}

impl Fem {
    /// Sets up the assembly and the symbolic factorisation for `p` with element matrix `ke`.
    pub fn new(p: &Problem, ke: Vec<f64>) -> Result<Fem> {
        let nd = p.dofs();
        let mut fixed = vec![false; nd];
        for &d in &p.fixed {
            fixed[d] = true;
        }
        let mut free_index = vec![usize::MAX; nd];
        let mut free = Vec::new();
        for d in 0..nd {
            if !fixed[d] {
                free_index[d] = free.len();
                free.push(d);
            }
        }
        let mut f = vec![0.0; nd];
        for &(d, v) in &p.loads {
            f[d] += v;
        }
        let m = (ke.len() as f64).sqrt() as usize;
        let ne = p.elements();
        let mut edofs = Vec::with_capacity(ne * m);
        let mut buf = Vec::with_capacity(m);
        for e in 0..ne {
            p.element_dofs(e, &mut buf);
            edofs.extend_from_slice(&buf);
        }
        let mut pairs = Vec::new();
        let mut contrib = Vec::new();
        for e in 0..ne {
            let ed = &edofs[e * m..(e + 1) * m];
            for i in 0..m {
                let r = free_index[ed[i]];
                if r == usize::MAX {
                    continue;
                }
                for j in 0..m {
                    let c = free_index[ed[j]];
                    if c == usize::MAX || r < c {
                        continue;
                    }
                    pairs.push(Pair::new(r, c));
                    contrib.push((e as u32, (i * m + j) as u32));
                }
            }
        }
        let n = free.len();
        let (symbolic, argsort) = SymbolicSparseColMat::try_new_from_indices(n, n, &pairs)
            .map_err(|e| Error::invalid(format!("assembling the stiffness pattern: {e:?}")))?;
        let llt = SymbolicLlt::try_new(symbolic.as_ref(), Side::Lower)
            .map_err(|e| Error::invalid(format!("symbolic Cholesky factorisation: {e:?}")))?;
        Ok(Fem {
            ke,
            m,
            edofs,
            contrib,
            symbolic,
            argsort,
            llt,
            free,
            free_index,
            f,
        })
    }

    /// Solves for the displacements (temperatures) with element moduli `stiffness`; fixed DOFs
    /// are zero.
    pub fn solve(&self, stiffness: &[f64]) -> Result<Vec<f64>> {
        let vals: Vec<f64> = self
            .contrib
            .iter()
            .map(|&(e, k)| stiffness[e as usize] * self.ke[k as usize])
            .collect();
        let k = SparseColMat::new_from_argsort(self.symbolic.clone(), &self.argsort, &vals)
            .map_err(|e| Error::invalid(format!("assembling the stiffness matrix: {e:?}")))?;
        let llt = Llt::try_new_with_symbolic(self.llt.clone(), k.as_ref(), Side::Lower).map_err(
            |_| {
                Error::invalid(
                    "the stiffness matrix is singular: supports do not hold the structure",
                )
            },
        )?;
        let n = self.free.len();
        let rhs = Mat::from_fn(n, 1, |i, _| self.f[self.free[i]]);
        let x = llt.solve(&rhs);
        let mut u = vec![0.0; self.free_index.len()];
        for (i, &d) in self.free.iter().enumerate() {
            u[d] = x[(i, 0)];
        }
        if u.iter().any(|v| !v.is_finite()) {
            return Err(Error::invalid(
                "the finite-element solve diverged (singular stiffness)",
            ));
        }
        Ok(u)
    }

    /// Element energies `ce_e = u_eᵀ KE u_e` (unit modulus).
    pub fn element_energy(&self, u: &[f64], out: &mut [f64]) {
        let m = self.m;
        let mut ue = vec![0.0; m];
        for (e, o) in out.iter_mut().enumerate() {
            for (i, d) in self.edofs[e * m..(e + 1) * m].iter().enumerate() {
                ue[i] = u[*d];
            }
            let mut s = 0.0;
            for i in 0..m {
                let row = &self.ke[i * m..(i + 1) * m];
                let mut t = 0.0;
                for j in 0..m {
                    t += ue[j] * row[j];
                }
                s += t * ue[i];
            }
            *o = s;
        }
    }
}
