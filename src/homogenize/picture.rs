//! The directional Young's modulus as a surface: the point `E(d)·d` for every direction `d`, a
//! sphere where the cell is isotropic, bulging along its stiff directions and pinched along its
//! soft ones — the picture designers compare cells by. Meshed as a latitude–longitude sphere
//! and drawn by the renderer's ray caster from three sides.

use super::tensor::{young_along, Voigt};
use crate::error::Result;
use crate::geom::bvh::Bvh;
use crate::geom::Mesh;
use crate::render::{self, camera::Camera, trace::Triangles};
use std::path::Path;

/// The surface `E(d)·d` on `rings` latitude rings (twice as many meridians).
pub fn young_surface(s: &Voigt, rings: usize) -> Mesh {
    let rings = rings.max(4);
    let meridians = 2 * rings;
    let mut positions = Vec::new();
    let mut push = |d: [f64; 3]| {
        let e = young_along(s, d);
        positions.extend(d.map(|x| (x * e) as f32));
    };
    push([0.0, 0.0, 1.0]);
    for i in 1..rings {
        let theta = std::f64::consts::PI * i as f64 / rings as f64;
        for j in 0..meridians {
            let phi = std::f64::consts::TAU * j as f64 / meridians as f64;
            push([
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            ]);
        }
    }
    push([0.0, 0.0, -1.0]);
    let ring = |i: usize, j: usize| (1 + (i - 1) * meridians + j % meridians) as u32;
    let south = (1 + (rings - 1) * meridians) as u32;
    let mut indices = Vec::new();
    for j in 0..meridians {
        indices.extend([0, ring(1, j), ring(1, j + 1)]);
        indices.extend([south, ring(rings - 1, j + 1), ring(rings - 1, j)]);
    }
    for i in 1..rings - 1 {
        for j in 0..meridians {
            let (a, b, c, d) = (
                ring(i, j),
                ring(i, j + 1),
                ring(i + 1, j),
                ring(i + 1, j + 1),
            );
            indices.extend([a, c, d, a, d, b]);
        }
    }
    Mesh { positions, indices }
}

/// Draws the surface of the compliance `s` from the iso view, the front and the top, side by
/// side, each `size` pixels square, into the PNG `path`.
pub fn write_picture(s: &Voigt, path: &Path, size: u32) -> Result<()> {
    let mesh = young_surface(s, 64);
    let bvh = Bvh::new(&mesh);
    let scene = Triangles {
        bvh: &bvh,
        section: None,
    };
    let bounds = bvh.bounds().expect("the surface has triangles");
    let frames: Vec<render::Frame> = [
        render::camera::View::Iso,
        render::camera::View::Front,
        render::camera::View::Top,
    ]
    .into_iter()
    .map(|v| {
        let (az, el) = v.angles();
        render::render(
            &scene,
            &Camera::looking_at(&bounds, az, el, None, size, size),
        )
    })
    .collect();
    render::Frame::strip(&frames)?.write_png(path)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::homogenize::element::elasticity;
    use crate::homogenize::tensor::invert;

    /// An isotropic solid's surface is a sphere of radius E, closed and outward.
    #[test]
    fn an_isotropic_surface_is_a_sphere() {
        let (e, nu) = (2.0, 0.3);
        let (l, m) = crate::homogenize::tensor::lame(e, nu);
        let s = invert(&elasticity(l, m), 1e-12).unwrap();
        let mesh = young_surface(&s, 16);
        for p in mesh.positions.chunks(3) {
            let r = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt() as f64;
            assert!((r - e).abs() < 1e-5);
        }
        let v = mesh.volume();
        let sphere = 4.0 / 3.0 * std::f64::consts::PI * e.powi(3);
        assert!(v > 0.95 * sphere && v < sphere, "{v} against {sphere}");
    }
}
