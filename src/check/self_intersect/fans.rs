//! Vertices whose facets provably hold no intersecting pair among those sharing only that vertex
//! — most vertices of a smooth mesh — so the exact tests skip those pairs (on a mesh latvox
//! makes, three quarters of the pairs whose boxes overlap).
//!
//! A vertex v qualifies when its facets (v, b, c) close into one fan that an axis projection
//! maps one-to-one: every facet keeps a strictly positive orientation in the projection (exact,
//! Shewchuk's `orient2d` on the f32 coordinates), each neighbour b starts exactly one link edge
//! b → c and ends exactly one, and the link edges wind once around v. The winding number is the
//! count of link edges b → c with `b.y ≤ v.y < c.y` in the projection: each facet spans a sector
//! of less than half a turn, and such a sector holds the direction +x (half-open) exactly when
//! its first edge is in the closed lower half-plane and its second in the open upper one —
//! comparisons of coordinates only. Winding once, the sectors tile the plane around v without
//! overlap, so two facets that share no edge meet in the projection only at v, and in space only
//! at v: CGAL's test for a pair sharing one vertex (does either opposite edge meet the other
//! facet?) answers no for every such pair.

use rayon::prelude::*;
use robust::{orient2d, Coord};

/// Per vertex of `positions`, whether it qualifies (see the module's text) among the facets
/// `tris`.
pub fn star_vertices(positions: &[f32], tris: &[[u32; 3]]) -> Vec<bool> {
    let nv = positions.len() / 3;
    let mut start = vec![0u32; nv + 1];
    for t in tris {
        for &v in t {
            start[v as usize + 1] += 1;
        }
    }
    for v in 0..nv {
        start[v + 1] += start[v];
    }
    let mut fill = start.clone();
    let mut link = vec![[0u32; 2]; start[nv] as usize];
    for t in tris {
        for k in 0..3 {
            let s = &mut fill[t[k] as usize];
            link[*s as usize] = [t[(k + 1) % 3], t[(k + 2) % 3]];
            *s += 1;
        }
    }
    drop(fill);
    (0..nv)
        .into_par_iter()
        .with_min_len(4096)
        .map(|v| {
            star(
                positions,
                v as u32,
                &link[start[v] as usize..start[v + 1] as usize],
            )
        })
        .collect()
}

fn star(positions: &[f32], v: u32, link: &[[u32; 2]]) -> bool {
    if link.len() < 3 {
        return false;
    }
    // One link edge starting and one ending at each neighbour.
    for e in link {
        if link.iter().filter(|f| f[0] == e[0]).count() != 1
            || link.iter().filter(|f| f[1] == e[0]).count() != 1
        {
            return false;
        }
    }
    let p = |i: u32| {
        let k = 3 * i as usize;
        [positions[k], positions[k + 1], positions[k + 2]]
    };
    let o = p(v);
    // The projection along the axis the fan's normal leans on most (any choice is sound; this
    // one makes the orientations positive on smooth fans), oriented to make them positive.
    let mut n = [0.0f64; 3];
    for e in link {
        let (b, c) = (p(e[0]), p(e[1]));
        let u = [0, 1, 2].map(|i| b[i] as f64 - o[i] as f64);
        let w = [0, 1, 2].map(|i| c[i] as f64 - o[i] as f64);
        n[0] += u[1] * w[2] - u[2] * w[1];
        n[1] += u[2] * w[0] - u[0] * w[2];
        n[2] += u[0] * w[1] - u[1] * w[0];
    }
    let a = (0..3)
        .max_by(|&i, &j| n[i].abs().total_cmp(&n[j].abs()))
        .unwrap_or(2);
    let (mut x, mut y) = ((a + 1) % 3, (a + 2) % 3);
    if n[a] < 0.0 {
        std::mem::swap(&mut x, &mut y);
    }
    let c2 = |q: [f32; 3]| Coord {
        x: q[x] as f64,
        y: q[y] as f64,
    };
    let mut winding = 0;
    for e in link {
        let (b, c) = (p(e[0]), p(e[1]));
        if orient2d(c2(o), c2(b), c2(c)) <= 0.0 {
            return false;
        }
        winding += (b[y] <= o[y] && o[y] < c[y]) as u32;
    }
    winding == 1
}
