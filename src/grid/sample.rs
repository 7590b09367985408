//! A Field sampled into a grid: leaf blocks culled by the field's clearance, the survivors
//! sampled in parallel and handed to OpenVDB.

use super::{Grid, GridSpec, IndexBox, MIN_ABS_VALUE_VOXELS};
use crate::error::Result;
use crate::ffi::vdb::ffi;
use crate::ffi::Backend;
use crate::field::Field;
use rayon::prelude::*;

/// Block `(bx, by, bz)` of a block range starting at `lo` with `n` blocks per axis.
fn block_at(lo: [i64; 3], n: [usize; 3], idx: usize) -> [i64; 3] {
    [
        lo[0] + (idx / (n[1] * n[2])) as i64,
        lo[1] + ((idx / n[2]) % n[1]) as i64,
        lo[2] + (idx % n[2]) as i64,
    ]
}

impl Grid {
    /// Samples `field` on the narrow band of its zero set within the padded region of `spec`.
    pub fn sample(field: &dyn Field, spec: GridSpec) -> Result<Grid> {
        Self::sample_box(field, spec, spec.padded_region())
    }

    /// Samples `field` on the narrow band within the leaf blocks that cover `region` (sample
    /// indices of `spec`). Every block the band does not reach takes the sign of the field at its
    /// first sample. (OpenVDB's flood fill from the band, used before, gave a whole internal node
    /// with no band in it the sign of its neighbour in key order: a gyroid of 11×11×11 cells on 36
    /// voxels a cell, meshed in tiles of 288, came out with a slab above its box marked inside.)
    pub fn sample_box(field: &dyn Field, spec: GridSpec, region: IndexBox) -> Result<Grid> {
        let inside = |first: [i64; 3]| field.value(spec.point(first)) < 0.0;
        Self::sample_blocks(field, spec, region, &inside)
    }

    /// As [`Grid::sample`], the sign of every block the band does not reach given by `inside`
    /// (called with a block's first sample) instead of the field's own sign there: for fields
    /// whose own inside test is more trustworthy than their value far from the surface (a scan
    /// with holes).
    pub fn sample_signed(
        field: &dyn Field,
        spec: GridSpec,
        inside: &(dyn Fn([i64; 3]) -> bool + Sync),
    ) -> Result<Grid> {
        Self::sample_blocks(field, spec, spec.padded_region(), inside)
    }

    fn sample_blocks(
        field: &dyn Field,
        spec: GridSpec,
        region: IndexBox,
        inside: &(dyn Fn([i64; 3]) -> bool + Sync),
    ) -> Result<Grid> {
        let h = spec.voxel;
        let band = spec.half_width * h;
        let lo = region.lo.map(|x| x.div_euclid(8));
        let hi = region.hi.map(|x| (x - 1).div_euclid(8));
        let n = [0, 1, 2].map(|a| (hi[a] - lo[a] + 1).max(0) as usize);
        let total = n[0] * n[1] * n[2];
        let frame = lo.map(|b| b * 8);
        // Half diagonal of a block of 8 samples spaced h apart: from its centre to a corner sample.
        let reach = 3.5 * h * 3f64.sqrt() + band;
        let bandf = band as f32;
        let eps = (MIN_ABS_VALUE_VOXELS * h) as f32;

        // Pass 1: which blocks can hold the band (cheap: one clearance per block).
        let candidates: Vec<usize> = (0..total)
            .into_par_iter()
            .filter(|&idx| {
                let b = block_at(lo, n, idx);
                let p0 = spec.point(b.map(|c| c * 8));
                let centre = [0, 1, 2].map(|a| p0[a] + 3.5 * h);
                field.clearance(centre) <= reach
            })
            .collect();
        // Pass 2: sample them straight into one flat buffer, then drop blocks the band missed.
        let mut values = vec![0.0f32; candidates.len() * 512];
        let keep: Vec<bool> = values
            .par_chunks_mut(512)
            .zip(candidates.par_iter())
            .map(|(vals, &idx)| {
                let b = block_at(lo, n, idx);
                let vals: &mut [f32; 512] = vals.try_into().expect("512 values per block");
                field.sample_block(spec.point(b.map(|c| c * 8)), h, vals);
                if !vals.iter().any(|v| v.abs() < bandf) {
                    return false;
                }
                for v in vals.iter_mut() {
                    *v = v.clamp(-bandf, bandf);
                    if v.abs() < eps {
                        *v = if *v < 0.0 { -eps } else { eps };
                    }
                }
                true
            })
            .collect();
        let inside_tiles: Vec<i32> = {
            let mut sampled_set = vec![false; total];
            for (k, &idx) in candidates.iter().enumerate() {
                sampled_set[idx] = keep[k];
            }
            (0..total)
                .into_par_iter()
                .filter(|&idx| !sampled_set[idx])
                .map(|idx| block_at(lo, n, idx).map(|c| c * 8))
                .filter(|first| inside(*first))
                .flat_map_iter(|first| (0..3).map(move |a| (first[a] - frame[a]) as i32))
                .collect()
        };
        let mut origins = Vec::with_capacity(candidates.len() * 3);
        let mut w = 0;
        for (k, &idx) in candidates.iter().enumerate() {
            if !keep[k] {
                continue;
            }
            let b = block_at(lo, n, idx);
            origins.extend((0..3).map(|a| (b[a] * 8 - frame[a]) as i32));
            if w != k {
                values.copy_within(k * 512..(k + 1) * 512, w * 512);
            }
            w += 1;
        }
        values.truncate(w * 512);
        let sampled = w as u64;
        let grid_origin = spec.point(frame).map(|x| x - 0.5 * h);
        let inner = ffi::vdb_grid_from_leaves(
            h,
            &grid_origin,
            spec.half_width as f32,
            &origins,
            &values,
            &inside_tiles,
        )
        .backend("building the OpenVDB grid")?;
        Ok(Grid {
            inner: inner.into(),
            spec,
            frame,
            blocks_tested: total as u64,
            blocks_sampled: sampled,
        })
    }
}
