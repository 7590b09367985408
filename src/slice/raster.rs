//! Anti-aliased masks of polygons: every pixel gets the exact fraction of its square the
//! polygons cover. Each edge deposits, on the pixels it crosses, its signed area and coverage
//! changes; a running sum along each row then gives the winding-weighted coverage (the
//! accumulation rasteriser of font-rs and stb_truetype). Outer loops counter-clockwise and holes
//! clockwise cancel to exactly 0 inside a hole, so the mask's sum is the section's area in pixels.

use crate::geom::contour::Loop;

/// A `width × height` coverage mask, rows from the top; pixel `(i, j)` covers
/// `[i, i + 1] × [j, j + 1]` in pixel units.
pub struct Mask {
    /// Width, pixels.
    pub width: usize,
    /// Height, pixels.
    pub height: usize,
    /// Row-wise accumulation buffer, `width + 2` per row.
    acc: Vec<f32>,
}

impl Mask {
    /// An empty mask.
    pub fn new(width: usize, height: usize) -> Mask {
        Mask {
            width,
            height,
            acc: vec![0.0; (width + 2) * height],
        }
    }

    /// Adds a closed loop given in pixel units (x right, y down). Points are clamped into the
    /// mask; callers size the mask to hold them.
    pub fn add_loop(&mut self, pts: impl IntoIterator<Item = [f64; 2]>) {
        let pts: Loop = pts.into_iter().collect();
        let n = pts.len();
        for i in 0..n {
            self.line(pts[i], pts[(i + 1) % n]);
        }
    }

    fn line(&mut self, p0: [f64; 2], p1: [f64; 2]) {
        let (w, h) = (self.width as f64, self.height as f64);
        let clamp = |p: [f64; 2]| [p[0].clamp(0.0, w), p[1].clamp(0.0, h)];
        let (p0, p1) = (clamp(p0), clamp(p1));
        if p0[1] == p1[1] {
            return;
        }
        let (dir, p0, p1) = if p0[1] < p1[1] {
            (1.0, p0, p1)
        } else {
            (-1.0, p1, p0)
        };
        let stride = self.width + 2;
        let dxdy = (p1[0] - p0[0]) / (p1[1] - p0[1]);
        let mut x = p0[0];
        let y0 = p0[1] as usize;
        let y1 = (p1[1].ceil() as usize).min(self.height);
        for y in y0..y1 {
            let row = y * stride;
            let dy = ((y + 1) as f64).min(p1[1]) - (y as f64).max(p0[1]);
            let xnext = x + dxdy * dy;
            let d = dy * dir;
            let (xa, xb) = if x < xnext { (x, xnext) } else { (xnext, x) };
            let xa_floor = xa.floor();
            let ia = xa_floor as usize;
            let xb_ceil = xb.ceil();
            let ib = xb_ceil as usize;
            if ib <= ia + 1 {
                // Within one pixel column: split by the mean x.
                let xm = 0.5 * (x + xnext) - xa_floor;
                self.acc[row + ia] += (d - d * xm) as f32;
                self.acc[row + ia + 1] += (d * xm) as f32;
            } else {
                let s = 1.0 / (xb - xa);
                let fa = xa - xa_floor;
                let a0 = 0.5 * s * (1.0 - fa) * (1.0 - fa);
                let fb = xb - xb_ceil + 1.0;
                let am = 0.5 * s * fb * fb;
                self.acc[row + ia] += (d * a0) as f32;
                if ib == ia + 2 {
                    self.acc[row + ia + 1] += (d * (1.0 - a0 - am)) as f32;
                } else {
                    let a1 = s * (1.5 - fa);
                    self.acc[row + ia + 1] += (d * (a1 - a0)) as f32;
                    for i in ia + 2..ib - 1 {
                        self.acc[row + i] += (d * s) as f32;
                    }
                    let a2 = a1 + (ib - ia - 3) as f64 * s;
                    self.acc[row + ib - 1] += (d * (1.0 - a2 - am)) as f32;
                }
                self.acc[row + ib] += (d * am) as f32;
            }
            x = xnext;
        }
    }

    /// Coverage per pixel, 0..=1, rows from the top.
    pub fn coverage(&self) -> Vec<f32> {
        let stride = self.width + 2;
        let mut out = Vec::with_capacity(self.width * self.height);
        for row in self.acc.chunks_exact(stride) {
            let mut a = 0.0f32;
            for &v in &row[..self.width] {
                a += v;
                out.push(a.abs().min(1.0));
            }
        }
        out
    }

    /// Coverage as 8-bit grey (255 full), rows from the top.
    pub fn grey(&self) -> Vec<u8> {
        self.coverage()
            .into_iter()
            .map(|c| (c * 255.0 + 0.5) as u8)
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ring_covers_its_area_and_nothing_in_its_hole() {
        let ring = |r: f64, ccw: bool| -> Loop {
            let n = 400;
            let mut l: Loop = (0..n)
                .map(|k| {
                    let a = k as f64 / n as f64 * std::f64::consts::TAU;
                    [50.3 + r * a.cos(), 50.7 + r * a.sin()]
                })
                .collect();
            if !ccw {
                l.reverse();
            }
            l
        };
        let (a, b) = (ring(40.0, true), ring(15.0, false));
        let mut m = Mask::new(101, 102);
        m.add_loop(a.iter().copied());
        m.add_loop(b.iter().copied());
        let cov = m.coverage();
        let sum: f64 = cov.iter().map(|&c| c as f64).sum();
        let exact = crate::geom::contour::signed_area(&a) + crate::geom::contour::signed_area(&b);
        assert!((sum - exact).abs() < 1e-3 * exact, "{sum} vs {exact}");
        assert!(cov[50 * 101 + 50] < 1e-6);
        assert!(cov[50 * 101 + 20] > 1.0 - 1e-6);
        assert_eq!(cov[0], 0.0);
    }
}
