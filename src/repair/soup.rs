//! A soup made solid: the inside of a mesh of open, overlapping or non-manifold pieces — a
//! printer-bed plate of patches, an exporter's loose faces, a box with a face missing — is where
//! the pieces' generalised winding number ([`crate::geom::winding`], Barill et al., "Fast
//! winding numbers for soups and clouds", SIGGRAPH 2018) exceeds ½: inside a closed piece it is
//! 1, inside overlapping pieces it is at least 1 (their union), and across a hole it falls
//! smoothly through ½ on a surface that spans the hole like a soap film.
//!
//! The field is `(½ − w)·4u` held within `±u`, `u` the exact distance to the nearest triangle
//! (through a BVH): the signed distance wherever the winding number is clearly in or out, zero
//! on the film. Its clearance is `u`, except in the blocks of 8³ samples whose winding sign (at
//! their centre) differs from a neighbour's away from the soup — the film runs there, and they
//! are sampled whatever `u` says; a block the narrow band misses takes its centre's winding
//! sign.

use crate::error::Result;
use crate::field::{Field, Vec3};
use crate::geom::bvh::Bvh;
use crate::geom::winding::Winding;
use crate::geom::{cross, dot, norm, sub, Mesh};
use crate::grid::{Grid, GridSpec};
use rayon::prelude::*;
use std::collections::HashSet;

/// A soup's field: the distance to its triangles, signed by its winding number.
pub struct SoupField {
    bvh: Bvh,
    winding: Winding,
    /// Per triangle of the BVH: its unit normal, and the winding number just behind and just
    /// ahead of its centroid (for points near it, where the sum would be taken again and again).
    sides: Vec<(Vec3, [f64; 2])>,
    /// Distances beyond this are reported as it, mm.
    cap: f64,
    /// The grid's blocks: the first, per axis, and the voxel.
    lo: [i64; 3],
    n: [i64; 3],
    spec: GridSpec,
    /// Per block: whether its centre is inside (winding number over ½).
    inside: Vec<bool>,
    /// Blocks away from the soup where the winding sign changes (the film): sampled.
    films: HashSet<[i64; 3]>,
}

impl SoupField {
    /// The field of `mesh`'s triangles (however they join) for sampling on `spec`.
    pub fn new(mesh: &Mesh, spec: GridSpec) -> SoupField {
        let triangles: Vec<[Vec3; 3]> = (0..mesh.triangle_count())
            .map(|t| mesh.triangle(t))
            .collect();
        let winding = Winding::of_triangles(&triangles);
        let region = spec.padded_region();
        let lo = region.lo.map(|x| x.div_euclid(8));
        let hi = region.hi.map(|x| (x - 1).div_euclid(8));
        let n = [0, 1, 2].map(|a| hi[a] - lo[a] + 1);
        let h = spec.voxel;
        let block_reach = 3.5 * h * 3f64.sqrt() + spec.half_width * h;
        let bvh = Bvh::over(triangles);
        let step = 1e-2 * spec.voxel;
        let sides = bvh
            .triangles()
            .par_iter()
            .map(|t| {
                let n = cross(sub(t[1], t[0]), sub(t[2], t[0]));
                let l = norm(n);
                let n = if l > 0.0 { n.map(|x| x / l) } else { [0.0; 3] };
                let c = [0, 1, 2].map(|k| (t[0][k] + t[1][k] + t[2][k]) / 3.0);
                let at = |d: f64| winding.at([0, 1, 2].map(|k| c[k] + d * n[k]));
                (n, [at(-step), at(step)])
            })
            .collect();
        let mut f = SoupField {
            bvh,
            winding,
            sides,
            cap: 2.0 * block_reach,
            lo,
            n,
            spec,
            inside: Vec::new(),
            films: HashSet::new(),
        };
        let total = (n[0] * n[1] * n[2]) as usize;
        // Per block: near the soup (the sampler keeps it for its clearance) and its sign.
        let classified: Vec<(bool, bool)> = (0..total)
            .into_par_iter()
            .map(|i| {
                let c = f.block_centre(f.block_at(i));
                (
                    f.bvh.distance(c, f.cap) <= block_reach,
                    f.winding.at(c) > 0.5,
                )
            })
            .collect();
        f.inside = classified.iter().map(|c| c.1).collect();
        for i in 0..total {
            let b = f.block_at(i);
            for a in 0..3 {
                let mut o = b;
                o[a] += 1;
                if let Some(j) = f.block_index(o) {
                    let far = !classified[i].0 || !classified[j].0;
                    if far && classified[i].1 != classified[j].1 {
                        f.films.insert(b);
                        f.films.insert(o);
                    }
                }
            }
        }
        f
    }

    /// The block at position `i` of the lattice (x slowest, z fastest).
    fn block_at(&self, i: usize) -> [i64; 3] {
        crate::geom::block_at(self.lo, self.n, i)
    }

    fn block_index(&self, b: [i64; 3]) -> Option<usize> {
        crate::geom::block_index(self.lo, self.n, b)
    }

    fn block_centre(&self, b: [i64; 3]) -> Vec3 {
        self.spec
            .point(b.map(|c| c * 8))
            .map(|x| x + 3.5 * self.spec.voxel)
    }

    fn block_of(&self, p: Vec3) -> [i64; 3] {
        [0, 1, 2].map(|a| {
            (((p[a] - self.spec.origin[a]) / self.spec.voxel - 0.5).floor() as i64).div_euclid(8)
        })
    }

    /// Whether the block whose first sample is `first` is inside (for a block the narrow band
    /// does not reach).
    pub fn inside_block(&self, first: [i64; 3]) -> bool {
        self.block_index(first.map(|c| c.div_euclid(8)))
            .is_some_and(|i| self.inside[i])
    }

    /// The soup's winding number at `p`.
    pub fn winding(&self, p: Vec3) -> f64 {
        self.winding.at(p)
    }

    /// The field sampled into a level set on `spec`'s voxels.
    pub fn grid(&self) -> Result<Grid> {
        Grid::sample_signed(self, self.spec, &|first| self.inside_block(first))
    }
}

impl Field for SoupField {
    fn value(&self, p: Vec3) -> f64 {
        let u = self.bvh.distance(p, self.cap);
        ((0.5 - self.winding.at(p)) * 4.0).clamp(-1.0, 1.0) * u
    }

    fn clearance(&self, p: Vec3) -> f64 {
        if self.films.contains(&self.block_of(p)) {
            0.0
        } else {
            self.bvh.distance(p, self.cap)
        }
    }

    /// The value, and the gradient of the distance times its sign (away from the nearest
    /// point of the soup, or along its triangle's normal on it). Within two voxels of the soup,
    /// where the nearest point lies inside a triangle (not on its edges), the winding number is
    /// that triangle's on the point's side (exact where the soup is closed about it): the
    /// simplifier asks there over and over, and a sum over the soup would cost every time. Near
    /// a triangle's edge — a hole's rim, where a film meets the soup — it is summed.
    fn implicit_with_gradient(&self, p: Vec3) -> (f64, Vec3) {
        let Some((q, u, k)) = self.bvh.closest(p, self.cap) else {
            let s = ((0.5 - self.winding.at(p)) * 4.0).clamp(-1.0, 1.0);
            return (s * self.cap, [0.0; 3]);
        };
        let (n, [behind, ahead]) = self.sides[k];
        let along = dot(sub(p, q), n);
        let inside_triangle = along.abs() >= (1.0 - 1e-9) * u;
        let w = match (u < 2.0 * self.spec.voxel && inside_triangle, along >= 0.0) {
            (true, true) => ahead,
            (true, false) => behind,
            (false, _) => self.winding.at(p),
        };
        let s = ((0.5 - w) * 4.0).clamp(-1.0, 1.0);
        let outward = if ahead <= behind { n } else { n.map(|x| -x) };
        if u > 1e-3 * self.spec.voxel {
            let g = [0, 1, 2].map(|k| (p[k] - q[k]) / u);
            return (s * u, if s < 0.0 { g.map(|x| -x) } else { g });
        }
        (s * u, outward)
    }
}
