//! Boundary loops of a 2D field at a level (marching squares on the pixel centres), ordered and
//! oriented: solid on the left, so outer boundaries run counter-clockwise and holes clockwise.
//! These loops are both the outline the STL is extruded from and the points the CAD curves fit.
//!
//! The field is padded with one ring of void, so every loop closes. Saddle cells are resolved
//! by the cell-centre average. Vertices never sit exactly on a sample, so loops never touch.

use super::raster::Raster;

pub use crate::slice::contour::{contains, polygons, signed_area, Loop};

/// Loops of `{f ≥ level}`, with the field's pixel `(i, j)` centred at `((i + ½)h, (j + ½)h)`.
pub fn loops(f: &Raster, level: f64) -> Vec<Loop> {
    let (nx, ny) = (f.n[0], f.n[1]);
    let (w, hgt) = (nx + 2, ny + 2);
    let val = |i: usize, j: usize| -> f64 {
        if i == 0 || j == 0 || i > nx || j > ny {
            0.0
        } else {
            f.data[(j - 1) * nx + (i - 1)]
        }
    };
    let inside = |i: usize, j: usize| val(i, j) >= level;
    // Edge ids: horizontal (i,j)-(i+1,j) and vertical (i,j)-(i,j+1).
    let hid = |i: usize, j: usize| j * (w - 1) + i;
    let voff = (w - 1) * hgt;
    let vid = |i: usize, j: usize| voff + j * w + i;
    let total = voff + w * (hgt - 1);
    let mut next = vec![u32::MAX; total];
    for j in 0..hgt - 1 {
        for i in 0..w - 1 {
            let c = [
                inside(i, j),
                inside(i + 1, j),
                inside(i + 1, j + 1),
                inside(i, j + 1),
            ];
            if c.iter().all(|&b| b) || c.iter().all(|&b| !b) {
                continue;
            }
            // Edges walked counter-clockwise: bottom, right, top, left.
            let e = [hid(i, j), vid(i + 1, j), hid(i, j + 1), vid(i, j)];
            let exits: Vec<usize> = (0..4).filter(|&k| c[k] && !c[(k + 1) % 4]).collect();
            let entries: Vec<usize> = (0..4).filter(|&k| !c[k] && c[(k + 1) % 4]).collect();
            if exits.len() == 1 {
                next[e[exits[0]]] = e[entries[0]] as u32;
            } else {
                // Saddle: two solid corners on a diagonal.
                let centre = 0.25 * (val(i, j) + val(i + 1, j) + val(i + 1, j + 1) + val(i, j + 1));
                for &x in &exits {
                    // Joined through the centre: pair each exit with the following entry;
                    // separate: with the preceding one.
                    let en = if centre >= level {
                        (x + 1) % 4
                    } else {
                        (x + 3) % 4
                    };
                    next[e[x]] = e[en] as u32;
                }
            }
        }
    }
    let point = |id: usize| -> [f64; 2] {
        let ((i0, j0), (i1, j1)) = if id < voff {
            let (j, i) = (id / (w - 1), id % (w - 1));
            ((i, j), (i + 1, j))
        } else {
            let k = id - voff;
            let (j, i) = (k / w, k % w);
            ((i, j), (i, j + 1))
        };
        let (a, b) = (val(i0, j0), val(i1, j1));
        let t = ((level - a) / (b - a)).clamp(1e-3, 1.0 - 1e-3);
        let p = |i: usize| (i as f64 - 0.5) * f.h;
        [p(i0) + t * (p(i1) - p(i0)), p(j0) + t * (p(j1) - p(j0))]
    };
    let mut out = Vec::new();
    for s in 0..total {
        if next[s] == u32::MAX {
            continue;
        }
        let mut l = Vec::new();
        let mut cur = s;
        while next[cur] != u32::MAX {
            l.push(point(cur));
            let n = next[cur] as usize;
            next[cur] = u32::MAX;
            cur = n;
        }
        if l.len() >= 3 {
            out.push(l);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ring_gives_an_outer_loop_and_a_hole() {
        let n = 40;
        let mut data = vec![0.0; n * n];
        for j in 0..n {
            for i in 0..n {
                let r = ((i as f64 - 19.5).powi(2) + (j as f64 - 19.5).powi(2)).sqrt();
                data[j * n + i] = if (8.0..15.0).contains(&r) { 1.0 } else { 0.0 };
            }
        }
        let f = Raster {
            n: [n, n, 1],
            h: 0.5,
            data,
        };
        let ls = loops(&f, 0.5);
        assert_eq!(ls.len(), 2);
        let polys = polygons(&ls);
        assert_eq!(polys.len(), 1);
        assert_eq!(polys[0].holes.len(), 1);
        let area: f64 = ls.iter().map(|l| signed_area(l)).sum();
        let exact = std::f64::consts::PI * (15.0f64.powi(2) - 8.0f64.powi(2)) * 0.25;
        assert!((area - exact).abs() / exact < 0.03, "{area} vs {exact}");
    }
}
