//! The mesh type: indexed triangles, wound counter-clockwise seen from outside, in millimetres.
//!
//! Measures here (volume by the divergence theorem, area, bounds, edge incidence) are latvox's
//! own; [`crate::verify::cgal`] re-measures with CGAL, independently.

use super::{Aabb, Vec3};

/// An indexed triangle mesh with flat storage (`positions` in xyz triples, `indices` in triples).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Mesh {
    /// Vertex coordinates, mm: x, y, z of vertex `i` at `3i..3i + 3`.
    pub positions: Vec<f32>,
    /// Vertex indices, three per triangle.
    pub indices: Vec<u32>,
}

/// Edge incidence counts: how many edges are bounded by one, two, or more triangles.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct EdgeStats {
    /// Distinct edges (vertex pairs).
    pub edges: u64,
    /// Edges with exactly one incident triangle (holes).
    pub boundary: u64,
    /// Edges with three or more incident triangles.
    pub non_manifold: u64,
    /// Edges whose two triangles traverse them in the same direction (inconsistent winding).
    pub misoriented: u64,
}

impl Mesh {
    /// The axis-aligned box `lo..hi`: 8 vertices, 12 facets wound outward.
    pub fn cuboid(lo: [f32; 3], hi: [f32; 3]) -> Mesh {
        let mut positions = Vec::with_capacity(24);
        for i in 0..8 {
            for (a, (l, h)) in lo.iter().zip(hi).enumerate() {
                positions.push(if i >> a & 1 == 1 { h } else { *l });
            }
        }
        let mut indices = Vec::with_capacity(36);
        for q in [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ] {
            indices.extend([q[0], q[1], q[2], q[0], q[2], q[3]]);
        }
        Mesh { positions, indices }
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len() / 3
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// Vertex `i`'s position, mm.
    pub fn vertex(&self, i: u32) -> Vec3 {
        let i = i as usize * 3;
        [
            self.positions[i] as f64,
            self.positions[i + 1] as f64,
            self.positions[i + 2] as f64,
        ]
    }

    /// The three corners of triangle `t`, mm.
    pub fn triangle(&self, t: usize) -> [Vec3; 3] {
        let i = &self.indices[3 * t..3 * t + 3];
        [self.vertex(i[0]), self.vertex(i[1]), self.vertex(i[2])]
    }

    /// Signed enclosed volume (positive for an outward closed mesh), mm³.
    pub fn volume(&self) -> f64 {
        ordered_sum(self.triangle_count(), |t| {
            let [a, b, c] = self.triangle(t);
            signed_volume(a, b, c)
        })
    }

    /// Total surface area, mm².
    pub fn area(&self) -> f64 {
        ordered_sum(self.triangle_count(), |t| {
            let [a, b, c] = self.triangle(t);
            triangle_area(a, b, c)
        })
    }

    /// Volume of the part of the enclosed solid that lies inside `b`, mm³.
    ///
    /// Along every vertical line the solid is the union of intervals between entry and exit
    /// crossings, so the solid's length within `[z₀, z₁]` is `Σ ± clamp(z, z₀, z₁)` over the
    /// crossings. Integrating over the box's xy-rectangle gives a sum over triangles of
    /// `∫ clamp(z) dA` on each triangle's projection clipped to the rectangle, signed by the
    /// triangle's facing. Exact for a closed, outward mesh (up to rounding).
    pub fn volume_in_box(&self, b: &Aabb) -> f64 {
        ordered_sum(self.triangle_count(), |t| {
            clipped_column_integral(self.triangle(t), b)
        })
    }

    /// Axis-aligned bounds of the vertices; `None` for an empty mesh.
    pub fn bounds(&self) -> Option<Aabb> {
        if self.positions.is_empty() {
            return None;
        }
        let mut min = [f64::INFINITY; 3];
        let mut max = [f64::NEG_INFINITY; 3];
        for p in self.positions.chunks_exact(3) {
            for a in 0..3 {
                min[a] = min[a].min(p[a] as f64);
                max[a] = max[a].max(p[a] as f64);
            }
        }
        Some(Aabb { min, max })
    }

    /// Edge incidence by sorting directed half-edges.
    pub fn edge_stats(&self) -> EdgeStats {
        let mut half: Vec<(u32, u32, bool)> = Vec::with_capacity(self.indices.len());
        for t in self.indices.chunks_exact(3) {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                half.push((a.min(b), a.max(b), a < b));
            }
        }
        half.sort_unstable();
        let mut s = EdgeStats::default();
        let mut i = 0;
        while i < half.len() {
            let mut j = i;
            while j < half.len() && half[j].0 == half[i].0 && half[j].1 == half[i].1 {
                j += 1;
            }
            s.edges += 1;
            match j - i {
                1 => s.boundary += 1,
                2 => {
                    if half[i].2 == half[i + 1].2 {
                        s.misoriented += 1
                    }
                }
                _ => s.non_manifold += 1,
            }
            i = j;
        }
        s
    }

    /// Reverses every triangle's winding.
    pub fn flip(&mut self) {
        for t in self.indices.chunks_exact_mut(3) {
            t.swap(1, 2);
        }
    }
}

/// `Σ f(i)` for `i < n`, in parallel but always added in the same order, so a measure (and the
/// calibrated level built on it) does not change with the thread count or scheduling.
pub fn ordered_sum(n: usize, f: impl Fn(usize) -> f64 + Sync) -> f64 {
    use rayon::prelude::*;
    const CHUNK: usize = 4096;
    let partial: Vec<f64> = (0..n.div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| (c * CHUNK..((c + 1) * CHUNK).min(n)).map(&f).sum())
        .collect();
    partial.iter().sum()
}

/// Clips a convex polygon to the half-space `s·p[axis] ≤ s·c`.
fn clip_polygon(poly: &[Vec3], axis: usize, c: f64, s: f64, out: &mut Vec<Vec3>) {
    out.clear();
    for i in 0..poly.len() {
        let (p, q) = (poly[i], poly[(i + 1) % poly.len()]);
        let (dp, dq) = (s * (p[axis] - c), s * (q[axis] - c));
        if dp <= 0.0 {
            out.push(p);
        }
        if (dp < 0.0 && dq > 0.0) || (dp > 0.0 && dq < 0.0) {
            let t = dp / (dp - dq);
            out.push([0, 1, 2].map(|k| p[k] + t * (q[k] - p[k])));
        }
    }
}

/// Signed xy-area and xy-centroid integral of `z` over a planar polygon: returns
/// `(∫dA, ∫z dA)` with the sign of the polygon's orientation seen from +z.
fn xy_moments(poly: &[Vec3]) -> (f64, f64) {
    if poly.len() < 3 {
        return (0.0, 0.0);
    }
    let mut area = 0.0;
    let mut zint = 0.0;
    let o = poly[0];
    for i in 1..poly.len() - 1 {
        let (p, q) = (poly[i], poly[i + 1]);
        let a = 0.5 * ((p[0] - o[0]) * (q[1] - o[1]) - (q[0] - o[0]) * (p[1] - o[1]));
        area += a;
        zint += a * (o[2] + p[2] + q[2]) / 3.0;
    }
    (area, zint)
}

pub(crate) fn clipped_column_integral(tri: [Vec3; 3], b: &Aabb) -> f64 {
    let lo = |a: usize| tri[0][a].min(tri[1][a]).min(tri[2][a]);
    let hi = |a: usize| tri[0][a].max(tri[1][a]).max(tri[2][a]);
    // Most triangles need no clipping: wholly beside the box's columns, or wholly within them
    // and below, inside or above the box.
    if (0..2).any(|a| hi(a) <= b.min[a] || lo(a) >= b.max[a]) || hi(2) <= b.min[2] {
        return 0.0;
    }
    let (z0, z1) = (b.min[2], b.max[2]);
    if (0..2).all(|a| lo(a) >= b.min[a] && hi(a) <= b.max[a]) {
        if lo(2) >= z1 {
            return (z1 - z0) * xy_moments(&tri).0;
        }
        if lo(2) >= z0 && hi(2) <= z1 {
            let (a, zint) = xy_moments(&tri);
            return zint - z0 * a;
        }
    }
    let mut poly = tri.to_vec();
    let mut tmp = Vec::with_capacity(8);
    for (axis, c, s) in [
        (0, b.min[0], -1.0),
        (0, b.max[0], 1.0),
        (1, b.min[1], -1.0),
        (1, b.max[1], 1.0),
    ] {
        clip_polygon(&poly, axis, c, s, &mut tmp);
        std::mem::swap(&mut poly, &mut tmp);
        if poly.len() < 3 {
            return 0.0;
        }
    }
    // Part between the two planes contributes ∫(z − z0); part above contributes (z1 − z0)·A.
    // A piece lying in the plane z = z1 would be kept by both clips: it is above.
    let (pz0, pz1) = poly
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p[2]), b.max(p[2]))
        });
    if pz0 >= z1 {
        return (z1 - z0) * xy_moments(&poly).0;
    }
    if pz1 <= z1 && pz0 >= z0 {
        let (a, zint) = xy_moments(&poly);
        return zint - z0 * a;
    }
    let mut mid = Vec::with_capacity(8);
    clip_polygon(&poly, 2, z1, 1.0, &mut tmp);
    clip_polygon(&tmp, 2, z0, -1.0, &mut mid);
    let (am, zm) = xy_moments(&mid);
    let mut above = Vec::with_capacity(8);
    clip_polygon(&poly, 2, z1, -1.0, &mut above);
    let (aa, _) = xy_moments(&above);
    (zm - z0 * am) + (z1 - z0) * aa
}

/// Triangle `abc`'s term of the divergence-theorem volume: the signed volume of the tetrahedron
/// it spans with the origin, mm³ (summed over a closed, outward mesh: the enclosed volume).
pub fn signed_volume(a: Vec3, b: Vec3, c: Vec3) -> f64 {
    dot(a, cross(b, c)) / 6.0
}

/// Triangle `abc`'s area, mm².
pub fn triangle_area(a: Vec3, b: Vec3, c: Vec3) -> f64 {
    0.5 * norm(cross(sub(b, a), sub(c, a)))
}

pub(crate) fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub(crate) fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub(crate) fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(crate) fn norm(a: Vec3) -> f64 {
    dot(a, a).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit cube, 12 triangles, outward.
    pub(crate) fn cube() -> Mesh {
        let positions = vec![
            0., 0., 0., 1., 0., 0., 1., 1., 0., 0., 1., 0., 0., 0., 1., 1., 0., 1., 1., 1., 1., 0.,
            1., 1.,
        ];
        let indices = vec![
            0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4, 1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7,
            6, 3, 0, 4, 3, 4, 7,
        ];
        Mesh { positions, indices }
    }

    #[test]
    fn cube_measures() {
        let m = cube();
        assert!((m.volume() - 1.0).abs() < 1e-12);
        assert!((m.area() - 6.0).abs() < 1e-12);
        let s = m.edge_stats();
        assert_eq!(
            (s.edges, s.boundary, s.non_manifold, s.misoriented),
            (18, 0, 0, 0)
        );
    }

    #[test]
    fn volume_in_box_of_a_cube() {
        let m = cube();
        let b = |min: Vec3, max: Vec3| Aabb { min, max };
        assert!((m.volume_in_box(&b([-1.0; 3], [2.0; 3])) - 1.0).abs() < 1e-12);
        assert!((m.volume_in_box(&b([0.5, -1.0, -1.0], [2.0; 3])) - 0.5).abs() < 1e-12);
        let v = m.volume_in_box(&b([0.25, 0.5, 0.1], [0.75, 3.0, 0.3]));
        assert!((v - 0.5 * 0.5 * 0.2).abs() < 1e-12, "{v}");
        assert!(m.volume_in_box(&b([2.0; 3], [3.0; 3])).abs() < 1e-12);
    }

    #[test]
    fn flipped_cube_is_negative_and_hole_is_counted() {
        let mut m = cube();
        m.flip();
        assert!((m.volume() + 1.0).abs() < 1e-12);
        m.indices.truncate(33);
        let s = m.edge_stats();
        assert_eq!(s.boundary, 3);
    }
}
