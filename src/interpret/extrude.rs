//! A 2D outline extruded into a closed prism mesh: side walls from every loop, top and bottom
//! caps by ear clipping (earcut) of each outer loop with its holes. The caps use only the loop
//! vertices, so every edge is shared by exactly two triangles.

use super::contour::{polygons, Loop};
use crate::error::{Error, Result};
use crate::geom::Mesh;

/// Extrudes `loops` (outer counter-clockwise, holes clockwise) from z = 0 to z = `thickness`.
pub fn extrude(loops: &[Loop], thickness: f64) -> Result<Mesh> {
    if !(thickness > 0.0 && thickness.is_finite()) {
        return Err(Error::invalid(
            "--thickness must be a positive length in mm",
        ));
    }
    // Ear clipping drops collinear vertices from the caps; drop them from the walls too, so
    // both use the same vertices (and the mesh stays closed). Near-duplicate and nearly
    // collinear vertices go as well: in single-precision STL they would make zero-area slivers.
    let scale = loops
        .iter()
        .flat_map(|l| l.windows(2))
        .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
        .fold(0.0f64, f64::max);
    // Coordinates are rounded to single precision first, so the caps are triangulated on
    // exactly the points the STL will hold.
    let loops: Vec<Loop> = loops
        .iter()
        .map(|l| {
            let l: Loop = l
                .iter()
                .map(|p| [p[0] as f32 as f64, p[1] as f32 as f64])
                .collect();
            simplified(&l, 0.05 * scale, 5e-3 * scale)
        })
        .collect();
    let loops = &loops[..];
    let total: usize = loops.iter().map(Vec::len).sum();
    let mut positions = Vec::with_capacity(total * 6);
    let mut starts = Vec::with_capacity(loops.len());
    for l in loops {
        starts.push(positions.len() / 3);
        for p in l {
            positions.extend_from_slice(&[p[0] as f32, p[1] as f32, 0.0]);
        }
    }
    let top = total as u32;
    for l in loops {
        for p in l {
            positions.extend_from_slice(&[p[0] as f32, p[1] as f32, thickness as f32]);
        }
    }
    let mut indices = Vec::with_capacity(total * 12);
    // Walls: for an edge a→b with the solid on its left, (a0, b0, b1) and (a0, b1, a1) face out.
    for (l, &s) in loops.iter().zip(&starts) {
        let n = l.len();
        for k in 0..n {
            let (a, b) = ((s + k) as u32, (s + (k + 1) % n) as u32);
            indices.extend_from_slice(&[a, b, b + top, a, b + top, a + top]);
        }
    }
    let mut ec = earcut::Earcut::new();
    let mut refiner = earcut::Refiner::new();
    let mut tris: Vec<u32> = Vec::new();
    for crate::geom::contour::Polygon { outer, holes } in polygons(loops) {
        let mut data: Vec<[f64; 2]> = loops[outer].clone();
        let mut map: Vec<u32> = (0..loops[outer].len())
            .map(|k| (starts[outer] + k) as u32)
            .collect();
        let mut hole_idx: Vec<u32> = Vec::new();
        for &h in &holes {
            hole_idx.push(data.len() as u32);
            data.extend_from_slice(&loops[h]);
            map.extend((0..loops[h].len()).map(|k| (starts[h] + k) as u32));
        }
        ec.earcut(data.iter().copied(), &hole_idx, &mut tris);
        // Lawson flips towards a Delaunay triangulation: fewer slivers, which single precision
        // and the self-intersection test both prefer.
        refiner.refine(&mut tris, &data);
        let dev = earcut::deviation(data.iter().copied(), &hole_idx, &tris);
        if dev.is_nan() || dev >= 1e-6 {
            return Err(Error::invalid(format!(
                "triangulating a cap failed (area deviation {dev:e})"
            )));
        }
        for t in tris.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| data[i as usize]);
            let ccw = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]) > 0.0;
            let [i, j, k] = [t[0], t[1], t[2]].map(|i| map[i as usize]);
            // Top faces +z (counter-clockwise seen from above), bottom faces −z.
            if ccw {
                indices.extend_from_slice(&[i + top, j + top, k + top, i, k, j]);
            } else {
                indices.extend_from_slice(&[i + top, k + top, j + top, i, j, k]);
            }
        }
    }
    Ok(Mesh { positions, indices })
}

/// `l` without vertices closer than `min_len` to the previous one or within `min_dev` of the
/// line through their neighbours. Moves the outline by at most `max(min_len, min_dev)`.
fn simplified(l: &Loop, min_len: f64, min_dev: f64) -> Loop {
    let mut pts = l.clone();
    loop {
        let n = pts.len();
        if n <= 3 {
            return pts;
        }
        let keep: Vec<bool> = (0..n)
            .map(|i| {
                let (a, p, b) = (pts[(i + n - 1) % n], pts[i], pts[(i + 1) % n]);
                let (u, v) = ([p[0] - a[0], p[1] - a[1]], [b[0] - a[0], b[1] - a[1]]);
                let chord = v[0].hypot(v[1]);
                let dev = if chord > 0.0 {
                    (u[0] * v[1] - u[1] * v[0]).abs() / chord
                } else {
                    u[0].hypot(u[1])
                };
                u[0].hypot(u[1]) >= min_len && dev > min_dev
            })
            .collect();
        if keep.iter().all(|&k| k) {
            return pts;
        }
        // Remove at most every other vertex per round, so each judgement stays valid.
        let mut out = Vec::with_capacity(n);
        let mut skipped_last = false;
        for i in 0..n {
            if !keep[i] && !skipped_last && (i + 1 != n || keep[0]) {
                skipped_last = true;
                continue;
            }
            skipped_last = false;
            out.push(pts[i]);
        }
        pts = out;
    }
}
