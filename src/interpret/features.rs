//! What makes a thresholded density field unprintable, found on the refined grid:
//! - **thin features** (Liu et al. 2018, step 1.3): in 2D, skeleton pixels whose inscribed radius
//!   is below `l_limit / 2` (to within half a pixel); in 3D, solid voxels that no ball of radius `l_limit / 2` inside the
//!   solid covers (the residue of a morphological opening computed with distance transforms),
//!   ignoring the thin rim such an opening always leaves along convex edges and corners;
//! - **islands**: solid parts not face-connected to the main (largest) body;
//! - **point contacts**: solids that touch only at a corner (or an edge, in 3D): two diagonal
//!   pixels of a 2 × 2 window solid and the other two void.

use super::distance::edt_squared;
use super::raster::{Mask, Raster};
use super::skeleton;

/// The defects of one mask, and what the images and the repair loop need.
#[derive(Debug, Clone, Default)]
pub struct Analysis {
    /// 2D skeleton after spur pruning (empty in 3D).
    pub skeleton: Vec<bool>,
    /// Thin-feature pixels (skeleton pixels in 2D, residue voxels in 3D).
    pub thin: Vec<usize>,
    /// Smallest inscribed radius found on the skeleton (2D) or feature size (3D), mm.
    pub min_radius_mm: f64,
    /// Pixels of each island (parts not connected to the main body).
    pub islands: Vec<Vec<usize>>,
    /// One pixel of each point contact (the lower-left pixel of its 2 × 2 window).
    pub contacts: Vec<usize>,
    /// Medial pixels of the thresholded design (its members' centre lines) that this mask has
    /// lost: a member that vanished instead of being thickened.
    pub lost: Vec<usize>,
    /// Solid pixels (voxels in 3D) of the mask.
    pub solid: usize,
}

impl Analysis {
    /// Whether no defect was found: no thin feature, island, point contact or lost member.
    pub fn is_clean(&self) -> bool {
        self.thin.is_empty()
            && self.islands.is_empty()
            && self.contacts.is_empty()
            && self.lost.is_empty()
    }

    /// The design's medial pixels: the pruned skeleton in 2D; in 3D the ridge of the distance
    /// transform (voxels at least as far from the void as all 26 neighbours).
    pub fn medial(&self, grid: &Raster, mask: &Mask) -> Vec<usize> {
        if !grid.is_3d() {
            return (0..self.skeleton.len())
                .filter(|&i| self.skeleton[i])
                .collect();
        }
        let n = grid.n;
        let void: Vec<bool> = mask.iter().map(|b| !b).collect();
        let d2 = edt_squared(n, &void, true);
        let mut out = Vec::new();
        for z in 0..n[2] {
            for y in 0..n[1] {
                for x in 0..n[0] {
                    let i = (z * n[1] + y) * n[0] + x;
                    if !mask[i] {
                        continue;
                    }
                    let mut top = true;
                    'nb: for dz in -1i64..=1 {
                        for dy in -1i64..=1 {
                            for dx in -1i64..=1 {
                                let (xx, yy, zz) = (x as i64 + dx, y as i64 + dy, z as i64 + dz);
                                if xx < 0
                                    || yy < 0
                                    || zz < 0
                                    || xx >= n[0] as i64
                                    || yy >= n[1] as i64
                                    || zz >= n[2] as i64
                                {
                                    continue;
                                }
                                let j = ((zz as usize * n[1]) + yy as usize) * n[0] + xx as usize;
                                if d2[j] > d2[i] {
                                    top = false;
                                    break 'nb;
                                }
                            }
                        }
                    }
                    if top {
                        out.push(i);
                    }
                }
            }
        }
        out
    }
}

/// Medial pixels of the design that `mask` no longer covers: void, with no solid neighbour.
pub fn lost(n: [usize; 3], mask: &Mask, medial: &[usize]) -> Vec<usize> {
    medial
        .iter()
        .copied()
        .filter(|&i| !mask[i] && face_neighbours(n, i).all(|j| !mask[j]))
        .collect()
}

/// Finds the defects of `mask` on `grid`'s geometry; `min_feature` in mm.
pub fn analyse(grid: &Raster, mask: &Mask, min_feature: f64) -> Analysis {
    let n = grid.n;
    let void: Vec<bool> = mask.iter().map(|b| !b).collect();
    let d2 = edt_squared(n, &void, true);
    let half = 0.5 * min_feature / grid.h; // l_limit / 2 in pixels
    let mut a = Analysis {
        solid: mask.iter().filter(|&&b| b).count(),
        min_radius_mm: f64::INFINITY,
        ..Default::default()
    };
    if grid.is_3d() {
        thin_3d(n, mask, &d2, half, &mut a);
    } else {
        let radius: Vec<f64> = d2.iter().map(|d| d.sqrt() - 0.5).collect();
        let mut skel = skeleton::thin(n[0], n[1], mask);
        skeleton::prune_spurs(n[0], n[1], &mut skel, &radius);
        for (i, &s) in skel.iter().enumerate() {
            if s {
                a.min_radius_mm = a.min_radius_mm.min(radius[i] * grid.h);
                // The pixel-centre distance is within half a pixel of the true inscribed radius
                // (under for odd widths, over for even): members down to l_limit − h pass.
                if radius[i] + 0.5 < half {
                    a.thin.push(i);
                }
            }
        }
        a.skeleton = skel;
    }
    a.islands = islands(n, mask);
    a.contacts = point_contacts(n, mask);
    a
}

fn thin_3d(n: [usize; 3], mask: &Mask, d2: &[f64], half: f64, a: &mut Analysis) {
    // Centres of balls of radius l/2 inside the solid, to within half a voxel (as in 2D).
    let r = half;
    let centres: Vec<bool> = d2.iter().map(|&d| d >= r * r).collect();
    let to_centre = edt_squared(n, &centres, false);
    // Covered: within r of such a centre. Residue: solid and not covered.
    let residue: Vec<bool> = mask
        .iter()
        .zip(&to_centre)
        .map(|(&m, &d)| m && d > r * r)
        .collect();
    if !residue.iter().any(|&b| b) {
        a.min_radius_mm = f64::INFINITY;
        return;
    }
    // The rim left at convex edges and corners lies within (√3 − 1)·r of the covered set;
    // residue farther than that is a member, plate or neck thinner than l_limit.
    let covered: Vec<bool> = mask.iter().zip(&residue).map(|(&m, &r)| m && !r).collect();
    let to_covered = edt_squared(n, &covered, false);
    let rim = (3f64.sqrt() - 1.0) * r + 1.0;
    for (i, (&res, &dc)) in residue.iter().zip(&to_covered).enumerate() {
        if res && dc > rim * rim {
            a.thin.push(i);
        }
    }
}

/// Face-connected components of the solid other than the largest, as pixel lists.
pub fn islands(n: [usize; 3], mask: &Mask) -> Vec<Vec<usize>> {
    let mut label = vec![u32::MAX; mask.len()];
    let mut comps: Vec<Vec<usize>> = Vec::new();
    let mut stack = Vec::new();
    for s in 0..mask.len() {
        if !mask[s] || label[s] != u32::MAX {
            continue;
        }
        let id = comps.len() as u32;
        let mut comp = Vec::new();
        label[s] = id;
        stack.push(s);
        while let Some(i) = stack.pop() {
            comp.push(i);
            for j in face_neighbours(n, i) {
                if mask[j] && label[j] == u32::MAX {
                    label[j] = id;
                    stack.push(j);
                }
            }
        }
        comps.push(comp);
    }
    if comps.len() <= 1 {
        return Vec::new();
    }
    let main = (0..comps.len()).max_by_key(|&c| comps[c].len()).unwrap();
    comps.swap_remove(main);
    comps
}

pub(crate) fn face_neighbours(n: [usize; 3], i: usize) -> impl Iterator<Item = usize> {
    let (x, y, z) = (i % n[0], (i / n[0]) % n[1], i / (n[0] * n[1]));
    let sx = 1;
    let sy = n[0];
    let sz = n[0] * n[1];
    [
        (x > 0).then(|| i - sx),
        (x + 1 < n[0]).then(|| i + sx),
        (y > 0).then(|| i - sy),
        (y + 1 < n[1]).then(|| i + sy),
        (z > 0).then(|| i - sz),
        (z + 1 < n[2]).then(|| i + sz),
    ]
    .into_iter()
    .flatten()
}

/// 2 × 2 windows (in every axis plane) whose solid pixels are exactly one diagonal pair, and in
/// 3D, 2 × 2 × 2 windows whose only solids are two opposite corners.
pub fn point_contacts(n: [usize; 3], mask: &Mask) -> Vec<usize> {
    let [nx, ny, nz] = n;
    let at = |x: usize, y: usize, z: usize| mask[(z * ny + y) * nx + x];
    let mut out = Vec::new();
    let planes: &[(usize, usize)] = if nz > 1 {
        &[(0, 1), (0, 2), (1, 2)]
    } else {
        &[(0, 1)]
    };
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                let p = [x, y, z];
                let mut hit = false;
                for &(a, b) in planes {
                    if p[a] + 1 >= n[a] || p[b] + 1 >= n[b] {
                        continue;
                    }
                    let q = |da: usize, db: usize| {
                        let mut c = p;
                        c[a] += da;
                        c[b] += db;
                        at(c[0], c[1], c[2])
                    };
                    let (s00, s10, s01, s11) = (q(0, 0), q(1, 0), q(0, 1), q(1, 1));
                    if (s00 && s11 && !s10 && !s01) || (s10 && s01 && !s00 && !s11) {
                        hit = true;
                    }
                }
                if !hit && nz > 1 && x + 1 < nx && y + 1 < ny && z + 1 < nz {
                    let c: Vec<bool> = (0..8)
                        .map(|k| at(x + (k & 1), y + ((k >> 1) & 1), z + (k >> 2)))
                        .collect();
                    let count = c.iter().filter(|&&b| b).count();
                    if count == 2 && (0..4).any(|k| c[k] && c[7 - k]) {
                        hit = true;
                    }
                }
                if hit {
                    out.push((z * ny + y) * nx + x);
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn contacts_and_islands_in_2d() {
        // Two 3×3 squares touching at one corner, and a lone pixel.
        let (nx, ny) = (10, 8);
        let mut m = vec![false; nx * ny];
        for y in 0..3 {
            for x in 0..3 {
                m[y * nx + x] = true;
                m[(y + 3) * nx + x + 3] = true;
            }
        }
        m[7 * nx + 9] = true;
        let n = [nx, ny, 1];
        assert_eq!(point_contacts(n, &m), vec![2 * nx + 2]);
        let isl = islands(n, &m);
        assert_eq!(isl.len(), 2);
    }
}
