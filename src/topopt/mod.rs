//! `topopt`: SIMP minimum-compliance topology optimisation, latvox's own, so the path from a
//! design problem to a printable part and a CAD model needs nothing else installed.
//!
//! The loop is the one of the 88-line code (Andreassen et al. 2011) in 2D and of top3d (Liu &
//! Tovar 2014) in 3D, step for step, so that the compliance histories agree with theirs to
//! rounding:
//! 1. modified SIMP stiffness `E(x) = Emin + x^p (E0 − Emin)`, assembled and solved by sparse
//!    Cholesky ([`fem`]);
//! 2. compliance `c = Σ E(x_e) u_eᵀ KE u_e` and its sensitivity;
//! 3. sensitivity filter (`H(x·dc) / Hs / max(1e-3, x)`) or density filter (chain rule through
//!    `xPhys = H x / Hs`), cone weights `max(0, rmin − d)` ([`filter`]);
//! 4. optimality-criteria update with move limit 0.2, the Lagrange multiplier by bisection to
//!    `(l2 − l1)/(l1 + l2) ≤ 1e-3`;
//! 5. stop when the largest density change is ≤ 0.01 (or at the iteration limit).

pub mod element;
pub mod fem;
pub mod filter;
pub mod problem;

use crate::error::{Error, Result};
use crate::progress::Progress;
pub use problem::{builtin, from_toml, parse_toml, Passive, Physics, Problem};

/// Which quantity the cone filter smooths.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum FilterKind {
    /// Filter the sensitivities (the 88-line code's `ft = 1`).
    Sensitivity,
    /// Filter the densities (`ft = 2`; top3d's filter).
    Density,
}

/// Optimiser settings (the codes' arguments).
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Settings {
    /// Target volume fraction, in (0, 1).
    pub volfrac: f64,
    /// SIMP penalty exponent.
    pub penal: f64,
    /// Filter radius, in elements.
    pub rmin: f64,
    /// What the cone filter smooths.
    pub filter: FilterKind,
    /// Iterations at most.
    pub max_iterations: usize,
    /// Stop when the largest density change is at most this.
    pub tolerance: f64,
    /// Move limit of the OC update.
    pub move_limit: f64,
}

impl Settings {
    /// Settings with the codes' defaults: at most 1000 iterations, stop at change ≤ 0.01, move
    /// limit 0.2.
    pub fn new(volfrac: f64, penal: f64, rmin: f64, filter: FilterKind) -> Settings {
        Settings {
            volfrac,
            penal,
            rmin,
            filter,
            max_iterations: 1000,
            tolerance: 0.01,
            move_limit: 0.2,
        }
    }

    fn check(&self) -> Result<()> {
        if !(self.volfrac > 0.0 && self.volfrac < 1.0) {
            return Err(Error::invalid(format!(
                "volume fraction must be in (0, 1), got {}",
                self.volfrac
            )));
        }
        if !(self.penal >= 1.0 && self.penal <= 10.0) {
            return Err(Error::invalid(format!(
                "penalty must be in [1, 10], got {}",
                self.penal
            )));
        }
        if !(self.rmin > 0.0 && self.rmin <= 50.0) {
            return Err(Error::invalid(format!(
                "filter radius must be in (0, 50] elements, got {}",
                self.rmin
            )));
        }
        if self.max_iterations == 0 {
            return Err(Error::invalid("at least one iteration is needed"));
        }
        Ok(())
    }
}

/// The optimised design and its history.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Optimised {
    /// Physical densities, in the problem's element order (see [`problem`]).
    #[serde(skip)]
    pub densities: Vec<f64>,
    /// Compliance at every iteration (evaluated before that iteration's update).
    pub compliance: Vec<f64>,
    /// Mean physical density after every iteration's update.
    pub volume: Vec<f64>,
    /// Largest design change of every iteration.
    pub change: Vec<f64>,
    /// Iterations run.
    pub iterations: usize,
    /// Whether the change fell to `tolerance` before `max_iterations`.
    pub converged: bool,
}

/// Runs the optimiser. `on_iteration(i, c, vol, change)` is called after every iteration.
pub fn optimise(
    p: &Problem,
    s: &Settings,
    progress: &Progress,
    mut on_iteration: impl FnMut(usize, f64, f64, f64),
) -> Result<Optimised> {
    s.check()?;
    let _stage = progress.stage("optimising");
    let ke = match (p.physics, p.is_3d()) {
        (Physics::Heat, _) => element::q4_conduction(),
        (Physics::Elastic, false) => element::q4_plane_stress(0.3),
        (Physics::Elastic, true) => element::h8(0.3),
    };
    let fem = fem::Fem::new(p, ke)?;
    let h = filter::ConeFilter::new(p, s.rmin);
    let ne = p.elements();
    let passive = |e: usize| p.passive.get(e).copied().unwrap_or(Passive::Free);
    let pin = |x: &mut [f64]| {
        if !p.passive.is_empty() {
            for (e, v) in x.iter_mut().enumerate() {
                match passive(e) {
                    Passive::Void => *v = 0.0,
                    Passive::Solid => *v = 1.0,
                    Passive::Free => {}
                }
            }
        }
    };
    let active = (0..ne).filter(|&e| passive(e) != Passive::Void).count();
    let target = s.volfrac * active as f64;
    let (e0, emin) = (1.0, p.emin);
    let mut x = vec![s.volfrac; ne];
    pin(&mut x);
    let mut x_phys = x.clone();
    let mut out = Optimised {
        densities: Vec::new(),
        compliance: Vec::new(),
        volume: Vec::new(),
        change: Vec::new(),
        iterations: 0,
        converged: false,
    };
    let (mut ce, mut dc, mut dv) = (vec![0.0; ne], vec![0.0; ne], vec![0.0; ne]);
    let (mut tmp, mut xnew) = (vec![0.0; ne], vec![0.0; ne]);
    let mut change = 1.0;
    while change > s.tolerance && out.iterations < s.max_iterations {
        out.iterations += 1;
        let stiff: Vec<f64> = x_phys
            .iter()
            .map(|&v| emin + v.powf(s.penal) * (e0 - emin))
            .collect();
        let u = fem.solve(&stiff)?;
        fem.element_energy(&u, &mut ce);
        let c: f64 = stiff.iter().zip(&ce).map(|(a, b)| a * b).sum();
        for e in 0..ne {
            dc[e] = -s.penal * (e0 - emin) * x_phys[e].powf(s.penal - 1.0) * ce[e];
            dv[e] = 1.0;
        }
        match s.filter {
            FilterKind::Sensitivity => {
                for e in 0..ne {
                    tmp[e] = x[e] * dc[e];
                }
                h.apply(&tmp, &mut dc);
                for e in 0..ne {
                    dc[e] = dc[e] / h.hs[e] / x[e].max(1e-3);
                }
            }
            FilterKind::Density => {
                for e in 0..ne {
                    tmp[e] = dc[e] / h.hs[e];
                }
                h.apply(&tmp, &mut dc);
                for e in 0..ne {
                    tmp[e] = dv[e] / h.hs[e];
                }
                h.apply(&tmp, &mut dv);
            }
        }
        let (mut l1, mut l2, mv) = (0.0f64, 1e9f64, s.move_limit);
        while (l2 - l1) / (l1 + l2) > 1e-3 {
            let lmid = 0.5 * (l2 + l1);
            for e in 0..ne {
                let b = x[e] * (-dc[e] / dv[e] / lmid).sqrt();
                xnew[e] = 0f64.max((x[e] - mv).max(1f64.min((x[e] + mv).min(b))));
            }
            pin(&mut xnew);
            match s.filter {
                FilterKind::Sensitivity => x_phys.copy_from_slice(&xnew),
                FilterKind::Density => {
                    h.apply(&xnew, &mut x_phys);
                    for (v, hs) in x_phys.iter_mut().zip(&h.hs) {
                        *v /= hs;
                    }
                    pin(&mut x_phys);
                }
            }
            if x_phys.iter().sum::<f64>() > target {
                l1 = lmid;
            } else {
                l2 = lmid;
            }
        }
        change = x
            .iter()
            .zip(&xnew)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        x.copy_from_slice(&xnew);
        let vol = x_phys.iter().sum::<f64>() / ne as f64;
        out.compliance.push(c);
        out.volume.push(vol);
        out.change.push(change);
        on_iteration(out.iterations, c, vol, change);
    }
    out.converged = change <= s.tolerance;
    out.densities = x_phys;
    Ok(out)
}

/// The design's SIMP stiffness relative to the solid, `Emin + ρᵖ(1 − Emin)`, at the nodes of its
/// elements (each the mean of the elements around it), in a part's coordinates: shape
/// `(nelx + 1, nely + 1, nelz + 1)` (a 2D design repeated through a thickness of one element),
/// x along nelx, y up (the optimiser's bottom row at y = 0), z along nelz; the box
/// `[0, nelx·h] × [0, nely·h] × [0, nelz·h]` with `h` the element size — what a lattice graded by
/// stiffness reads (`--stiffness-field`).
pub fn stiffness_at_nodes(p: &Problem, densities: &[f64], penal: f64) -> (Vec<usize>, Vec<f64>) {
    let (nx, ny, nz) = (p.nelx, p.nely, p.nelz.max(1));
    let stiffness = |ix: usize, iy: usize, iz: usize| {
        // The optimiser's rows count down from the top: y up is row ny − 1 − iy.
        let rho = densities[p.element(ix, ny - 1 - iy, if p.is_3d() { iz } else { 0 })];
        p.emin + rho.powf(penal) * (1.0 - p.emin)
    };
    let mut v = Vec::with_capacity((nx + 1) * (ny + 1) * (nz + 1));
    for i in 0..=nx {
        for j in 0..=ny {
            for k in 0..=nz {
                let (mut sum, mut count) = (0.0, 0.0);
                for ex in [i.wrapping_sub(1), i] {
                    for ey in [j.wrapping_sub(1), j] {
                        for ez in [k.wrapping_sub(1), k] {
                            if ex < nx && ey < ny && ez < nz {
                                sum += stiffness(ex, ey, ez);
                                count += 1.0;
                            }
                        }
                    }
                }
                v.push(sum / count);
            }
        }
    }
    (vec![nx + 1, ny + 1, nz + 1], v)
}

/// Densities in the layout of `.npy` files written by optimisers: shape `(nely, nelx)` in 2D or
/// `(nely, nelx, nelz)` in 3D, C order, row 0 at the top (MATLAB's `xPhys` as NumPy sees it).
pub fn to_array(p: &Problem, densities: &[f64]) -> (Vec<usize>, Vec<f64>) {
    let (nx, ny, nz) = (p.nelx, p.nely, p.nelz.max(1));
    let mut v = Vec::with_capacity(densities.len());
    for row in 0..ny {
        for ix in 0..nx {
            for iz in 0..nz {
                v.push(densities[p.element(ix, row, iz)]);
            }
        }
    }
    let shape = if p.is_3d() {
        vec![ny, nx, nz]
    } else {
        vec![ny, nx]
    };
    (shape, v)
}
