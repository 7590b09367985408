//! Vertex welding: corners at the same position become one vertex, so neighbouring facets share
//! edges by index and topology (edges, shells, holes) can be read off the indices.
//!
//! Exact welding (the default) merges bit-identical coordinates (with −0 = +0) through a hash map
//! keyed on the raw bits, with a small multiplicative hash: reading 1M facets is dominated by
//! these three million look-ups. Tolerance welding is greedy in vertex order: each vertex joins
//! the nearest earlier *representative* within the tolerance, or becomes one. Clusters therefore
//! have radius ≤ tolerance (no chaining across a long row of close points) and the result does not
//! depend on hash order.

use crate::error::{Error, Result};
use crate::geom::Mesh;
use std::collections::HashMap;
use std::hash::{BuildHasher, Hasher};

/// A fast, non-cryptographic hasher for fixed-size numeric keys.
#[derive(Default, Clone, Copy)]
pub struct FastHash;

/// The hasher [`FastHash`] builds.
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

/// A hash map with [`FastHash`].
pub type FastMap<K, V> = HashMap<K, V, FastHash>;

fn key(p: [f32; 3]) -> u128 {
    // +0.0 and -0.0 are the same point.
    let b = p.map(|v| if v == 0.0 { 0u32 } else { v.to_bits() });
    b[0] as u128 | (b[1] as u128) << 32 | (b[2] as u128) << 64
}

/// Exact vertex numbering: one id per distinct position (`+0.0` and `-0.0` are one), numbered
/// in the order positions first arrive.
#[derive(Default)]
pub struct ExactIndex(FastMap<u128, u32>);

impl ExactIndex {
    /// `capacity`: expected number of distinct positions (a hint only).
    pub fn with_capacity(capacity: usize) -> Self {
        ExactIndex(HashMap::with_capacity_and_hasher(capacity, FastHash))
    }

    /// Distinct positions so far.
    pub fn len(&self) -> usize {
        self.0.len()
    }

    /// Whether no position has been seen.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// The id of position `p`, and whether it is new.
    pub fn index(&mut self, p: [f32; 3]) -> (u32, bool) {
        let next = self.0.len() as u32;
        let id = *self.0.entry(key(p)).or_insert(next);
        (id, id == next)
    }
}

/// Builds a mesh corner by corner, merging bit-identical positions.
pub struct ExactWelder {
    index: ExactIndex,
    /// The mesh built so far.
    pub mesh: Mesh,
    /// Corners seen (each `corner` call).
    pub corners: u64,
}

impl ExactWelder {
    /// `capacity`: expected number of distinct vertices (a hint only; never trust file headers).
    pub fn new(capacity: usize) -> Self {
        ExactWelder {
            index: ExactIndex::with_capacity(capacity),
            mesh: Mesh::default(),
            corners: 0,
        }
    }

    /// The vertex id of position `p`, creating it if new. Non-finite coordinates are an error.
    pub fn vertex(&mut self, p: [f32; 3]) -> Result<u32> {
        if !p.iter().all(|v| v.is_finite()) {
            return Err(Error::parse(format!("non-finite vertex coordinate {p:?}")));
        }
        if self.index.len() >= u32::MAX as usize {
            return Err(Error::parse("more than 2^32 vertices"));
        }
        let (id, new) = self.index.index(p);
        if new {
            self.mesh.positions.extend_from_slice(&p);
        }
        Ok(id)
    }

    /// Adds one corner of the current facet.
    pub fn corner(&mut self, p: [f32; 3]) -> Result<()> {
        let id = self.vertex(p)?;
        self.mesh.indices.push(id);
        self.corners += 1;
        Ok(())
    }
}

/// Shards of the parallel weld: enough that each shard's map stays in a core's cache.
const SHARDS: usize = 64;
/// Corners per chunk in the weld's partitioning passes (whole facets).
const CHUNK: usize = 3 << 14;

/// One corner on its way to its shard: its position's bits and its index.
#[derive(Clone, Copy, Default)]
struct Entry {
    key_lo: u64,
    key_hi: u32,
    corner: u32,
}

/// A chunk of corners partitioned by shard.
struct Chunk {
    /// Shard of each corner of the chunk, in corner order.
    shard: Vec<u8>,
    /// The chunk's corners grouped by shard, in corner order within each group.
    entries: Vec<Entry>,
    /// Where each shard's group starts in `entries`, and the end.
    starts: [u32; SHARDS + 1],
}

/// Welds a triangle soup of `facets` facets, `facet(f)` giving the corners of each, in
/// parallel: corners are dealt to `SHARDS` shards by the hash of their position's bits
/// (partitioned chunk by chunk, so every pass reads and writes memory in order), each shard
/// welds its own with a hash map small enough to stay in cache, and the shards' vertices are
/// numbered one shard after another, each shard's in the order of their first corners
/// (deterministic, whatever the thread count). Non-finite coordinates are an error naming the
/// facet.
pub fn weld_facets_by(
    facets: usize,
    facet: impl Fn(usize) -> [[f32; 3]; 3] + Sync,
) -> Result<Mesh> {
    use rayon::prelude::*;
    let count = 3 * facets;
    if count >= u32::MAX as usize {
        return Err(Error::parse("more than 2^32 corners"));
    }
    let corner = |c: usize| facet(c / 3)[c % 3];
    let n_chunks = count.div_ceil(CHUNK);
    let chunk_range = |j: usize| j * CHUNK..((j + 1) * CHUNK).min(count);
    // 1. Partition each chunk by shard (u8::MAX marks a non-finite corner).
    let chunks: Vec<Chunk> = (0..n_chunks)
        .into_par_iter()
        .map(|j| {
            let range = chunk_range(j);
            let mut keys = Vec::with_capacity(range.len());
            let mut shard = Vec::with_capacity(range.len());
            let mut starts = [0u32; SHARDS + 1];
            for f in range.start / 3..range.end / 3 {
                for p in facet(f) {
                    let k = key(p);
                    let s = if p.iter().all(|v| v.is_finite()) {
                        ((FastHash.hash_one(k) >> 40) % SHARDS as u64) as u8
                    } else {
                        u8::MAX
                    };
                    keys.push(k);
                    shard.push(s);
                    if s != u8::MAX {
                        starts[s as usize + 1] += 1;
                    }
                }
            }
            for s in 0..SHARDS {
                starts[s + 1] += starts[s];
            }
            let mut next = starts;
            let mut entries = vec![Entry::default(); starts[SHARDS] as usize];
            for ((c, &k), &s) in range.zip(&keys).zip(&shard) {
                if s != u8::MAX {
                    entries[next[s as usize] as usize] = Entry {
                        key_lo: k as u64,
                        key_hi: (k >> 64) as u32,
                        corner: c as u32,
                    };
                    next[s as usize] += 1;
                }
            }
            Chunk {
                shard,
                entries,
                starts,
            }
        })
        .collect();
    if let Some(c) = chunks.par_iter().enumerate().find_map_first(|(j, ch)| {
        ch.shard
            .iter()
            .position(|&s| s == u8::MAX)
            .map(|i| j * CHUNK + i)
    }) {
        return Err(Error::parse(format!(
            "facet {}: non-finite vertex coordinate {:?}",
            c / 3 + 1,
            corner(c)
        )));
    }
    // 2. Each shard welds its corners, chunk after chunk: a vertex id (within the shard) per
    //    corner, and the first corner of each vertex.
    let parts: Vec<(Vec<u32>, Vec<u32>)> = (0..SHARDS)
        .into_par_iter()
        .map(|s| {
            let total: usize = chunks
                .iter()
                .map(|ch| (ch.starts[s + 1] - ch.starts[s]) as usize)
                .sum();
            // A closed triangle mesh has about six corners per vertex; the map grows if not.
            let mut map: FastMap<u128, u32> =
                HashMap::with_capacity_and_hasher(total / 4 + 16, FastHash);
            let mut ids = Vec::with_capacity(total);
            let mut firsts = Vec::new();
            for ch in &chunks {
                for e in &ch.entries[ch.starts[s] as usize..ch.starts[s + 1] as usize] {
                    let next = firsts.len() as u32;
                    let k = e.key_lo as u128 | (e.key_hi as u128) << 64;
                    let id = *map.entry(k).or_insert(next);
                    if id == next {
                        firsts.push(e.corner);
                    }
                    ids.push(id);
                }
            }
            (ids, firsts)
        })
        .collect();
    let mut offset = [0u32; SHARDS + 1];
    for s in 0..SHARDS {
        offset[s + 1] = offset[s] + parts[s].1.len() as u32;
    }
    // 3. Each corner's vertex, chunk by chunk: within a chunk, a shard's corners come in order,
    //    so a cursor per shard walks that shard's ids.
    let mut base = Vec::with_capacity(n_chunks);
    let mut running = [0u32; SHARDS];
    for ch in &chunks {
        base.push(running);
        for (s, r) in running.iter_mut().enumerate() {
            *r += ch.starts[s + 1] - ch.starts[s];
        }
    }
    let mut indices = vec![0u32; count];
    indices
        .par_chunks_mut(CHUNK)
        .zip(chunks.par_iter())
        .zip(base.par_iter())
        .for_each(|((out, ch), base)| {
            let mut cursor = *base;
            for (o, &s) in out.iter_mut().zip(&ch.shard) {
                let s = s as usize;
                *o = offset[s] + parts[s].0[cursor[s] as usize];
                cursor[s] += 1;
            }
        });
    drop(chunks);
    // 4. Positions, shard by shard.
    let mut positions = vec![0f32; 3 * offset[SHARDS] as usize];
    let mut slices = Vec::with_capacity(SHARDS);
    let mut rest = &mut positions[..];
    for (_, firsts) in &parts {
        let (head, tail) = rest.split_at_mut(3 * firsts.len());
        slices.push(head);
        rest = tail;
    }
    slices
        .into_par_iter()
        .zip(parts.par_iter())
        .for_each(|(out, (_, firsts))| {
            for (o, &c) in out.chunks_exact_mut(3).zip(firsts) {
                o.copy_from_slice(&corner(c as usize));
            }
        });
    Ok(Mesh { positions, indices })
}

/// Welds an indexed mesh whose vertex list may repeat positions (OBJ, OFF, PLY, 3MF): returns the
/// mesh over distinct positions. Unreferenced vertices are kept (at their first occurrence).
pub fn weld_indexed(positions: &[f32], indices: &[u32]) -> Result<Mesh> {
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
                .ok_or_else(|| Error::parse(format!("vertex index {i} past the {nv} vertices")))
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

    #[test]
    fn parallel_soup_weld_matches_a_sequential_one() {
        // A soup over several chunks: positions drawn from a small set (with −0 beside +0), so
        // most corners repeat one seen in another chunk and shard.
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let corners: Vec<[f32; 3]> = (0..3 * 70_000)
            .map(|_| {
                let r = next();
                let v = [
                    (r % 37) as f32,
                    ((r >> 8) % 41) as f32,
                    ((r >> 16) % 43) as f32,
                ];
                if r >> 40 & 1 == 1 && v[0] == 0.0 {
                    [-0.0, v[1], v[2]]
                } else {
                    v
                }
            })
            .collect();
        let weld = |c: &[[f32; 3]]| {
            weld_facets_by(c.len() / 3, |f| [c[3 * f], c[3 * f + 1], c[3 * f + 2]])
        };
        let mesh = weld(&corners).unwrap();
        // Every corner maps to its own position, and no two vertices share one.
        for (c, &i) in corners.iter().zip(&mesh.indices) {
            let p = &mesh.positions[3 * i as usize..3 * i as usize + 3];
            assert_eq!(key([p[0], p[1], p[2]]), key(*c));
        }
        let mut seq = ExactWelder::new(0);
        for &c in &corners {
            seq.corner(c).unwrap();
        }
        assert_eq!(mesh.vertex_count(), seq.mesh.vertex_count());
        // Again, the same numbering.
        assert_eq!(weld(&corners).unwrap().indices, mesh.indices);

        let mut bad = corners.clone();
        bad[3 * 60_000 + 2] = [1.0, f32::INFINITY, 0.0];
        let e = weld(&bad).unwrap_err().to_string();
        assert!(e.starts_with("facet 60001:"), "{e}");
    }
}
