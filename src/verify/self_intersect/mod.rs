//! Self-intersections of any facet subset: which pairs of facets meet in more than the vertices
//! and edge they share. latvox's own search ([`soup_self_intersections`]: a hierarchical grid
//! broad phase, [`grid`], and CGAL's exact triangle tests ported onto Shewchuk's adaptive
//! predicates, [`exact`]) answers the check, the repair and the verification of every mesh latvox
//! writes; CGAL's box-intersection search on spatial tiles ([`cgal_soup_self_intersections`]) is
//! kept as the independent oracle the tests compare it with.

pub mod exact;
pub mod fans;
mod grid;

pub use grid::Stars;

use crate::error::Result;
use crate::ffi::cgal::ffi;
use crate::ffi::Backend;
use crate::geom::Mesh;
use crate::progress::Progress;
use rayon::prelude::*;

/// Counts intersecting pairs among the facets `keep` of `mesh`; returns the total and up to
/// `limit` pairs as facet indices of `mesh`, in ascending order of their positions in `keep`, the
/// earlier facet first. Two facets intersect when their closed triangles meet anywhere but in
/// the vertices and the edge they share (CGAL's definition in `self_intersections`, with sharing
/// read off the vertex indices); a facet whose corners are collinear counts once, as a pair with
/// itself; facets with the same three vertices are duplicates, not intersections.
pub fn soup_self_intersections(mesh: &Mesh, keep: &[u32], limit: usize) -> (u64, Vec<(u32, u32)>) {
    soup_self_intersections_shown(mesh, keep, limit, Stars::Own, &Progress::hidden())
}

/// [`soup_self_intersections`] with a bar counting the blocks of the grid searched, and the star
/// vertices from `stars`.
pub fn soup_self_intersections_shown(
    mesh: &Mesh,
    keep: &[u32],
    limit: usize,
    stars: Stars<'_>,
    progress: &Progress,
) -> (u64, Vec<(u32, u32)>) {
    let tris: Vec<[u32; 3]> = keep
        .par_iter()
        .map(|&f| {
            let t = &mesh.indices[3 * f as usize..3 * f as usize + 3];
            [t[0], t[1], t[2]]
        })
        .collect();
    let pairs = grid::intersecting_pairs(&mesh.positions, &tris, stars, progress);
    let total = pairs.len() as u64;
    let pairs = pairs
        .into_iter()
        .take(limit)
        .map(|(a, b)| (keep[a as usize], keep[b as usize]))
        .collect();
    (total, pairs)
}

/// CGAL's count of intersecting pairs among the facets `keep` of `mesh` (which must have three
/// distinct vertices each), and up to `limit` of them, as [`soup_self_intersections`] returns
/// them. `flip` (per facet of `mesh`), when given, reverses facets so neighbours agree: the
/// answer does not depend on winding, but CGAL can then build its mesh directly instead of
/// orienting a soup (which pulls facets apart at non-manifold vertices: facets touching only
/// there are not counted).
///
/// The search runs on spatial tiles searched in parallel (see [`box_tiles`]), more of them the
/// more threads there are; the answer is the same as one search of the whole soup.
pub fn cgal_soup_self_intersections(
    mesh: &Mesh,
    keep: &[u32],
    flip: Option<&[bool]>,
    limit: usize,
) -> Result<(u64, Vec<(u32, u32)>)> {
    soup_self_intersections_in_tiles(mesh, keep, flip, limit, tile_depth(keep.len()))
}

/// [`cgal_soup_self_intersections`] with a k-d split `depth` levels deep (`2^depth` tiles at
/// most; 0 searches the whole soup at once).
pub fn soup_self_intersections_in_tiles(
    mesh: &Mesh,
    keep: &[u32],
    flip: Option<&[bool]>,
    limit: usize,
    depth: u32,
) -> Result<(u64, Vec<(u32, u32)>)> {
    let indices: Vec<u32> = keep
        .iter()
        .flat_map(|&f| {
            let t = &mesh.indices[3 * f as usize..3 * f as usize + 3];
            if flip.is_some_and(|fl| fl[f as usize]) {
                [t[0], t[2], t[1]]
            } else {
                [t[0], t[1], t[2]]
            }
        })
        .collect();
    let (tile_faces, tile_starts) = box_tiles(&mesh.positions, &indices, depth);
    let r = ffi::cgal_soup_self_intersections(
        &mesh.positions,
        &indices,
        &tile_faces,
        &tile_starts,
        limit,
    )
    .backend("CGAL self-intersection search")?;
    let pairs = r
        .pairs
        .chunks_exact(2)
        .map(|p| (keep[p[0] as usize], keep[p[1] as usize]))
        .collect();
    Ok((r.total, pairs))
}

/// Below this many facets the search runs as one tile (splitting costs more than it saves).
const MIN_TILED_FACETS: usize = 20_000;

/// Depth of the k-d split for `facets` facets: at least two tiles per thread, so that a thread
/// whose tile is quicker picks up another.
fn tile_depth(facets: usize) -> u32 {
    if facets < MIN_TILED_FACETS {
        return 0;
    }
    (2 * rayon::current_num_threads())
        .next_power_of_two()
        .trailing_zeros()
}

/// Splits the facets of a soup (`indices`, triples into `positions`) into spatial tiles for a
/// tiled self-intersection search: a k-d split on the centres of the facets' bounding boxes,
/// each cut at the median along the longest side, into `2^depth` leaves. A facet goes to every
/// leaf its (closed) bounding box touches, so two facets whose boxes meet share at least the leaf
/// that holds the lowest corner of their boxes' intersection: every pair CGAL's box test would
/// see on the whole soup is seen in some tile. Returns the facets of each tile, flattened, and
/// where each tile starts (one extra entry closes the last). Coordinates must be finite.
pub fn box_tiles(positions: &[f32], indices: &[u32], depth: u32) -> (Vec<u32>, Vec<u32>) {
    let boxes: Vec<[[f32; 3]; 2]> = indices
        .par_chunks_exact(3)
        .map(|t| {
            let p = |k: usize| {
                let i = 3 * t[k] as usize;
                [positions[i], positions[i + 1], positions[i + 2]]
            };
            let (a, b, c) = (p(0), p(1), p(2));
            [
                [0, 1, 2].map(|i| a[i].min(b[i]).min(c[i])),
                [0, 1, 2].map(|i| a[i].max(b[i]).max(c[i])),
            ]
        })
        .collect();
    let all: Vec<u32> = (0..boxes.len() as u32).collect();
    let leaves = split(&boxes, all, depth);
    let mut starts = Vec::with_capacity(leaves.len() + 1);
    let mut flat = Vec::with_capacity(leaves.iter().map(Vec::len).sum());
    for l in leaves {
        starts.push(flat.len() as u32);
        flat.extend(l);
    }
    starts.push(flat.len() as u32);
    (flat, starts)
}

fn split(boxes: &[[[f32; 3]; 2]], faces: Vec<u32>, depth: u32) -> Vec<Vec<u32>> {
    if depth == 0 || faces.len() < 2 {
        return vec![faces];
    }
    // Centres in f64 (exact for the sum of two f32s).
    let centre = |f: u32, a: usize| {
        let b = &boxes[f as usize];
        (b[0][a] as f64 + b[1][a] as f64) * 0.5
    };
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for &f in &faces {
        for a in 0..3 {
            lo[a] = lo[a].min(centre(f, a));
            hi[a] = hi[a].max(centre(f, a));
        }
    }
    let axis = (0..3)
        .max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b])))
        .unwrap_or(0);
    let mut c: Vec<f64> = faces.iter().map(|&f| centre(f, axis)).collect();
    let mid = c.len() / 2;
    let (_, &mut cut, _) = c.select_nth_unstable_by(mid, |x, y| x.total_cmp(y));
    let (left, right): (Vec<u32>, Vec<u32>) = (
        faces
            .iter()
            .copied()
            .filter(|&f| boxes[f as usize][0][axis] as f64 <= cut)
            .collect(),
        faces
            .iter()
            .copied()
            .filter(|&f| boxes[f as usize][1][axis] as f64 >= cut)
            .collect(),
    );
    // Facets much larger than the tiles would be searched again in every tile: stop splitting.
    if 2 * (left.len() + right.len()) > 3 * faces.len() {
        return vec![faces];
    }
    drop(faces);
    let (mut l, r) = rayon::join(
        || split(boxes, left, depth - 1),
        || split(boxes, right, depth - 1),
    );
    l.extend(r);
    l
}
