//! Tiles: a part meshed one block of its grid at a time and streamed out, so that memory depends
//! on the tile, not on the part.
//!
//! The grid's samples are cut into cubic tiles of whole 8³ blocks. Each tile is sampled with a
//! margin of [`MARGIN`] samples on every side, meshed by OpenVDB, and snapped, exactly as the whole
//! part would be ([`crate::mesh::extract`] names every vertex by its voxel and edge group and computes
//! its position from that name alone; snapping moves a vertex by its own data, and its fold
//! repair looks no further than [`crate::mesh::snap::UNFOLD_PASSES`] rings, well inside the margin). A
//! tile keeps the quads whose edge starts in it, so every quad is written by exactly one tile,
//! with the same corners, bit for bit, as in the untiled mesh: seams are welded exactly and the
//! tiled part is the same solid, triangle for triangle.
//!
//! Each tile is checked as it is written, on the mesh around it (which the margin holds
//! complete): every edge of a kept triangle must meet exactly one other triangle, running the other
//! way, and the self-intersection search runs on the kept triangles with their neighbours.
//!
//! The part's pieces are found across the tiles ([`TiledPieces`]): each tile's kept triangles
//! form shells (joined through shared vertices), and the shells of neighbouring tiles are joined
//! through the vertices on their seams — a vertex is named by its key in every tile, so the
//! same vertex met in two tiles is one. The pieces are found while the part is measured, and the
//! fragments dropped when it is meshed again, on the same tiles, to be written (a fragment is a
//! whole closed shell: what stays is as closed as before).

use crate::error::Result;
use crate::field::Aabb;
use crate::geom::topology::UnionFind;
use crate::grid::IndexBox;
use crate::io::sink::{Measures, MeshSink, Triangle};
use crate::mesh::extract::{KeyedMesh, VertexKey};
use crate::mesh::pieces::{self, Fragments, Shells};
use crate::progress::Progress;
use crate::verify::Verify;
use rayon::prelude::*;
use std::collections::HashMap;

/// Samples around a tile that are sampled and meshed with it but not kept.
pub const MARGIN: i64 = 8;

/// Tiles meshed at once (each also uses every core inside).
pub const CONCURRENT_TILES: usize = 2;

/// Memory a tile takes while it is meshed, checked and written: per voxel of the tile and its
/// margin (the sampled grid, OpenVDB's masks) and per triangle (the keyed mesh, the triangles
/// written, the edge and self-intersection checks). Measured (heap profile and peak resident
/// memory of gyroid parts at 12 to 48 voxels per cell, one tile of 240 voxels beside a thin
/// one) at about 8 bytes a voxel and 175 a triangle; taken with a margin.
pub const BYTES_PER_VOXEL: f64 = 10.0;
/// See [`BYTES_PER_VOXEL`].
pub const BYTES_PER_TRIANGLE: f64 = 190.0;
/// Memory the process holds beside the part's meshing (code, libraries, thread stacks).
pub const RESERVED_BYTES: u64 = 64 << 20;

/// The most triangles a voxel can hold: each of its three edges crossed, two triangles each.
pub const MAX_TRIANGLE_DENSITY: f64 = 6.0;

/// Memory to mesh, check and write `voxels` voxels holding `density` triangles a voxel.
pub fn meshing_bytes(voxels: u64, density: f64) -> u64 {
    (voxels as f64 * (BYTES_PER_VOXEL + BYTES_PER_TRIANGLE * density)) as u64
}

/// The tile edge (samples, a multiple of 8) that keeps [`CONCURRENT_TILES`] tiles with their
/// margins, at `density` triangles a voxel, within `budget` bytes.
pub fn tile_edge_for_budget(budget: u64, density: f64) -> i64 {
    let per_tile = budget.saturating_sub(RESERVED_BYTES) as f64
        / CONCURRENT_TILES as f64
        / (BYTES_PER_VOXEL + BYTES_PER_TRIANGLE * density);
    let with_margin = per_tile.cbrt() as i64;
    ((with_margin - 2 * MARGIN) / 8 * 8).max(16)
}

/// Triangles a voxel where the part's surface is densest, estimated before meshing: the solid's
/// field is sampled on 27 probes of 24³ samples spread over `region` (3 × 3 × 3, each at the
/// middle of its part), and the edges between samples of opposite sign — each crossed by one
/// quad of the mesh, two triangles — counted; the densest probe's count a voxel is returned.
pub fn triangle_density(field: &dyn crate::field::Field, spec: &crate::grid::GridSpec) -> f64 {
    const N: i64 = 24;
    let region = spec.padded_region();
    let probes: Vec<[i64; 3]> = (0..27)
        .map(|i| {
            let c = [i % 3, i / 3 % 3, i / 9];
            [0, 1, 2].map(|a| {
                let (lo, hi) = (region.lo[a], region.hi[a]);
                let mid = lo + (hi - lo) * (2 * c[a] + 1) / 6;
                (mid - N / 2).clamp(lo, (hi - N).max(lo))
            })
        })
        .collect();
    probes
        .par_iter()
        .map(|lo| {
            let inside: Vec<bool> = (0..N * N * N)
                .map(|i| {
                    let idx = [lo[0] + i % N, lo[1] + i / N % N, lo[2] + i / (N * N)];
                    field.value(spec.point(idx)) < 0.0
                })
                .collect();
            let at = |x: i64, y: i64, z: i64| inside[(x + N * (y + N * z)) as usize];
            let mut crossings = 0u64;
            for z in 0..N {
                for y in 0..N {
                    for x in 0..N {
                        let v = at(x, y, z);
                        crossings += (x + 1 < N && v != at(x + 1, y, z)) as u64
                            + (y + 1 < N && v != at(x, y + 1, z)) as u64
                            + (z + 1 < N && v != at(x, y, z + 1)) as u64;
                    }
                }
            }
            2.0 * crossings as f64 / ((N - 1) * (N - 1) * (N - 1)) as f64
        })
        .reduce(|| 0.0, f64::max)
}

/// Cuts `region` (whole blocks) into tiles of `edge` samples (a multiple of 8), in x-major order.
pub fn tiles(region: IndexBox, edge: i64) -> Vec<IndexBox> {
    let n = [0, 1, 2].map(|a| (region.hi[a] - region.lo[a] + edge - 1) / edge);
    let mut out = Vec::new();
    for i in 0..n[0] {
        for j in 0..n[1] {
            for k in 0..n[2] {
                let lo = [0, 1, 2].map(|a| region.lo[a] + [i, j, k][a] * edge);
                let hi = [0, 1, 2].map(|a| (lo[a] + edge).min(region.hi[a]));
                out.push(IndexBox { lo, hi });
            }
        }
    }
    out
}

/// What a tiled meshing does with the part's pieces.
#[derive(Clone, Copy)]
pub enum Pieces<'a> {
    /// Nothing: every triangle is written.
    Keep,
    /// Finds them (returned in [`TiledOutcome::pieces`]).
    Find,
    /// Drops the fragments that an earlier meshing of the same part, on the same tiles, found.
    Drop(&'a TiledPieces),
}

/// The pieces of a part meshed in tiles: the tiles' shells joined across their seams, and which
/// of them belong to the part (the largest piece, see [`crate::mesh::pieces`]).
#[derive(Debug, Default)]
pub struct TiledPieces {
    /// Each tile's first shell (shells are numbered tile after tile).
    first: Vec<u32>,
    /// Per shell: its signed volume, mm³, and bounds, until the pieces are found.
    volume: Vec<f64>,
    bounds: Vec<Aabb>,
    /// The shells joined so far.
    joined: UnionFind,
    /// Vertices on a seam: key → a shell it is on.
    seams: HashMap<VertexKey, u32>,
    /// Per shell: whether it belongs to the part (set by [`TiledPieces::finish`]).
    kept: Vec<bool>,
    /// The fragments (set by [`TiledPieces::finish`]).
    pub fragments: Fragments,
    /// Each fragment's volume, mm³, and bounds (set by [`TiledPieces::finish`]).
    pub loose: Vec<(f64, Aabb)>,
}

/// Whether a vertex in voxel `v` may be on triangles of another tile than `own`: a quad is
/// kept by the tile holding the start of its edge, and the quads around a vertex have their
/// edges start in `[v, v + 1]³`.
fn on_seam(v: [i32; 3], own: &IndexBox) -> bool {
    (0..3).any(|a| (v[a] as i64) < own.lo[a] || v[a] as i64 + 1 >= own.hi[a])
}

impl TiledPieces {
    /// Adds the next tile's shells and the keys of its vertices on a seam.
    fn add(&mut self, shells: &Shells, seams: &[(VertexKey, u32)]) {
        let first = self.volume.len() as u32;
        self.first.push(first);
        self.volume.extend_from_slice(&shells.volume);
        self.bounds.extend_from_slice(&shells.bounds);
        self.joined
            .0
            .extend(first..first + shells.volume.len() as u32);
        for &(key, s) in seams {
            let node = first + s;
            match self.seams.entry(key) {
                std::collections::hash_map::Entry::Occupied(e) => self.joined.union(*e.get(), node),
                std::collections::hash_map::Entry::Vacant(e) => {
                    e.insert(node);
                }
            }
        }
    }

    /// Joins the shells into pieces and marks the part's.
    fn finish(&mut self) {
        let n = self.volume.len();
        let mut id = vec![u32::MAX; n];
        let mut piece_volume = Vec::new();
        let mut piece_bounds: Vec<Aabb> = Vec::new();
        let of: Vec<u32> = (0..n as u32)
            .map(|s| {
                let r = self.joined.find(s) as usize;
                if id[r] == u32::MAX {
                    id[r] = piece_volume.len() as u32;
                    piece_volume.push(0.0);
                    piece_bounds.push(Aabb {
                        min: [f64::INFINITY; 3],
                        max: [f64::NEG_INFINITY; 3],
                    });
                }
                id[r]
            })
            .collect();
        for (s, &p) in of.iter().enumerate() {
            let p = p as usize;
            piece_volume[p] += self.volume[s];
            let (b, o) = (&mut piece_bounds[p], &self.bounds[s]);
            for a in 0..3 {
                b.min[a] = b.min[a].min(o.min[a]);
                b.max[a] = b.max[a].max(o.max[a]);
            }
        }
        let kept = pieces::kept_shells(&piece_volume, &piece_bounds);
        self.fragments = pieces::fragments_of(&piece_volume, &kept, false);
        self.loose = (0..kept.len())
            .filter(|&p| !kept[p])
            .map(|p| (piece_volume[p], piece_bounds[p]))
            .collect();
        self.kept = of.iter().map(|&p| kept[p as usize]).collect();
        self.volume = Vec::new();
        self.bounds = Vec::new();
    }

    /// Whether shell `s` of tile `tile` belongs to the part.
    fn kept(&self, tile: usize, s: u32) -> bool {
        self.kept[(self.first[tile] + s) as usize]
    }

    /// Whether the vertex with `key`, on a seam, belongs to the part.
    fn seam_kept(&self, key: &VertexKey) -> Option<bool> {
        self.seams.get(key).map(|&s| self.kept[s as usize])
    }
}

/// What the tiled meshing wrote and found.
#[derive(Debug, Default)]
pub struct TiledOutcome {
    /// Measures of the triangles written.
    pub measures: Measures,
    /// Vertices of the part: each counted in the tile holding its voxel.
    pub vertices: u64,
    /// Tiles meshed.
    pub tiles: u64,
    /// Kept triangles' edges that did not meet exactly one other triangle running the other way
    /// (an edge between two tiles is looked at from both).
    pub bad_edges: u64,
    /// Whether CGAL looked for self-intersections.
    pub self_intersection_checked: bool,
    /// Whether CGAL found a kept triangle intersecting another.
    pub self_intersecting: bool,
    /// The part's pieces, when asked to find them ([`Pieces::Find`]).
    pub pieces: Option<TiledPieces>,
}

struct TileResult {
    triangles: Vec<Triangle>,
    vertices: u64,
    bad_edges: u64,
    self_intersecting: bool,
    /// With [`Pieces::Find`]: the tile's shells and its seam vertices' keys with their shells.
    shells: Option<(Shells, Vec<(VertexKey, u32)>)>,
}

/// Meshes `region` tile by tile with `mesh_tile` (which meshes the samples of the box it is
/// given) and streams the triangles into `sink`, tiles in order.
pub fn mesh_tiled(
    region: IndexBox,
    edge: i64,
    mesh_tile: &(dyn Fn(IndexBox) -> Result<KeyedMesh> + Sync),
    verify: Verify,
    pieces: Pieces,
    progress: &Progress,
    sink: &mut dyn MeshSink,
) -> Result<TiledOutcome> {
    let all = tiles(region, edge);
    sink.begin(None)?;
    let mut out = TiledOutcome {
        tiles: all.len() as u64,
        self_intersection_checked: verify.self_intersection(),
        ..Default::default()
    };
    let mut found = TiledPieces::default();
    let counter = progress.counter(all.len() as u64, "tiles meshed, verified and written");
    for (g, group) in all.chunks(CONCURRENT_TILES).enumerate() {
        let results: Vec<Result<TileResult>> = group
            .par_iter()
            .enumerate()
            .map(|(i, own)| {
                let mesh = mesh_tile(own.grown(MARGIN))?;
                tile_result(&mesh, own, verify, pieces, g * CONCURRENT_TILES + i)
            })
            .collect();
        for r in results {
            let r = r?;
            if let Some((shells, seams)) = &r.shells {
                found.add(shells, seams);
            }
            out.measures = out.measures.merged(&Measures::of(&r.triangles));
            out.vertices += r.vertices;
            out.bad_edges += r.bad_edges;
            out.self_intersecting |= r.self_intersecting;
            sink.triangles(&r.triangles)?;
            counter.inc();
        }
        release_freed_memory();
    }
    sink.finish()?;
    if matches!(pieces, Pieces::Find) {
        found.finish();
        out.pieces = Some(found);
    }
    Ok(out)
}

/// Hands the memory freed by the tiles just meshed back to the system. glibc's allocator keeps
/// freed blocks under its mmap threshold (which rises to 32 MB as large blocks are freed) in its
/// per-thread arenas; over a tiled part that kept a gigabyte more than the tiles held at once.
fn release_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        extern "C" {
            fn malloc_trim(pad: usize) -> i32;
        }
        // SAFETY: malloc_trim only returns free pages of glibc's own arenas to the system.
        unsafe {
            malloc_trim(0);
        }
    }
}

fn tile_result(
    mesh: &KeyedMesh,
    own: &IndexBox,
    verify: Verify,
    pieces: Pieces,
    tile: usize,
) -> Result<TileResult> {
    let inside = |e: [i32; 3], m: i64| own.grown(m).contains(e.map(|x| x as i64));
    let ours = |q: usize| inside(mesh.edges[q], 0);
    let mut shells = None;
    let every_kept = || (0..mesh.quads.len()).filter(|&q| ours(q)).collect();
    let every_vertex = || mesh.keys.iter().filter(|k| inside(k.voxel, 0)).count() as u64;
    let (kept, vertices): (Vec<usize>, u64) = match pieces {
        Pieces::Keep => (every_kept(), every_vertex()),
        Pieces::Find => {
            let found = Shells::of_quads(mesh, ours);
            let seams: Vec<(VertexKey, u32)> = (0..mesh.keys.len())
                .filter(|&v| found.of_vertex[v] != u32::MAX && on_seam(mesh.keys[v].voxel, own))
                .map(|v| (mesh.keys[v], found.of_vertex[v]))
                .collect();
            shells = Some((found, seams));
            (every_kept(), every_vertex())
        }
        Pieces::Drop(p) => {
            let found = Shells::of_quads(mesh, ours);
            let of = &found.of_vertex;
            let kept = (0..mesh.quads.len())
                .filter(|&q| ours(q) && p.kept(tile, of[mesh.quads[q][0] as usize]))
                .collect();
            // A vertex of this tile on none of its triangles is on a seam, on another tile's.
            let vertices = (0..mesh.keys.len())
                .filter(|&v| inside(mesh.keys[v].voxel, 0))
                .filter(|&v| match of[v] {
                    u32::MAX => p.seam_kept(&mesh.keys[v]).unwrap_or(true),
                    s => p.kept(tile, s),
                })
                .count() as u64;
            (kept, vertices)
        }
    };
    let f32pos = |v: u32| mesh.positions[v as usize].map(|x| x as f32);
    let mut triangles = Vec::with_capacity(2 * kept.len());
    for &q in &kept {
        let (t, u) = mesh.quad_triangles(q);
        triangles.push(t.map(f32pos));
        if let Some(u) = u {
            triangles.push(u.map(f32pos));
        }
    }

    // Edges: the quads within two samples of the tile hold every triangle that shares an edge
    // with a kept one. Their directed edges are listed by first vertex (counted, then placed:
    // 4 bytes an edge, where a map would take several times that).
    let tris_of = |q: usize| {
        let (t, u) = mesh.quad_triangles(q);
        std::iter::once(t).chain(u)
    };
    let near = || (0..mesh.quads.len()).filter(|&q| inside(mesh.edges[q], 2));
    let n = mesh.positions.len();
    let mut start = vec![0u32; n + 1];
    for q in near() {
        for t in tris_of(q) {
            t.iter().for_each(|&v| start[v as usize + 1] += 1);
        }
    }
    for v in 0..n {
        start[v + 1] += start[v];
    }
    let mut to = vec![0u32; start[n] as usize];
    let mut next = start.clone();
    for q in near() {
        for t in tris_of(q) {
            for k in 0..3 {
                let a = t[k] as usize;
                to[next[a] as usize] = t[(k + 1) % 3];
                next[a] += 1;
            }
        }
    }
    drop(next);
    let count = |a: u32, b: u32| {
        to[start[a as usize] as usize..start[a as usize + 1] as usize]
            .iter()
            .filter(|&&x| x == b)
            .count()
    };
    let mut bad_edges = 0;
    for &q in &kept {
        for t in tris_of(q) {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                if count(a, b) != 1 || count(b, a) != 1 {
                    bad_edges += 1;
                }
            }
        }
    }
    drop((start, to));

    // Self-intersection: kept triangles (first) and every triangle close enough to touch one;
    // only pairs with a kept triangle count (the patch's own rim may be non-manifold).
    let self_intersecting = if verify.self_intersection() && !kept.is_empty() {
        let around = (0..mesh.quads.len())
            .filter(|&q| !inside(mesh.edges[q], 0) && inside(mesh.edges[q], 3));
        let mut index = vec![u32::MAX; n];
        let mut patch = crate::geom::Mesh::default();
        let mut kept_triangles = 0;
        for (i, q) in kept.iter().copied().chain(around).enumerate() {
            for t in tris_of(q) {
                if i < kept.len() {
                    kept_triangles += 1;
                }
                for v in t {
                    let id = &mut index[v as usize];
                    if *id == u32::MAX {
                        *id = (patch.positions.len() / 3) as u32;
                        patch.positions.extend_from_slice(&f32pos(v));
                    }
                    patch.indices.push(*id);
                }
            }
        }
        drop(index);
        let all: Vec<u32> = (0..patch.triangle_count() as u32).collect();
        let (_, pairs) = if verify == Verify::Cgal {
            crate::verify::self_intersect::cgal_soup_self_intersections(
                &patch,
                &all,
                None,
                usize::MAX,
            )?
        } else {
            crate::verify::self_intersect::soup_self_intersections(&patch, &all, usize::MAX)
        };
        pairs.iter().any(|&(f, g)| f.min(g) < kept_triangles)
    } else {
        false
    };
    Ok(TileResult {
        triangles,
        vertices,
        bad_edges,
        self_intersecting,
        shells,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_partition_the_region() {
        let region = IndexBox {
            lo: [-8, -8, 0],
            hi: [40, 24, 16],
        };
        let t = tiles(region, 16);
        assert_eq!(t.len(), 6);
        let total: u64 = t.iter().map(|b| b.voxels()).sum();
        assert_eq!(total, region.voxels());
        assert_eq!(t.last().unwrap().hi, [40, 24, 16]);
        assert!(tile_edge_for_budget(2 << 30, 0.2) >= 128);
        assert!(tile_edge_for_budget(2 << 30, 1.0) < tile_edge_for_budget(2 << 30, 0.2));
        assert_eq!(tile_edge_for_budget(1, 0.2), 16);
    }
}
