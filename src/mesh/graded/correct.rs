//! Meshing a graded part and correcting its cells: each promised cell measured on the mesh,
//! its density shifted by its miss (the shifts un-blurred so each cell gets what it asked, read
//! trilinearly between cell centres), until every cell is within [`AIM`] or [`MAX_MESHINGS`].

use super::levels::{Graded, LevelGrid};
use super::{CellDensity, AIM, CELL_PROMISE, FLAT_CELL_PROMISE, MAX_MESHINGS};
use crate::error::Result;
use crate::field::nodes::Nodes;
use crate::field::{Aabb, Vec3};
use crate::io::sink::MeshSink;
use crate::mesh::cells::{CellTee, CellVolumes};
use crate::mesh::pipeline::{self, Family, Made, MeshingStats, Options, Route, Written};
use crate::mesh::report::LevelSearch;
use crate::progress::Progress;

/// The cells of a graded part: which are promised, and what each is promised.
pub struct Cells {
    /// The cells, nothing measured.
    pub grid: CellVolumes,
    /// Whether each cell's density is promised.
    pub promised: Vec<bool>,
    /// The field at each cell's centre.
    pub targets: Vec<f64>,
    /// Each cell's promise.
    pub tolerances: Vec<f64>,
}

impl Cells {
    /// The cells of `grid` at density `target`; `promised` says which are.
    pub fn new(
        grid: CellVolumes,
        target: &dyn Fn(Vec3) -> f64,
        promised: impl Fn([usize; 3]) -> bool,
    ) -> Cells {
        let all: Vec<[usize; 3]> = grid.cells().collect();
        Cells {
            promised: all.iter().map(|c| promised(*c)).collect(),
            targets: all
                .iter()
                .map(|c| target(grid.cell_box(*c).centre()))
                .collect(),
            tolerances: all
                .iter()
                .map(|c| {
                    if flat_over(target, &grid.cell_box(*c)) {
                        FLAT_CELL_PROMISE
                    } else {
                        CELL_PROMISE
                    }
                })
                .collect(),
            grid,
        }
    }
}

/// A graded part meshed and written.
pub struct Outcome {
    /// What was written.
    pub written: Written,
    /// The route it took.
    pub route: Route,
    /// The meshings, as a level search.
    pub level_search: LevelSearch,
    /// Statistics of the meshings before the written one.
    pub meshing: MeshingStats,
    /// Meshings of the part.
    pub meshings: u32,
    /// Every cell, measured on what was written.
    pub cells: Vec<CellDensity>,
    /// The largest error over the promised cells.
    pub max_cell_error: f64,
    /// Every promised cell within its promise.
    pub cells_met: bool,
    /// The mean level written.
    pub mean_level: f64,
}

/// Meshes the graded part of `kind` over `bounds` to density `target`, corrects its cells (see
/// the module's notes) and writes the best meshing to `sink` — unless `hold_back` and even the
/// best meshing misses a promised cell: then nothing is written and `None` returned (finer
/// voxels may meet it).
#[allow(clippy::too_many_arguments)]
pub fn mesh<G: Graded>(
    kind: &G,
    target: &(dyn Fn(Vec3) -> f64 + Sync),
    bounds: &Aabb,
    cells: Cells,
    voxel: f64,
    opts: &Options,
    hold_back: bool,
    progress: &Progress,
    sink: &mut dyn MeshSink,
) -> Result<Option<Outcome>> {
    let Cells {
        grid,
        promised,
        targets,
        tolerances,
    } = cells;
    let margin = (pipeline::HALF_WIDTH + 2.0) * voxel;
    // Density shift per cell, read trilinearly between cell centres.
    let mut shift = vec![0.0; promised.len()];
    let build = |shift: &[f64]| {
        let shifts = between_centres(&grid, shift);
        LevelGrid::build(bounds, grid.cell(), margin, |p| {
            kind.level(p, target(p) + shifts.at(p))
        })
    };
    let mut levels = build(&shift);
    let mut brackets = vec![Bracket::default(); promised.len()];
    // The worst cell's miss, whether a cell missed its promise, the meshing and the shifts it
    // was made with.
    let mut best: Option<(f64, bool, pipeline::Measured, Vec<f64>)> = None;
    let mut meshings = 0u32;
    let mut tried = Vec::new();
    let mut search_meshing = MeshingStats::default();
    let route = Route::choose(&kind.family(&levels).at(0.0), voxel, opts);
    let measured = loop {
        // A part meshed tile by tile is measured cell by cell as its tiles pass.
        let mut observer = CellTee {
            inner: &mut pipeline::VolumeSink,
            cells: grid.clone(),
        };
        let m = {
            let _p = progress.stage(if meshings == 0 {
                "sampling and meshing the graded part"
            } else {
                "meshing the part again with its cells corrected"
            });
            pipeline::measure_observed(
                &kind.family(&levels),
                0.0,
                voxel,
                route,
                opts,
                &mut observer,
            )?
        };
        meshings += 1;
        search_meshing.add(&m.meshing);
        tried.push((0.0, m.fraction));
        let measured = match &m.made {
            Made::Whole(mesh) => {
                let mut measured = grid.clone();
                measured.add_mesh(&mesh.to_mesh());
                measured.fractions()
            }
            Made::TilePieces(found) => {
                // The fragments are dropped when the part is written.
                let mut cells = observer.cells;
                for (volume, within) in &found.loose {
                    cells.remove(*volume, within);
                }
                cells.fractions()
            }
            _ => break m,
        };
        let worst = (0..promised.len())
            .filter(|&i| promised[i])
            .map(|i| (measured[i] - targets[i]).abs())
            .fold(0.0, f64::max);
        let missed = (0..promised.len())
            .any(|i| promised[i] && (measured[i] - targets[i]).abs() > tolerances[i]);
        let done = worst <= AIM || meshings >= MAX_MESHINGS;
        // The meshing whose worst cell is closest is written.
        if best.as_ref().is_none_or(|b| worst < b.0) {
            best = Some((worst, missed, m, shift.clone()));
        }
        if done {
            let (_, missed, m, best_shift) = best.take().expect("a meshing was kept");
            if missed && hold_back {
                return Ok(None);
            }
            if best_shift != shift {
                // Tiles are meshed again as they are written: at the best meshing's levels.
                levels = build(&best_shift);
            }
            break m;
        }
        for i in 0..promised.len() {
            if promised[i] {
                shift[i] = brackets[i].next(shift[i], measured[i], targets[i]);
            }
        }
        extend_to_unpromised(&grid, &promised, &mut shift);
        levels = build(&shift);
    };
    let level_search = LevelSearch::new(&measured, route, &tried, Vec::new());
    let mut tee = CellTee {
        inner: sink,
        cells: grid,
    };
    let family = kind.family(&levels);
    let written = pipeline::write(&family, measured, voxel, route, opts, progress, &mut tee)?;
    let densities = tee.cells.fractions();
    let cells: Vec<CellDensity> = tee
        .cells
        .cells()
        .enumerate()
        .map(|(i, c)| CellDensity {
            cell: c,
            target: targets[i],
            density: densities[i],
            whole: promised[i],
            tolerance: tolerances[i],
        })
        .collect();
    let checked = cells.iter().filter(|c| c.whole);
    let max_cell_error = checked
        .clone()
        .map(|c| (c.density - c.target).abs())
        .fold(0.0, f64::max);
    let cells_met = checked
        .into_iter()
        .all(|c| (c.density - c.target).abs() <= c.tolerance);
    Ok(Some(Outcome {
        written,
        route,
        level_search,
        meshing: search_meshing,
        meshings,
        cells,
        max_cell_error,
        cells_met,
        mean_level: levels.mean,
    }))
}

/// Whether `f` is constant over the box (on a 3×3×3 set of points).
fn flat_over(f: &dyn Fn(Vec3) -> f64, b: &Aabb) -> bool {
    let mut values = Vec::with_capacity(27);
    for i in 0..27 {
        let w = [i / 9, i / 3 % 3, i % 3];
        values.push(f(
            [0, 1, 2].map(|a| b.min[a] + (b.max[a] - b.min[a]) * w[a] as f64 / 2.0)
        ));
    }
    let (lo, hi) = values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(*v), b.max(*v))
        });
    hi - lo < 1e-9
}

/// Nodes at the cells' centres (read trilinearly between them, held at the outer centres
/// beyond them) whose mean over each cell is the cell's `means`: the reading's cell means are
/// a blur of the node values (along an axis, ⅛ of each neighbour and ¾ of the cell's own; ⅞ at
/// the ends, where the reading is held), so the node values are the means un-blurred — one
/// tridiagonal solve per line of cells along each axis. A cell is then shifted by what it asked,
/// not by a mixture of its neighbours' asks, and the correction converges in a few meshings
/// where the field bends sharply.
fn between_centres(cells: &CellVolumes, means: &[f64]) -> Nodes {
    let n = cells.counts;
    let mut values = means.to_vec();
    for axis in 0..3 {
        if n[axis] < 2 {
            continue;
        }
        let stride = [n[1] * n[2], n[2], 1][axis];
        let lines = (0..n[0] * n[1] * n[2]).filter(|i| (i / stride).is_multiple_of(n[axis]));
        for start in lines.collect::<Vec<_>>() {
            let idx: Vec<usize> = (0..n[axis]).map(|k| start + k * stride).collect();
            let line: Vec<f64> = idx.iter().map(|&i| values[i]).collect();
            for (k, v) in unblur(&line).into_iter().enumerate() {
                values[idx[k]] = v;
            }
        }
    }
    let b0 = cells.cell_box([0, 0, 0]);
    Nodes {
        origin: [0, 1, 2].map(|a| b0.min[a] + 0.5 * cells.cell()[a]),
        step: cells.cell(),
        n,
        values,
    }
}

/// Solves `⅛ s[k−1] + ¾ s[k] + ⅛ s[k+1] = m[k]` (`⅞ s[0] + ⅛ s[1]` and `⅛ s[n−2] + ⅞ s[n−1]`
/// at the ends) for `s` (Thomas' algorithm; the system is diagonally dominant). At least two
/// values.
fn unblur(m: &[f64]) -> Vec<f64> {
    let n = m.len();
    let (off, diag) = (
        0.125,
        |k: usize| if k == 0 || k == n - 1 { 0.875 } else { 0.75 },
    );
    let mut c = vec![0.0; n];
    let mut d = vec![0.0; n];
    c[0] = off / diag(0);
    d[0] = m[0] / diag(0);
    for k in 1..n {
        let w = diag(k) - off * c[k - 1];
        c[k] = off / w;
        d[k] = (m[k] - off * d[k - 1]) / w;
    }
    let mut s = d;
    for k in (0..n - 1).rev() {
        s[k] -= c[k] * s[k + 1];
    }
    s
}

/// One cell's correction: the shifts tried on either side of its target.
#[derive(Clone, Copy, Default)]
struct Bracket {
    /// `(shift, density)` of the last meshing below the target, and above it.
    below: Option<(f64, f64)>,
    above: Option<(f64, f64)>,
}

impl Bracket {
    /// The next shift of a cell that measured `density` at `shift`: its error added, until the
    /// target is bracketed; then the secant between the two sides, or their midpoint where the
    /// density jumps between them (a piece the box cuts loose, and that is removed, joins the
    /// lattice again between them: the level is pinned just above the jump).
    fn next(&mut self, shift: f64, density: f64, target: f64) -> f64 {
        if density < target {
            self.below = Some((shift, density));
        } else {
            self.above = Some((shift, density));
        }
        match (self.below, self.above) {
            (Some((s0, d0)), Some((s1, d1))) => {
                // The shift is in density's units: a jump moves the density far more.
                if (d1 - d0) > 2.0 * (s1 - s0).abs() + 0.002 {
                    0.5 * (s0 + s1)
                } else {
                    s0 + (target - d0) * (s1 - s0) / (d1 - d0).max(1e-9)
                }
            }
            _ => shift + target - density,
        }
    }
}

/// Gives each unpromised cell the shift of the nearest promised cell (along each axis, the
/// nearest promised index; unchanged where none is).
fn extend_to_unpromised(cells: &CellVolumes, promised: &[bool], shift: &mut [f64]) {
    let all: Vec<[usize; 3]> = cells.cells().collect();
    let on = |c: &[usize; 3]| promised[cells.index(*c)];
    let range = [0, 1, 2].map(|a| {
        let idx = all.iter().filter(|c| on(c)).map(|c| c[a]);
        idx.clone().min().zip(idx.max())
    });
    for c in &all {
        if on(c) {
            continue;
        }
        let Some(near) = (0..3)
            .map(|a| range[a].map(|(lo, hi)| c[a].clamp(lo, hi)))
            .collect::<Option<Vec<usize>>>()
        else {
            continue;
        };
        let near = [near[0], near[1], near[2]];
        if on(&near) {
            shift[cells.index(*c)] = shift[cells.index(near)];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The nodes' trilinear reading has each cell's asked mean over the cell (by a fine
    /// midpoint rule), partial-free grids of 1 to 4 cells per axis.
    #[test]
    fn shifts_are_met_on_average_over_each_cell() {
        let grid = CellVolumes::new(
            Aabb {
                min: [1.0, -2.0, 0.5],
                max: [4.0, 2.0, 1.5],
            },
            [1.0; 3],
        );
        let means: Vec<f64> = (0..grid.counts.iter().product::<usize>())
            .map(|i| ((i * 7919) % 13) as f64 / 13.0 - 0.5)
            .collect();
        let nodes = between_centres(&grid, &means);
        let m = 24;
        for c in grid.cells().collect::<Vec<_>>() {
            let b = grid.cell_box(c);
            let mut sum = 0.0;
            for q in 0..m * m * m {
                let w = [q / (m * m), q / m % m, q % m];
                let p = [0, 1, 2].map(|a| b.min[a] + (w[a] as f64 + 0.5) / m as f64);
                sum += nodes.at(p);
            }
            let mean = sum / (m * m * m) as f64;
            assert!((mean - means[grid.index(c)]).abs() < 1e-3, "{c:?}");
        }
    }

    /// A bracketed cell takes the secant; a jump across the target takes the midpoint.
    #[test]
    fn brackets_close_on_the_target() {
        let mut b = Bracket::default();
        let s = b.next(0.0, 0.29, 0.30);
        assert!((s - 0.01).abs() < 1e-12);
        let s2 = b.next(s, 0.302, 0.30);
        assert!((s2 - (0.0 + 0.01 * 0.01 / 0.012)).abs() < 1e-12);
        let mut j = Bracket::default();
        j.next(0.0, 0.20, 0.30);
        assert!((j.next(0.02, 0.40, 0.30) - 0.01).abs() < 1e-12);
    }
}
