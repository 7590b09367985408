//! Calibration: the level `t` that gives a TPMS solid a target volume fraction, measured on the
//! mesh that latvox will actually write.
//!
//! 1. **Analytic level.** The volume fraction of a periodic lattice is that of one unit cell, and
//!    does not depend on the cell's size or aspect. `F` and its gradient are sampled at the
//!    midpoints of an `n³` grid over the unit cell once per surface; each sample stands for its
//!    voxel with `F` spread as wide as the gradient across it, which makes the fraction where
//!    `F ≤ t` (net) or `|F| ≤ t` (sheet) a smooth function of `t` (counting the samples alone
//!    steps wherever a symmetric set of them shares a value), and the level is read off it.
//! 2. **Mesh level.** Meshing a surface on voxels changes its volume slightly (chords across
//!    curved surfaces, sub-voxel features). The unit cell is meshed at the part's own voxel size
//!    and phase twice, side by side: once with a margin of neighbouring cells, measuring the
//!    volume inside the cell only ([`crate::geom::Mesh::volume_in_box`]) — what every interior cell of the
//!    part contributes — and once clipped by its own box, whose difference from the first is the
//!    effect of a cut face. A part of `nx × ny × nz` cells is predicted as
//!    `interior + (1/nx + 1/ny + 1/nz)/3 · face`. The difference between that prediction and the
//!    exact fraction (the meshing's bias) changes little with the level, so the level is read
//!    off the exact distribution at the target less the bias; a correction of more than
//!    0.02 is meshed again before it is trusted. Where the solid is its own image under
//!    inversion through the cell's centre (every sheet; nets of the all-cosine surfaces), half
//!    the cell is meshed and counted twice. The part is meshed once, at the level found, and its
//!    volume fraction confirmed on its own mesh.
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

/// Buckets of the sample table.
const BUCKETS: usize = 4096;

struct Table {
    /// `F` (net) or `|F|` (sheet) at the samples, bucketed by value: bucket `b` holds the
    /// values in `[lo + b·width, lo + (b + 1)·width)` (the last one its upper end too).
    values: Vec<f32>,
    /// Half the spread of `F` across each sample's voxel (`|∇F| h / 2`), in the order of
    /// `values`.
    half_spread: Vec<f32>,
    /// Where each bucket starts in `values`, and the end.
    starts: Vec<u32>,
    lo: f64,
    width: f64,
    /// Largest of `half_spread`.
    max_half_spread: f64,
    /// Largest `|∇F|` (cell coordinates) on the surface `F = 0`, for sheet wall thickness.
    grad_max_mid: f64,
    structure: Structure,
}

fn table(surface: Surface, structure: Structure) -> &'static Table {
    static TABLES: [[OnceLock<Table>; 3]; Surface::ALL.len()] =
        [const { [const { OnceLock::new() }; 3] }; Surface::ALL.len()];
    let si = Surface::ALL.iter().position(|s| *s == surface).unwrap();
    let ki = match structure {
        Structure::Net => 0,
        Structure::Sheet => 1,
        Structure::NetOther => 2,
    };
    TABLES[si][ki].get_or_init(|| Table::new(surface, structure))
}

impl Table {
    fn new(surface: Surface, structure: Structure) -> Table {
        let h = 1.0 / N as f64;
        let samples: Vec<(f32, f32, f32)> = surface.map_cell_midpoints(N, |f, g| {
            let gn = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
            // Within a tenth of a sample spacing of F = 0 (first order): on the mid-surface.
            let near = f.abs() < gn * 0.1 * h;
            let v = match structure {
                Structure::Net => f,
                Structure::Sheet => f.abs(),
                Structure::NetOther => -f,
            };
            (
                v as f32,
                (0.5 * gn * h) as f32,
                if near { gn as f32 } else { 0.0 },
            )
        });
        let (mut lo, mut hi, mut grad_max_mid, mut max_half_spread) =
            (f32::INFINITY, f32::NEG_INFINITY, 0.0f32, 0.0f32);
        for s in &samples {
            lo = lo.min(s.0);
            hi = hi.max(s.0);
            grad_max_mid = grad_max_mid.max(s.2);
            max_half_spread = max_half_spread.max(s.1);
        }
        let (lo, width) = (lo as f64, ((hi - lo) as f64 / BUCKETS as f64).max(1e-30));
        let bucket = |v: f32| (((v as f64 - lo) / width) as usize).min(BUCKETS - 1);
        // A counting sort by bucket.
        let mut starts = vec![0u32; BUCKETS + 1];
        for s in &samples {
            starts[bucket(s.0) + 1] += 1;
        }
        for b in 0..BUCKETS {
            starts[b + 1] += starts[b];
        }
        let mut next = starts.clone();
        let (mut values, mut half_spread) = (vec![0f32; samples.len()], vec![0f32; samples.len()]);
        for s in &samples {
            let b = bucket(s.0);
            let i = next[b] as usize;
            next[b] += 1;
            values[i] = s.0;
            half_spread[i] = s.1;
        }
        Table {
            values,
            half_spread,
            starts,
            lo,
            width,
            max_half_spread: max_half_spread as f64,
            grad_max_mid: grad_max_mid as f64,
            structure,
        }
    }

    /// The bucket holding level `t`, clamped to the buckets.
    fn bucket(&self, t: f64) -> usize {
        ((t - self.lo) / self.width)
            .floor()
            .clamp(0.0, (BUCKETS - 1) as f64) as usize
    }

    /// Fraction of the unit cell at or below level `t`. Each sample stands for its voxel, over
    /// which `F` is taken as linear: the part of the voxel below `t` is read from a spread of
    /// `F` as wide as the gradient across the voxel (a uniform spread of the same variance as
    /// the cube's). Counting samples alone would step at every level a symmetric set of samples
    /// shares; this is smooth in `t`.
    fn fraction(&self, t: f64) -> f64 {
        let w = self.max_half_spread;
        let below = |t: f64| -> f64 {
            // Buckets wholly below t − w count whole; those wholly above t + w not at all.
            let (b0, b1) = (self.bucket(t - w), self.bucket(t + w));
            let whole = if t - w >= self.lo {
                self.starts[b0] as f64
            } else {
                0.0
            };
            let (i0, i1) = (self.starts[b0] as usize, self.starts[b1 + 1] as usize);
            let partial: f64 = (i0..i1)
                .map(|i| {
                    let hw = self.half_spread[i] as f64;
                    let d = t - self.values[i] as f64;
                    if hw > 0.0 {
                        (0.5 + 0.5 * d / hw).clamp(0.0, 1.0)
                    } else if d >= 0.0 {
                        1.0
                    } else {
                        0.0
                    }
                })
                .sum();
            whole + partial
        };
        let count = match self.structure {
            Structure::Net | Structure::NetOther => below(t),
            // |F| ≤ t is F ≤ t less F < −t; the spread is symmetric, so |F| serves for F.
            Structure::Sheet => below(t) - if t < w { below(-t) } else { 0.0 },
        };
        count / self.values.len() as f64
    }

    /// The level whose fraction is `target`: regula falsi (Illinois) on the monotone
    /// [`Table::fraction`], bracketed around the sample quantile by the widest spread.
    fn level(&self, target: f64) -> f64 {
        // The bucket where the count of samples reaches the target.
        let n = target * self.values.len() as f64;
        let b = self.starts[1..].partition_point(|&c| (c as f64) < n);
        let q = self.lo + (b as f64 + 0.5) * self.width;
        let w = 2.0 * self.max_half_spread + self.width;
        let (mut a, mut b) = (q - w, q + w);
        let (mut fa, mut fb) = (self.fraction(a) - target, self.fraction(b) - target);
        while fa > 0.0 {
            (b, fb) = (a, fa);
            a -= w;
            fa = self.fraction(a) - target;
        }
        while fb < 0.0 {
            (a, fa) = (b, fb);
            b += w;
            fb = self.fraction(b) - target;
        }
        let mut side = 0;
        for _ in 0..100 {
            if fb - fa <= 0.0 || b - a < 1e-12 {
                break;
            }
            let c = ((a * fb - b * fa) / (fb - fa)).clamp(a, b);
            let fc = self.fraction(c) - target;
            if fc.abs() < 1e-12 {
                return c;
            }
            if fc < 0.0 {
                (a, fa) = (c, fc);
                if side == -1 {
                    fb *= 0.5;
                }
                side = -1;
            } else {
                (b, fb) = (c, fc);
                if side == 1 {
                    fa *= 0.5;
                }
                side = 1;
            }
        }
        if fb - fa > 0.0 {
            (a * fb - b * fa) / (fb - fa)
        } else {
            0.5 * (a + b)
        }
    }
}

/// Volume fraction of the exact (unmeshed) unit cell at level `t`.
pub fn analytic_fraction(surface: Surface, structure: Structure, t: f64) -> f64 {
    table(surface, structure).fraction(t)
}

/// The level whose exact unit-cell volume fraction is `target`.
pub fn analytic_level(surface: Surface, structure: Structure, target: f64) -> f64 {
    table(surface, structure).level(target)
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
    let vals: Vec<f64> = surface.map_cell_midpoints(n, |f, _| f);
    let one = |member: &(dyn Fn(f64) -> bool + Sync)| one_percolating_component(&vals, n, member);
    match structure {
        Structure::Net => Connectivity {
            solid: one(&|f| f <= t),
            void: one(&|f| f > t),
        },
        Structure::NetOther => Connectivity {
            solid: one(&|f| -f <= t),
            void: one(&|f| -f > t),
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
    /// Smallest feasible volume fraction.
    pub min: f64,
    /// Largest feasible volume fraction.
    pub max: f64,
}

/// Scans and bisects the solid's connectivity for the ends of the feasible range around the
/// middle of the fraction range. Slow (hundreds of percolation tests): a table holds its
/// results ([`feasible`]), and a test recomputes them.
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
    /// The level `t` found for the target fraction.
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
    /// Whether the meshed cell's fraction came within reach of the target (on voxels too
    /// coarse for the lattice's members it jumps past it).
    pub converged: bool,
    /// Wall time of the calibration, seconds.
    pub seconds: f64,
}

/// Margin of neighbouring lattice around the periodic unit cell, voxels.
const MARGIN: f64 = 2.0;

/// Largest correction of the level's fraction taken without meshing the corrected level.
const ACCEPT: f64 = 0.02;

/// The axis along which half the unit cell is enough to measure (see [`calibrate`]): the solid
/// `|F| ≤ t` is its own image under `u ↦ −u` when `F` is even or odd, `F ≤ t` when `F` is
/// even; the cell's longest axis is halved.
fn half_cell_axis(surface: Surface, structure: Structure, cell: Vec3, voxel: f64) -> Option<usize> {
    let symmetric = matches!(
        (structure, surface.is_even()),
        (Structure::Sheet, Some(_)) | (Structure::Net | Structure::NetOther, Some(true))
    );
    let whole = (0..3).all(|a| {
        let n = cell[a] / voxel;
        (n - n.round()).abs() < 1e-6 * n && n.round() >= 2.0
    });
    (symmetric && whole).then(|| (0..3).max_by(|&a, &b| cell[a].total_cmp(&cell[b])).unwrap())
}

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
    // Half a cell is measured, and counted twice, where the solid is its own image under
    // inversion through the cell's centre and so is the voxel grid (a whole number of voxels
    // along every axis): the cell's upper half is then the lower half turned about the centre.
    let half = half_cell_axis(surface, structure, cell, voxel);
    let mut measured = cell_box;
    if let Some(a) = half {
        measured.max[a] = 0.5 * cell[a];
    }
    let scale = if half.is_some() { 2.0 } else { 1.0 } / cell_volume;
    let padded = Aabb {
        min: [-m; 3],
        max: [0, 1, 2].map(|a| measured.max[a] + m),
    };
    // The cut cell: clipped by the cell's faces, and past the half cell's inner face by the margin.
    let mut cut = cell_box;
    if let Some(a) = half {
        cut.max[a] = measured.max[a] + m;
    }
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
    let cut_spec = GridSpec::covering(&cut, voxel, super::HALF_WIDTH);
    // What an interior cell contributes: the periodic cell's mesh measured inside the cell.
    let interior = |t: f64| -> Result<f64> {
        Ok(mk(t, padded).volume_in(spec, adaptivity, &measured)? * scale)
    };
    // What a cell with cut faces contributes.
    let cut_cell = |t: f64| -> Result<f64> {
        Ok(mk(t, cut).volume_in(cut_spec, adaptivity, &measured)? * scale)
    };

    // At t0, the interior cell and the cut cell are meshed side by side; the cut face's effect
    // changes little with the level over the few steps that follow, so it is kept.
    let (ia, ca) = rayon::join(|| interior(t0), || cut_cell(t0));
    let (mut ia, ca) = (ia?, ca?);
    meshings += 2;
    let fa = ca - ia;
    let predict = |i: f64| i + k * fa;
    let (mut ta, mut pa) = (t0, predict(ia));
    let mut converged = false;
    // Meshing biases the fraction by nearly the same amount at nearby levels (the exact
    // fraction is smooth in the level, see `Table::fraction`): each step reads the level off
    // the exact cell's distribution at the target less the bias last measured. A step whose
    // correction is small is taken without meshing its level: the bias it leaves is the bias's
    // own change over the step, a few hundredths of the correction (the part's own mesh
    // confirms it).
    for _ in 0..4 {
        let bias = pa - analytic_fraction(surface, structure, ta);
        let tb = analytic_level(surface, structure, (target - bias).clamp(1e-6, 1.0 - 1e-6));
        if (pa - target).abs() < ACCEPT {
            ia += target - pa;
            (ta, pa) = (tb, target);
            converged = true;
            break;
        }
        ia = interior(tb)?;
        meshings += 1;
        (ta, pa) = (tb, predict(ia));
    }
    converged |= (pa - target).abs() < ACCEPT;
    Ok(Calibration {
        level: ta,
        analytic_level: t0,
        interior_fraction: ia,
        face_effect: fa,
        predicted_fraction: pa,
        meshings,
        converged,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// Where each lattice holds together, from [`percolation_range`] (64 samples per cell axis; the
/// two net minima near 0.1 refined at 128). Sheet minima are 0: a wall around the connected
/// surface `F = 0` cannot fall apart however thin (the sampled test loses walls thinner than a
/// sample spacing). `(surface, structure, solid range, void range)`; a test recomputes them.
pub const PERCOLATION: [(Surface, Structure, FeasibleRange, FeasibleRange); 18] = {
    const fn r(min: f64, max: f64) -> FeasibleRange {
        FeasibleRange { min, max }
    }
    use Structure::{Net, Sheet};
    use Surface::*;
    [
        (P, Net, r(0.2138, 1.0), r(0.0, 0.7862)),
        (P, Sheet, r(0.0, 1.0), r(0.0, 0.5721)),
        (Gyroid, Net, r(0.0191, 1.0), r(0.0, 0.9809)),
        (Gyroid, Sheet, r(0.0, 1.0), r(0.0, 0.96)),
        (D, Net, r(0.0834, 1.0), r(0.0, 0.9166)),
        (D, Sheet, r(0.0, 1.0), r(0.0, 0.83)),
        (Iwp, Net, r(0.1019, 1.0), r(0.0, 0.9862)),
        (Iwp, Sheet, r(0.0, 1.0), r(0.0, 0.88)),
        (S, Net, r(0.1164, 1.0), r(0.0, 0.8836)),
        (S, Sheet, r(0.0, 1.0), r(0.0, 0.7656)),
        (Frd, Net, r(0.3359, 1.0), r(0.0, 0.78)),
        (Frd, Sheet, r(0.0, 0.4409), r(0.0, 0.4259)),
        (Neovius, Net, r(0.3388, 1.0), r(0.0, 0.66)),
        (Neovius, Sheet, r(0.0, 1.0), r(0.0, 0.3245)),
        // Their sheets sampled at 64 seem to fall apart below 0.22 and 0.13: walls thinner than a
        // sample; at 128 and 192 samples they hold at 0.15 and 0.08.
        (Lidinoid, Net, r(0.2544, 1.0), r(0.0, 0.5035)),
        (Lidinoid, Sheet, r(0.0, 1.0), r(0.0, 0.2305)),
        (SplitP, Net, r(0.1434, 1.0), r(0.0, 0.7222)),
        (SplitP, Sheet, r(0.0, 1.0), r(0.0, 0.4325)),
    ]
};

/// The net's other labyrinth at density `ρ` is the net's void at `1 − ρ`, and its void the
/// net's solid: its ranges from the net's, `(solid, void)`.
fn other_side(surface: Surface) -> (FeasibleRange, FeasibleRange) {
    let flip = |r: FeasibleRange| FeasibleRange {
        min: 1.0 - r.max,
        max: 1.0 - r.min,
    };
    (
        flip(void_connected_range(surface, Structure::Net)),
        flip(feasible(surface, Structure::Net)),
    )
}

/// The feasible range (solid in one piece) of a surface and structure.
pub fn feasible(surface: Surface, structure: Structure) -> FeasibleRange {
    if structure == Structure::NetOther {
        return other_side(surface).0;
    }
    PERCOLATION
        .iter()
        .find(|e| e.0 == surface && e.1 == structure)
        .map(|e| e.2)
        .expect("every surface and structure is tabulated")
}

/// Where the void percolates (no closed voids).
pub fn void_connected_range(surface: Surface, structure: Structure) -> FeasibleRange {
    if structure == Structure::NetOther {
        return other_side(surface).1;
    }
    PERCOLATION
        .iter()
        .find(|e| e.0 == surface && e.1 == structure)
        .map(|e| e.3)
        .expect("every surface and structure is tabulated")
}
