//! The refined grid the pipeline works on: every element split into `nc` (× `nc` × `nc` in 3D)
//! pixels of the same density (Liu et al. 2018, steps 1.1 and 2.1), the density filter of step 2.3
//! and the volume-keeping threshold of step 2.4.

use super::Density;
use rayon::prelude::*;

/// A 2D (`n[2] == 1`) or 3D grid of values, x fastest, then y (up), then z.
#[derive(Debug, Clone, PartialEq)]
pub struct Raster {
    /// Samples along x, y, z (`n[2] == 1` in 2D).
    pub n: [usize; 3],
    /// Pixel edge length, mm.
    pub h: f64,
    /// The values, `data[index(x, y, z)]`.
    pub data: Vec<f64>,
}

/// A solid/void mask on a raster's grid.
pub type Mask = Vec<bool>;

impl Raster {
    /// Whether the raster is 3D (more than one layer in z).
    pub fn is_3d(&self) -> bool {
        self.n[2] > 1
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.data.len()
    }

    /// Whether the raster has no samples.
    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }

    /// Position of sample `(x, y, z)` in `data`.
    pub fn index(&self, x: usize, y: usize, z: usize) -> usize {
        (z * self.n[1] + y) * self.n[0] + x
    }

    /// Refines `d` into `nc` pixels per element edge, each taking its element's density.
    pub fn refine(d: &Density, nc: usize) -> Raster {
        let ncz = if d.is_3d { nc } else { 1 };
        let n = [d.nx * nc, d.ny * nc, d.nz * ncz];
        let mut data = vec![0.0; n[0] * n[1] * n[2]];
        data.par_chunks_mut(n[0])
            .enumerate()
            .for_each(|(row, out)| {
                let (y, z) = (row % n[1], row / n[1]);
                for (x, o) in out.iter_mut().enumerate() {
                    *o = d.at(x / nc, y / nc, z / ncz);
                }
            });
        Raster {
            n,
            h: d.element_size / nc as f64,
            data,
        }
    }

    /// Pixels at or above `t`.
    pub fn threshold(&self, t: f64) -> Mask {
        self.data.par_iter().map(|&v| v >= t).collect()
    }

    /// The level `t` at which `count(v ≥ t)` is closest to `target` pixels, by bisection on `t`
    /// (step 2.4: re-threshold at the level that keeps the volume).
    pub fn level_for_count(&self, target: usize) -> f64 {
        let count = |t: f64| self.data.par_iter().filter(|&&v| v >= t).count();
        let top = self.data.iter().copied().fold(1.0f64, f64::max);
        let (mut lo, mut hi) = (0.0f64, top + 1e-9);
        // count(lo) ≥ target ≥ count(hi); the count falls as t rises.
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if count(mid) >= target {
                lo = mid;
            } else {
                hi = mid;
            }
            if hi - lo < 1e-12 {
                break;
            }
        }
        let (cl, ch) = (count(lo), count(hi));
        if cl.abs_diff(target) <= ch.abs_diff(target) {
            lo
        } else {
            hi
        }
    }

    /// The density filter of step 2.3: `ρ̃_i = Σ_e w_ie ρ_e / Σ_e w_ie`, `w = max(0, r − |x_i − x_e|)`
    /// with `r` in pixels. Pixels whose whole window is constant keep their value (the weighted
    /// mean of a constant), which skips most of the work away from boundaries.
    pub fn cone_filter(&self, r: f64) -> Raster {
        let ri = (r.ceil() as isize - 1).max(0);
        let d3 = self.is_3d();
        let rz = if d3 { ri } else { 0 };
        let mut offsets = Vec::new();
        for dz in -rz..=rz {
            for dy in -ri..=ri {
                let mut row = Vec::new();
                for dx in -ri..=ri {
                    let w = r - ((dx * dx + dy * dy + dz * dz) as f64).sqrt();
                    row.push(w.max(0.0));
                }
                if row.iter().any(|&w| w > 0.0) {
                    offsets.push((dz, dy, row));
                }
            }
        }
        let [nx, ny, nz] = self.n;
        let (nyi, nzi) = (ny as isize, nz as isize);
        // Row-wise min and max over the x-window, to find constant windows cheaply.
        let win = |v: &[f64], f: fn(f64, f64) -> f64| -> Vec<f64> {
            let mut out = vec![0.0; v.len()];
            for (x, o) in out.iter_mut().enumerate() {
                let a = x.saturating_sub(ri as usize);
                let b = (x + ri as usize).min(v.len() - 1);
                *o = v[a..=b].iter().copied().reduce(f).unwrap();
            }
            out
        };
        let rows: Vec<(Vec<f64>, Vec<f64>)> = self
            .data
            .par_chunks(nx)
            .map(|v| (win(v, f64::min), win(v, f64::max)))
            .collect();
        let src = &self.data;
        let width = 2 * ri as usize + 1;
        let mut out = vec![0.0; src.len()];
        out.par_chunks_mut(nx).enumerate().for_each(|(row, o)| {
            let (y, z) = ((row % ny) as isize, (row / ny) as isize);
            let mut lo = vec![f64::INFINITY; nx];
            let mut hi = vec![f64::NEG_INFINITY; nx];
            let mut taps: Vec<(usize, &[f64])> = Vec::with_capacity(offsets.len());
            for (dz, dy, wrow) in &offsets {
                let (yy, zz) = (y + dy, z + dz);
                if yy < 0 || yy >= nyi || zz < 0 || zz >= nzi {
                    continue;
                }
                let r2 = (zz * nyi + yy) as usize;
                for x in 0..nx {
                    lo[x] = lo[x].min(rows[r2].0[x]);
                    hi[x] = hi[x].max(rows[r2].1[x]);
                }
                taps.push((r2 * nx, wrow.as_slice()));
            }
            // Runs of pixels whose window is not constant: 1D convolutions row by row, on a
            // zero-padded copy so the inner loop has no bounds tests.
            let mut padded = vec![0.0; nx + width];
            let mut acc = vec![0.0; nx];
            // Weight sums: the row sums of the taps inside the domain; fewer near its x ends.
            let interior: f64 = taps.iter().map(|(_, w)| w.iter().sum::<f64>()).sum();
            let mut wsum = vec![interior; nx];
            for x in (0..ri.min(nx as isize)).chain((nx as isize - ri).max(0)..nx as isize) {
                wsum[x as usize] = taps
                    .iter()
                    .flat_map(|(_, w)| w.iter().enumerate())
                    .filter(|(k, _)| {
                        let xs = x + *k as isize - ri;
                        xs >= 0 && xs < nx as isize
                    })
                    .map(|(_, w)| w)
                    .sum();
            }
            let mut x = 0;
            while x < nx {
                if lo[x] == hi[x] {
                    o[x] = lo[x];
                    x += 1;
                    continue;
                }
                let start = x;
                while x < nx && lo[x] != hi[x] {
                    x += 1;
                }
                let (a, b) = (start, x);
                acc[a..b].iter_mut().for_each(|v| *v = 0.0);
                for &(base, wrow) in &taps {
                    let line = &src[base..base + nx];
                    // padded[k] = line[k − ri], zero outside the row.
                    let (pa, pb) = (a, (b + width - 1).min(nx + width));
                    for (k, pk) in padded.iter_mut().enumerate().take(pb).skip(pa) {
                        let xs = k as isize - ri;
                        *pk = if xs >= 0 && (xs as usize) < nx {
                            line[xs as usize]
                        } else {
                            0.0
                        };
                    }
                    for (k, &w) in wrow.iter().enumerate() {
                        if w == 0.0 {
                            continue;
                        }
                        let src_k = &padded[a + k..b + k];
                        for (acc, &v) in acc[a..b].iter_mut().zip(src_k) {
                            *acc += w * v;
                        }
                    }
                }
                for k in a..b {
                    o[k] = acc[k] / wsum[k];
                }
            }
        });
        Raster {
            n: self.n,
            h: self.h,
            data: out,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refine_filter_and_level() {
        let d = Density::from_array(&[2, 2], &[1.0, 0.0, 0.0, 0.5], 4.0).unwrap();
        let r = Raster::refine(&d, 4);
        assert_eq!(r.n, [8, 8, 1]);
        assert_eq!(r.h, 1.0);
        // Top-left element (row 0, col 0) is solid: pixel (0, 7) at the top left.
        assert_eq!(r.data[r.index(0, 7, 0)], 1.0);
        assert_eq!(r.data[r.index(7, 0, 0)], 0.5);
        // Filtering keeps the mean of a field far from its borders, and constants stay constant.
        let c = Raster {
            n: [9, 9, 1],
            h: 1.0,
            data: vec![0.3; 81],
        };
        assert!(c
            .cone_filter(2.5)
            .data
            .iter()
            .all(|&v| (v - 0.3).abs() < 1e-12));
        let mut spike = c.clone();
        spike.data.iter_mut().for_each(|v| *v = 0.0);
        spike.data[40] = 1.0;
        let f = spike.cone_filter(2.0);
        // Brute force: weight at the centre over the normalisation of a full window.
        let wsum: f64 = (-1i32..=1)
            .flat_map(|a| {
                (-1i32..=1).map(move |b| (2.0 - ((a * a + b * b) as f64).sqrt()).max(0.0))
            })
            .sum();
        assert!((f.data[40] - 2.0 / wsum).abs() < 1e-12);
        let t = f.level_for_count(5);
        assert_eq!(f.threshold(t).iter().filter(|&&b| b).count(), 5);
    }
}
