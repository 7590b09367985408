//! Mesh: indexed triangles, wound counter-clockwise seen from outside, in millimetres.
//!
//! Measures here (volume by the divergence theorem, area, bounds, edge incidence) are latvox's
//! own; `verify` re-measures with CGAL, independently.

use crate::field::{Aabb, Vec3};

/// An indexed triangle mesh with flat storage (`positions` in xyz triples, `indices` in triples).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Mesh {
    pub positions: Vec<f32>,
    pub indices: Vec<u32>,
}

/// Edge incidence counts: how many edges are bounded by one, two, or more triangles.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct EdgeStats {
    pub edges: u64,
    /// Edges with exactly one incident triangle (holes).
    pub boundary: u64,
    /// Edges with three or more incident triangles.
    pub non_manifold: u64,
    /// Edges whose two triangles traverse them in the same direction (inconsistent winding).
    pub misoriented: u64,
}

impl Mesh {
    pub fn vertex_count(&self) -> usize {
        self.positions.len() / 3
    }

    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    pub fn vertex(&self, i: u32) -> Vec3 {
        let i = i as usize * 3;
        [
            self.positions[i] as f64,
            self.positions[i + 1] as f64,
            self.positions[i + 2] as f64,
        ]
    }

    pub fn triangle(&self, t: usize) -> [Vec3; 3] {
        let i = &self.indices[3 * t..3 * t + 3];
        [self.vertex(i[0]), self.vertex(i[1]), self.vertex(i[2])]
    }

    /// Signed enclosed volume (positive for an outward closed mesh), mm³.
    pub fn volume(&self) -> f64 {
        use rayon::prelude::*;
        (0..self.triangle_count())
            .into_par_iter()
            .map(|t| {
                let [a, b, c] = self.triangle(t);
                dot(a, cross(b, c)) / 6.0
            })
            .sum()
    }

    /// Total surface area, mm².
    pub fn area(&self) -> f64 {
        use rayon::prelude::*;
        (0..self.triangle_count())
            .into_par_iter()
            .map(|t| {
                let [a, b, c] = self.triangle(t);
                0.5 * norm(cross(sub(b, a), sub(c, a)))
            })
            .sum()
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
            0., 0., 0., 1., 0., 0., 1., 1., 0., 0., 1., 0., 0., 0., 1., 1., 0., 1., 1., 1., 1., 0., 1.,
            1.,
        ];
        let indices = vec![
            0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4, 1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6,
            3, 0, 4, 3, 4, 7,
        ];
        Mesh { positions, indices }
    }

    #[test]
    fn cube_measures() {
        let m = cube();
        assert!((m.volume() - 1.0).abs() < 1e-12);
        assert!((m.area() - 6.0).abs() < 1e-12);
        let s = m.edge_stats();
        assert_eq!((s.edges, s.boundary, s.non_manifold, s.misoriented), (18, 0, 0, 0));
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
