//! The part's geometry as a signed distance field, from a scanned point cloud.
//!
//! **Near the scan** the value is an implicit moving-least-squares distance (Kolluri, "Provably
//! good moving least squares", SODA 2005): the Gaussian-weighted mean of the signed distances
//! `nᵢ·(q − pᵢ)` from `q` to the tangent planes of its 8 nearest points, the width of the
//! Gaussian the local point spacing (at least a voxel). It is smooth, its zero set runs through
//! the points' mean (noise averages out) and near the surface it is the distance to it.
//!
//! **Away from the scan** — more than three spacings from the nearest point — the tangent planes
//! say nothing trustworthy, and the sign comes from an inside test that looks at the whole
//! cloud:
//! - `Winding` (default): the generalised winding number `w` of the oriented points
//!   ([`crate::geom::winding`]); the value is `(½ − w)·4u` held within `±u`, `u` the distance to the
//!   nearest point — `±u` where the winding number is clearly in or out, zero where `w = ½`,
//!   which spans a hole in the scan like a soap film, so a missing patch closes instead of
//!   letting the outside in;
//! - `Scan`: the method of the implicit FGM modelling literature (cell classification and line
//!   scans): the grid's 8³ blocks that hold the scan are boundary cells; every other block is
//!   inside or outside by the parity of the boundary runs a line from the box (outside) crosses
//!   on its way to it, along x, y and z from both ends, by majority. It is exact for clean closed
//!   scans and kept as the literature writes it; a hole in the scan lets lines through and
//!   mislabels whole rows — what the winding number is for.
//!
//! The two are blended over a further three spacings, so the field has no jump.
//!
//! **Sampling.** The field's clearance is the distance to the nearest point less a noise margin,
//! so [`crate::grid::Grid::sample`] keeps only the blocks around the scan; the blocks far from it
//! where the inside test changes sign between neighbours (the film over a hole) are sampled too
//! (clearance 0), so the narrow band is closed and OpenVDB's sign flood fill gives the deep
//! inside its sign.

use super::cloud::Cloud;
use crate::field::{Field, Vec3};
use crate::geom::winding::Winding;
use crate::grid::GridSpec;
use rayon::prelude::*;
use std::collections::HashSet;

/// How the inside is told from the outside away from the scan.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Sign {
    /// Generalised winding numbers of the oriented points (robust to holes and noise).
    Winding,
    /// Boundary cells and line scans from the box, as the implicit FGM literature writes it.
    Scan,
}

/// Nearest points the distance is averaged over.
const NEIGHBOURS: usize = 8;

/// A point cloud's signed distance field, set up for sampling on one grid.
pub struct ScanSdf<'a> {
    cloud: &'a Cloud,
    winding: Option<Winding>,
    spec: GridSpec,
    /// Block lattice of the padded region: first block, blocks per axis.
    lo: [i64; 3],
    n: [i64; 3],
    /// Per block: 0 near the scan, ±1 outside/inside away from it.
    signs: Vec<i8>,
    /// Blocks away from the scan where the inside test changes sign (sampled regardless).
    films: HashSet<[i64; 3]>,
    /// Per block: whether its centre is inside (the sign of a block the band misses).
    inside: Vec<bool>,
    method: Sign,
}

impl<'a> ScanSdf<'a> {
    /// The field of `cloud` for sampling on `spec`, the inside told by `method`.
    pub fn new(cloud: &'a Cloud, spec: GridSpec, method: Sign) -> ScanSdf<'a> {
        let region = spec.padded_region();
        let mut lo = region.lo.map(|x| x.div_euclid(8));
        let hi = region.hi.map(|x| (x - 1).div_euclid(8));
        let mut n = [0, 1, 2].map(|a| hi[a] - lo[a] + 1);
        if cloud.planar {
            // A plane contour: one layer of blocks, taken at z = 0.
            lo[2] = 0;
            n[2] = 1;
        }
        let winding = (method == Sign::Winding)
            .then(|| Winding::of_points(&cloud.points, &cloud.normals, &cloud.area, cloud.planar));
        let mut sdf = ScanSdf {
            cloud,
            winding,
            spec,
            lo,
            n,
            signs: Vec::new(),
            films: HashSet::new(),
            inside: Vec::new(),
            method,
        };
        sdf.classify_blocks();
        sdf
    }

    /// The centre of block `b`, mm (on the plane `z = 0` for a plane contour).
    fn block_centre(&self, b: [i64; 3]) -> Vec3 {
        let p0 = self.spec.point(b.map(|c| c * 8));
        let mut c = p0.map(|x| x + 3.5 * self.spec.voxel);
        if self.cloud.planar {
            c[2] = 0.0;
        }
        c
    }

    /// The block at position `i` of the lattice (x slowest, z fastest).
    fn block_at(&self, i: usize) -> [i64; 3] {
        crate::geom::block_at(self.lo, self.n, i)
    }

    fn block_index(&self, b: [i64; 3]) -> Option<usize> {
        crate::geom::block_index(self.lo, self.n, b)
    }

    fn block_of(&self, p: Vec3) -> [i64; 3] {
        let mut b = [0, 1, 2].map(|a| {
            (((p[a] - self.spec.origin[a]) / self.spec.voxel - 0.5).floor() as i64).div_euclid(8)
        });
        if self.cloud.planar {
            b[2] = 0;
        }
        b
    }

    /// How far from the nearest point the tangent planes are trusted, mm.
    fn trust(&self, nearest: usize) -> f64 {
        3.0 * self.cloud.spacing[nearest].max(self.spec.voxel)
    }

    /// Each block's sign away from the scan, and the blocks where it changes.
    fn classify_blocks(&mut self) {
        let [nx, ny, nz] = self.n;
        let total = (nx * ny * nz) as usize;
        let h = self.spec.voxel;
        // A block is near the scan when the sampler keeps it for its clearance (the test of
        // `Grid::sample`), so that near and far blocks leave no gap between them.
        let reach = 3.5 * h * 3f64.sqrt() + self.spec.half_width * h;
        // Per block: whether it is near the scan, and its inside test's sign (the winding
        // number's at every block centre; the line scans' away from the scan only).
        let classified: Vec<(bool, i8)> = (0..total)
            .into_par_iter()
            .map(|i| {
                let c = self.block_centre(self.block_at(i));
                let (k, u) = self.cloud.nearest_one(&c);
                let near = u - self.trust(k) <= reach;
                let sign = match &self.winding {
                    Some(w) if w.at(c) > 0.5 => 1,
                    Some(_) => -1,
                    None => 2, // decided by the scans below
                };
                (near, sign)
            })
            .collect();
        self.signs = classified
            .iter()
            .map(|&(near, s)| if near { 0 } else { s })
            .collect();
        // Near the scan the sign is the tangent planes' at the block's centre (for the line
        // scans, and for the blocks the narrow band misses when they are decided by them).
        let tangent: Vec<bool> = (0..total)
            .into_par_iter()
            .map(|i| {
                self.method == Sign::Scan && classified[i].0 && {
                    let c = self.block_centre(self.block_at(i));
                    let nearest: Vec<(usize, f64)> = self.cloud.nearest(&c, NEIGHBOURS).collect();
                    self.near_value(c, &nearest).0 < 0.0
                }
            })
            .collect();
        if self.method == Sign::Scan {
            self.scan_lines(&tangent);
        }
        let test: Vec<i8> = match self.method {
            Sign::Winding => classified.iter().map(|c| c.1).collect(),
            Sign::Scan => self.signs.clone(),
        };
        self.inside = (0..total)
            .map(|i| match test[i] {
                0 => tangent[i],
                s => s > 0,
            })
            .collect();
        // Blocks away from the scan whose sign differs from a neighbour's (near the scan too,
        // when its sign is known), and those neighbours: the inside test's zero set runs there.
        let mut films = HashSet::new();
        for x in 0..nx {
            for y in 0..ny {
                for z in 0..nz {
                    let b = [self.lo[0] + x, self.lo[1] + y, self.lo[2] + z];
                    let i = self.block_index(b).unwrap();
                    let s = test[i];
                    if s == 0 {
                        continue;
                    }
                    for a in 0..3 {
                        let mut o = b;
                        o[a] += 1;
                        if let Some(j) = self.block_index(o) {
                            let t = test[j];
                            let far = self.signs[i] != 0 || self.signs[j] != 0;
                            if t != 0 && t != s && far {
                                films.insert(b);
                                films.insert(o);
                            }
                        }
                    }
                }
            }
        }
        self.films = films;
    }

    /// Line scans over the block lattice: a run of boundary blocks (near the scan) toggles the
    /// parity of a line that crosses the surface in it — the tangent planes' sign (`tangent`)
    /// differs between the run's first and last block; a line that only grazes the band, or
    /// crosses a thin wall twice within it, keeps its parity. A block is inside when most of
    /// its six scans (along ±x, ±y, ±z from the box; ±x, ±y for a plane contour) say so.
    fn scan_lines(&mut self, tangent: &[bool]) {
        let n = self.n;
        let at = |p: [i64; 3]| ((p[0] * n[1] + p[1]) * n[2] + p[2]) as usize;
        let mut votes = vec![0i8; self.signs.len()];
        for axis in 0..if self.cloud.planar { 2 } else { 3 } {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            for i in 0..n[u] {
                for j in 0..n[v] {
                    for forward in [true, false] {
                        let mut inside = false;
                        // The run of boundary blocks the line is in: its first and last block.
                        let mut run: Option<(usize, usize)> = None;
                        for s in 0..n[axis] {
                            let mut p = [0; 3];
                            p[axis] = if forward { s } else { n[axis] - 1 - s };
                            p[u] = i;
                            p[v] = j;
                            let k = at(p);
                            if self.signs[k] == 0 {
                                run = Some((run.map_or(k, |r| r.0), k));
                            } else {
                                if let Some((first, last)) = run.take() {
                                    if tangent[first] != tangent[last] {
                                        inside = !inside;
                                    }
                                }
                                votes[k] += if inside { 1 } else { -1 };
                            }
                        }
                    }
                }
            }
        }
        for (s, v) in self.signs.iter_mut().zip(votes) {
            if *s != 0 {
                *s = if v > 0 { 1 } else { -1 };
            }
        }
    }

    /// Whether the block whose first sample is `first` is inside (for a block the narrow band
    /// does not reach: [`crate::grid::Grid::sample_signed`]).
    pub fn inside_block(&self, first: [i64; 3]) -> bool {
        self.block_index(first.map(|c| c.div_euclid(8)))
            .is_some_and(|i| self.inside[i])
    }

    /// The moving-least-squares distance at `q` and the nearest point (index, distance), from
    /// `q`'s nearest points (index, squared distance), nearest first.
    fn near_value(&self, q: Vec3, nearest: &[(usize, f64)]) -> (f64, usize, f64) {
        let mut num = 0.0;
        let mut den = 0.0;
        let (i0, d0) = nearest.first().copied().unwrap_or((0, 0.0));
        let sigma = self.cloud.spacing[i0].max(self.spec.voxel);
        for &(i, d2) in nearest {
            let w = (-(d2 - d0) / (sigma * sigma)).exp();
            let p = self.cloud.points[i];
            let n = self.cloud.normals[i];
            num += w * (n[0] * (q[0] - p[0]) + n[1] * (q[1] - p[1]) + n[2] * (q[2] - p[2]));
            den += w;
        }
        (num / den, i0, d0.sqrt())
    }

    /// The field at `q` from its nearest points.
    fn value_with(&self, q: Vec3, nearest: &[(usize, f64)]) -> f64 {
        let (near, i0, u) = self.near_value(q, nearest);
        let trust = self.trust(i0);
        if u <= trust {
            return near;
        }
        let far = self.far_value(q, u, near);
        let t = ((u - trust) / trust).min(1.0);
        let t = t * t * (3.0 - 2.0 * t);
        (1.0 - t) * near + t * far
    }

    /// The value away from the scan: `(½ − w)·4u` within `±u`, or the block's sign times `u` (in a block
    /// near the scan, which the line scans leave undecided, the tangent planes' sign).
    fn far_value(&self, q: Vec3, u: f64, near: f64) -> f64 {
        match &self.winding {
            Some(w) => ((0.5 - w.at(q)) * 4.0).clamp(-1.0, 1.0) * u,
            None => {
                let s = self
                    .block_index(self.block_of(q))
                    .map_or(-1, |i| self.signs[i]);
                match s {
                    0 => near.signum() * u,
                    s if s > 0 => -u,
                    _ => u,
                }
            }
        }
    }
}

impl Field for ScanSdf<'_> {
    fn value(&self, q: Vec3) -> f64 {
        let nearest: Vec<(usize, f64)> = self.cloud.nearest(&q, NEIGHBOURS).collect();
        self.value_with(q, &nearest)
    }

    fn clearance(&self, p: Vec3) -> f64 {
        if self.films.contains(&self.block_of(p)) {
            return 0.0;
        }
        let (i, u) = self.cloud.nearest_one(&p);
        (u - self.trust(i)).max(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::Aabb;
    use crate::grid::Grid;
    use crate::io::points::PointCloud;

    /// `n` points on a sphere of radius `r` (a Fibonacci lattice), less those within the polar
    /// cap of `hole` of its area, moved radially by up to `noise` mm.
    fn sphere(n: usize, r: f64, hole: f64, noise: f64) -> PointCloud {
        let mut points = Vec::new();
        let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
        let mut seed = 12345u64;
        for i in 0..n {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            if z > 1.0 - 2.0 * hole {
                continue;
            }
            let rho = (1.0 - z * z).sqrt();
            let phi = golden * i as f64;
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let e = ((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 2.0 * noise;
            let rr = r + e;
            points.push([rr * rho * phi.cos(), rr * rho * phi.sin(), rr * z]);
        }
        PointCloud {
            points,
            normals: None,
        }
    }

    fn grid_of(cloud: &Cloud, voxel: f64, sign: Sign) -> Grid {
        let b = cloud.bounds();
        let m = 4.0 * voxel;
        let bounds = Aabb {
            min: b.min.map(|x| x - m),
            max: b.max.map(|x| x + m),
        };
        let spec = GridSpec::covering(&bounds, voxel, 3.0);
        let f = ScanSdf::new(cloud, spec, sign);
        Grid::sample_signed(&f, spec, &|b| f.inside_block(b)).unwrap()
    }

    #[test]
    fn a_sphere_with_a_hole_keeps_its_inside() {
        let r = 10.0;
        let voxel = 0.5;
        for (hole, noise) in [(0.0, 0.0), (0.0, 0.1), (0.1, 0.0)] {
            let cloud = Cloud::new(sphere(20_000, r, hole, noise)).unwrap();
            assert!(cloud.normals_estimated);
            let g = grid_of(&cloud, voxel, Sign::Winding);
            let mut worst = 0.0f64;
            for i in 0..400 {
                let z = 1.0 - 2.0 * (i as f64 + 0.5) / 400.0;
                let phi = 2.4 * i as f64;
                let dir = [
                    (1.0 - z * z).sqrt() * phi.cos(),
                    (1.0 - z * z).sqrt() * phi.sin(),
                    z,
                ];
                // Deep inside, and across the band, away from the cap the hole took.
                for rr in [0.0, 3.0, 8.0, 9.0, 9.5, 10.0, 10.5, 11.0] {
                    let p = dir.map(|x| x * rr);
                    let v = g.value_at(p);
                    let exact = rr - r;
                    let in_cap = z > 1.0 - 2.0 * hole - 0.1;
                    if in_cap {
                        continue;
                    }
                    if exact.abs() < 1.4 {
                        worst = worst.max((v - exact).abs());
                    } else {
                        assert!(
                            v.signum() == exact.signum(),
                            "hole {hole} noise {noise}: {v} at {p:?}"
                        );
                    }
                }
            }
            eprintln!("hole {hole} noise {noise}: worst {worst}");
            assert!(
                worst < 0.5 * voxel,
                "hole {hole} noise {noise}: worst {worst}"
            );
        }
    }
}
