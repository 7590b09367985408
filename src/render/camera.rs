//! Cameras: where the eye is, where it looks, and the ray through each pixel.
//!
//! Angles follow the build plate's frame (z up): the azimuth turns the eye about z, from the
//! front (the eye on −y looking along +y, azimuth 0°) towards the right side (the eye on +x,
//! azimuth 90°); the elevation lifts it above the xy plane (90°: looking straight down).

pub use crate::geom::Ray;
pub(crate) use crate::geom::{cross, dot, normalized};
use crate::geom::{Aabb, Vec3};

/// A named view: the azimuth and elevation it stands for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum View {
    /// From the front-right, above: azimuth 45°, elevation 35.26° (the cube's diagonal).
    Iso,
    /// From −y.
    Front,
    /// From +y.
    Back,
    /// From −x.
    Left,
    /// From +x.
    Right,
    /// From +z, looking down.
    Top,
    /// From −z, looking up.
    Bottom,
}

impl View {
    /// Azimuth and elevation, degrees.
    pub fn angles(self) -> (f64, f64) {
        let iso = (1.0f64 / 2.0f64.sqrt()).atan().to_degrees();
        match self {
            View::Iso => (45.0, iso),
            View::Front => (0.0, 0.0),
            View::Back => (180.0, 0.0),
            View::Left => (-90.0, 0.0),
            View::Right => (90.0, 0.0),
            View::Top => (0.0, 90.0),
            View::Bottom => (0.0, -90.0),
        }
    }
}

/// A perspective camera.
#[derive(Debug, Clone, Copy)]
pub struct Camera {
    /// The eye, mm.
    pub eye: Vec3,
    /// Unit vectors: where it looks, the image's right and up.
    pub forward: Vec3,
    /// The image's right.
    pub right: Vec3,
    /// The image's up.
    pub up: Vec3,
    /// Vertical field of view, degrees.
    pub fov: f64,
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
}

/// The vertical field of view, degrees: a moderate telephoto, so parts look as on a drawing.
pub const FOV: f64 = 30.0;

impl Camera {
    /// A camera looking at the centre of `bounds` from `azimuth` and `elevation` (degrees), at
    /// `distance` mm from it, or where the box's bounding sphere just fills the image.
    pub fn looking_at(
        bounds: &Aabb,
        azimuth: f64,
        elevation: f64,
        distance: Option<f64>,
        width: u32,
        height: u32,
    ) -> Camera {
        let centre = [0, 1, 2].map(|a| 0.5 * (bounds.min[a] + bounds.max[a]));
        let s = bounds.size();
        let radius = 0.5 * (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
        let aspect = width as f64 / height as f64;
        let half_v = (0.5 * FOV).to_radians();
        let half = if aspect < 1.0 {
            (half_v.tan() * aspect).atan()
        } else {
            half_v
        };
        let distance = distance.unwrap_or(1.04 * radius / half.sin());
        let (az, el) = (azimuth.to_radians(), elevation.to_radians());
        // Eye direction from the centre: azimuth 0 on −y, 90° on +x.
        let towards_eye = [az.sin() * el.cos(), -az.cos() * el.cos(), el.sin()];
        let eye = [0, 1, 2].map(|a| centre[a] + distance * towards_eye[a]);
        let forward = towards_eye.map(|x| -x);
        // Up is +z, except looking straight down or up, where it is the front view's +y.
        let world_up = if el.cos().abs() < 1e-9 {
            [-az.sin(), az.cos(), 0.0]
        } else {
            [0.0, 0.0, 1.0]
        };
        let right = normalized(cross(forward, world_up));
        let up = cross(right, forward);
        Camera {
            eye,
            forward,
            right,
            up,
            fov: FOV,
            width,
            height,
        }
    }

    /// The ray through the centre of pixel `(x, y)`, `y` counted from the top row.
    pub fn ray(&self, x: f64, y: f64) -> Ray {
        let half = (0.5 * self.fov).to_radians().tan();
        let (w, h) = (self.width as f64, self.height as f64);
        let u = (2.0 * (x + 0.5) / w - 1.0) * half * w / h;
        let v = (1.0 - 2.0 * (y + 0.5) / h) * half;
        let d = [0, 1, 2].map(|a| self.forward[a] + u * self.right[a] + v * self.up[a]);
        Ray {
            origin: self.eye,
            dir: normalized(d),
        }
    }

    /// The width of one pixel at distance `t` from the eye, mm.
    pub fn pixel_at(&self, t: f64) -> f64 {
        2.0 * t * (0.5 * self.fov).to_radians().tan() / self.height as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn views_look_at_the_centre_from_where_they_say() {
        let b = Aabb {
            min: [0.0; 3],
            max: [10.0, 20.0, 30.0],
        };
        let c = Camera::looking_at(&b, 0.0, 0.0, Some(100.0), 80, 60);
        assert!((c.eye[1] - (10.0 - 100.0)).abs() < 1e-9);
        assert!((c.forward[1] - 1.0).abs() < 1e-12);
        let top = Camera::looking_at(&b, View::Top.angles().0, 90.0, Some(50.0), 80, 60);
        assert!((top.eye[2] - 65.0).abs() < 1e-9 && (top.forward[2] + 1.0).abs() < 1e-12);
        assert!((top.up[1] - 1.0).abs() < 1e-9, "top view: +y is up");
        // The centre pixel's ray (for an odd size) passes through the box's centre.
        let c = Camera::looking_at(&b, 30.0, 20.0, None, 81, 61);
        let r = c.ray(40.0, 30.0);
        let to = [5.0 - r.origin[0], 10.0 - r.origin[1], 15.0 - r.origin[2]];
        let t = dot(to, r.dir);
        let q = r.at(t);
        assert!((0..3).all(|a| (q[a] - [5.0, 10.0, 15.0][a]).abs() < 1e-9));
    }

    #[test]
    fn clipping_a_ray_by_a_box() {
        let b = Aabb {
            min: [0.0; 3],
            max: [1.0; 3],
        };
        let r = Ray {
            origin: [-1.0, 0.5, 0.5],
            dir: [1.0, 0.0, 0.0],
        };
        assert_eq!(r.clip(&b), Some((1.0, 2.0)));
        let miss = Ray {
            origin: [-1.0, 2.0, 0.5],
            dir: [1.0, 0.0, 0.0],
        };
        assert_eq!(miss.clip(&b), None);
    }
}
