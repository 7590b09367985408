//! The repair loop of Liu et al. 2018 (steps 1–2): threshold and refine, find thin features,
//! islands and point contacts; then raise the density of what is too thin by 0.1, filter,
//! re-threshold at the level that keeps the thresholded volume, and look again — until nothing is
//! left or the iteration bound is reached (reported, never hidden).
//!
//! What gets raised: the pixels within `max(l_limit, filter radius) / 2` of each thin-feature
//! pixel, of each point contact, of each medial pixel of the thresholded design that vanished
//! (the loop preserves the design's members: the paper's "feature-preserving" boundary
//! refinement), and of the shortest path from each island to the main body (a bridge). Islands
//! smaller than one element are removed; larger ones farther than `l_limit` plus one element are
//! left and reported.

use super::distance::edt_squared;
use super::features::{analyse, face_neighbours, Analysis};
use super::raster::{Mask, Raster};
use super::Density;
use crate::error::{Error, Result};
use std::collections::VecDeque;

/// The cleanup's parameters; the defaults are Liu et al. 2018's.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct CleanOptions {
    /// ρcutoff of step 1.1.
    pub cutoff: f64,
    /// Refinement nc of steps 1.1/2.1 (pixels per element edge).
    pub refine: usize,
    /// l_limit: the printer's minimum feature, mm.
    pub min_feature: f64,
    /// Density filter radius (step 2.3), in elements of the input field.
    pub filter_radius: f64,
    /// Density added to thin features per iteration (step 2.2).
    pub raise: f64,
    /// Passes of the loop at most; defects left after the last are reported.
    pub max_iterations: usize,
}

impl Default for CleanOptions {
    fn default() -> Self {
        CleanOptions {
            cutoff: 0.5,
            refine: 8,
            min_feature: 2.0,
            filter_radius: 1.0,
            raise: 0.1,
            max_iterations: 30,
        }
    }
}

/// Counts after one pass of the loop.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Pass {
    /// Pass number, from 1.
    pub iteration: usize,
    /// Threshold level that keeps the volume.
    pub level: f64,
    /// Solid pixels (voxels in 3D) after the pass.
    pub solid_pixels: usize,
    /// Thin-feature pixels left.
    pub thin_pixels: usize,
    /// Islands left.
    pub islands: usize,
    /// Point contacts left.
    pub point_contacts: usize,
    /// Medial pixels of the thresholded design no longer covered (vanished members).
    pub lost_pixels: usize,
    /// Islands removed before this pass's filtering.
    pub islands_removed: usize,
}

/// Everything the loop produced; the stage images and the outputs are drawn from it.
pub struct Cleaned {
    /// Step 1.1/2.1: the refined raw densities.
    pub raw: Raster,
    /// Step 1.1: thresholded at ρcutoff.
    pub thresholded: Mask,
    /// Steps 1.2–1.3 on the thresholded field.
    pub initial: Analysis,
    /// The final filtered field and its level.
    pub field: Raster,
    /// The final level.
    pub level: f64,
    /// The final solid: the filtered field thresholded at `level`.
    pub mask: Mask,
    /// The defects found on the final solid.
    pub last: Analysis,
    /// Solid pixels of the thresholded field: the volume the loop keeps.
    pub target_pixels: usize,
    /// Counts after each pass, in order.
    pub passes: Vec<Pass>,
}

impl Cleaned {
    /// Whether the final solid has no defect left.
    pub fn is_clean(&self) -> bool {
        self.last.is_clean()
    }
}

/// Runs the loop on `d`.
pub fn clean(d: &Density, o: &CleanOptions) -> Result<Cleaned> {
    if !(o.cutoff > 0.0 && o.cutoff < 1.0) {
        return Err(Error::invalid(format!(
            "--cutoff must be in (0, 1), got {}",
            o.cutoff
        )));
    }
    if o.refine == 0 || o.refine > 64 {
        return Err(Error::invalid("--refine must be in 1..=64"));
    }
    if !(o.min_feature >= 0.0 && o.min_feature.is_finite()) {
        return Err(Error::invalid("--min-feature must be a length ≥ 0 in mm"));
    }
    if !(o.filter_radius > 0.0 && o.filter_radius <= 10.0) {
        return Err(Error::invalid(
            "--filter-radius must be in (0, 10] elements",
        ));
    }
    let ncz = if d.is_3d { o.refine } else { 1 };
    let pixels = (d.nx * o.refine) as u128 * (d.ny * o.refine) as u128 * (d.nz * ncz) as u128;
    if pixels > 400_000_000 {
        return Err(Error::invalid(format!(
            "refining by {} makes {pixels} pixels; lower --refine",
            o.refine
        )));
    }
    let raw = Raster::refine(d, o.refine);
    let thresholded = raw.threshold(o.cutoff);
    let target = thresholded.iter().filter(|&&b| b).count();
    if target == 0 {
        return Err(Error::invalid(format!(
            "no element reaches the cutoff density {}: nothing to make",
            o.cutoff
        )));
    }
    let initial = analyse(&raw, &thresholded, o.min_feature);
    let medial = initial.medial(&raw, &thresholded);
    let radius_px = o.filter_radius * o.refine as f64;
    // Step 2.1: the raw refined field; islands smaller than an element are cleared from it, and the
    // raised densities accumulate beside it, so every pass filters raw + raises (never a
    // filtered field again, which would blur members away).
    let mut base = raw.clone();
    let mut extra = vec![0.0; raw.len()];
    let mut flagged = initial.clone();
    let mut flagged_mask = thresholded.clone();
    let mut passes = Vec::new();
    let (mut field, mut level, mut mask, mut last);
    let mut it = 0;
    loop {
        it += 1;
        let removed = raise(
            &mut base,
            &mut extra,
            &flagged_mask,
            &flagged,
            o,
            d.element_size,
        );
        let raised = Raster {
            n: base.n,
            h: base.h,
            data: base.data.iter().zip(&extra).map(|(a, b)| a + b).collect(),
        };
        field = raised.cone_filter(radius_px);
        level = field.level_for_count(target);
        // The 2D outline is the contour of the field, whose area differs from the pixel count
        // by a fraction of a pixel along the boundary: the level keeps the area. (In 3D the job
        // matches the meshed volume after the loop.)
        if !field.is_3d() {
            level = level_for_area(&field, level, target as f64 * field.h * field.h);
        }
        mask = field.threshold(level);
        last = analyse(&field, &mask, o.min_feature);
        last.lost = super::features::lost(field.n, &mask, &medial);
        passes.push(Pass {
            iteration: it,
            level,
            solid_pixels: last.solid,
            thin_pixels: last.thin.len(),
            islands: last.islands.len(),
            point_contacts: last.contacts.len(),
            lost_pixels: last.lost.len(),
            islands_removed: removed,
        });
        if last.is_clean() || it >= o.max_iterations {
            break;
        }
        flagged = last.clone();
        flagged_mask = mask.clone();
    }
    Ok(Cleaned {
        raw,
        thresholded,
        initial,
        field,
        level,
        mask,
        last,
        target_pixels: target,
        passes,
    })
}

/// Step 2.2 and the island/contact repairs: adds `o.raise` within `l_limit/2` of every defect,
/// removes far islands. Returns the number of islands removed.
fn raise(
    base: &mut Raster,
    extra: &mut [f64],
    mask: &Mask,
    a: &Analysis,
    o: &CleanOptions,
    element: f64,
) -> usize {
    let field = base;
    let n = field.n;
    let mut seeds = vec![false; field.len()];
    for &i in a.thin.iter().chain(&a.contacts).chain(&a.lost) {
        seeds[i] = true;
    }
    let mut removed = 0;
    // An island smaller than one element is debris: removed. A larger one within reach is
    // bridged; one beyond reach is left in place and reported (the loop cannot guess intent).
    let cell = field.h.powi(if field.is_3d() { 3 } else { 2 });
    let small = |pixels: usize| (pixels as f64) * cell < element.powi(if n[2] > 1 { 3 } else { 2 });
    if !a.islands.is_empty() {
        let reach = (o.min_feature + element) / field.h;
        let mut is_island = vec![u32::MAX; field.len()];
        for (k, isl) in a.islands.iter().enumerate() {
            for &i in isl {
                is_island[i] = k as u32;
            }
        }
        // Breadth-first search from the main body through the void: the first pixel of each
        // island reached, and the path back, is the shortest bridge.
        let mut parent = vec![usize::MAX; field.len()];
        let mut dist = vec![u32::MAX; field.len()];
        let mut q = VecDeque::new();
        for (i, p) in parent.iter_mut().enumerate() {
            if mask[i] && is_island[i] == u32::MAX {
                *p = i;
                dist[i] = 0;
                q.push_back(i);
            }
        }
        let mut reached = vec![false; a.islands.len()];
        while let Some(i) = q.pop_front() {
            if (dist[i] as f64) > reach + 2.0 {
                break;
            }
            for j in face_neighbours(n, i) {
                if dist[j] != u32::MAX {
                    continue;
                }
                dist[j] = dist[i] + 1;
                parent[j] = i;
                let k = is_island[j];
                if k != u32::MAX {
                    if !reached[k as usize] && !small(a.islands[k as usize].len()) {
                        reached[k as usize] = true;
                        let mut p = j;
                        while parent[p] != p {
                            seeds[p] = true;
                            p = parent[p];
                        }
                    }
                    continue;
                }
                q.push_back(j);
            }
        }
        for isl in &a.islands {
            if small(isl.len()) {
                removed += 1;
                for &i in isl {
                    field.data[i] = 0.0;
                }
            }
        }
    }
    if seeds.iter().any(|&s| s) {
        // Raise a neighbourhood comparable with the filter, or the raise is averaged away.
        let r = (0.5 * o.min_feature / field.h)
            .max(0.5 * o.filter_radius * o.refine as f64)
            .max(1.0);
        let d2 = edt_squared(n, &seeds, false);
        for (v, d) in extra.iter_mut().zip(&d2) {
            if *d <= r * r {
                *v += o.raise;
            }
        }
    }
    removed
}

/// The level near `start` at which the contour of `f` encloses `goal` mm² (secant iteration).
fn level_for_area(f: &Raster, start: f64, goal: f64) -> f64 {
    use super::contour::{loops, signed_area};
    secant(
        |t| loops(f, t).iter().map(|l| signed_area(l)).sum(),
        start,
        goal,
    )
}

/// The level near `start` at which `measure` is `goal` (secant iteration, at most six steps);
/// `start` itself if no step improves on it.
pub(crate) fn secant(measure: impl FnMut(f64) -> f64, start: f64, goal: f64) -> f64 {
    secant_in(
        measure,
        start,
        goal,
        [(start - 0.45).max(1e-3), start + 0.45],
        0.01,
    )
}

/// [`secant`] within `range`, with `step` for the first trial.
pub(crate) fn secant_in(
    mut measure: impl FnMut(f64) -> f64,
    start: f64,
    goal: f64,
    range: [f64; 2],
    step: f64,
) -> f64 {
    let m0 = measure(start);
    let (mut t0, mut a0) = (start, m0);
    let (mut t1, mut a1) = (start - step, measure(start - step));
    for _ in 0..6 {
        if (a1 - goal).abs() <= 1e-4 * goal || a1 == a0 {
            break;
        }
        let t2 = (t1 - (a1 - goal) * (t1 - t0) / (a1 - a0)).clamp(range[0], range[1]);
        t0 = t1;
        a0 = a1;
        t1 = t2;
        a1 = measure(t1);
    }
    if (a1 - goal).abs() < (m0 - goal).abs() {
        t1
    } else {
        start
    }
}
