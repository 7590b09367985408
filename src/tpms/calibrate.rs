//! Calibration: the level `t` that gives a TPMS solid a target volume fraction.
//!
//! A TPMS is periodic, so the volume fraction of a whole lattice is that of one unit cell, and
//! the unit cell's volume fraction does not depend on the cell's size or aspect. `F` is sampled at
//! the midpoints of an `n³` grid over the unit cell once per surface; the fraction of the cell
//! where `F ≤ t` is then the empirical distribution of those samples, so the level for a target
//! fraction is read off as a quantile (of `F` for a net, of `|F|` for a sheet) with no search.

use super::surface::{Structure, Surface};
use std::sync::OnceLock;

/// Samples per axis over the unit cell.
const N: usize = 96;

/// Sorted `F` samples over the unit cell, one table per surface, built on first use.
fn sorted_samples(surface: Surface, structure: Structure) -> &'static [f32] {
    static TABLES: [[OnceLock<Vec<f32>>; 2]; 7] = [const { [const { OnceLock::new() }; 2] }; 7];
    let si = Surface::ALL.iter().position(|s| *s == surface).unwrap();
    let ki = match structure {
        Structure::Net => 0,
        Structure::Sheet => 1,
    };
    TABLES[si][ki].get_or_init(|| {
        use rayon::prelude::*;
        let mut v: Vec<f32> = (0..N * N * N)
            .into_par_iter()
            .map(|i| {
                let u = [
                    ((i / (N * N)) as f64 + 0.5) / N as f64,
                    (((i / N) % N) as f64 + 0.5) / N as f64,
                    ((i % N) as f64 + 0.5) / N as f64,
                ];
                let f = surface.eval(u).0;
                match structure {
                    Structure::Net => f as f32,
                    Structure::Sheet => f.abs() as f32,
                }
            })
            .collect();
        v.par_sort_unstable_by(|a, b| a.total_cmp(b));
        v
    })
}

/// Volume fraction of the unit cell at level `t`.
pub fn volume_fraction(surface: Surface, structure: Structure, t: f64) -> f64 {
    let s = sorted_samples(surface, structure);
    let below = s.partition_point(|&v| (v as f64) <= t);
    below as f64 / s.len() as f64
}

/// The level whose unit-cell volume fraction is `target` (linear between neighbouring samples).
pub fn level_for(surface: Surface, structure: Structure, target: f64) -> f64 {
    let s = sorted_samples(surface, structure);
    let x = (target * s.len() as f64 - 0.5).clamp(0.0, (s.len() - 1) as f64);
    let i = x.floor() as usize;
    let j = (i + 1).min(s.len() - 1);
    let f = x - i as f64;
    s[i] as f64 * (1.0 - f) + s[j] as f64 * f
}
