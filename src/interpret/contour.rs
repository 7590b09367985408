//! Boundary loops of a 2D field at a level (marching squares on the pixel centres), ordered and
//! oriented: solid on the left, so outer boundaries run counter-clockwise and holes clockwise.
//! These loops are both the outline the STL is extruded from and the points the CAD curves fit.
//!
//! The field is padded with one ring of void, so every loop closes. Saddle cells are resolved
//! by the cell-centre average. Vertices never sit exactly on a sample, so loops never touch.

use super::raster::Raster;

pub use crate::geom::contour::{contains, iso_loops, polygons, signed_area, Loop};

/// Loops of `{f ≥ level}`, with the field's pixel `(i, j)` centred at `((i + ½)h, (j + ½)h)`;
/// beyond the raster counts as 0 (void).
pub fn loops(f: &Raster, level: f64) -> Vec<Loop> {
    let nx = f.n[0];
    let mut out = iso_loops([f.n[0], f.n[1]], |i, j| f.data[j * nx + i], level, 0.0);
    for l in &mut out {
        for p in l.iter_mut() {
            *p = [(p[0] + 0.5) * f.h, (p[1] + 0.5) * f.h];
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
