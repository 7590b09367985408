//! A scanned point cloud made ready for a distance field: a k-d tree over the points, each
//! point's local spacing and the surface area it stands for, and an outward unit normal per
//! point.
//!
//! Normals a file does not give are estimated as Hoppe et al. do ("Surface reconstruction from
//! unorganized points", SIGGRAPH 1992): the least-variance direction of each point's 16 nearest
//! neighbours (principal component analysis), then oriented consistently by walking a minimum
//! spanning tree of the 8-nearest-neighbour graph whose edge weights are `1 − |nᵢ·nⱼ|` (so the
//! walk crosses flat regions before creases), flipping each normal to agree with the one it was
//! reached from; each connected piece starts from its highest point, whose normal points up.
//! Given or estimated, the normals are finally checked against the divergence theorem — the
//! enclosed volume `⅓ Σ aᵢ pᵢ·nᵢ` must be positive for outward normals — and flipped if not.
//!
//! The area a point stands for is `π ρ² / 8`, ρ the distance to its 8th neighbour: a uniform
//! sample with one point per `s²` has about 8 other points within ρ when `π ρ² ≈ 8 s²`.
//!
//! A **plane contour** (points at `z = 0` sampling a closed curve, [`Cloud::in_plane`]) is the
//! same with one dimension less: normals in the plane (the least-variance direction of the
//! neighbours within it), the walk started from the contour's point of largest `y`, and each
//! point standing for a length `2ρ / 8` of the curve.

use crate::error::{Error, Result};
use crate::field::Vec3;
use crate::io::points::PointCloud;
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use rayon::prelude::*;
use std::collections::BinaryHeap;
use std::num::NonZero;

/// Neighbours whose spread gives a point's normal.
const NORMAL_NEIGHBOURS: usize = 16;
/// Neighbours that give a point's spacing, and the graph the orientation walks.
const SPACING_NEIGHBOURS: usize = 8;
/// Fewer points than this cannot enclose a volume whose inside can be told from its outside.
pub const MIN_POINTS: usize = 32;

/// Points with outward normals, local spacings and areas, and a k-d tree over them.
pub struct Cloud {
    /// The points, mm.
    pub points: Vec<Vec3>,
    /// Outward unit normals.
    pub normals: Vec<Vec3>,
    /// Distance from each point to its 8th nearest neighbour, mm.
    pub spacing: Vec<f64>,
    /// The surface area each point stands for, mm².
    pub area: Vec<f64>,
    /// The median of `spacing`, mm.
    pub median_spacing: f64,
    /// Whether the normals were estimated (the file gave none).
    pub normals_estimated: bool,
    /// Whether the normals (given or estimated) had to be flipped to point outward.
    pub normals_flipped: bool,
    /// A plane contour (points at `z = 0`, normals in the plane, `area` a length).
    pub planar: bool,
    tree: ImmutableKdTree<f64, 3>,
}

impl Cloud {
    /// Prepares `cloud`: refuses one with too few points to decide a sign from, estimates and
    /// orients normals the file lacks.
    pub fn new(cloud: PointCloud) -> Result<Cloud> {
        Cloud::prepare(cloud, false)
    }

    /// Prepares a plane contour: points at `z = 0` (and normals, if given, in the plane).
    pub fn in_plane(cloud: PointCloud) -> Result<Cloud> {
        Cloud::prepare(cloud, true)
    }

    fn prepare(cloud: PointCloud, planar: bool) -> Result<Cloud> {
        let PointCloud { points, normals } = cloud;
        if points.is_empty() {
            return Err(Error::invalid("the point cloud is empty"));
        }
        if let Some(p) = points.iter().position(|p| !p.iter().all(|x| x.is_finite())) {
            return Err(Error::invalid(format!(
                "point {p} has a coordinate that is not a finite number"
            )));
        }
        let tree = ImmutableKdTree::new_from_slice(&points);
        let distinct = {
            let mut d = 0;
            for p in &points {
                let n = tree.nearest_n::<SquaredEuclidean>(p, NonZero::new(2).unwrap());
                if n.len() < 2 || n[1].distance > 0.0 {
                    d += 1;
                }
                if d >= MIN_POINTS {
                    break;
                }
            }
            d
        };
        if distinct < MIN_POINTS {
            return Err(Error::invalid(format!(
                "the point cloud has {} distinct points; at least {MIN_POINTS} are needed to tell its inside from its outside",
                distinct
            )));
        }
        // One neighbour query per point serves the spacing, and the normals when they are
        // estimated: each point's nearest (itself first), by increasing distance.
        let k = if normals.is_none() {
            NORMAL_NEIGHBOURS
        } else {
            SPACING_NEIGHBOURS + 1
        };
        let (neighbours, spacing): (Vec<Vec<u32>>, Vec<f64>) = points
            .par_iter()
            .map(|p| {
                let n = tree.nearest_n::<SquaredEuclidean>(p, NonZero::new(k).unwrap());
                let spacing = n
                    .get(SPACING_NEIGHBOURS.min(n.len().saturating_sub(1)))
                    .map_or(0.0, |x| x.distance.sqrt());
                (n.iter().map(|x| x.item as u32).collect(), spacing)
            })
            .unzip();
        let area: Vec<f64> = spacing
            .iter()
            .map(|r| match planar {
                true => 2.0 * r / SPACING_NEIGHBOURS as f64,
                false => std::f64::consts::PI * r * r / SPACING_NEIGHBOURS as f64,
            })
            .collect();
        let normals_estimated = normals.is_none();
        let normals = match normals {
            Some(n) => n,
            None => {
                let mut n = pca_normals(&points, &neighbours, planar);
                let pieces = orient(&points, &neighbours, &mut n, if planar { 1 } else { 2 });
                orient_pieces(&points, &area, &mut n, &pieces, planar);
                n
            }
        };
        let median_spacing = {
            let mut s = spacing.clone();
            let mid = s.len() / 2;
            *s.select_nth_unstable_by(mid, f64::total_cmp).1
        };
        let mut cloud = Cloud {
            points,
            normals,
            median_spacing,
            spacing,
            area,
            normals_estimated,
            normals_flipped: false,
            planar,
            tree,
        };
        if cloud.enclosed_volume() < 0.0 {
            for n in &mut cloud.normals {
                *n = n.map(|x| -x);
            }
            cloud.normals_flipped = true;
        }
        Ok(cloud)
    }

    /// The volume the oriented points enclose, `⅓ Σ aᵢ pᵢ·nᵢ` (positive for outward normals),
    /// taken about the cloud's centroid so that it does not depend on where the part lies; a
    /// plane contour's area, `½ Σ aᵢ pᵢ·nᵢ`.
    pub fn enclosed_volume(&self) -> f64 {
        let c = self.centroid();
        self.points
            .iter()
            .zip(&self.normals)
            .zip(&self.area)
            .map(|((p, n), a)| {
                a * ((p[0] - c[0]) * n[0] + (p[1] - c[1]) * n[1] + (p[2] - c[2]) * n[2])
            })
            .sum::<f64>()
            / if self.planar { 2.0 } else { 3.0 }
    }

    /// The mean of the points.
    pub fn centroid(&self) -> Vec3 {
        let mut c = [0.0; 3];
        for p in &self.points {
            for a in 0..3 {
                c[a] += p[a];
            }
        }
        c.map(|x| x / self.points.len() as f64)
    }

    /// The box around the points.
    pub fn bounds(&self) -> crate::field::Aabb {
        let mut b = crate::field::Aabb {
            min: [f64::INFINITY; 3],
            max: [f64::NEG_INFINITY; 3],
        };
        for p in &self.points {
            b.min = [0, 1, 2].map(|a| b.min[a].min(p[a]));
            b.max = [0, 1, 2].map(|a| b.max[a].max(p[a]));
        }
        b
    }

    /// The `k` nearest points to `q`: (index, squared distance), nearest first.
    pub fn nearest(&self, q: &Vec3, k: usize) -> impl Iterator<Item = (usize, f64)> {
        self.tree
            .nearest_n::<SquaredEuclidean>(q, NonZero::new(k.max(1)).unwrap())
            .into_iter()
            .map(|n| (n.item as usize, n.distance))
    }

    /// The nearest point to `q`: (index, distance).
    pub fn nearest_one(&self, q: &Vec3) -> (usize, f64) {
        let n = self.tree.nearest_one::<SquaredEuclidean>(q);
        (n.item as usize, n.distance.sqrt())
    }
}

/// Each point's least-variance direction among its neighbours (unoriented); within the plane
/// `z = 0` when `planar`.
fn pca_normals(points: &[Vec3], neighbours: &[Vec<u32>], planar: bool) -> Vec<Vec3> {
    neighbours
        .par_iter()
        .map(|near| {
            let mut c = [0.0; 3];
            for &n in near {
                let q = points[n as usize];
                for a in 0..3 {
                    c[a] += q[a];
                }
            }
            c = c.map(|x| x / near.len() as f64);
            let mut m = [[0.0; 3]; 3];
            for &n in near {
                let q = points[n as usize];
                let d = [q[0] - c[0], q[1] - c[1], q[2] - c[2]];
                for i in 0..3 {
                    for j in 0..3 {
                        m[i][j] += d[i] * d[j];
                    }
                }
            }
            if planar {
                // z made the direction of most variance, so the least lies in the plane.
                m[2][2] += 1.0 + m[0][0] + m[1][1];
            }
            least_eigenvector(m)
        })
        .collect()
}

/// The unit eigenvector of the smallest eigenvalue of a symmetric 3×3 matrix (cyclic Jacobi
/// rotations: a handful of sweeps converge to machine precision at this size).
pub fn least_eigenvector(mut a: [[f64; 3]; 3]) -> Vec3 {
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _ in 0..16 {
        let off = a[0][1].abs() + a[0][2].abs() + a[1][2].abs();
        let scale = a[0][0].abs() + a[1][1].abs() + a[2][2].abs();
        if off <= 1e-15 * scale || off == 0.0 {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            for row in a.iter_mut() {
                let (akp, akq) = (row[p], row[q]);
                row[p] = c * akp - s * akq;
                row[q] = s * akp + c * akq;
            }
            let (rp, rq) = (a[p], a[q]);
            a[p] = [0, 1, 2].map(|k| c * rp[k] - s * rq[k]);
            a[q] = [0, 1, 2].map(|k| s * rp[k] + c * rq[k]);
            for row in &mut v {
                let (vp, vq) = (row[p], row[q]);
                row[p] = c * vp - s * vq;
                row[q] = s * vp + c * vq;
            }
        }
    }
    let k = (0..3)
        .min_by(|&i, &j| a[i][i].total_cmp(&a[j][j]))
        .unwrap_or(2);
    let n = [v[0][k], v[1][k], v[2][k]];
    let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if l > 0.0 {
        n.map(|x| x / l)
    } else {
        [0.0, 0.0, 1.0]
    }
}

/// Orients `normals` consistently: a minimum spanning tree of the k-nearest-neighbour graph
/// walked from each piece's highest point along axis `up` (Prim's algorithm), flipping as it
/// goes. Returns the piece (connected component) of each point.
fn orient(points: &[Vec3], nearest: &[Vec<u32>], normals: &mut [Vec3], up: usize) -> Vec<u32> {
    let k = SPACING_NEIGHBOURS + 1;
    let neighbours: Vec<&[u32]> = nearest.iter().map(|n| &n[..k.min(n.len())]).collect();
    // The graph made symmetric, so that a piece is walked whole from any of its points.
    let mut adjacency: Vec<Vec<u32>> = neighbours.iter().map(|n| n.to_vec()).collect();
    for (i, ns) in neighbours.iter().enumerate() {
        for &j in ns.iter() {
            if j as usize != i && !neighbours[j as usize].contains(&(i as u32)) {
                adjacency[j as usize].push(i as u32);
            }
        }
    }
    let mut order: Vec<usize> = (0..points.len()).collect();
    order.sort_by(|&a, &b| points[b][up].total_cmp(&points[a][up]));
    let mut done = vec![false; points.len()];
    let mut piece = vec![0u32; points.len()];
    let mut pieces = 0u32;
    let dot = |a: &Vec3, b: &Vec3| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    // Max-heap on −weight: (weight as ordered bits, to, from).
    let mut heap: BinaryHeap<(std::cmp::Reverse<u64>, u32, u32)> = BinaryHeap::new();
    for &seed in &order {
        if done[seed] {
            continue;
        }
        if normals[seed][up] < 0.0 {
            normals[seed] = normals[seed].map(|x| -x);
        }
        done[seed] = true;
        piece[seed] = pieces;
        let push = |heap: &mut BinaryHeap<_>, normals: &[Vec3], done: &[bool], i: usize| {
            for &j in &adjacency[i] {
                if !done[j as usize] {
                    let w = 1.0 - dot(&normals[i], &normals[j as usize]).abs();
                    heap.push((std::cmp::Reverse(w.max(0.0).to_bits()), j, i as u32));
                }
            }
        };
        push(&mut heap, normals, &done, seed);
        while let Some((_, j, from)) = heap.pop() {
            let (j, from) = (j as usize, from as usize);
            if done[j] {
                continue;
            }
            done[j] = true;
            piece[j] = pieces;
            if dot(&normals[j], &normals[from]) < 0.0 {
                normals[j] = normals[j].map(|x| -x);
            }
            push(&mut heap, normals, &done, j);
        }
        pieces += 1;
    }
    piece
}

/// Pieces whose nesting is decided (the largest; the rest are left enclosing their own side).
const NESTED_PIECES: usize = 64;

/// Orients each piece of a cloud of several (a part with a cavity, a section with a bore) by
/// how deeply it is nested: every piece first made to enclose a positive volume (area), then
/// flipped when the other pieces wind around it an odd number of times — a cavity's outward
/// normals point into the cavity.
fn orient_pieces(points: &[Vec3], area: &[f64], normals: &mut [Vec3], piece: &[u32], planar: bool) {
    let count = piece.iter().map(|&p| p as usize + 1).max().unwrap_or(0);
    if count < 2 {
        return;
    }
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); count];
    for (i, &p) in piece.iter().enumerate() {
        members[p as usize].push(i);
    }
    // Each piece enclosing a positive volume: Σ aᵢ (pᵢ − c)·nᵢ > 0 about its own centre.
    for m in &members {
        let mut c = [0.0; 3];
        for &i in m {
            for a in 0..3 {
                c[a] += points[i][a] / m.len() as f64;
            }
        }
        let v: f64 = m
            .iter()
            .map(|&i| {
                area[i]
                    * (0..3)
                        .map(|a| (points[i][a] - c[a]) * normals[i][a])
                        .sum::<f64>()
            })
            .sum();
        if v < 0.0 {
            for &i in m {
                normals[i] = normals[i].map(|x| -x);
            }
        }
    }
    let mut largest: Vec<usize> = (0..count).collect();
    largest.sort_by_key(|&p| std::cmp::Reverse(members[p].len()));
    largest.truncate(NESTED_PIECES);
    let full = if planar {
        2.0 * std::f64::consts::PI
    } else {
        4.0 * std::f64::consts::PI
    };
    let dipole = if planar {
        crate::geom::winding::dipole_2d
    } else {
        crate::geom::winding::dipole
    };
    // The nesting depth of each piece: the winding number of the others at one of its points.
    let depth: Vec<(usize, i64)> = largest
        .par_iter()
        .map(|&p| {
            let q = points[members[p][0]];
            let w: f64 = (0..points.len())
                .filter(|&i| piece[i] as usize != p)
                .map(|i| dipole(&points[i], &normals[i].map(|x| x * area[i]), &q))
                .sum();
            (p, (w / full).round() as i64)
        })
        .collect();
    for (p, d) in depth {
        if d.rem_euclid(2) == 1 {
            for &i in &members[p] {
                normals[i] = normals[i].map(|x| -x);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn least_eigenvector_of_a_rotated_plane() {
        // Spread along x and y, thin along z, then rotated 30° about x.
        let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
        let r = [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]];
        let d = [4.0, 2.0, 0.01];
        let mut m = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                m[i][j] = (0..3).map(|k| r[i][k] * d[k] * r[j][k]).sum();
            }
        }
        let n = least_eigenvector(m);
        let expect = [0.0, -s, c];
        let dot: f64 = (0..3).map(|a| n[a] * expect[a]).sum();
        assert!((dot.abs() - 1.0).abs() < 1e-9, "{n:?}");
    }
}
