//! The seeds of a Voronoi foam: Poisson-disk points at a mean spacing that may vary through the
//! part, moved toward a body-centred cubic lattice by a regularity, or the user's own.
//!
//! **Spacing.** The spacing `s` is the edge of the mean cell: a region of volume `V` holds
//! `∫ dV / s³` cells. The points are Bridson's Poisson-disk sampling ("Fast Poisson disk
//! sampling in arbitrary dimensions", SIGGRAPH 2007 sketches) with a radius that varies with
//! the point: a candidate `q` is kept when no point lies within `ρ(q) = RADIUS · s(q)` of it.
//! Bridson's 30 tries per point leave a sample close to saturation, whose number density is
//! `1/s³` when `RADIUS` is as measured below; the points are then as even as random points can
//! be (no two closer than `ρ`), which gives Voronoi cells of similar size, as bone and foams have.
//!
//! **Regularity** `R ∈ [0, 1]`: the body-centred cubic sites of the same mean cell (two per
//! cube of edge `2^{1/3} s`, whose Voronoi cells are Kelvin's truncated octahedra) are matched
//! to the points nearest first, each site to one point; a matched point moves `R` of the way
//! to its site, a site left without a point gets one at random within its cell, and a point
//! left without a site is dropped when `R > 0`. `R = 0` is the random foam, `R = 1` the Kelvin
//! foam, and values between are as regular as they say.
//!
//! The points are made by one deterministic generator (splitmix64) from `seed`: the same seed
//! gives the same points, bit for bit.

use crate::error::{Error, Result};
use crate::geom::{Aabb, Vec3};
use kiddo::{KdTree, SquaredEuclidean};
use std::path::Path;

/// The disk radius of the sampling, in spacings: Bridson's sampling with 30 tries at this
/// radius has one point per `s³` (measured on ten 8 000-point samples in a cube of 20 `s`, the
/// points within two spacings of its faces left out: 0.995 points per `s³`, each within 0.015).
pub const RADIUS: f64 = 0.833;

/// Candidates tried around each point before it is retired (Bridson's `k`).
const TRIES: usize = 30;

/// Most seeds a foam may have.
pub const MAX_SEEDS: usize = 20_000_000;

/// A deterministic generator (splitmix64).
#[derive(Debug, Clone)]
pub struct Rng(u64);

impl Rng {
    /// A generator started from `seed`.
    pub fn new(seed: u64) -> Rng {
        Rng(seed ^ 0x6c61_7476_6f78_u64)
    }

    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in the unit ball.
    fn in_ball(&mut self) -> Vec3 {
        loop {
            let v = [0; 3].map(|_| 2.0 * self.unit() - 1.0);
            if v.iter().map(|x| x * x).sum::<f64>() <= 1.0 {
                return v;
            }
        }
    }
}

fn dist2(a: Vec3, b: Vec3) -> f64 {
    (0..3).map(|k| (a[k] - b[k]).powi(2)).sum()
}

/// How many seeds a region of `volume` mm³ at the smallest spacing `s_min` holds at most, and
/// the refusal when that is too many.
pub fn check_count(volume: f64, s_min: f64) -> Result<()> {
    let n = volume / s_min.powi(3);
    if n > MAX_SEEDS as f64 {
        return Err(Error::invalid(format!(
            "the foam would need about {n:.3e} seeds (more than {MAX_SEEDS}): give a larger spacing or a smaller box"
        )));
    }
    Ok(())
}

/// Poisson-disk points filling `region`, at the spacing `spacing(p)` (mm, positive).
pub fn poisson(region: &Aabb, spacing: &dyn Fn(Vec3) -> f64, seed: u64) -> Vec<Vec3> {
    sample(region, spacing, seed, false)
}

/// Poisson-disk points at a uniform `spacing` in `cell` that tile space when the cell is
/// repeated: a point's distance to the others is measured to their nearest copies, and a
/// candidate that leaves the cell comes back through the opposite face. Every point lies in
/// the half-open cell `[min, max)`.
pub fn poisson_periodic(cell: &Aabb, spacing: f64, seed: u64) -> Vec<Vec3> {
    sample(cell, &|_| spacing, seed, true)
}

/// The 27 translates of `p` by whole cells of `size` (itself first).
pub fn images(p: Vec3, size: Vec3) -> impl Iterator<Item = Vec3> {
    (0..27).map(move |n| {
        let shift = [n % 3, (n / 3) % 3, n / 9].map(|x| [0.0, -1.0, 1.0][x]);
        [0, 1, 2].map(|k| p[k] + shift[k] * size[k])
    })
}

/// `p` moved by whole cells of `region` into it (half open).
pub fn wrap(p: Vec3, region: &Aabb) -> Vec3 {
    let size = region.size();
    [0, 1, 2].map(|k| {
        let x = region.min[k] + (p[k] - region.min[k]).rem_euclid(size[k]);
        // rem_euclid may round up to the size itself.
        if x >= region.max[k] {
            region.min[k]
        } else {
            x
        }
    })
}

fn sample(region: &Aabb, spacing: &dyn Fn(Vec3) -> f64, seed: u64, periodic: bool) -> Vec<Vec3> {
    let mut rng = Rng::new(seed);
    let size = region.size();
    let inside = |p: Vec3| (0..3).all(|k| p[k] >= region.min[k] && p[k] <= region.max[k]);
    let mut tree: KdTree<f64, 3> = KdTree::new();
    let mut points: Vec<Vec3> = Vec::new();
    let mut active: Vec<usize> = Vec::new();
    let free = |tree: &KdTree<f64, 3>, q: Vec3, r: f64| {
        tree.size() == 0 || tree.nearest_one::<SquaredEuclidean>(&q).distance >= r * r
    };
    let add =
        |tree: &mut KdTree<f64, 3>, points: &mut Vec<Vec3>, active: &mut Vec<usize>, q: Vec3| {
            if periodic {
                for image in images(q, size) {
                    tree.add(&image, points.len() as u64);
                }
            } else {
                tree.add(&q, points.len() as u64);
            }
            active.push(points.len());
            points.push(q);
        };
    // Start points spread over the region (a thin region may otherwise be reached only round
    // corners): one try per spacing-sized block.
    let s0 = spacing(region.centre()).max(1e-9);
    let blocks = size.map(|x| ((x / s0).ceil() as usize).max(1));
    let starts = (blocks[0] * blocks[1] * blocks[2]).min(4096);
    for _ in 0..starts {
        let mut q = [0, 1, 2].map(|k| region.min[k] + rng.unit() * size[k]);
        if periodic {
            q = wrap(q, region);
        }
        if free(&tree, q, RADIUS * spacing(q)) {
            add(&mut tree, &mut points, &mut active, q);
        }
    }
    while !active.is_empty() {
        let i = (rng.unit() * active.len() as f64) as usize;
        let p = points[active[i]];
        let r = RADIUS * spacing(p);
        let mut placed = false;
        for _ in 0..TRIES {
            // A point of the spherical shell between r and 2r, uniform in volume.
            let d = rng.in_ball();
            let len = dist2(d, [0.0; 3]).sqrt();
            if len < 1e-9 {
                continue;
            }
            let t = r * (1.0 + 7.0 * rng.unit()).cbrt() / len;
            let mut q = [0, 1, 2].map(|k| p[k] + d[k] * t);
            if periodic {
                q = wrap(q, region);
            } else if !inside(q) {
                continue;
            }
            if free(&tree, q, RADIUS * spacing(q)) {
                add(&mut tree, &mut points, &mut active, q);
                placed = true;
                break;
            }
        }
        if !placed {
            active.swap_remove(i);
        }
    }
    points
}

/// `points` moved `regularity` of the way toward the body-centred cubic sites of cells of
/// `spacing` (see the module's notes); `region` is where the points were made. When
/// `periodic`, the region is a cell that tiles space: the sites' cube is adjusted to a whole
/// number per cell, distances are to the nearest copies, and the points stay in the cell.
pub fn regularise(
    points: &[Vec3],
    region: &Aabb,
    spacing: f64,
    regularity: f64,
    seed: u64,
    periodic: bool,
) -> Vec<Vec3> {
    if regularity <= 0.0 {
        return points.to_vec();
    }
    // Two sites per cube of edge a: a³ = 2 s³.
    let a0 = 2f64.cbrt() * spacing;
    let size = region.size();
    let mut sites = Vec::new();
    let a = if periodic {
        let n = size.map(|x| (x / a0).round().max(1.0));
        let a = [0, 1, 2].map(|k| size[k] / n[k]);
        for i in 0..n[0] as i64 {
            for j in 0..n[1] as i64 {
                for k in 0..n[2] as i64 {
                    let c = [i, j, k].map(|x| x as f64);
                    sites.push([0, 1, 2].map(|q| region.min[q] + c[q] * a[q]));
                    sites.push([0, 1, 2].map(|q| region.min[q] + (c[q] + 0.5) * a[q]));
                }
            }
        }
        a
    } else {
        let lo = region.min.map(|x| (x / a0).floor() as i64 - 1);
        let hi = region.max.map(|x| (x / a0).ceil() as i64 + 1);
        for i in lo[0]..=hi[0] {
            for j in lo[1]..=hi[1] {
                for k in lo[2]..=hi[2] {
                    let c = [i as f64 * a0, j as f64 * a0, k as f64 * a0];
                    for p in [c, c.map(|x| x + 0.5 * a0)] {
                        if region.contains(p) {
                            sites.push(p);
                        }
                    }
                }
            }
        }
        [a0; 3]
    };
    // Each site with its copies in the neighbouring cells when periodic.
    let copies: Vec<(u32, Vec3)> = sites
        .iter()
        .enumerate()
        .flat_map(|(n, &s)| {
            images(s, size)
                .take(if periodic { 27 } else { 1 })
                .map(move |p| (n as u32, p))
        })
        .collect();
    let mut tree: KdTree<f64, 3> = KdTree::new();
    for (n, (_, p)) in copies.iter().enumerate() {
        tree.add(p, n as u64);
    }
    // Candidate pairs within a cell's reach, nearest first.
    let reach = a.iter().cloned().fold(0.0, f64::max);
    let mut pairs: Vec<(f64, u32, u32)> = Vec::new();
    for (n, p) in points.iter().enumerate() {
        for nb in tree.within_unsorted::<SquaredEuclidean>(p, reach * reach) {
            pairs.push((nb.distance, n as u32, nb.item as u32));
        }
    }
    pairs.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)).then(x.2.cmp(&y.2)));
    let mut copy_of = vec![u32::MAX; points.len()];
    let mut taken = vec![false; sites.len()];
    for &(_, p, c) in &pairs {
        let s = copies[c as usize].0 as usize;
        if copy_of[p as usize] == u32::MAX && !taken[s] {
            copy_of[p as usize] = c;
            taken[s] = true;
        }
    }
    let settle = |p: Vec3| if periodic { wrap(p, region) } else { p };
    let mut rng = Rng::new(seed.wrapping_add(1));
    let mut out = Vec::with_capacity(sites.len());
    for (p, &c) in points.iter().zip(&copy_of) {
        if c != u32::MAX {
            let t = copies[c as usize].1;
            out.push(settle([0, 1, 2].map(|k| p[k] + regularity * (t[k] - p[k]))));
        }
    }
    // A site without a point: one at random in its cell (within the inscribed ball of the
    // truncated octahedron, radius √3/4 a), moved toward the site like the others.
    for (s, t) in sites.iter().enumerate() {
        if !taken[s] {
            let d = rng.in_ball();
            let p = [0, 1, 2].map(|k| t[k] + 0.433 * a[k] * d[k]);
            out.push(settle([0, 1, 2].map(|k| p[k] + regularity * (t[k] - p[k]))));
        }
    }
    out
}

/// Seeds from a CSV file: `x,y,z` per line, mm (a header line, blank lines and `#` comments
/// allowed).
pub fn read_csv(path: &Path) -> Result<Vec<Vec3>> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| Error::invalid(format!("cannot read {}: {e}", path.display())))?;
    let mut seeds = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let cols: Vec<&str> = line
            .split([',', ';', ' ', '\t'])
            .filter(|c| !c.is_empty())
            .collect();
        let parsed: Vec<f64> = cols.iter().filter_map(|c| c.parse::<f64>().ok()).collect();
        if parsed.len() != cols.len() || cols.len() != 3 || parsed.iter().any(|v| !v.is_finite()) {
            if n == 0 && parsed.is_empty() {
                continue; // a header
            }
            return Err(Error::invalid(format!(
                "{} line {}: a seed is three finite numbers x,y,z (mm), got '{line}'",
                path.display(),
                n + 1
            )));
        }
        seeds.push([parsed[0], parsed[1], parsed[2]]);
    }
    if seeds.len() < 5 {
        return Err(Error::invalid(format!(
            "{}: a Voronoi foam needs at least 5 seeds, the file gives {}",
            path.display(),
            seeds.len()
        )));
    }
    if seeds.len() > MAX_SEEDS {
        return Err(Error::invalid(format!(
            "{}: {} seeds, more than {MAX_SEEDS}",
            path.display(),
            seeds.len()
        )));
    }
    Ok(seeds)
}

/// The seeds as CSV, `x,y,z` per line with a header, shortest round-trip decimals.
pub fn to_csv(seeds: &[Vec3]) -> String {
    let mut s = String::from("x,y,z\n");
    for p in seeds {
        s.push_str(&format!("{},{},{}\n", p[0], p[1], p[2]));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn count_inside(points: &[Vec3], b: &Aabb) -> usize {
        points.iter().filter(|p| b.contains(**p)).count()
    }

    /// One point per s³ away from the region's faces, none closer than the disk radius, and
    /// the same points from the same seed.
    #[test]
    fn poisson_points_have_the_mean_spacing() {
        let region = Aabb {
            min: [0.0; 3],
            max: [20.0; 3],
        };
        let s = 1.0;
        let pts = poisson(&region, &|_| s, 7);
        assert_eq!(pts, poisson(&region, &|_| s, 7));
        let core = region.grown(-2.0 * s);
        let per_cell = count_inside(&pts, &core) as f64 / core.volume();
        assert!((per_cell - 1.0).abs() < 0.03, "{per_cell} points per s³");
        let mut tree: KdTree<f64, 3> = KdTree::new();
        for (i, p) in pts.iter().enumerate() {
            tree.add(p, i as u64);
        }
        for p in &pts {
            let n = tree.within_unsorted::<SquaredEuclidean>(p, (RADIUS * s * 0.999).powi(2));
            assert_eq!(n.len(), 1);
        }
    }

    /// Regularity 1 gives exactly the body-centred cubic sites.
    #[test]
    fn full_regularity_is_the_bcc_lattice() {
        let region = Aabb {
            min: [0.0; 3],
            max: [10.0; 3],
        };
        let pts = poisson(&region, &|_| 1.5, 3);
        let reg = regularise(&pts, &region, 1.5, 1.0, 3, false);
        let a = 2f64.cbrt() * 1.5;
        for p in &reg {
            let u = p.map(|x| x / a);
            let corner = u.iter().all(|x| (x - x.round()).abs() < 1e-9);
            let centre = u.iter().all(|x| (x - x.floor() - 0.5).abs() < 1e-9);
            assert!(corner || centre, "{p:?} is not a site");
        }
        let mut sorted = reg.clone();
        sorted.sort_by(|a, b| a.partial_cmp(b).unwrap());
        sorted.dedup();
        assert_eq!(sorted.len(), reg.len(), "two seeds on one site");
    }
}
