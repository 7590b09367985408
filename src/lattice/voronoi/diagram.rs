//! The Voronoi diagram of points in space, as the dual of their Delaunay triangulation by CGAL
//! (`cpp/cgal_voronoi.cc`): vertices (the Delaunay cells' circumcentres), edges between them,
//! and faces, each the convex polygon between two points. Only the finite diagram is given:
//! the cells of points on the hull reach infinity and their unbounded edges and faces are left
//! out, so a caller seeds beyond the region it uses.
//!
//! [`Voronoi::merged`] joins vertices closer than a length (four points on a sphere, as in a
//! regular lattice, give a vertex several times over; near-degenerate ones give edges far
//! shorter than any voxel) and drops the edges and faces that vanish.

use crate::error::Result;
use crate::ffi::{cgal::ffi, Backend};
use crate::geom::Vec3;

/// A Voronoi face: the polygon between two points.
#[derive(Debug, Clone)]
pub struct Face {
    /// The two points (indices into [`Voronoi::seeds`]) the face lies between.
    pub seeds: [u32; 2],
    /// Its vertices, in order around it.
    pub vertices: Vec<u32>,
}

/// The finite part of the Voronoi diagram of a set of points.
#[derive(Debug, Clone)]
pub struct Voronoi {
    /// The points.
    pub seeds: Vec<Vec3>,
    /// Voronoi vertices.
    pub vertices: Vec<Vec3>,
    /// Edges as vertex pairs, each once.
    pub edges: Vec<[u32; 2]>,
    /// Faces.
    pub faces: Vec<Face>,
}

fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn norm(a: Vec3) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

impl Voronoi {
    /// The diagram of `seeds` (coincident points count once: the later ones have empty cells).
    pub fn of(seeds: &[Vec3]) -> Result<Voronoi> {
        let flat: Vec<f64> = seeds.iter().flatten().copied().collect();
        let d = ffi::cgal_voronoi(&flat).backend("computing the Voronoi diagram")?;
        let vertices = d
            .vertices
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect();
        let edges = d.edges.chunks_exact(2).map(|c| [c[0], c[1]]).collect();
        let faces = d
            .face_seeds
            .chunks_exact(2)
            .zip(d.face_starts.windows(2))
            .map(|(s, w)| Face {
                seeds: [s[0], s[1]],
                vertices: d.face_vertices[w[0] as usize..w[1] as usize].to_vec(),
            })
            .collect();
        Ok(Voronoi {
            seeds: seeds.to_vec(),
            vertices,
            edges,
            faces,
        })
    }

    /// The diagram with vertices closer than `within` joined (each cluster at the mean of
    /// its vertices), the edges that become points and the faces that become segments dropped.
    pub fn merged(&self, within: f64) -> Voronoi {
        let n = self.vertices.len();
        let mut parent: Vec<u32> = (0..n as u32).collect();
        fn root(parent: &mut [u32], mut i: u32) -> u32 {
            while parent[i as usize] != i {
                let up = parent[parent[i as usize] as usize];
                parent[i as usize] = up;
                i = up;
            }
            i
        }
        for &[a, b] in &self.edges {
            if norm(sub(self.vertices[a as usize], self.vertices[b as usize])) < within {
                let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
                if ra != rb {
                    parent[ra.max(rb) as usize] = ra.min(rb);
                }
            }
        }
        // Renumber the surviving vertices in order, each at the mean of the vertices merged
        // into it (so that translated copies of a diagram merge into translated vertices).
        let mut new = vec![u32::MAX; n];
        let mut sums: Vec<(Vec3, f64)> = Vec::new();
        for i in 0..n as u32 {
            let r = root(&mut parent, i);
            if new[r as usize] == u32::MAX {
                new[r as usize] = sums.len() as u32;
                sums.push(([0.0; 3], 0.0));
            }
            new[i as usize] = new[r as usize];
            let (sum, count) = &mut sums[new[i as usize] as usize];
            let v = self.vertices[i as usize];
            *sum = [0, 1, 2].map(|k| sum[k] + v[k]);
            *count += 1.0;
        }
        let vertices: Vec<Vec3> = sums
            .iter()
            .map(|(sum, count)| sum.map(|x| x / count))
            .collect();
        let mut edges: Vec<[u32; 2]> = self
            .edges
            .iter()
            .map(|&[a, b]| {
                let (a, b) = (new[a as usize], new[b as usize]);
                [a.min(b), a.max(b)]
            })
            .filter(|e| e[0] != e[1])
            .collect();
        edges.sort_unstable();
        edges.dedup();
        let faces = self
            .faces
            .iter()
            .filter_map(|f| {
                let mut v: Vec<u32> = f.vertices.iter().map(|&i| new[i as usize]).collect();
                v.dedup();
                while v.len() > 1 && v.first() == v.last() {
                    v.pop();
                }
                (v.len() >= 3).then_some(Face {
                    seeds: f.seeds,
                    vertices: v,
                })
            })
            .collect();
        Voronoi {
            seeds: self.seeds.clone(),
            vertices,
            edges,
            faces,
        }
    }

    /// A face's area, mm².
    pub fn face_area(&self, f: &Face) -> f64 {
        let p = |i: u32| self.vertices[i as usize];
        let o = p(f.vertices[0]);
        let mut s = [0.0; 3];
        for w in f.vertices[1..].windows(2) {
            let c = cross(sub(p(w[0]), o), sub(p(w[1]), o));
            s = [s[0] + c[0], s[1] + c[1], s[2] + c[2]];
        }
        0.5 * norm(s)
    }

    /// The volume of each seed's cell, mm³, from its faces (each the base of a pyramid with its
    /// apex at the seed, as high as half the distance to the other seed). Exact for a cell
    /// whose faces are all finite; smaller for one on the hull.
    pub fn cell_volumes(&self) -> Vec<f64> {
        let mut v = vec![0.0; self.seeds.len()];
        for f in &self.faces {
            let [a, b] = f.seeds;
            let h = 0.5 * norm(sub(self.seeds[a as usize], self.seeds[b as usize]));
            let pyramid = self.face_area(f) * h / 3.0;
            v[a as usize] += pyramid;
            v[b as usize] += pyramid;
        }
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The body-centred cubic points' Voronoi cells are truncated octahedra of half the
    /// cube's volume, with 14 faces (6 squares, 8 hexagons) and 24 vertices each.
    #[test]
    fn bcc_points_give_kelvin_cells() {
        let mut seeds = Vec::new();
        for i in -2..=2 {
            for j in -2..=2 {
                for k in -2..=2 {
                    let c = [i as f64, j as f64, k as f64];
                    seeds.push(c);
                    seeds.push(c.map(|x| x + 0.5));
                }
            }
        }
        let d = Voronoi::of(&seeds).unwrap().merged(1e-9);
        let centre = seeds.iter().position(|&s| s == [0.0; 3]).unwrap() as u32;
        let faces: Vec<&Face> = d
            .faces
            .iter()
            .filter(|f| f.seeds.contains(&centre))
            .collect();
        assert_eq!(faces.len(), 14);
        let mut sides: Vec<usize> = faces.iter().map(|f| f.vertices.len()).collect();
        sides.sort();
        assert_eq!(sides, [[4; 6].as_slice(), &[6; 8]].concat());
        let volume = d.cell_volumes()[centre as usize];
        assert!((volume - 0.5).abs() < 1e-9, "{volume}");
        let mut corners: Vec<u32> = faces.iter().flat_map(|f| f.vertices.clone()).collect();
        corners.sort();
        corners.dedup();
        assert_eq!(corners.len(), 24);
    }
}
