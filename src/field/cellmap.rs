//! Conformal cell maps: cells wrapped around an axis, so that a periodic lattice follows a
//! tube's wall instead of a box's faces.
//!
//! A map takes a point `p` to cell coordinates `u` (one cell per unit) with its Jacobian, for a
//! lattice field `F(u(p))`. The cylindrical map, about the axis through `centre` along z,
//!
//! ```text
//! u₀ = θ·N/2π,   u₁ = (r − R)/a_r,   u₂ = (z − z₀)/a_z
//! ```
//!
//! puts `N` whole cells around (the seam at θ = ±π joins cell `N − 1` to cell 0: `F` has period
//! 1, so no cell is cut), cells of `a_r` through the wall from the bore `R` out, and of `a_z`
//! along the axis. The map is smooth and one-to-one on the wall, so the solid keeps the
//! topology of a box of cells joined around: what holds together in a box holds together here.

use super::{Aabb, Field, Vec3};
use crate::error::{Error, Result};
use std::f64::consts::TAU;

/// Cells wrapped around an axis.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Cylindrical {
    /// The axis (parallel to z) passes through this point; its z is the tube's lower end, mm.
    pub centre: Vec3,
    /// Inner radius, mm.
    pub bore: f64,
    /// Cells around, through the wall, along the axis.
    pub cells: [u32; 3],
    /// Cell size through the wall and along the axis, mm.
    pub cell: [f64; 2],
}

impl Cylindrical {
    /// A tube of `cells` (around, through the wall, along) with cells `cell` mm through the wall
    /// and along the axis, its bore `bore` mm, its axis through `centre` (the lower end's centre).
    pub fn new(centre: Vec3, bore: f64, cells: [u32; 3], cell: [f64; 2]) -> Result<Cylindrical> {
        if !(bore > 0.0 && bore.is_finite()) {
            return Err(Error::invalid(format!(
                "--bore must be a positive radius in mm, got {bore}"
            )));
        }
        if cells.contains(&0) {
            return Err(Error::invalid("cell counts must be at least 1"));
        }
        if cells[0] < 3 {
            return Err(Error::invalid(format!(
                "a tube needs at least 3 cells around, got {}",
                cells[0]
            )));
        }
        if !cell.iter().all(|c| *c > 0.0 && c.is_finite()) || !centre.iter().all(|c| c.is_finite())
        {
            return Err(Error::invalid(
                "cell sizes must be positive and the origin finite",
            ));
        }
        Ok(Cylindrical {
            centre,
            bore,
            cells,
            cell,
        })
    }

    /// Outer radius, mm.
    pub fn outer(&self) -> f64 {
        self.bore + self.cells[1] as f64 * self.cell[0]
    }

    /// Length along the axis, mm.
    pub fn length(&self) -> f64 {
        self.cells[2] as f64 * self.cell[1]
    }

    /// The tube's volume, mm³.
    pub fn volume(&self) -> f64 {
        std::f64::consts::PI * (self.outer().powi(2) - self.bore.powi(2)) * self.length()
    }

    /// The box around the tube.
    pub fn bounds(&self) -> Aabb {
        let (c, r) = (self.centre, self.outer());
        Aabb {
            min: [c[0] - r, c[1] - r, c[2]],
            max: [c[0] + r, c[1] + r, c[2] + self.length()],
        }
    }

    /// A cell's edge around at radius `r`, mm.
    pub fn arc(&self, r: f64) -> f64 {
        TAU * r / self.cells[0] as f64
    }

    /// A cell's size along its three directions at the middle of the wall, mm (around, through,
    /// along).
    pub fn mid_cell(&self) -> Vec3 {
        let mid = 0.5 * (self.bore + self.outer());
        [self.arc(mid), self.cell[0], self.cell[1]]
    }

    /// The shortest cell edge anywhere: the smaller of the arc at the bore and the two sizes.
    pub fn shortest_edge(&self) -> f64 {
        self.arc(self.bore).min(self.cell[0]).min(self.cell[1])
    }

    /// Cell coordinates of `p`, and the gradient of each (the rows of the Jacobian), per mm.
    #[inline(always)]
    pub fn coords(&self, p: Vec3) -> (Vec3, [Vec3; 3]) {
        let (x, y) = (p[0] - self.centre[0], p[1] - self.centre[1]);
        let r2 = (x * x + y * y).max(1e-300);
        let r = r2.sqrt();
        let n = self.cells[0] as f64 / TAU;
        let u = [
            y.atan2(x) * n,
            (r - self.bore) / self.cell[0],
            (p[2] - self.centre[2]) / self.cell[1],
        ];
        let jac = [
            [-y / r2 * n, x / r2 * n, 0.0],
            [x / r / self.cell[0], y / r / self.cell[0], 0.0],
            [0.0, 0.0, 1.0 / self.cell[1]],
        ];
        (u, jac)
    }

    /// Distance from `p` to the axis, mm.
    pub fn radius(&self, p: Vec3) -> f64 {
        (p[0] - self.centre[0]).hypot(p[1] - self.centre[1])
    }

    /// A bound on `|∇(F∘u)|` (per mm) at radii of at least `r`, from bounds `l` on
    /// `|∂F/∂u_a|`: the arc's scale grows as the radius falls.
    pub fn lipschitz(&self, l: Vec3, r: f64) -> f64 {
        let n = self.cells[0] as f64 / TAU;
        ((l[0] * n / r).powi(2) + (l[1] / self.cell[0]).powi(2) + (l[2] / self.cell[1]).powi(2))
            .sqrt()
    }

    /// The volume of a closed outward mesh's solid within radius `radius` of the axis, mm³, by the
    /// divergence theorem with the field `V = ½(x, y, 0)·min(1, R²/r²)` (divergence 1 within
    /// the radius, 0 beyond it, continuous across it), integrated over each triangle by its edge
    /// midpoints (exact where V is linear; the triangles the cylinder crosses, and those
    /// larger than a quarter of the radius, are split in four first).
    pub fn volume_within(&self, triangles: impl Iterator<Item = [Vec3; 3]>, radius: f64) -> f64 {
        let c = self.centre;
        let v = |p: Vec3| {
            let (x, y) = (p[0] - c[0], p[1] - c[1]);
            let s = 0.5 * (radius * radius / (x * x + y * y).max(1e-300)).min(1.0);
            [s * x, s * y]
        };
        fn flux(
            t: [Vec3; 3],
            v: &dyn Fn(Vec3) -> [f64; 2],
            depth: u32,
            radius: f64,
            c: Vec3,
        ) -> f64 {
            let [a, b, d] = t;
            let r = |p: Vec3| (p[0] - c[0]).hypot(p[1] - c[1]);
            let rs = [r(a), r(b), r(d)];
            let crosses = rs.iter().any(|&x| x < radius) && rs.iter().any(|&x| x > radius);
            let edge = |p: Vec3, q: Vec3| (p[0] - q[0]).hypot(p[1] - q[1]);
            // Beyond the radius V bends: large triangles there are split too.
            let large = edge(a, b).max(edge(b, d)).max(edge(d, a)) > 0.25 * radius;
            let mid = |p: Vec3, q: Vec3| [0, 1, 2].map(|i| 0.5 * (p[i] + q[i]));
            let (ab, bd, da) = (mid(a, b), mid(b, d), mid(d, a));
            if (crosses || large) && depth > 0 {
                return [[a, ab, da], [ab, b, bd], [da, bd, d], [ab, bd, da]]
                    .into_iter()
                    .map(|t| flux(t, v, depth - 1, radius, c))
                    .sum();
            }
            // ½ (b − a) × (d − a): the area vector; only its x and y matter.
            let (e, f) = (
                [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
                [d[0] - a[0], d[1] - a[1], d[2] - a[2]],
            );
            let n = [
                0.5 * (e[1] * f[2] - e[2] * f[1]),
                0.5 * (e[2] * f[0] - e[0] * f[2]),
            ];
            let mean = [ab, bd, da].iter().fold([0.0; 2], |m, p| {
                let w = v(*p);
                [m[0] + w[0] / 3.0, m[1] + w[1] / 3.0]
            });
            mean[0] * n[0] + mean[1] * n[1]
        }
        triangles.map(|t| flux(t, &v, 6, radius, c)).sum()
    }
}

/// The tube (a hollow cylinder) as an exact signed distance field: the distance to a rectangle
/// in the half-plane through the axis.
impl Field for Cylindrical {
    fn value(&self, p: Vec3) -> f64 {
        let r = self.radius(p);
        let dr = (self.bore - r).max(r - self.outer());
        let dz = (self.centre[2] - p[2]).max(p[2] - self.centre[2] - self.length());
        if dr > 0.0 || dz > 0.0 {
            (dr.max(0.0).powi(2) + dz.max(0.0).powi(2)).sqrt()
        } else {
            dr.max(dz)
        }
    }

    fn clearance(&self, p: Vec3) -> f64 {
        self.value(p).abs()
    }

    fn implicit_with_gradient(&self, p: Vec3) -> (f64, Vec3) {
        let (x, y) = (p[0] - self.centre[0], p[1] - self.centre[1]);
        let r = x.hypot(y).max(1e-300);
        let (di, dout) = (self.bore - r, r - self.outer());
        let (dlo, dhi) = (self.centre[2] - p[2], p[2] - self.centre[2] - self.length());
        let radial = if di > dout {
            (di, [-x / r, -y / r, 0.0])
        } else {
            (dout, [x / r, y / r, 0.0])
        };
        let axial = if dlo > dhi {
            (dlo, [0.0, 0.0, -1.0])
        } else {
            (dhi, [0.0, 0.0, 1.0])
        };
        if radial.0 > axial.0 {
            radial
        } else {
            axial
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tube() -> Cylindrical {
        Cylindrical::new([1.0, -2.0, 3.0], 6.0, [12, 2, 3], [2.0, 4.0]).unwrap()
    }

    #[test]
    fn coordinates_wrap_whole_cells_and_the_jacobian_matches_differences() {
        let t = tube();
        let p = [1.0 + 7.0 * 0.3f64.cos(), -2.0 + 7.0 * 0.3f64.sin(), 5.0];
        let (u, j) = t.coords(p);
        assert!((u[0] - 0.3 * 12.0 / TAU).abs() < 1e-12);
        assert!((u[1] - 0.5).abs() < 1e-12 && (u[2] - 0.5).abs() < 1e-12);
        for (a, row) in j.iter().enumerate() {
            let g = crate::field::numeric_gradient(|q| t.coords(q).0[a], p);
            for (gi, ji) in g.iter().zip(row) {
                assert!((gi - ji).abs() < 1e-6, "{a}: {g:?} {row:?}");
            }
        }
        // Across the seam u₀ jumps by the number of cells around: a whole number of periods.
        let above = t.coords([1.0 - 7.0, -2.0 + 1e-9, 5.0]).0[0];
        let below = t.coords([1.0 - 7.0, -2.0 - 1e-9, 5.0]).0[0];
        assert!((above - below - 12.0).abs() < 1e-6);
    }

    #[test]
    fn the_tube_distance_and_the_volume_within_a_radius_are_exact() {
        let t = tube();
        assert!((t.value([1.0 + 8.0, -2.0, 4.0]) + 1.0).abs() < 1e-12);
        assert!((t.value([1.0 + 11.0, -2.0, 4.0]) - 1.0).abs() < 1e-12);
        assert!((t.value([1.0 + 11.0, -2.0, 19.0]) - 1.0f64.hypot(4.0)).abs() < 1e-12);
        // A box from the axis out: its volume within radius 2 is a disc's (π·2²·h) when the
        // box's half width is over 2.
        let mesh = crate::mesh::Mesh::cuboid([-3.0, -4.0, 0.0], [4.0, 3.0, 2.0]);
        let tris = (0..mesh.triangle_count()).map(|i| mesh.triangle(i));
        let t0 = Cylindrical::new([0.0, 0.0, 0.0], 1.0, [3, 1, 1], [1.0, 1.0]).unwrap();
        let v = t0.volume_within(tris, 2.0);
        let exact = std::f64::consts::PI * 4.0 * 2.0;
        assert!((v - exact).abs() < 1e-3 * exact, "{v} vs {exact}");
    }
}
