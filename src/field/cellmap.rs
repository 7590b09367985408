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
//!
//! The spherical map ([`Spherical`]) wraps cells around a centre as a cubed sphere: six faces of
//! `N × N` cells at the bore, every cell whole, no poles.
//!
//! The graded map ([`GradedCells`]) keeps a box but lets the cell size grow linearly along one
//! axis, `s(x) = a + (b − a)·x/L`: `u = ∫dx/s = L/(b − a)·ln(s(x)/a)`, its ends scaled so that a
//! whole number of cells spans the box (cells are not torn: each is the image of a unit cell).

use super::{Aabb, Field, Vec3};
use crate::error::{Error, Result};
use std::f64::consts::TAU;

/// 4/π: an equiangular face's angle (±π/4) to its cell coordinate (±1).
const FRAC_4_PI: f64 = 4.0 / std::f64::consts::PI;

/// The cell maps a part can be made on.
#[derive(Debug, Clone)]
pub enum Mapping {
    /// Cells wrapped around an axis.
    Cylindrical(Cylindrical),
    /// Cells growing along an axis of a box.
    Graded(GradedCells),
    /// Cells wrapped around a centre.
    Spherical(Spherical),
    /// Cells of a box sized by a field.
    Sized(super::sizing::SizedCells),
}

/// A map from space to cell coordinates, and the region its cells fill.
pub trait CellMap: Clone + Send + Sync + std::fmt::Debug {
    /// Cell coordinates of `p` and the gradient of each (the Jacobian's rows), per mm.
    fn coords(&self, p: Vec3) -> (Vec3, [Vec3; 3]);
    /// A bound on `|∇(F∘u)|` per mm from bounds `l` on `|∂F/∂u_a|`, valid within
    /// [`CellMap::room`] of a point.
    fn lipschitz(&self, l: Vec3) -> f64;
    /// The radius around `p` within which [`CellMap::lipschitz`] holds.
    fn room(&self, p: Vec3) -> f64;
    /// The region the cells fill when it is not the box (a tube): its signed distance and that
    /// distance's gradient at `p`.
    fn cut(&self, p: Vec3) -> Option<(f64, Vec3)>;
    /// The box around the region.
    fn bounds(&self) -> Aabb;
    /// The region's volume, mm³ (the density's base).
    fn volume(&self) -> f64;
    /// The shortest cell edge anywhere, mm.
    fn shortest_edge(&self) -> f64;
    /// A typical cell's size (for a first level), mm.
    fn mid_cell(&self) -> Vec3;
    /// Cells per direction (whole along the mapped ones).
    fn counts(&self) -> [f64; 3];
}

impl CellMap for Cylindrical {
    fn coords(&self, p: Vec3) -> (Vec3, [Vec3; 3]) {
        Cylindrical::coords(self, p)
    }
    fn lipschitz(&self, l: Vec3) -> f64 {
        Cylindrical::lipschitz(self, l, 0.5 * self.bore)
    }
    /// The bound holds beyond half the bore.
    fn room(&self, p: Vec3) -> f64 {
        self.radius(p) - 0.5 * self.bore
    }
    fn cut(&self, p: Vec3) -> Option<(f64, Vec3)> {
        Some((self.value(p), self.implicit_with_gradient(p).1))
    }
    fn bounds(&self) -> Aabb {
        Cylindrical::bounds(self)
    }
    fn volume(&self) -> f64 {
        Cylindrical::volume(self)
    }
    fn shortest_edge(&self) -> f64 {
        Cylindrical::shortest_edge(self)
    }
    fn mid_cell(&self) -> Vec3 {
        Cylindrical::mid_cell(self)
    }
    fn counts(&self) -> [f64; 3] {
        self.cells.map(f64::from)
    }
}

/// A box whose cells grow linearly along one axis (and keep their size along the others).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct GradedCells {
    /// The box; cells start at its lower corner.
    #[serde(rename = "box")]
    pub bounds: Aabb,
    /// The graded axis: 0, 1 or 2.
    pub axis: usize,
    /// The cell size along the graded axis at its two ends (scaled from those asked for so
    /// that whole cells span the box), mm.
    pub ends: [f64; 2],
    /// Whole cells along the graded axis.
    pub count: u32,
    /// Cell size along each axis (the graded axis' entry unused), mm.
    pub cell: Vec3,
}

impl GradedCells {
    /// Cells of `cell` in `bounds`, their size along `axis` growing from `a` to `b` (scaled so
    /// that whole cells span the box: the count is the nearest to what `a` → `b` would hold).
    pub fn new(bounds: Aabb, axis: usize, a: f64, b: f64, cell: Vec3) -> Result<GradedCells> {
        if !(a > 0.0 && b > 0.0 && a.is_finite() && b.is_finite()) {
            return Err(Error::invalid(format!(
                "cell sizes of a grade must be positive lengths in mm, got {a} and {b}"
            )));
        }
        let l = bounds.size()[axis];
        // Cells that sizes a → b hold over the length: ∫dx/s.
        let held = |a: f64, b: f64| {
            if (b - a).abs() <= 1e-12 * a {
                l / a
            } else {
                l * (b / a).ln() / (b - a)
            }
        };
        let count = held(a, b).round().max(1.0);
        if count > 1e6 {
            return Err(Error::invalid(
                "the cell-size grade makes over a million cells",
            ));
        }
        let k = held(a, b) / count;
        Ok(GradedCells {
            bounds,
            axis,
            ends: [a * k, b * k],
            count: count as u32,
            cell,
        })
    }

    /// The cell size along the graded axis at `x` along it from the box's face (held at the
    /// ends' sizes beyond them), mm.
    fn size_at(&self, x: f64) -> f64 {
        let l = self.bounds.size()[self.axis];
        let [a, b] = self.ends;
        a + (b - a) * (x / l).clamp(0.0, 1.0)
    }

    /// Cell coordinate along the graded axis at `x` from the box's face: `∫dx/s`, extended
    /// beyond the box at the ends' sizes.
    fn along(&self, x: f64) -> f64 {
        let l = self.bounds.size()[self.axis];
        let [a, b] = self.ends;
        let inside = |x: f64| {
            if (b - a).abs() <= 1e-12 * a {
                x / a
            } else {
                l / (b - a) * (self.size_at(x) / a).ln()
            }
        };
        if x < 0.0 {
            x / a
        } else if x > l {
            inside(l) + (x - l) / b
        } else {
            inside(x)
        }
    }

    /// The cells' faces along the graded axis, from the box's lower face to its upper one, mm.
    pub fn faces(&self) -> Vec<f64> {
        let l = self.bounds.size()[self.axis];
        let [a, b] = self.ends;
        let lo = self.bounds.min[self.axis];
        (0..=self.count)
            .map(|i| {
                let u = i as f64;
                if i == self.count {
                    lo + l
                } else if (b - a).abs() <= 1e-12 * a {
                    lo + u * a
                } else {
                    lo + (a * (u * (b - a) / l).exp() - a) * l / (b - a)
                }
            })
            .collect()
    }
}

impl CellMap for GradedCells {
    fn coords(&self, p: Vec3) -> (Vec3, [Vec3; 3]) {
        let mut u = [0.0; 3];
        let mut j = [[0.0; 3]; 3];
        for a in 0..3 {
            let x = p[a] - self.bounds.min[a];
            if a == self.axis {
                u[a] = self.along(x);
                j[a][a] = 1.0 / self.size_at(x);
            } else {
                u[a] = x / self.cell[a];
                j[a][a] = 1.0 / self.cell[a];
            }
        }
        (u, j)
    }
    fn lipschitz(&self, l: Vec3) -> f64 {
        let s = self.shortest_edge_along();
        (0..3)
            .map(|a| {
                let c = if a == self.axis { s } else { self.cell[a] };
                (l[a] / c).powi(2)
            })
            .sum::<f64>()
            .sqrt()
    }
    fn room(&self, _p: Vec3) -> f64 {
        f64::INFINITY
    }
    fn cut(&self, _p: Vec3) -> Option<(f64, Vec3)> {
        None
    }
    fn bounds(&self) -> Aabb {
        self.bounds
    }
    fn volume(&self) -> f64 {
        self.bounds.volume()
    }
    fn shortest_edge(&self) -> f64 {
        (0..3)
            .map(|a| {
                if a == self.axis {
                    self.shortest_edge_along()
                } else {
                    self.cell[a]
                }
            })
            .fold(f64::INFINITY, f64::min)
    }
    fn mid_cell(&self) -> Vec3 {
        let mut c = self.cell;
        c[self.axis] = 0.5 * (self.ends[0] + self.ends[1]);
        c
    }
    fn counts(&self) -> [f64; 3] {
        let size = self.bounds.size();
        [0, 1, 2].map(|a| {
            if a == self.axis {
                self.count as f64
            } else {
                size[a] / self.cell[a]
            }
        })
    }
}

impl GradedCells {
    fn shortest_edge_along(&self) -> f64 {
        self.ends[0].min(self.ends[1])
    }
}

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
    /// the radius, 0 beyond it, continuous across it).
    pub fn volume_within(&self, triangles: impl Iterator<Item = [Vec3; 3]>, radius: f64) -> f64 {
        let c = self.centre;
        let v = |p: Vec3| {
            let (x, y) = (p[0] - c[0], p[1] - c[1]);
            let s = 0.5 * (radius * radius / (x * x + y * y).max(1e-300)).min(1.0);
            [s * x, s * y, 0.0]
        };
        flux_within(triangles, radius, &|p| self.radius(p), &v)
    }
}

/// The flux of `v` out of a closed outward mesh, where `v`'s divergence is 1 within `radius`
/// (as `dist` measures it) and 0 beyond, continuous across: the solid's volume within the
/// radius, mm³. Each triangle is integrated by its edge midpoints (exact where `v` is linear);
/// those the radius crosses, and those longer than a quarter of it (`v` bends beyond it), are
/// split in four first, up to six times.
fn flux_within(
    triangles: impl Iterator<Item = [Vec3; 3]>,
    radius: f64,
    dist: &dyn Fn(Vec3) -> f64,
    v: &dyn Fn(Vec3) -> Vec3,
) -> f64 {
    fn flux(
        t: [Vec3; 3],
        depth: u32,
        radius: f64,
        dist: &dyn Fn(Vec3) -> f64,
        v: &dyn Fn(Vec3) -> Vec3,
    ) -> f64 {
        let [a, b, d] = t;
        let rs = [dist(a), dist(b), dist(d)];
        let crosses = rs.iter().any(|&x| x < radius) && rs.iter().any(|&x| x > radius);
        let sub = |p: Vec3, q: Vec3| [p[0] - q[0], p[1] - q[1], p[2] - q[2]];
        let len = |e: Vec3| (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]).sqrt();
        let large = len(sub(a, b)).max(len(sub(b, d))).max(len(sub(d, a))) > 0.25 * radius;
        let mid = |p: Vec3, q: Vec3| [0, 1, 2].map(|i| 0.5 * (p[i] + q[i]));
        let (ab, bd, da) = (mid(a, b), mid(b, d), mid(d, a));
        if (crosses || large) && depth > 0 {
            return [[a, ab, da], [ab, b, bd], [da, bd, d], [ab, bd, da]]
                .into_iter()
                .map(|t| flux(t, depth - 1, radius, dist, v))
                .sum();
        }
        // ½ (b − a) × (d − a): the area vector.
        let (e, f) = (sub(b, a), sub(d, a));
        let n = [
            0.5 * (e[1] * f[2] - e[2] * f[1]),
            0.5 * (e[2] * f[0] - e[0] * f[2]),
            0.5 * (e[0] * f[1] - e[1] * f[0]),
        ];
        [ab, bd, da]
            .iter()
            .map(|p| {
                let w = v(*p);
                (w[0] * n[0] + w[1] * n[1] + w[2] * n[2]) / 3.0
            })
            .sum()
    }
    triangles.map(|t| flux(t, 6, radius, dist, v)).sum()
}

/// Maps whose cells lie in layers between radii (a tube's wall, a shell's): the density of each
/// layer is measured on the closed mesh, the solid within each radius by the divergence
/// theorem.
pub trait Layered: CellMap + Copy {
    /// The radii between layers, bore outwards (one more than the layers).
    fn layer_radii(&self) -> Vec<f64>;
    /// The volume of the map's region between radii `r0` and `r1`, mm³.
    fn region_between(&self, r0: f64, r1: f64) -> f64;
    /// The volume of a closed outward mesh's solid within `radius`, mm³.
    fn volume_within(&self, triangles: &mut dyn Iterator<Item = [Vec3; 3]>, radius: f64) -> f64;
}

impl Layered for Cylindrical {
    fn layer_radii(&self) -> Vec<f64> {
        (0..=self.cells[1])
            .map(|k| self.bore + k as f64 * self.cell[0])
            .collect()
    }
    fn region_between(&self, r0: f64, r1: f64) -> f64 {
        std::f64::consts::PI * (r1 * r1 - r0 * r0) * self.length()
    }
    fn volume_within(&self, triangles: &mut dyn Iterator<Item = [Vec3; 3]>, radius: f64) -> f64 {
        Cylindrical::volume_within(self, triangles, radius)
    }
}

impl Layered for Spherical {
    fn layer_radii(&self) -> Vec<f64> {
        (0..=self.cells[1])
            .map(|k| self.bore + k as f64 * self.cell)
            .collect()
    }
    fn region_between(&self, r0: f64, r1: f64) -> f64 {
        4.0 / 3.0 * std::f64::consts::PI * (r1.powi(3) - r0.powi(3))
    }
    /// With `V = (d/3)·min(1, R³/|d|³)`.
    fn volume_within(&self, triangles: &mut dyn Iterator<Item = [Vec3; 3]>, radius: f64) -> f64 {
        let c = self.centre;
        let v = |p: Vec3| {
            let d = [0, 1, 2].map(|i| p[i] - c[i]);
            let r2 = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).max(1e-300);
            let s = (radius.powi(3) / (r2 * r2.sqrt())).min(1.0) / 3.0;
            d.map(|x| s * x)
        };
        flux_within(triangles, radius, &|p| self.radius(p), &v)
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

/// Cells wrapped around a centre: a spherical shell made of the six faces of a cube (a cubed
/// sphere, equiangular), so that no cell shrinks to a point (a latitude–longitude map has poles).
///
/// With `d = p − c`, `m = |d|∞`, `h = N/2 + (|d| − R)/a`:
///
/// ```text
/// u_i = h·(4/π)·atan(d_i/m) + N/2
/// ```
///
/// takes the sphere of radius `|d|` onto the surface of a cube of half-side `h` (each face
/// equiangular), so the shell `R ≤ |d| ≤ R + K·a` is the image of the cubic shell
/// `[−K, N + K]³ ∖ (0, N)³` of cell coordinates: `(N + 2K)³ − N³` whole cells, `N × N` on each
/// face at the bore, `K` through the wall. The map is continuous everywhere and smooth but for
/// a crease along the cube's edges (where two faces meet, its derivative turns).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Spherical {
    /// The shell's centre, mm.
    pub centre: Vec3,
    /// Inner radius, mm.
    pub bore: f64,
    /// Cells along each edge of the cube's faces at the bore, and cells through the wall.
    pub cells: [u32; 2],
    /// Cell size through the wall, mm.
    pub cell: f64,
}

impl Spherical {
    /// A shell of `cells` (per face edge at the bore, through the wall), its cells `cell` mm
    /// through the wall (by default the size that makes the bore's cells cubes at the faces'
    /// middles, `πR/2N`), its inner radius `bore` mm, about `centre`.
    pub fn new(centre: Vec3, bore: f64, cells: [u32; 2], cell: Option<f64>) -> Result<Spherical> {
        if !(bore > 0.0 && bore.is_finite()) {
            return Err(Error::invalid(format!(
                "--bore must be a positive radius in mm, got {bore}"
            )));
        }
        if cells.contains(&0) {
            return Err(Error::invalid("cell counts must be at least 1"));
        }
        if cells[0] > 4096 || cells[1] > 4096 {
            return Err(Error::invalid(format!(
                "a spherical shell of {} × {} cells per face and {} through is too many",
                cells[0], cells[0], cells[1]
            )));
        }
        let cell = cell.unwrap_or(std::f64::consts::FRAC_PI_2 * bore / cells[0] as f64);
        if !(cell > 0.0 && cell.is_finite() && centre.iter().all(|c| c.is_finite())) {
            return Err(Error::invalid(
                "the cell size must be positive and the origin finite",
            ));
        }
        Ok(Spherical {
            centre,
            bore,
            cells,
            cell,
        })
    }

    /// Outer radius, mm.
    pub fn outer(&self) -> f64 {
        self.bore + self.cells[1] as f64 * self.cell
    }

    /// Every cell of the shell: `(N + 2K)³ − N³`.
    pub fn total(&self) -> u64 {
        let [n, k] = self.cells.map(u64::from);
        (n + 2 * k).pow(3) - n.pow(3)
    }

    /// The shell's volume, mm³.
    pub fn volume(&self) -> f64 {
        4.0 / 3.0 * std::f64::consts::PI * (self.outer().powi(3) - self.bore.powi(3))
    }

    /// Distance from the centre, mm.
    pub fn radius(&self, p: Vec3) -> f64 {
        let d = [0, 1, 2].map(|i| p[i] - self.centre[i]);
        (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
    }

    /// The half-side of the cube of cell coordinates at radius `r`.
    fn half_side(&self, r: f64) -> f64 {
        0.5 * self.cells[0] as f64 + (r - self.bore) / self.cell
    }

    /// Cell coordinates of `p`, and the gradient of each (the rows of the Jacobian), per mm.
    #[inline(always)]
    pub fn coords(&self, p: Vec3) -> (Vec3, [Vec3; 3]) {
        let d = [0, 1, 2].map(|i| p[i] - self.centre[i]);
        let r = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt().max(1e-300);
        let k = if d[0].abs() >= d[1].abs() && d[0].abs() >= d[2].abs() {
            0
        } else if d[1].abs() >= d[2].abs() {
            1
        } else {
            2
        };
        let m = d[k].abs().max(1e-300);
        let sk = d[k].signum();
        let h = self.half_side(r);
        let half = 0.5 * self.cells[0] as f64;
        let mut u = [0.0; 3];
        let mut jac = [[0.0; 3]; 3];
        for i in 0..3 {
            let t = d[i] / m;
            let phi = FRAC_4_PI * t.atan();
            u[i] = h * phi + half;
            let s = h * FRAC_4_PI / (1.0 + t * t) / m;
            for j in 0..3 {
                let own = if i == j { 1.0 } else { 0.0 } - if j == k { t * sk } else { 0.0 };
                jac[i][j] = phi * d[j] / (r * self.cell) + s * own;
            }
        }
        (u, jac)
    }

    /// A bound on `|∇(F∘u)|` per mm beyond half the bore, from bounds `l` on `|∂F/∂u_a|`:
    /// `‖J‖ ≤ √3·(1/a + (4/π)·|h|/r)` (the radial part moves `u` by at most `√3/a`, the
    /// tangential part's two rows by `(4/π)·|h|/m·…`, at most `√3·(4/π)·|h|/r`).
    pub fn lipschitz(&self, l: Vec3) -> f64 {
        let a = self.cell;
        let n = self.cells[0] as f64;
        let h_over_r = (1.0 / a).max((n / self.bore - 1.0 / a).abs());
        let norm = (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]).sqrt();
        norm * 3f64.sqrt() * (1.0 / a + FRAC_4_PI * h_over_r)
    }

    /// The narrowest a cell gets anywhere: one over the Jacobian's largest singular value, the
    /// largest over one face's directions (every face is the same) at the bore and the outer
    /// wall. Towards the cube's corners cells are sheared (a step through the wall crosses
    /// them on a slant) and narrower across: about half the width at the faces' middles.
    pub fn shortest_edge(&self) -> f64 {
        let mut most: f64 = 0.0;
        for r in [self.bore, self.outer()] {
            for i in 0..=16 {
                for j in 0..=16 {
                    let (s, t) = (i as f64 / 16.0, j as f64 / 16.0);
                    let n = (1.0 + s * s + t * t).sqrt();
                    let p = [
                        self.centre[0] + r / n,
                        self.centre[1] + r * s / n,
                        self.centre[2] + r * t / n,
                    ];
                    most = most.max(largest_singular_value(self.coords(p).1));
                }
            }
        }
        1.0 / most
    }

    /// A cell's size in the middle of the wall at a face's middle, mm (two sizes around, one
    /// through).
    pub fn mid_cell(&self) -> Vec3 {
        let r = self.bore + 0.5 * self.cells[1] as f64 * self.cell;
        let around = std::f64::consts::FRAC_PI_4 * r / self.half_side(r);
        [around, around, self.cell]
    }

    /// The box around the shell.
    pub fn bounds(&self) -> Aabb {
        let r = self.outer();
        Aabb {
            min: self.centre.map(|c| c - r),
            max: self.centre.map(|c| c + r),
        }
    }
}

/// The largest singular value of `j`: the square root of `jᵀj`'s largest eigenvalue, by power
/// iteration.
fn largest_singular_value(j: [Vec3; 3]) -> f64 {
    let mut g = [[0.0; 3]; 3];
    for (a, row) in g.iter_mut().enumerate() {
        for (b, x) in row.iter_mut().enumerate() {
            *x = (0..3).map(|i| j[i][a] * j[i][b]).sum();
        }
    }
    let mut v = [1.0, 0.7, 0.3];
    let mut lambda = 0.0;
    for _ in 0..64 {
        let w = [0, 1, 2].map(|a| (0..3).map(|b| g[a][b] * v[b]).sum::<f64>());
        let n = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
        if n == 0.0 {
            return 0.0;
        }
        lambda = n;
        v = w.map(|x| x / n);
    }
    lambda.sqrt()
}

impl CellMap for Spherical {
    fn coords(&self, p: Vec3) -> (Vec3, [Vec3; 3]) {
        Spherical::coords(self, p)
    }
    fn lipschitz(&self, l: Vec3) -> f64 {
        Spherical::lipschitz(self, l)
    }
    /// The bound holds beyond half the bore.
    fn room(&self, p: Vec3) -> f64 {
        self.radius(p) - 0.5 * self.bore
    }
    fn cut(&self, p: Vec3) -> Option<(f64, Vec3)> {
        Some(self.implicit_with_gradient(p))
    }
    fn bounds(&self) -> Aabb {
        Spherical::bounds(self)
    }
    fn volume(&self) -> f64 {
        Spherical::volume(self)
    }
    fn shortest_edge(&self) -> f64 {
        Spherical::shortest_edge(self)
    }
    fn mid_cell(&self) -> Vec3 {
        Spherical::mid_cell(self)
    }
    fn counts(&self) -> [f64; 3] {
        let [n, k] = self.cells.map(f64::from);
        [n, n, k]
    }
}

/// The spherical shell as an exact signed distance field.
impl Field for Spherical {
    fn value(&self, p: Vec3) -> f64 {
        let r = self.radius(p);
        (self.bore - r).max(r - self.outer())
    }

    fn clearance(&self, p: Vec3) -> f64 {
        self.value(p).abs()
    }

    fn implicit_with_gradient(&self, p: Vec3) -> (f64, Vec3) {
        let d = [0, 1, 2].map(|i| p[i] - self.centre[i]);
        let r = self.radius(p).max(1e-300);
        let out = d.map(|x| x / r);
        let (inner, outer) = (self.bore - r, r - self.outer());
        if inner > outer {
            (inner, out.map(|x| -x))
        } else {
            (outer, out)
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
    fn graded_cells_are_whole_and_their_faces_are_whole_cell_coordinates() {
        let b = Aabb {
            min: [1.0, -2.0, 0.5],
            max: [31.0, 8.0, 10.5],
        };
        let g = GradedCells::new(b, 0, 2.0, 6.0, [5.0; 3]).unwrap();
        // 30·ln 3/4 = 8.24 cells: 8, the sizes scaled up.
        assert_eq!(g.count, 8);
        let faces = g.faces();
        assert_eq!(faces.len(), 9);
        for (i, x) in faces.iter().enumerate() {
            let (u, _) = g.coords([*x, 0.0, 0.0]);
            assert!((u[0] - i as f64).abs() < 1e-9, "{i}: {u:?}");
        }
        let widths: Vec<f64> = faces.windows(2).map(|w| w[1] - w[0]).collect();
        assert!(widths.windows(2).all(|w| w[1] > w[0]), "{widths:?}");
        let p = [12.0, 3.0, 4.0];
        let (_, j) = g.coords(p);
        for (a, row) in j.iter().enumerate() {
            let d = crate::field::numeric_gradient(|q| g.coords(q).0[a], p);
            for (x, y) in d.iter().zip(row) {
                assert!((x - y).abs() < 1e-6, "{a}: {d:?} {row:?}");
            }
        }
    }

    #[test]
    fn the_tube_distance_and_the_volume_within_a_radius_are_exact() {
        let t = tube();
        assert!((t.value([1.0 + 8.0, -2.0, 4.0]) + 1.0).abs() < 1e-12);
        assert!((t.value([1.0 + 11.0, -2.0, 4.0]) - 1.0).abs() < 1e-12);
        assert!((t.value([1.0 + 11.0, -2.0, 19.0]) - 1.0f64.hypot(4.0)).abs() < 1e-12);
        // A box from the axis out: its volume within radius 2 is a disc's (π·2²·h) when the
        // box's half width is over 2.
        let mesh = crate::geom::Mesh::cuboid([-3.0, -4.0, 0.0], [4.0, 3.0, 2.0]);
        let tris = (0..mesh.triangle_count()).map(|i| mesh.triangle(i));
        let t0 = Cylindrical::new([0.0, 0.0, 0.0], 1.0, [3, 1, 1], [1.0, 1.0]).unwrap();
        let v = t0.volume_within(tris, 2.0);
        let exact = std::f64::consts::PI * 4.0 * 2.0;
        assert!((v - exact).abs() < 1e-3 * exact, "{v} vs {exact}");
    }

    #[test]
    fn the_cubed_sphere_is_whole_cells_continuous_and_its_jacobian_matches_differences() {
        let s = Spherical::new([1.0, -2.0, 0.5], 8.0, [4, 2], Some(3.0)).unwrap();
        let mut rng = 12345u64;
        let mut next = || {
            rng = rng
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (rng >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        for _ in 0..200 {
            let d = [next(), next(), next()];
            let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            // On the bore the coordinates are on the cube [0, 4]³'s surface; on the outer wall
            // on [−2, 6]³'s.
            for (r, lo, hi) in [(8.0, 0.0, 4.0), (14.0, -2.0, 6.0)] {
                let p = [0, 1, 2].map(|i| s.centre[i] + r * d[i] / n);
                let u = s.coords(p).0;
                assert!(
                    u.iter().all(|x| *x >= lo - 1e-9 && *x <= hi + 1e-9),
                    "{u:?}"
                );
                assert!(u
                    .iter()
                    .any(|x| (x - lo).abs() < 1e-9 || (x - hi).abs() < 1e-9));
            }
            let p = [0, 1, 2].map(|i| s.centre[i] + 10.0 * d[i] / n);
            let (_, j) = s.coords(p);
            for (a, row) in j.iter().enumerate() {
                let g = crate::field::numeric_gradient(|q| s.coords(q).0[a], p);
                for (gi, ji) in g.iter().zip(row) {
                    assert!((gi - ji).abs() < 1e-5, "{a}: {g:?} {row:?}");
                }
            }
            let norm = largest_singular_value(j);
            assert!(s.lipschitz([1.0, 0.0, 0.0]) >= norm, "{norm}");
        }
        // Across a cube edge (|x| = |y|) the coordinates do not jump.
        let e = [1.0 + 7.0, -2.0 + 7.0, 0.5 + 2.0];
        let a = s.coords([e[0] + 1e-9, e[1], e[2]]).0;
        let b = s.coords([e[0], e[1] + 1e-9, e[2]]).0;
        assert!((0..3).all(|i| (a[i] - b[i]).abs() < 1e-6), "{a:?} {b:?}");
        assert_eq!(s.total(), 8 * 8 * 8 - 4 * 4 * 4);
    }

    #[test]
    fn the_volume_within_a_sphere_is_exact() {
        // A cube of half side 5 about the centre holds the whole ball of radius 4 and a part of
        // the ball of radius 6 (the ball less six caps of height 1).
        let s = Spherical::new([0.0; 3], 1.0, [2, 1], None).unwrap();
        let mesh = crate::geom::Mesh::cuboid([-5.0; 3], [5.0; 3]);
        let within = |r: f64| {
            let mut tris = (0..mesh.triangle_count()).map(|i| mesh.triangle(i));
            Layered::volume_within(&s, &mut tris, r)
        };
        let pi = std::f64::consts::PI;
        let ball = 4.0 / 3.0 * pi * 64.0;
        assert!((within(4.0) - ball).abs() < 1e-3 * ball, "{}", within(4.0));
        let cap = pi * 1.0 * (3.0 * 6.0 - 1.0) / 3.0;
        let exact = 4.0 / 3.0 * pi * 216.0 - 6.0 * cap;
        assert!(
            (within(6.0) - exact).abs() < 2e-3 * exact,
            "{} vs {exact}",
            within(6.0)
        );
    }
}
