//! Calibration: the level `t` that gives a TPMS solid a target volume fraction, measured on the
//! mesh that latvox will actually write.
//!
//! 1. **Analytic level.** The volume fraction of a periodic lattice is that of one unit cell, and
//!    does not depend on the cell's size or aspect. `F` is sampled at the midpoints of an `n³`
//!    grid over the unit cell once per surface; the fraction where `F ≤ t` (net) or `|F| ≤ t`
//!    (sheet) is the empirical distribution of the samples, so the level is read off as a quantile.
//! 2. **Mesh level.** Meshing a surface on voxels changes its volume slightly (chords across
//!    curved surfaces, sub-voxel features). The unit cell is meshed at the part's own voxel size
//!    and phase twice: once with a margin of neighbouring cells, measuring the volume inside the
//!    cell only ([`Mesh::volume_in_box`]) — what every interior cell of the part contributes — and
//!    once clipped by its own box, whose difference from the first is the effect of a cut face.
//!    A part of `nx × ny × nz` cells is predicted as `interior + (1/nx + 1/ny + 1/nz)/3 · face`,
//!    and a secant search on that prediction gives the level. The part is meshed once, at that
//!    level, and its volume fraction confirmed on its own mesh.
//!
//! Feasibility: the solid and the void must each stay one connected piece (a lattice falls apart
//! into islands or traps closed voids beyond that). This is tested on a periodic 64³ sampling of
//! the cell with union-find.

use super::surface::{Structure, Surface};
use super::Lattice;
use crate::error::{Error, Result};
use crate::field::{Aabb, Vec3};
use crate::grid::GridSpec;
use std::sync::OnceLock;

/// Samples per axis over the unit cell for the analytic level.
const N: usize = 64;
/// Samples per axis for the connectivity test.
const NC: usize = 64;

struct Table {
    /// Sorted `F` (net) or `|F|` (sheet) samples.
    sorted: Vec<f32>,
    /// Largest `|∇F|` (cell coordinates) on the surface `F = 0`, for sheet wall thickness.
    grad_max_mid: f64,
}

fn table(surface: Surface, structure: Structure) -> &'static Table {
    static TABLES: [[OnceLock<Table>; 2]; 7] = [const { [const { OnceLock::new() }; 2] }; 7];
    let si = Surface::ALL.iter().position(|s| *s == surface).unwrap();
    let ki = match structure {
        Structure::Net => 0,
        Structure::Sheet => 1,
    };
    TABLES[si][ki].get_or_init(|| {
        use rayon::prelude::*;
        let samples: Vec<(f32, f32)> = surface
            .eval_cell_midpoints(N)
            .into_par_iter()
            .map(|(f, g)| {
                let gn = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
                // Within a tenth of a sample spacing of F = 0 (first order): on the mid-surface.
                let near = f.abs() < gn * 0.1 / N as f64;
                let v = match structure {
                    Structure::Net => f,
                    Structure::Sheet => f.abs(),
                };
                (v as f32, if near { gn as f32 } else { 0.0 })
            })
            .collect();
        let grad_max_mid = samples.iter().map(|s| s.1).fold(0.0f32, f32::max) as f64;
        let mut sorted: Vec<f32> = samples.into_iter().map(|s| s.0).collect();
        sorted.par_sort_unstable_by(|a, b| a.total_cmp(b));
        Table {
            sorted,
            grad_max_mid,
        }
    })
}

/// Volume fraction of the exact (unmeshed) unit cell at level `t`.
pub fn analytic_fraction(surface: Surface, structure: Structure, t: f64) -> f64 {
    let s = &table(surface, structure).sorted;
    let below = s.partition_point(|&v| (v as f64) <= t);
    below as f64 / s.len() as f64
}

/// The level whose exact unit-cell volume fraction is `target`.
pub fn analytic_level(surface: Surface, structure: Structure, target: f64) -> f64 {
    let s = &table(surface, structure).sorted;
    let x = (target * s.len() as f64 - 0.5).clamp(0.0, (s.len() - 1) as f64);
    let i = x.floor() as usize;
    let j = (i + 1).min(s.len() - 1);
    let f = x - i as f64;
    s[i] as f64 * (1.0 - f) + s[j] as f64 * f
}

/// The thinnest wall of a sheet at level `t`, as a fraction of the cell (first order: `2t/|∇F|`).
pub fn thinnest_sheet_wall(surface: Surface, t: f64) -> f64 {
    2.0 * t / table(surface, Structure::Sheet).grad_max_mid
}

/// Which phases of the lattice percolate (form one connected, space-spanning piece).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct Connectivity {
    /// The solid is one piece: no islands that would fall off.
    pub solid: bool,
    /// The void (each labyrinth, for a sheet) is one piece: no closed voids trapping powder.
    pub void: bool,
}

/// Percolation of solid and void at level `t`, tested on a periodic 2×2×2 block of cells
/// sampled `NC` per cell: a blob that is connected only to its own periodic image stays one
/// component in one cell but splits into eight in the block.
pub fn connectivity(surface: Surface, structure: Structure, t: f64) -> Connectivity {
    connectivity_sampled(surface, structure, t, NC)
}

/// [`connectivity`] with `n` samples per cell axis.
pub fn connectivity_sampled(
    surface: Surface,
    structure: Structure,
    t: f64,
    n: usize,
) -> Connectivity {
    let vals: Vec<f64> = surface
        .eval_cell_midpoints(n)
        .into_iter()
        .map(|(f, _)| f)
        .collect();
    let one = |member: &(dyn Fn(f64) -> bool + Sync)| one_percolating_component(&vals, n, member);
    match structure {
        Structure::Net => Connectivity {
            solid: one(&|f| f <= t),
            void: one(&|f| f > t),
        },
        Structure::Sheet => Connectivity {
            solid: t > 0.0 && one(&|f| f.abs() <= t),
            void: one(&|f| f > t) && one(&|f| f < -t),
        },
    }
}

/// Union-find over the periodic `(2n)³` block of `n³` samples: does `member` pick exactly one
/// 6-connected component?
fn one_percolating_component(vals: &[f64], n: usize, member: &dyn Fn(f64) -> bool) -> bool {
    let m = 2 * n;
    let inside: Vec<bool> = (0..m * m * m)
        .map(|i| {
            let (x, y, z) = ((i / (m * m)) % n, ((i / m) % m) % n, (i % m) % n);
            member(vals[(x * n + y) * n + z])
        })
        .collect();
    let mut parent: Vec<u32> = (0..inside.len() as u32).collect();
    fn find(p: &mut [u32], mut x: u32) -> u32 {
        while p[x as usize] != x {
            p[x as usize] = p[p[x as usize] as usize];
            x = p[x as usize];
        }
        x
    }
    let idx = |i: usize, j: usize, k: usize| (i * m + j) * m + k;
    for i in 0..m {
        for j in 0..m {
            for k in 0..m {
                let a = idx(i, j, k);
                if !inside[a] {
                    continue;
                }
                for b in [
                    idx((i + 1) % m, j, k),
                    idx(i, (j + 1) % m, k),
                    idx(i, j, (k + 1) % m),
                ] {
                    if inside[b] {
                        let (ra, rb) = (find(&mut parent, a as u32), find(&mut parent, b as u32));
                        if ra != rb {
                            parent[ra as usize] = rb;
                        }
                    }
                }
            }
        }
    }
    let mut root = None;
    for (a, &is_in) in inside.iter().enumerate() {
        if is_in {
            let r = find(&mut parent, a as u32);
            match root {
                None => root = Some(r),
                Some(r0) if r0 != r => return false,
                _ => {}
            }
        }
    }
    root.is_some()
}

/// The volume fractions a surface and structure can take with both phases connected.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct FeasibleRange {
    pub min: f64,
    pub max: f64,
}

/// Scans and bisects the solid's connectivity for the ends of the feasible range around the
/// middle of the fraction range. Slow (hundreds of percolation tests): [`FEASIBLE`] holds its
/// results, and a test recomputes them.
pub fn feasible_range(surface: Surface, structure: Structure) -> FeasibleRange {
    percolation_range(surface, structure, NC, false)
}

/// Whether the solid (or, with `void`, the void) percolates at volume fraction `vf`, sampled
/// `n` per cell axis.
pub fn percolates(surface: Surface, structure: Structure, vf: f64, n: usize, void: bool) -> bool {
    let c = connectivity_sampled(
        surface,
        structure,
        analytic_level(surface, structure, vf),
        n,
    );
    if void {
        c.void
    } else {
        c.solid
    }
}

/// The range of volume fraction around the middle where the solid (or, with `void`, the void)
/// percolates, sampled `n` per cell axis.
pub fn percolation_range(
    surface: Surface,
    structure: Structure,
    n: usize,
    void: bool,
) -> FeasibleRange {
    let ok = |vf: f64| percolates(surface, structure, vf, n, void);
    let step = 0.01;
    let start = (0..50)
        .flat_map(|k| [0.5 + k as f64 * step, 0.5 - k as f64 * step])
        .find(|&v| ok(v))
        .unwrap_or(0.5);
    let bisect = |mut good: f64, mut bad: f64| {
        for _ in 0..10 {
            let m = 0.5 * (good + bad);
            if ok(m) {
                good = m
            } else {
                bad = m
            }
        }
        good
    };
    let mut hi = start;
    while hi + step < 1.0 && ok(hi + step) {
        hi += step;
    }
    let max = if hi + step >= 1.0 {
        1.0
    } else {
        bisect(hi, hi + step)
    };
    let mut lo = start;
    while lo - step > 0.0 && ok(lo - step) {
        lo -= step;
    }
    let min = if lo - step <= 0.0 {
        0.0
    } else {
        bisect(lo, lo - step)
    };
    FeasibleRange { min, max }
}

/// The calibrated level and how it was found.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Calibration {
    pub level: f64,
    /// Level from the exact unit cell alone.
    pub analytic_level: f64,
    /// Volume fraction of an interior cell's mesh at `level`.
    pub interior_fraction: f64,
    /// Change in volume fraction a cut face brings to one cell at `level`.
    pub face_effect: f64,
    /// Predicted volume fraction of the part's mesh.
    pub predicted_fraction: f64,
    /// Unit-cell meshings performed.
    pub meshings: u32,
    pub seconds: f64,
}

/// Margin of neighbouring lattice around the periodic unit cell, voxels.
const MARGIN: f64 = 4.0;

/// Finds the level for `target` on the part described by `cell`, voxel size `voxel` and
/// `counts` cells per axis.
pub fn calibrate(
    surface: Surface,
    structure: Structure,
    target: f64,
    cell: Vec3,
    voxel: f64,
    counts: Vec3,
    adaptivity: f64,
) -> Result<Calibration> {
    let start = std::time::Instant::now();
    if !(target > 0.0 && target < 1.0) {
        return Err(Error::invalid(format!(
            "density must be in (0, 1), got {target}"
        )));
    }
    let t0 = analytic_level(surface, structure, target);

    let cell_box = Aabb {
        min: [0.0; 3],
        max: cell,
    };
    let cell_volume = cell_box.volume();
    let m = MARGIN * voxel;
    let padded = Aabb {
        min: [-m; 3],
        max: [0, 1, 2].map(|a| cell[a] + m),
    };
    let k = (1.0 / counts[0] + 1.0 / counts[1] + 1.0 / counts[2]) / 3.0;
    let mut meshings = 0;
    let mk = |t: f64, bounds: Aabb| Lattice {
        surface,
        structure,
        level: t,
        cell,
        bounds,
        phase: [0.0; 3],
    };
    let spec = GridSpec::covering(&padded, voxel, super::HALF_WIDTH);
    // What an interior cell contributes: the periodic cell's mesh measured inside the cell.
    let interior = |t: f64| -> Result<f64> {
        Ok(mk(t, padded).volume_in(spec, adaptivity, &cell_box)? / cell_volume)
    };

    // Slope of the exact fraction at t0, for the first step.
    let span = {
        let s = &table(surface, structure).sorted;
        (s[s.len() - 1] - s[0]) as f64
    };
    let d = 1e-3 * span;
    let slope = ((analytic_fraction(surface, structure, t0 + d)
        - analytic_fraction(surface, structure, t0 - d))
        / (2.0 * d))
        .max(1e-9);

    // At t0, the interior cell and the cut cell are meshed side by side; the cut face's effect
    // changes little with the level over the few steps that follow, so it is kept.
    let (ia, clipped) = rayon::join(|| interior(t0), || mk(t0, cell_box).mesh(voxel, adaptivity));
    let (mut ia, (clipped, _)) = (ia?, clipped?);
    meshings += 2;
    let fa = clipped.volume() / cell_volume - ia;
    let predict = |i: f64| i + k * fa;
    let (mut ta, mut pa) = (t0, predict(ia));
    // Meshing biases the fraction by nearly the same amount at nearby levels: the first step
    // reads the level off the exact cell's distribution at the target less that bias.
    let mut tb = analytic_level(
        surface,
        structure,
        (2.0 * target - pa).clamp(1e-6, 1.0 - 1e-6),
    );
    for _ in 0..4 {
        if (pa - target).abs() < 1e-4 {
            break;
        }
        let ib = interior(tb)?;
        meshings += 1;
        let pb = predict(ib);
        let s = if (pb - pa).abs() > 1e-12 {
            (pb - pa) / (tb - ta)
        } else {
            slope
        };
        let near = (pb - target).abs() < 2e-3 && (pb - pa).abs() < 1e-2;
        (ta, pa, ia) = (tb, pb, ib);
        tb = ta - (pa - target) / if s > 0.0 { s } else { slope };
        if near && (pa - target).abs() >= 1e-4 {
            // Two meshed levels this close pin the fraction down to a straight line: its root
            // is taken without meshing it (the part's own mesh confirms it).
            ia += target - pa;
            (ta, pa) = (tb, target);
            break;
        }
    }
    Ok(Calibration {
        level: ta,
        analytic_level: t0,
        interior_fraction: ia,
        face_effect: fa,
        predicted_fraction: pa,
        meshings,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// Where each lattice holds together, from [`percolation_range`] (64 samples per cell axis; the
/// two net minima near 0.1 refined at 128). Sheet minima are 0: a wall around the connected
/// surface `F = 0` cannot fall apart however thin (the sampled test loses walls thinner than a
/// sample spacing). `(surface, structure, solid range, void range)`; a test recomputes them.
pub const PERCOLATION: [(Surface, Structure, FeasibleRange, FeasibleRange); 14] = {
    const fn r(min: f64, max: f64) -> FeasibleRange {
        FeasibleRange { min, max }
    }
    use Structure::{Net, Sheet};
    use Surface::*;
    [
        (P, Net, r(0.2138, 1.0), r(0.0, 0.7862)),
        (P, Sheet, r(0.0, 1.0), r(0.0, 0.5775)),
        (Gyroid, Net, r(0.0191, 1.0), r(0.0, 0.9809)),
        (Gyroid, Sheet, r(0.0, 1.0), r(0.0, 0.96)),
        (D, Net, r(0.0834, 1.0), r(0.0, 0.9166)),
        (D, Sheet, r(0.0, 1.0), r(0.0, 0.83)),
        (Iwp, Net, r(0.1019, 1.0), r(0.0, 0.9862)),
        (Iwp, Sheet, r(0.0, 1.0), r(0.0, 0.88)),
        (S, Net, r(0.1164, 1.0), r(0.0, 0.8836)),
        (S, Sheet, r(0.0, 1.0), r(0.0, 0.77)),
        (Frd, Net, r(0.3359, 1.0), r(0.0, 0.78)),
        (Frd, Sheet, r(0.0, 0.4409), r(0.0, 0.4259)),
        (Neovius, Net, r(0.3388, 1.0), r(0.0, 0.66)),
        (Neovius, Sheet, r(0.0, 1.0), r(0.0, 0.3245)),
    ]
};

/// The feasible range (solid in one piece) of a surface and structure.
pub fn feasible(surface: Surface, structure: Structure) -> FeasibleRange {
    PERCOLATION
        .iter()
        .find(|e| e.0 == surface && e.1 == structure)
        .map(|e| e.2)
        .expect("every surface and structure is tabulated")
}

/// Where the void percolates (no closed voids).
pub fn void_connected_range(surface: Surface, structure: Structure) -> FeasibleRange {
    PERCOLATION
        .iter()
        .find(|e| e.0 == surface && e.1 == structure)
        .map(|e| e.3)
        .expect("every surface and structure is tabulated")
}
