//! Vertex welding: corners at the same position become one vertex, so neighbouring facets share
//! edges by index and topology (edges, shells, holes) can be read off the indices.
//!
//! Exact welding (the default) merges bit-identical coordinates (with −0 = +0) through a hash map
//! keyed on the raw bits, with a small multiplicative hash: reading 1M facets is dominated by
//! these three million look-ups. Tolerance welding is greedy in vertex order: each vertex joins
//! the nearest earlier *representative* within the tolerance, or becomes one. Clusters therefore
//! have radius ≤ tolerance (no chaining across a long row of close points) and the result does not
//! depend on hash order.

use crate::mesh::Mesh;
use std::collections::HashMap;
use std::hash::{BuildHasher, Hasher};

/// A fast, non-cryptographic hasher for fixed-size numeric keys.
#[derive(Default, Clone, Copy)]
pub struct FastHash;

pub struct FastHasher(u64);

impl BuildHasher for FastHash {
    type Hasher = FastHasher;
    fn build_hasher(&self) -> FastHasher {
        FastHasher(0)
    }
}

impl Hasher for FastHasher {
    fn write(&mut self, bytes: &[u8]) {
        for b in bytes {
            self.write_u64(*b as u64);
        }
    }
    fn write_u64(&mut self, i: u64) {
        self.0 = (self.0.rotate_left(26) ^ i).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    }
    fn write_u32(&mut self, i: u32) {
        self.write_u64(i as u64);
    }
    fn write_usize(&mut self, i: usize) {
        self.write_u64(i as u64);
    }
    fn write_u128(&mut self, i: u128) {
        self.write_u64(i as u64);
        self.write_u64((i >> 64) as u64);
    }
    fn finish(&self) -> u64 {
        self.0 ^ (self.0 >> 29)
    }
}

pub type FastMap<K, V> = HashMap<K, V, FastHash>;

fn key(p: [f32; 3]) -> u128 {
    // +0.0 and -0.0 are the same point.
    let b = p.map(|v| if v == 0.0 { 0u32 } else { v.to_bits() });
    b[0] as u128 | (b[1] as u128) << 32 | (b[2] as u128) << 64
}

/// Builds a mesh corner by corner, merging bit-identical positions.
pub struct ExactWelder {
    map: FastMap<u128, u32>,
    pub mesh: Mesh,
    /// Corners seen (each `corner` call).
    pub corners: u64,
}

impl ExactWelder {
    /// `capacity`: expected number of distinct vertices (a hint only; never trust file headers).
    pub fn new(capacity: usize) -> Self {
        ExactWelder {
            map: HashMap::with_capacity_and_hasher(capacity, FastHash),
            mesh: Mesh::default(),
            corners: 0,
        }
    }

    /// The vertex id of position `p`, creating it if new. Non-finite coordinates are an error.
    pub fn vertex(&mut self, p: [f32; 3]) -> Result<u32, String> {
        if !p.iter().all(|v| v.is_finite()) {
            return Err(format!("non-finite vertex coordinate {p:?}"));
        }
        let next = self.map.len();
        if next >= u32::MAX as usize {
            return Err("more than 2^32 vertices".into());
        }
        let id = *self.map.entry(key(p)).or_insert(next as u32);
        if id as usize == next {
            self.mesh.positions.extend_from_slice(&p);
        }
        Ok(id)
    }

    /// Adds one corner of the current facet.
    pub fn corner(&mut self, p: [f32; 3]) -> Result<(), String> {
        let id = self.vertex(p)?;
        self.mesh.indices.push(id);
        self.corners += 1;
        Ok(())
    }
}

/// Welds a triangle soup given corner by corner (three per facet), in parallel: corners are
/// dealt to a fixed number of shards by hash, each shard welds its own with a hash map, and the
/// shards' vertices are numbered one shard after another (deterministic, whatever the thread
/// count). Non-finite coordinates are an error naming the facet.
pub fn weld_corners(corners: &[[f32; 3]]) -> Result<Mesh, String> {
    use rayon::prelude::*;
    const SHARDS: usize = 8;
    if let Some(i) = corners
        .par_iter()
        .position_first(|p| !p.iter().all(|v| v.is_finite()))
    {
        return Err(format!(
            "facet {}: non-finite vertex coordinate {:?}",
            i / 3 + 1,
            corners[i]
        ));
    }
    let shard: Vec<u8> = corners
        .par_iter()
        .map(|&p| ((FastHash.hash_one(key(p)) >> 40) % SHARDS as u64) as u8)
        .collect();
    let parts: Vec<(Vec<u32>, Vec<u32>)> = (0..SHARDS)
        .into_par_iter()
        .map(|s| {
            let mut map: FastMap<u128, u32> =
                HashMap::with_capacity_and_hasher(corners.len() / (2 * SHARDS) + 16, FastHash);
            let mut ids = Vec::with_capacity(corners.len() / SHARDS + 16);
            let mut firsts = Vec::new();
            for (c, &sh) in shard.iter().enumerate() {
                if sh as usize != s {
                    continue;
                }
                let next = firsts.len() as u32;
                let id = *map.entry(key(corners[c])).or_insert(next);
                if id == next {
                    firsts.push(c as u32);
                }
                ids.push(id);
            }
            (ids, firsts)
        })
        .collect();
    let mut offset = [0u32; SHARDS + 1];
    for s in 0..SHARDS {
        offset[s + 1] = offset[s] + parts[s].1.len() as u32;
    }
    let mut cursor = [0usize; SHARDS];
    let mut indices = Vec::with_capacity(corners.len());
    for &sh in &shard {
        let s = sh as usize;
        indices.push(offset[s] + parts[s].0[cursor[s]]);
        cursor[s] += 1;
    }
    let mut positions = Vec::with_capacity(3 * offset[SHARDS] as usize);
    for (_, firsts) in &parts {
        for &c in firsts {
            positions.extend_from_slice(&corners[c as usize]);
        }
    }
    Ok(Mesh { positions, indices })
}

/// Welds an indexed mesh whose vertex list may repeat positions (OBJ, OFF, PLY, 3MF): returns the
/// mesh over distinct positions. Unreferenced vertices are kept (at their first occurrence).
pub fn weld_indexed(positions: &[f32], indices: &[u32]) -> Result<Mesh, String> {
    let nv = positions.len() / 3;
    let mut w = ExactWelder::new(nv.min(1 << 24));
    let mut remap = Vec::with_capacity(nv);
    for p in positions.chunks_exact(3) {
        remap.push(w.vertex([p[0], p[1], p[2]])?);
    }
    let mut mesh = w.mesh;
    mesh.indices = indices
        .iter()
        .map(|&i| {
            remap
                .get(i as usize)
                .copied()
                .ok_or_else(|| format!("vertex index {i} past the {nv} vertices"))
        })
        .collect::<Result<_, _>>()?;
    Ok(mesh)
}

/// Greedy clustering of `points` (see the module notes): the representative (an index into
/// `points`) of each point. Points are taken in order; each joins the nearest earlier
/// representative within `tol`, or becomes one.
pub fn cluster(points: &[[f64; 3]], tol: f64) -> Vec<usize> {
    let cell = |p: [f64; 3]| p.map(|x| (x / tol).floor() as i64);
    let mut grid: FastMap<[i64; 3], Vec<usize>> = HashMap::with_hasher(FastHash);
    let mut rep = Vec::with_capacity(points.len());
    for (i, &p) in points.iter().enumerate() {
        let c = cell(p);
        let mut best: Option<(f64, usize)> = None;
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let Some(list) = grid.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) else {
                        continue;
                    };
                    for &r in list {
                        let q = points[r];
                        let d2 = (0..3).map(|a| (p[a] - q[a]).powi(2)).sum::<f64>();
                        if d2 <= tol * tol && best.is_none_or(|(b, _)| d2 < b) {
                            best = Some((d2, r));
                        }
                    }
                }
            }
        }
        rep.push(match best {
            Some((_, r)) => r,
            None => {
                grid.entry(c).or_default().push(i);
                i
            }
        });
    }
    rep
}

/// Merges vertices closer than `tol` mm (see the module notes); returns how many vertices were
/// merged away. Unreferenced positions are dropped from the result.
pub fn weld_tolerance(mesh: &mut Mesh, tol: f64) -> u64 {
    if tol.is_nan() || tol <= 0.0 {
        return 0;
    }
    let nv = mesh.vertex_count();
    let mut used = vec![false; nv];
    for &i in &mesh.indices {
        used[i as usize] = true;
    }
    let ids: Vec<u32> = (0..nv as u32).filter(|&v| used[v as usize]).collect();
    let pts: Vec<[f64; 3]> = ids.iter().map(|&v| mesh.vertex(v)).collect();
    let rep = cluster(&pts, tol);
    let mut new_id = vec![u32::MAX; nv];
    let mut positions = Vec::new();
    for (k, &v) in ids.iter().enumerate() {
        if rep[k] == k {
            new_id[v as usize] = (positions.len() / 3) as u32;
            positions.extend_from_slice(&mesh.positions[3 * v as usize..3 * v as usize + 3]);
        }
    }
    for (k, &v) in ids.iter().enumerate() {
        new_id[v as usize] = new_id[ids[rep[k]] as usize];
    }
    for i in mesh.indices.iter_mut() {
        *i = new_id[*i as usize];
    }
    let merged = (ids.len() - positions.len() / 3) as u64;
    mesh.positions = positions;
    merged
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tolerance_weld_does_not_chain() {
        // Points 0.6 apart on a line, tolerance 1: 0 takes 0.6; 1.2 is 1.2 from 0, so it starts a
        // new cluster that takes 1.8 (chaining would have merged all four).
        let mut m = Mesh {
            positions: vec![
                0., 0., 0., 0.6, 0., 0., 1.2, 0., 0., 1.8, 0., 0., 0., 5., 0.,
            ],
            indices: vec![0, 1, 4, 2, 3, 4],
        };
        let merged = weld_tolerance(&mut m, 1.0);
        assert_eq!(merged, 2);
        assert_eq!(m.vertex_count(), 3);
        assert_eq!(m.indices, vec![0, 0, 2, 1, 1, 2]);
    }

    #[test]
    fn exact_weld_merges_signed_zero() {
        let mut w = ExactWelder::new(4);
        let a = w.vertex([0.0, 1.0, 2.0]).unwrap();
        let b = w.vertex([-0.0, 1.0, 2.0]).unwrap();
        assert_eq!(a, b);
        assert!(w.vertex([f32::NAN, 0.0, 0.0]).is_err());
    }
}
