//! Triangulation of a simple polygon in space: the polygon is projected onto the plane that drops
//! the dominant axis of its Newell normal and cut into triangles by ear clipping, so a non-convex
//! outline (an L-shaped hole, a notched face) is filled exactly — never its convex hull.
//!
//! Used for n-gon faces in OBJ/OFF/PLY files and for filling planar holes in `repair`. The
//! triangles keep the polygon's winding. `None` when the outline is not a simple polygon in its
//! projection (self-crossing, or folded), so the caller can fall back to something else.

use super::Vec3;

/// Newell's normal of a closed polygon (length = twice its vector area).
pub fn newell_normal(pts: &[Vec3]) -> Vec3 {
    let mut n = [0.0; 3];
    for i in 0..pts.len() {
        let (p, q) = (pts[i], pts[(i + 1) % pts.len()]);
        n[0] += (p[1] - q[1]) * (p[2] + q[2]);
        n[1] += (p[2] - q[2]) * (p[0] + q[0]);
        n[2] += (p[0] - q[0]) * (p[1] + q[1]);
    }
    n
}

fn cross2(o: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
}

/// Whether segments `ab` and `cd` properly cross (interiors intersect at one point).
fn segments_cross(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]) -> bool {
    let d1 = cross2(a, b, c);
    let d2 = cross2(a, b, d);
    let d3 = cross2(c, d, a);
    let d4 = cross2(c, d, b);
    ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
}

/// Triangulates the polygon `pts` (in order; first vertex not repeated). Returns index triples
/// into `pts`, wound like the polygon, or `None` if the polygon is degenerate or not simple.
pub fn triangulate_polygon(pts: &[Vec3]) -> Option<Vec<[usize; 3]>> {
    let n = pts.len();
    if n < 3 {
        return None;
    }
    if n == 3 {
        return Some(vec![[0, 1, 2]]);
    }
    let nrm = newell_normal(pts);
    let axis = (0..3).max_by(|&a, &b| nrm[a].abs().total_cmp(&nrm[b].abs()))?;
    if nrm[axis] == 0.0 || !nrm[axis].is_finite() {
        return None;
    }
    let (u, v) = match axis {
        0 => (1, 2),
        1 => (2, 0),
        _ => (0, 1),
    };
    // In (u, v) the polygon is counter-clockwise exactly when nrm[axis] > 0.
    let flip = nrm[axis] < 0.0;
    let p2: Vec<[f64; 2]> = pts
        .iter()
        .map(|p| if flip { [p[v], p[u]] } else { [p[u], p[v]] })
        .collect();
    // Simplicity: no two non-adjacent edges cross (O(n²); holes and faces are small).
    if n <= 4096 {
        for i in 0..n {
            for j in i + 2..n {
                if i == 0 && j == n - 1 {
                    continue;
                }
                if segments_cross(p2[i], p2[(i + 1) % n], p2[j], p2[(j + 1) % n]) {
                    return None;
                }
            }
        }
    }
    let mut idx: Vec<usize> = (0..n).collect();
    let mut out = Vec::with_capacity(n - 2);
    let mut guard = 0usize;
    while idx.len() > 3 {
        let m = idx.len();
        let mut clipped = false;
        for k in 0..m {
            let (a, b, c) = (idx[(k + m - 1) % m], idx[k], idx[(k + 1) % m]);
            if cross2(p2[a], p2[b], p2[c]) <= 0.0 {
                continue; // reflex or flat
            }
            let inside = idx.iter().any(|&q| {
                q != a
                    && q != b
                    && q != c
                    && p2[q] != p2[a]
                    && p2[q] != p2[b]
                    && p2[q] != p2[c]
                    && cross2(p2[a], p2[b], p2[q]) >= 0.0
                    && cross2(p2[b], p2[c], p2[q]) >= 0.0
                    && cross2(p2[c], p2[a], p2[q]) >= 0.0
            });
            if inside {
                continue;
            }
            out.push([a, b, c]);
            idx.remove(k);
            clipped = true;
            break;
        }
        if !clipped {
            // Only flat vertices left on a degenerate stretch: drop one collinear vertex if the
            // rest still bounds area; otherwise give up.
            let flat = (0..m).find(|&k| {
                let (a, b, c) = (idx[(k + m - 1) % m], idx[k], idx[(k + 1) % m]);
                cross2(p2[a], p2[b], p2[c]) == 0.0
            })?;
            let (a, b, c) = (idx[(flat + m - 1) % m], idx[flat], idx[(flat + 1) % m]);
            out.push([a, b, c]);
            idx.remove(flat);
        }
        guard += 1;
        if guard > 4 * n {
            return None;
        }
    }
    if cross2(p2[idx[0]], p2[idx[1]], p2[idx[2]]) <= 0.0 && out.is_empty() {
        return None;
    }
    out.push([idx[0], idx[1], idx[2]]);
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area2(pts: &[Vec3], t: [usize; 3]) -> f64 {
        let (a, b, c) = (pts[t[0]], pts[t[1]], pts[t[2]]);
        (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    }

    #[test]
    fn l_shape_is_not_its_hull() {
        // Area 3, convex hull area 3.5.
        let pts = [
            [0., 0., 0.],
            [2., 0., 0.],
            [2., 1., 0.],
            [1., 1., 0.],
            [1., 2., 0.],
            [0., 2., 0.],
        ];
        let tris = triangulate_polygon(&pts).unwrap();
        assert_eq!(tris.len(), 4);
        let total: f64 = tris.iter().map(|&t| area2(&pts, t) / 2.0).sum();
        assert!((total - 3.0).abs() < 1e-12);
        assert!(tris.iter().all(|&t| area2(&pts, t) > 0.0));
    }

    #[test]
    fn clockwise_polygon_keeps_its_winding_and_bowtie_is_refused() {
        let pts = [[0., 0., 1.], [0., 1., 1.], [1., 1., 1.], [1., 0., 1.]];
        let tris = triangulate_polygon(&pts).unwrap();
        assert!(tris.iter().all(|&t| area2(&pts, t) < 0.0));
        let bow = [[0., 0., 0.], [1., 1., 0.], [1., 0., 0.], [0., 1., 0.]];
        assert!(triangulate_polygon(&bow).is_none());
    }
}
