//! The linear cone filter of the 88-line code and top3d: `H(e, f) = max(0, rmin − dist(e, f))`
//! between element centres, with row sums `Hs`. Used on sensitivities or on densities.

use super::problem::Problem;

/// Filter weights in compressed rows.
pub struct ConeFilter {
    start: Vec<usize>,
    cols: Vec<u32>,
    weights: Vec<f64>,
    /// Row sums.
    pub hs: Vec<f64>,
}

impl ConeFilter {
    /// The cone filter of radius `rmin` (elements) on `p`'s mesh: weights
    /// `max(0, rmin − distance)`.
    pub fn new(p: &Problem, rmin: f64) -> ConeFilter {
        let step = (rmin.ceil() as i64 - 1).max(0);
        let (nx, ny, nz) = (p.nelx as i64, p.nely as i64, p.nelz.max(1) as i64);
        let mut start = Vec::with_capacity(p.elements() + 1);
        let mut cols = Vec::new();
        let mut weights = Vec::new();
        start.push(0);
        for e in 0..p.elements() as i64 {
            let (k, i, j) = (e / (nx * ny), (e % (nx * ny)) / ny, e % ny);
            for k2 in (k - step).max(0)..=(k + step).min(nz - 1) {
                for i2 in (i - step).max(0)..=(i + step).min(nx - 1) {
                    for j2 in (j - step).max(0)..=(j + step).min(ny - 1) {
                        let d2 = ((i - i2).pow(2) + (j - j2).pow(2) + (k - k2).pow(2)) as f64;
                        let w = (rmin - d2.sqrt()).max(0.0);
                        if w > 0.0 {
                            cols.push((k2 * nx * ny + i2 * ny + j2) as u32);
                            weights.push(w);
                        }
                    }
                }
            }
            start.push(cols.len());
        }
        let hs = (0..p.elements())
            .map(|e| weights[start[e]..start[e + 1]].iter().sum())
            .collect();
        ConeFilter {
            start,
            cols,
            weights,
            hs,
        }
    }

    /// `out = H · v`.
    pub fn apply(&self, v: &[f64], out: &mut [f64]) {
        for (e, o) in out.iter_mut().enumerate() {
            let r = self.start[e]..self.start[e + 1];
            *o = self.cols[r.clone()]
                .iter()
                .zip(&self.weights[r])
                .map(|(&c, &w)| w * v[c as usize])
                .sum();
        }
    }
}
