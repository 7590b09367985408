//! Slicing: a solid cut by parallel planes into closed contours, and the files printers read.
//!
//! [`plan`] places the layers (uniform, or adaptive by the change of cross-section area or by the
//! stair-step cusp); [`mesh`] cuts a triangle mesh at the layers' mid-heights, chaining segments
//! through the mesh's own edges so a closed solid gives closed loops; [`contour`] measures loops
//! and nests them into polygons with holes; [`raster`] turns them into anti-aliased masks; the
//! writers ([`common_layer`], [`svg`], [`masks`], [`csv`], [`plot`]) write the stack; [`job`] runs it all, as
//! `latvox slice` and batch jobs do.

pub mod common_layer;
pub mod csv;
pub mod implicit;
pub mod job;
pub mod masks;
pub mod mesh;
pub mod plan;
pub mod plot;
pub mod raster;
pub mod svg;

use crate::error::{Error, Result};
use crate::field::Vec3;

pub use crate::geom::contour::{Loop, Section};
pub use plan::Layer;

/// The build frame: `d` the build direction (unit), `u` and `v` the in-layer axes, right-handed
/// (`u × v = d`), so a loop counter-clockwise in `(u, v)` is counter-clockwise seen from `+d`.
/// For `d = +Z`, `u = +X` and `v = +Y`: layer coordinates are the part's own x and y.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// First in-layer axis.
    pub u: Vec3,
    /// Second in-layer axis.
    pub v: Vec3,
    /// Build direction.
    pub d: Vec3,
}

impl Frame {
    /// The frame of build direction `dir` (any length but zero).
    pub fn new(dir: Vec3) -> Result<Frame> {
        let n = dot(dir, dir).sqrt();
        if !(n > 1e-12 && n.is_finite()) {
            return Err(Error::invalid(format!(
                "the build direction {},{},{} has no length",
                dir[0], dir[1], dir[2]
            )));
        }
        let d = [dir[0] / n, dir[1] / n, dir[2] / n];
        // +X projected into the layer, unless the direction is close to X itself.
        let e = if d[0].abs() < 0.9 {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 1.0, 0.0]
        };
        let k = dot(e, d);
        let u = [e[0] - k * d[0], e[1] - k * d[1], e[2] - k * d[2]];
        let un = dot(u, u).sqrt();
        let u = [u[0] / un, u[1] / un, u[2] / un];
        let v = [
            d[1] * u[2] - d[2] * u[1],
            d[2] * u[0] - d[0] * u[2],
            d[0] * u[1] - d[1] * u[0],
        ];
        Ok(Frame { u, v, d })
    }

    /// Height of `p` along the build direction.
    pub fn height(&self, p: Vec3) -> f64 {
        dot(p, self.d)
    }

    /// In-layer coordinates of `p`.
    pub fn plane(&self, p: Vec3) -> [f64; 2] {
        [dot(p, self.u), dot(p, self.v)]
    }

    /// Whether this is the default frame (+Z up, layer axes x and y).
    pub fn is_z(&self) -> bool {
        self.d == [0.0, 0.0, 1.0]
    }
}

/// What a writer knows of the stack before its first layer.
#[derive(Debug, Clone)]
pub struct Stack {
    /// Every layer of the part, bottom up (a shard writes some of them).
    pub layers: Vec<Layer>,
    /// In-layer bounds of the part, `[u_min, v_min, u_max, v_max]`, mm.
    pub bounds: [f64; 4],
    /// Lowest and highest heights of the part along the build direction, mm.
    pub heights: [f64; 2],
    /// The build frame.
    pub frame: Frame,
    /// The part's name (its file's stem), for labels inside the files.
    pub name: String,
}

/// A writer of a layer stack. Each layer is encoded on its own (in parallel, by
/// [`StackWriter::encode`]), then stored in order ([`StackWriter::put`]); then the writer is
/// finished. A writer dropped unfinished leaves nothing behind.
pub trait StackWriter: Send + Sync {
    /// Layer `index` (into [`Stack::layers`]) in the file's form.
    fn encode(&self, index: usize, section: &Section) -> Result<Vec<u8>>;
    /// Stores layer `index`, encoded; layers come in ascending order.
    fn put(&mut self, index: usize, encoded: Vec<u8>) -> Result<()>;
    /// Completes the output and puts it in place.
    fn finish(self: Box<Self>) -> Result<()>;
}

fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_right_handed_and_z_keeps_x_and_y() {
        let f = Frame::new([0.0, 0.0, 2.0]).unwrap();
        assert_eq!((f.u, f.v), ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]));
        for dir in [
            [1.0, 0.0, 0.0],
            [1.0, 2.0, 3.0],
            [0.0, -1.0, 0.0],
            [-3.0, 0.1, 0.0],
        ] {
            let f = Frame::new(dir).unwrap();
            let c = [
                f.u[1] * f.v[2] - f.u[2] * f.v[1],
                f.u[2] * f.v[0] - f.u[0] * f.v[2],
                f.u[0] * f.v[1] - f.u[1] * f.v[0],
            ];
            for (ca, da) in c.iter().zip(f.d) {
                assert!((ca - da).abs() < 1e-12);
            }
            assert!(dot(f.u, f.d).abs() < 1e-12 && dot(f.v, f.d).abs() < 1e-12);
        }
        assert!(Frame::new([0.0; 3]).is_err());
    }
}
