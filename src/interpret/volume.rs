//! 3D results to a mesh through latvox's own pipeline: the filtered density grid is a
//! [`Field`] (trilinear between voxel centres, void beyond the domain), sampled into an OpenVDB
//! narrow-band level set by [`Grid::sample`] and meshed by [`Grid::to_mesh`]; optionally
//! smoothed first by OpenVDB's level-set filter ([`Smoothed`], [`Grid::smoothed`]).
//!
//! Value: `(level − ρ) / |∇ρ|`, a first-order signed distance to the iso-surface `ρ = level`.
//! Clearance: with ρ in [0, top] each partial derivative of the trilinear interpolant is at most
//! `top/h`, so `|∇ρ| ≤ √3·top/h` and the surface is at least `|ρ − level|·h/(√3·top)` away — a
//! bound that never overestimates, as block culling requires.

use super::raster::Raster;
use crate::error::Result;
use crate::field::{Aabb, Field, Intersection, Vec3};
use crate::geom::Mesh;
use crate::grid::{Grid, GridSpec, Smoothing};
use crate::mesh::simplify::{self, Simplified, Surface};

/// The iso-surface `ρ = level` of a 3D raster.
pub struct DensityField<'a> {
    /// The densities, one per voxel.
    pub grid: &'a Raster,
    /// The density at the surface.
    pub level: f64,
    /// Largest density (raised features may exceed 1): the gradient bound scales with it.
    pub top: f64,
}

impl DensityField<'_> {
    fn at(&self, i: isize, j: isize, k: isize) -> f64 {
        let n = self.grid.n;
        if i < 0 || j < 0 || k < 0 || i >= n[0] as isize || j >= n[1] as isize || k >= n[2] as isize
        {
            return 0.0;
        }
        self.grid.data[(k as usize * n[1] + j as usize) * n[0] + i as usize].max(0.0)
    }

    /// Trilinear density and its gradient (per mm).
    fn interp(&self, p: Vec3) -> (f64, Vec3) {
        let h = self.grid.h;
        let u = p.map(|c| c / h - 0.5);
        let b = u.map(|c| c.floor());
        let t = [u[0] - b[0], u[1] - b[1], u[2] - b[2]];
        let (i, j, k) = (b[0] as isize, b[1] as isize, b[2] as isize);
        let mut c = [0.0; 8];
        for (m, cm) in c.iter_mut().enumerate() {
            *cm = self.at(
                i + (m & 1) as isize,
                j + ((m >> 1) & 1) as isize,
                k + (m >> 2) as isize,
            );
        }
        let lerp = |a: f64, b: f64, s: f64| a + s * (b - a);
        let x00 = lerp(c[0], c[1], t[0]);
        let x10 = lerp(c[2], c[3], t[0]);
        let x01 = lerp(c[4], c[5], t[0]);
        let x11 = lerp(c[6], c[7], t[0]);
        let y0 = lerp(x00, x10, t[1]);
        let y1 = lerp(x01, x11, t[1]);
        let v = lerp(y0, y1, t[2]);
        let dx = lerp(
            lerp(c[1] - c[0], c[3] - c[2], t[1]),
            lerp(c[5] - c[4], c[7] - c[6], t[1]),
            t[2],
        );
        let dy = lerp(x10 - x00, x11 - x01, t[2]);
        let dz = y1 - y0;
        (v, [dx / h, dy / h, dz / h])
    }
}

impl DensityField<'_> {
    /// Distance from `p` to the domain box when outside it (0 inside).
    fn outside(&self, p: Vec3) -> f64 {
        let mut s = 0.0;
        for (a, &c) in p.iter().enumerate() {
            let hi = self.grid.n[a] as f64 * self.grid.h;
            let d = (-c).max(c - hi).max(0.0);
            s += d * d;
        }
        s.sqrt()
    }
}

impl Field for DensityField<'_> {
    fn value(&self, p: Vec3) -> f64 {
        // Beyond the domain the part is clipped away: the distance to the box is a lower bound
        // and ramps up steadily, so the narrow band closes the part along the domain's faces.
        let out = self.outside(p);
        if out > 0.0 {
            return out;
        }
        let (v, g) = self.interp(p);
        let gn = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
        let bound = self.clearance(p);
        // First-order distance where the gradient is meaningful; never below the proven bound.
        let d = if gn > 1e-9 {
            ((self.level - v).abs() / gn).max(bound)
        } else {
            bound.max(self.grid.h * 4.0)
        };
        if v >= self.level {
            -d
        } else {
            d
        }
    }

    fn clearance(&self, p: Vec3) -> f64 {
        let out = self.outside(p);
        if out > 0.0 {
            return out;
        }
        let (v, _) = self.interp(p);
        (v - self.level).abs() * self.grid.h / (3f64.sqrt() * self.top)
    }
}

/// Meshes the iso-surface of a 3D raster at `level` with OpenVDB, at the raster's voxel size.
pub fn mesh(grid: &Raster, level: f64) -> Result<Mesh> {
    sample(grid, level)?.to_mesh(0.0)
}

/// The iso-surface of a 3D raster at `level` as a narrow-band level set at the raster's voxel
/// size.
fn sample(grid: &Raster, level: f64) -> Result<Grid> {
    let (f, bounds) = iso_surface(grid, level);
    let spec = GridSpec::covering(&bounds, grid.h, 3.0);
    // Clipped by the domain box, whose exact distance closes the part where it meets the
    // domain's faces (the density alone drops to void there without a distance-like ramp).
    let clipped = Intersection { a: f, b: bounds };
    Grid::sample(&clipped, spec)
}

/// The iso-surface of `grid` at `level` and the domain box that clips it.
fn iso_surface(grid: &Raster, level: f64) -> (DensityField<'_>, Aabb) {
    let top = grid.data.iter().copied().fold(1.0f64, f64::max);
    let bounds = Aabb {
        min: [0.0; 3],
        max: [0, 1, 2].map(|a| grid.n[a] as f64 * grid.h),
    };
    (DensityField { grid, level, top }, bounds)
}

/// `mesh`, made by [`mesh`] from `grid` at `level`, simplified within `tolerance` of that
/// iso-surface (clipped by the domain, whose faces stay flat and their edges sharp), its volume
/// kept ([`crate::mesh::simplify::mesh_within`]).
pub fn simplified(grid: &Raster, level: f64, mesh: &Mesh, tolerance: f64) -> (Mesh, Simplified) {
    let (field, clip) = iso_surface(grid, level);
    let surface = Surface {
        field: &field,
        clip,
    };
    simplify::mesh_within(mesh, surface, grid.h, tolerance)
}

/// Half width, in voxels, of the smoothed level set's band: room for the filter's stencils and
/// for the offsets of up to three voxels that keep the part's volume.
const SMOOTHED_BAND: f64 = 6.0;

/// A 3D raster's iso-surface at `level`, smoothed by `iterations` passes of OpenVDB's level-set
/// filter ([`Grid::smoothed`]) on the level set that [`mesh`] would mesh. Mesh it with
/// [`Smoothed::mesh`] at any offset of the surface.
pub struct Smoothed {
    grid: Grid,
}

impl Smoothed {
    /// Builds the level set of `grid`'s iso-surface at `level` and smooths it.
    pub fn new(grid: &Raster, level: f64, mode: Smoothing, iterations: u32) -> Result<Smoothed> {
        let grid = sample(grid, level)?.smoothed(mode, iterations, SMOOTHED_BAND)?;
        Ok(Smoothed { grid })
    }

    /// The smoothed surface offset outwards by `offset` mm (negative: inwards), meshed.
    pub fn mesh(&self, offset: f64) -> Result<Mesh> {
        self.grid.to_mesh_at(offset, 0.0)
    }
}
