//! Grids of plain values on a level set's voxels (a distance, a material fraction): built from
//! 8³ blocks sampled in Rust, NaN where a voxel holds nothing; and the blocks a level set covers.

use super::Grid;
use crate::error::Result;
use crate::ffi::vdb::ffi;
use crate::ffi::Backend;

impl Grid {
    /// The first sample of every leaf block the grid holds (sample indices of its spec).
    pub fn leaf_blocks(&self) -> Vec<[i64; 3]> {
        ffi::vdb_leaf_origins(&self.inner)
            .chunks_exact(3)
            .map(|o| [0, 1, 2].map(|a| o[a] as i64 + self.frame[a]))
            .collect()
    }

    /// The blocks of the leaf lattice, within the box of the leaves, whose centre is inside
    /// the level set (negative), that are not leaves: the part's interior, stored as tiles.
    pub fn interior_blocks(&self) -> Vec<[i64; 3]> {
        let leaves = self.leaf_blocks();
        if leaves.is_empty() {
            return Vec::new();
        }
        let mut lo = [i64::MAX; 3];
        let mut hi = [i64::MIN; 3];
        for b in &leaves {
            for a in 0..3 {
                lo[a] = lo[a].min(b[a]);
                hi[a] = hi[a].max(b[a]);
            }
        }
        let set: std::collections::HashSet<[i64; 3]> = leaves.into_iter().collect();
        let mut out = Vec::new();
        let mut z_column = Vec::new();
        let mut values = Vec::new();
        for x in (lo[0]..=hi[0]).step_by(8) {
            for y in (lo[1]..=hi[1]).step_by(8) {
                z_column.clear();
                for z in (lo[2]..=hi[2]).step_by(8) {
                    if !set.contains(&[x, y, z]) {
                        z_column.push([x, y, z]);
                    }
                }
                let points: Vec<f64> = z_column
                    .iter()
                    .flat_map(|b| {
                        self.spec
                            .point(b.map(|c| c + 3))
                            .map(|c| c + 0.5 * self.spec.voxel)
                    })
                    .collect();
                values.resize(z_column.len(), 0.0f32);
                self.probe(&points, &mut values);
                out.extend(
                    z_column
                        .iter()
                        .zip(&values)
                        .filter(|(_, v)| **v < 0.0)
                        .map(|(b, _)| *b),
                );
            }
        }
        out
    }

    /// A grid of values on this grid's voxels: `values` holds 512 per block of `blocks` (first
    /// samples, as [`Grid::leaf_blocks`] gives them), in OpenVDB's leaf order, NaN where a
    /// voxel holds nothing (inactive, `background`). `fog` marks it a fog volume (values in
    /// [0, 1], as a material fraction is).
    pub fn values_like(
        &self,
        blocks: &[[i64; 3]],
        values: &[f32],
        background: f32,
        fog: bool,
    ) -> Result<Grid> {
        let origins: Vec<i32> = blocks
            .iter()
            .flat_map(|b| (0..3).map(move |a| (b[a] - self.frame[a]) as i32))
            .collect();
        let h = self.spec.voxel;
        let origin = self.spec.point(self.frame).map(|x| x - 0.5 * h);
        let inner = ffi::vdb_values_from_leaves(h, &origin, background, fog, &origins, values)
            .backend("building a grid of values")?;
        Ok(Grid {
            inner: inner.into(),
            spec: self.spec,
            frame: self.frame,
            blocks_tested: 0,
            blocks_sampled: blocks.len() as u64,
        })
    }
}
