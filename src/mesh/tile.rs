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
//! way, and CGAL's self-intersection test runs on the kept triangles with their neighbours.

use crate::check::verify::Verify;
use crate::error::Result;
use crate::grid::IndexBox;
use crate::io::sink::{Measures, MeshSink, Triangle};
use crate::mesh::extract::KeyedMesh;
use crate::progress::Progress;
use rayon::prelude::*;
use std::collections::HashMap;

/// Samples around a tile that are sampled and meshed with it but not kept.
pub const MARGIN: i64 = 8;

/// Tiles meshed at once (each also uses every core inside).
pub const CONCURRENT_TILES: usize = 2;

/// Memory used per voxel of a tile while it is meshed (grid, OpenVDB's meshing, the mesh):
/// measured on dense lattices, about 20 bytes; taken as 32.
pub const BYTES_PER_VOXEL: u64 = 32;

/// The tile edge (samples, a multiple of 8) that keeps [`CONCURRENT_TILES`] tiles with their
/// margins within `budget` bytes.
pub fn tile_edge_for_budget(budget: u64) -> i64 {
    let per_tile = budget as f64 / (CONCURRENT_TILES as u64 * BYTES_PER_VOXEL) as f64;
    let with_margin = per_tile.cbrt() as i64;
    ((with_margin - 2 * MARGIN) / 8 * 8).max(16)
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

/// What the tiled meshing wrote and found.
#[derive(Debug, Clone, Copy, Default)]
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
}

struct TileResult {
    triangles: Vec<Triangle>,
    vertices: u64,
    bad_edges: u64,
    self_intersecting: bool,
}

/// Meshes `region` tile by tile with `mesh_tile` (which meshes the samples of the box it is
/// given) and streams the triangles into `sink`, tiles in order.
pub fn mesh_tiled(
    region: IndexBox,
    edge: i64,
    mesh_tile: &(dyn Fn(IndexBox) -> Result<KeyedMesh> + Sync),
    verify: Verify,
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
    let counter = progress.counter(all.len() as u64, "tiles meshed, verified and written");
    for group in all.chunks(CONCURRENT_TILES) {
        let results: Vec<Result<TileResult>> = group
            .par_iter()
            .map(|own| {
                let mesh = mesh_tile(own.grown(MARGIN))?;
                tile_result(&mesh, own, verify)
            })
            .collect();
        for r in results {
            let r = r?;
            out.measures = out.measures.merged(&Measures::of(&r.triangles));
            out.vertices += r.vertices;
            out.bad_edges += r.bad_edges;
            out.self_intersecting |= r.self_intersecting;
            sink.triangles(&r.triangles)?;
            counter.inc();
        }
    }
    sink.finish()?;
    Ok(out)
}

fn tile_result(mesh: &KeyedMesh, own: &IndexBox, verify: Verify) -> Result<TileResult> {
    let inside = |e: [i32; 3], m: i64| own.grown(m).contains(e.map(|x| x as i64));
    let kept: Vec<usize> = (0..mesh.quads.len())
        .filter(|&q| inside(mesh.edges[q], 0))
        .collect();
    let vertices = mesh.keys.iter().filter(|k| inside(k.voxel, 0)).count() as u64;
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
    // with a kept one.
    let near: Vec<usize> = (0..mesh.quads.len())
        .filter(|&q| inside(mesh.edges[q], 2))
        .collect();
    let mut directed: HashMap<(u32, u32), u32> = HashMap::with_capacity(6 * near.len());
    let tris_of = |q: usize| {
        let (t, u) = mesh.quad_triangles(q);
        std::iter::once(t).chain(u)
    };
    for &q in &near {
        for t in tris_of(q) {
            for k in 0..3 {
                *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
            }
        }
    }
    let mut bad_edges = 0;
    for &q in &kept {
        for t in tris_of(q) {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let fwd = directed.get(&(a, b)).copied().unwrap_or(0);
                let back = directed.get(&(b, a)).copied().unwrap_or(0);
                if fwd != 1 || back != 1 {
                    bad_edges += 1;
                }
            }
        }
    }

    // Self-intersection: kept triangles (first) and every triangle close enough to touch one;
    // only pairs with a kept triangle count (the patch's own rim may be non-manifold).
    let self_intersecting = if verify.self_intersection() && !kept.is_empty() {
        let around = (0..mesh.quads.len())
            .filter(|&q| !inside(mesh.edges[q], 0) && inside(mesh.edges[q], 3));
        let mut index = HashMap::new();
        let mut patch = crate::mesh::Mesh::default();
        let mut kept_triangles = 0;
        for (n, q) in kept.iter().copied().chain(around).enumerate() {
            for t in tris_of(q) {
                if n < kept.len() {
                    kept_triangles += 1;
                }
                for v in t {
                    let next = index.len() as u32;
                    let id = *index.entry(v).or_insert(next);
                    if id == next {
                        patch.positions.extend_from_slice(&f32pos(v));
                    }
                    patch.indices.push(id);
                }
            }
        }
        let all: Vec<u32> = (0..patch.triangle_count() as u32).collect();
        let (_, pairs) = if verify == Verify::Cgal {
            crate::check::self_intersect::cgal_soup_self_intersections(
                &patch,
                &all,
                None,
                usize::MAX,
            )?
        } else {
            crate::check::self_intersect::soup_self_intersections(&patch, &all, usize::MAX)
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
        assert!(tile_edge_for_budget(2 << 30) >= 128);
        assert_eq!(tile_edge_for_budget(1), 16);
    }
}
