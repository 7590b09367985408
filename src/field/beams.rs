//! Beams and balls as a [`Field`]: the solid of a beam lattice as the 3MF Beam Lattice
//! extension (v1.2) defines it — each beam a conical frustum between two points with a radius
//! at each end, each end closed by a sphere of that radius, the half of it beyond the end, or
//! left flat; each ball a sphere — and the union of them all.
//!
//! Values are exact signed distances to each piece (Quilez's exact capped-cone distance for
//! the frustum; a half sphere is a sphere cut by the end's plane, `max` of the two), and their
//! `min` over the pieces: the exact distance outside the union, a lower bound on it inside —
//! so the value's magnitude is a clearance. Pieces are listed in a uniform grid of bins, each
//! bin holding the pieces that come within the *reach* of it; beyond the reach of every piece
//! the value is the reach, so a sample looks at a few pieces, not all.

use super::{Aabb, Field, Vec3};
pub use crate::io::threemf::Cap;

/// A piece of the solid.
#[derive(Debug, Clone, Copy)]
enum Piece {
    /// A frustum from `a` to `b` with radii `ra`, `rb`, its ends capped.
    Beam {
        a: Vec3,
        b: Vec3,
        ra: f64,
        rb: f64,
        caps: [Cap; 2],
    },
    /// A sphere.
    Ball { c: Vec3, r: f64 },
}

fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn norm(a: Vec3) -> f64 {
    dot(a, a).sqrt()
}

impl Piece {
    fn distance(&self, p: Vec3) -> f64 {
        match *self {
            Piece::Ball { c, r } => norm(sub(p, c)) - r,
            Piece::Beam { a, b, ra, rb, caps } => {
                let mut d = capped_cone(p, a, b, ra, rb);
                let ab = sub(b, a);
                let l = norm(ab);
                for (end, r, cap, outward) in [(a, ra, caps[0], -1.0), (b, rb, caps[1], 1.0)] {
                    let s = norm(sub(p, end)) - r;
                    d = d.min(match cap {
                        Cap::Sphere => s,
                        Cap::Butt => continue,
                        // The half space beyond the end: `(p − end)·u ≥ 0`, u pointing away
                        // from the beam.
                        Cap::Hemisphere => s.max(-outward * dot(sub(p, end), ab) / l),
                    });
                }
                d
            }
        }
    }

    /// The piece's bounding box.
    fn bounds(&self) -> Aabb {
        match *self {
            Piece::Ball { c, r } => Aabb {
                min: c.map(|x| x - r),
                max: c.map(|x| x + r),
            },
            Piece::Beam { a, b, ra, rb, .. } => {
                let r = ra.max(rb);
                Aabb {
                    min: [0, 1, 2].map(|k| a[k].min(b[k]) - r),
                    max: [0, 1, 2].map(|k| a[k].max(b[k]) + r),
                }
            }
        }
    }
}

/// Quilez's exact signed distance to the conical frustum from `a` (radius `ra`) to `b`
/// (radius `rb`), flat at both ends.
fn capped_cone(p: Vec3, a: Vec3, b: Vec3, ra: f64, rb: f64) -> f64 {
    let rba = rb - ra;
    let ba = sub(b, a);
    let pa = sub(p, a);
    let baba = dot(ba, ba);
    let papa = dot(pa, pa);
    let paba = dot(pa, ba) / baba;
    let x = (papa - paba * paba * baba).max(0.0).sqrt();
    let cax = (x - if paba < 0.5 { ra } else { rb }).max(0.0);
    let cay = (paba - 0.5).abs() - 0.5;
    let k = rba * rba + baba;
    let f = ((rba * (x - ra) + paba * baba) / k).clamp(0.0, 1.0);
    let cbx = x - ra - f * rba;
    let cby = paba - f;
    let s = if cbx < 0.0 && cay < 0.0 { -1.0 } else { 1.0 };
    s * (cax * cax + cay * cay * baba)
        .min(cbx * cbx + cby * cby * baba)
        .sqrt()
}

/// A beam: its two end points, the radius at each and how each is closed.
#[derive(Debug, Clone, Copy)]
pub struct Beam {
    /// End points, mm.
    pub ends: [Vec3; 2],
    /// Radius at each end, mm.
    pub radii: [f64; 2],
    /// How each end is closed.
    pub caps: [Cap; 2],
}

/// Most bins of the index.
const MAX_BINS: usize = 1 << 22;

/// The union of beams and balls, with an index of which pieces reach each bin.
#[derive(Debug, Clone)]
pub struct BeamField {
    pieces: Vec<Piece>,
    /// Values beyond this are reported as this.
    reach: f64,
    /// The pieces' bounds.
    bounds: Aabb,
    /// The bins' grid: lower corner, edge, bins per axis.
    origin: Vec3,
    edge: f64,
    dims: [usize; 3],
    /// Per bin, the range of `items` listing its pieces (CSR).
    start: Vec<u32>,
    items: Vec<u32>,
    /// Per bin, rings of bins (26-neighbourhood) to the nearest bin that lists a piece: a point
    /// in a bin `k` rings away is more than `reach + (k − 1)·edge` from every piece.
    rings: Vec<u16>,
}

/// Distance from `p` to the segment `ab`.
pub fn segment_distance(p: Vec3, a: Vec3, b: Vec3) -> f64 {
    let ab = sub(b, a);
    let ap = sub(p, a);
    let l2 = dot(ab, ab);
    let t = if l2 > 0.0 {
        (dot(ap, ab) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    norm(sub(ap, ab.map(|x| x * t)))
}

impl BeamField {
    /// The union of `beams` and `balls` (centre, radius), exact up to `reach` mm from it.
    /// Beams of zero length are left out (a ball stands for a capped one).
    pub fn new(beams: &[Beam], balls: &[(Vec3, f64)], reach: f64) -> BeamField {
        let mut pieces: Vec<Piece> = Vec::with_capacity(beams.len() + balls.len());
        for b in beams {
            if norm(sub(b.ends[1], b.ends[0])) > 0.0 {
                pieces.push(Piece::Beam {
                    a: b.ends[0],
                    b: b.ends[1],
                    ra: b.radii[0],
                    rb: b.radii[1],
                    caps: b.caps,
                });
            }
        }
        pieces.extend(balls.iter().map(|&(c, r)| Piece::Ball { c, r }));
        let boxes: Vec<Aabb> = pieces.iter().map(Piece::bounds).collect();
        let bounds = boxes.iter().skip(1).fold(
            boxes.first().copied().unwrap_or(Aabb {
                min: [0.0; 3],
                max: [0.0; 3],
            }),
            |u, b| Aabb {
                min: [0, 1, 2].map(|k| u.min[k].min(b.min[k])),
                max: [0, 1, 2].map(|k| u.max[k].max(b.max[k])),
            },
        );
        let grown = bounds.grown(reach);
        let size = grown.size();
        // Bins as small as the reach (a lookup then sees the pieces near the point, a few),
        // no more of them than MAX_BINS.
        let edge = (size[0] * size[1] * size[2] / MAX_BINS as f64)
            .cbrt()
            .max(reach)
            .max(1e-9);
        let dims = size.map(|s| ((s / edge).ceil() as usize).clamp(1, MAX_BINS));
        let cells = dims[0] * dims[1] * dims[2];
        let half_diagonal = 0.5 * 3f64.sqrt() * edge;
        let bin = |c: [usize; 3]| (c[0] * dims[1] + c[1]) * dims[2] + c[2];
        // A piece is listed in the bins whose centre lies within its radius, the reach and
        // the bin's half diagonal of its axis.
        let listed = |n: usize, f: &mut dyn FnMut(usize)| {
            let g = boxes[n].grown(reach);
            let lo = [0, 1, 2].map(|k| {
                (((g.min[k] - grown.min[k]) / edge).floor().max(0.0) as usize).min(dims[k] - 1)
            });
            let hi = [0, 1, 2].map(|k| {
                (((g.max[k] - grown.min[k]) / edge).floor().max(0.0) as usize).min(dims[k] - 1)
            });
            let (a, b, r) = match pieces[n] {
                Piece::Beam { a, b, ra, rb, .. } => (a, b, ra.max(rb)),
                Piece::Ball { c, r } => (c, c, r),
            };
            for i in lo[0]..=hi[0] {
                for j in lo[1]..=hi[1] {
                    for k in lo[2]..=hi[2] {
                        let c = [i, j, k];
                        let centre = [0, 1, 2].map(|x| grown.min[x] + (c[x] as f64 + 0.5) * edge);
                        if segment_distance(centre, a, b) <= r + reach + half_diagonal {
                            f(bin(c));
                        }
                    }
                }
            }
        };
        let mut count = vec![0u32; cells + 1];
        for n in 0..pieces.len() {
            listed(n, &mut |c| count[c + 1] += 1);
        }
        for c in 1..=cells {
            count[c] += count[c - 1];
        }
        let mut fill = count.clone();
        let mut items = vec![0u32; count[cells] as usize];
        for n in 0..pieces.len() {
            listed(n, &mut |c| {
                items[fill[c] as usize] = n as u32;
                fill[c] += 1;
            });
        }
        // Rings to the nearest listing bin: breadth first from all of them at once.
        let mut rings = vec![u16::MAX; cells];
        let mut front: Vec<usize> = (0..cells).filter(|&c| count[c + 1] > count[c]).collect();
        for &c in &front {
            rings[c] = 0;
        }
        let mut ring = 0u16;
        while !front.is_empty() && ring < u16::MAX - 1 {
            ring += 1;
            let mut next = Vec::new();
            for c in front {
                let (i, j, k) = (
                    c / (dims[1] * dims[2]),
                    (c / dims[2]) % dims[1],
                    c % dims[2],
                );
                for di in -1i64..=1 {
                    for dj in -1i64..=1 {
                        for dk in -1i64..=1 {
                            let n = [i as i64 + di, j as i64 + dj, k as i64 + dk];
                            if (0..3).any(|x| n[x] < 0 || n[x] >= dims[x] as i64) {
                                continue;
                            }
                            let nb = bin(n.map(|x| x as usize));
                            if rings[nb] == u16::MAX {
                                rings[nb] = ring;
                                next.push(nb);
                            }
                        }
                    }
                }
            }
            front = next;
        }
        BeamField {
            pieces,
            reach,
            bounds,
            origin: grown.min,
            edge,
            dims,
            start: count,
            items,
            rings,
        }
    }

    /// The bounding box of the beams and balls.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// Whether there is no piece.
    pub fn is_empty(&self) -> bool {
        self.pieces.is_empty()
    }

    /// The bin holding `p`, or `None` outside the bins.
    fn bin_of(&self, p: Vec3) -> Option<usize> {
        let mut c = [0usize; 3];
        for k in 0..3 {
            let x = (p[k] - self.origin[k]) / self.edge;
            if !(x >= 0.0 && x < self.dims[k] as f64) {
                return None;
            }
            c[k] = x as usize;
        }
        Some((c[0] * self.dims[1] + c[1]) * self.dims[2] + c[2])
    }

    fn listed(&self, b: usize) -> &[u32] {
        &self.items[self.start[b] as usize..self.start[b + 1] as usize]
    }

    /// The value at `p` and the piece that gives it (`None` beyond the reach).
    fn nearest(&self, p: Vec3) -> (f64, Option<u32>) {
        let Some(b) = self.bin_of(p) else {
            return (self.reach, None);
        };
        let mut best = (self.reach, None);
        for &i in self.listed(b) {
            let d = self.pieces[i as usize].distance(p);
            if d < best.0 {
                best = (d, Some(i));
            }
        }
        best
    }
}

impl Field for BeamField {
    fn value(&self, p: Vec3) -> f64 {
        self.nearest(p).0
    }

    fn clearance(&self, p: Vec3) -> f64 {
        match self.bin_of(p) {
            // Outside the bins: at least the reach from every piece, and beyond their bounds.
            None => self.reach.max(self.bounds.value(p)),
            Some(b) if self.start[b] == self.start[b + 1] => {
                let k = self.rings[b];
                if k == u16::MAX {
                    f64::INFINITY
                } else {
                    self.reach + (k as f64 - 1.0).max(0.0) * self.edge
                }
            }
            Some(_) => self.value(p).abs(),
        }
    }

    /// The nearest piece's value and gradient (by central differences of that piece alone).
    fn implicit_with_gradient(&self, p: Vec3) -> (f64, Vec3) {
        match self.nearest(p) {
            (v, Some(i)) => {
                let piece = &self.pieces[i as usize];
                (v, super::numeric_gradient(|q| piece.distance(q), p))
            }
            (v, None) => (v, super::numeric_gradient(|q| self.value(q), p)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn beam(a: Vec3, b: Vec3, ra: f64, rb: f64, caps: [Cap; 2]) -> Beam {
        Beam {
            ends: [a, b],
            radii: [ra, rb],
            caps,
        }
    }

    #[test]
    fn capsule_cone_and_caps_distances() {
        let f = BeamField::new(
            &[beam([0.0; 3], [10.0, 0.0, 0.0], 1.0, 1.0, [Cap::Sphere; 2])],
            &[],
            5.0,
        );
        assert!((f.value([5.0, 3.0, 0.0]) - 2.0).abs() < 1e-12);
        assert!((f.value([-2.0, 0.0, 0.0]) - 1.0).abs() < 1e-12);
        assert!((f.value([5.0, 0.0, 0.0]) + 1.0).abs() < 1e-12);
        // Far away: the reach.
        assert_eq!(f.value([50.0, 0.0, 0.0]), 5.0);
        assert!(f.clearance([50.0, 0.0, 0.0]) >= 39.0);
        // Butt ends: flat at x = 0; the rim is a circle of radius 1 there.
        let f = BeamField::new(
            &[beam([0.0; 3], [10.0, 0.0, 0.0], 1.0, 2.0, [Cap::Butt; 2])],
            &[],
            5.0,
        );
        assert!((f.value([-2.0, 0.0, 0.0]) - 2.0).abs() < 1e-12);
        assert!((f.value([-1.0, 4.0, 0.0]) - 10f64.sqrt()).abs() < 1e-12);
        // The cone's side at the middle: radius 1.5, slope 1/10.
        let d = f.value([5.0, 3.0, 0.0]);
        let exact = 1.5 / (1.0 + 0.01f64).sqrt();
        assert!((d - exact).abs() < 1e-12, "{d} {exact}");
        // A hemisphere cap at b: beyond it as a sphere, beside it not.
        let f = BeamField::new(
            &[beam(
                [0.0; 3],
                [10.0, 0.0, 0.0],
                1.0,
                1.0,
                [Cap::Butt, Cap::Hemisphere],
            )],
            &[],
            5.0,
        );
        assert!((f.value([12.0, 0.0, 0.0]) - 1.0).abs() < 1e-12);
        assert!((f.value([-2.0, 0.0, 0.0]) - 2.0).abs() < 1e-12);
        // Balls.
        let f = BeamField::new(&[], &[([1.0, 2.0, 3.0], 0.5)], 2.0);
        assert!((f.value([1.0, 2.0, 4.0]) - 0.5).abs() < 1e-12);
    }

    /// Over many beams, the binned union equals the union of every piece up to the reach,
    /// and the clearance never exceeds the true distance.
    #[test]
    fn bins_give_the_union_of_every_piece() {
        let mut s = 12345u64;
        let mut rnd = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut beams = Vec::new();
        for _ in 0..300 {
            let a = [rnd() * 20.0, rnd() * 20.0, rnd() * 20.0];
            let b = [0, 1, 2].map(|k| a[k] + (rnd() - 0.5) * 6.0);
            let caps = [Cap::Sphere, Cap::Hemisphere, Cap::Butt];
            beams.push(beam(
                a,
                b,
                0.2 + rnd() * 0.5,
                0.2 + rnd() * 0.5,
                [caps[(rnd() * 3.0) as usize], caps[(rnd() * 3.0) as usize]],
            ));
        }
        let balls = vec![([10.0, 10.0, 10.0], 1.5), ([0.0, 20.0, 5.0], 0.7)];
        let reach = 1.0;
        let f = BeamField::new(&beams, &balls, reach);
        assert_eq!(f.pieces.len(), 302);
        assert!(f.rings.iter().any(|&k| k > 1));
        for _ in 0..20000 {
            let p = [0, 1, 2].map(|_| rnd() * 30.0 - 5.0);
            let exact = f
                .pieces
                .iter()
                .map(|q| q.distance(p))
                .fold(f64::INFINITY, f64::min);
            let v = f.value(p);
            assert!((v - exact.min(reach)).abs() < 1e-12, "{p:?}: {v} {exact}");
            assert!(f.clearance(p) <= exact.abs() + 1e-12);
        }
    }
}
