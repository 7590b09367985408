//! A bounding volume hierarchy over a mesh's triangles, for casting rays at explicit shells.
//!
//! Built top-down with the surface-area heuristic over 16 bins of triangle centroids (leaves
//! of at most 4 triangles). A ray visits the nearer child first and skips every node whose box
//! it enters beyond the nearest hit found so far, so a ray costs about the logarithm of the
//! triangle count; a ray that starts inside a box (the camera inside the part) enters it at 0.
//! Triangles are hit from both sides (Möller–Trumbore), so open shells render too.

use super::{cross, dot, Aabb, Mesh, Ray, Vec3};

const LEAF: usize = 4;
const BINS: usize = 16;

#[derive(Debug, Clone, Copy)]
struct Node {
    bounds: Aabb,
    /// Inner node: index of the first child (the second follows it). Leaf: first triangle.
    first: u32,
    /// Triangles in a leaf; 0 for an inner node.
    count: u32,
}

/// Triangles and the hierarchy over them.
#[derive(Debug, Clone)]
pub struct Bvh {
    triangles: Vec<[Vec3; 3]>,
    nodes: Vec<Node>,
}

/// Where a ray meets a triangle.
#[derive(Debug, Clone, Copy)]
pub struct TriangleHit {
    /// Distance along the ray.
    pub t: f64,
    /// The triangle's unit normal by its winding.
    pub normal: Vec3,
}

fn empty_box() -> Aabb {
    Aabb {
        min: [f64::INFINITY; 3],
        max: [f64::NEG_INFINITY; 3],
    }
}

fn grow(b: &mut Aabb, p: Vec3) {
    b.min = [0, 1, 2].map(|a| b.min[a].min(p[a]));
    b.max = [0, 1, 2].map(|a| b.max[a].max(p[a]));
}

fn union(a: &Aabb, b: &Aabb) -> Aabb {
    Aabb {
        min: [0, 1, 2].map(|k| a.min[k].min(b.min[k])),
        max: [0, 1, 2].map(|k| a.max[k].max(b.max[k])),
    }
}

fn area(b: &Aabb) -> f64 {
    let s = b.size().map(|x| x.max(0.0));
    s[0] * s[1] + s[1] * s[2] + s[2] * s[0]
}

impl Bvh {
    /// The hierarchy over `mesh`'s triangles.
    pub fn new(mesh: &Mesh) -> Bvh {
        let p = |i: u32| {
            let o = 3 * i as usize;
            [0, 1, 2].map(|a| mesh.positions[o + a] as f64)
        };
        let triangles: Vec<[Vec3; 3]> = mesh
            .indices
            .chunks_exact(3)
            .map(|t| [p(t[0]), p(t[1]), p(t[2])])
            .collect();
        Bvh::over(triangles)
    }

    /// The hierarchy over `triangles` (given by their corners).
    pub fn over(mut triangles: Vec<[Vec3; 3]>) -> Bvh {
        let mut nodes = Vec::with_capacity(2 * triangles.len() / LEAF + 1);
        if !triangles.is_empty() {
            nodes.push(Node {
                bounds: empty_box(),
                first: 0,
                count: 0,
            });
            let n = triangles.len();
            build(&mut triangles, &mut nodes, 0, 0, n);
        }
        Bvh { triangles, nodes }
    }

    /// The triangles, in the order the leaves list them.
    pub fn triangles(&self) -> &[[Vec3; 3]] {
        &self.triangles
    }

    /// The hierarchy as flat arrays (for a shader): per node its box's lower corner, the index
    /// of its first child (inner node; the second follows it) or first triangle (leaf), its
    /// box's upper corner and its triangle count (0 for an inner node); the root first.
    pub fn nodes(&self) -> Vec<[f64; 8]> {
        self.nodes
            .iter()
            .map(|n| {
                let (lo, hi) = (n.bounds.min, n.bounds.max);
                [
                    lo[0],
                    lo[1],
                    lo[2],
                    n.first as f64,
                    hi[0],
                    hi[1],
                    hi[2],
                    n.count as f64,
                ]
            })
            .collect()
    }

    /// The box of every triangle, or `None` for an empty mesh.
    pub fn bounds(&self) -> Option<Aabb> {
        self.nodes.first().map(|n| n.bounds)
    }

    /// Triangles held.
    pub fn len(&self) -> usize {
        self.triangles.len()
    }

    /// Whether it holds no triangle.
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    /// The nearest triangle the ray meets at a distance in `(0, t_max)`.
    pub fn hit(&self, ray: &Ray, t_max: f64) -> Option<TriangleHit> {
        let mut best: Option<(f64, usize)> = None;
        let mut limit = t_max;
        let root = self.nodes.first()?;
        if !enters_before(ray, &root.bounds, limit) {
            return None;
        }
        // Nodes to visit, with the distance at which the ray enters them.
        let mut stack = Stack::<(u32, f64)>::new();
        stack.push((0, 0.0));
        while let Some((i, t_in)) = stack.pop() {
            // Entered beyond the nearest hit found since it was pushed: nothing nearer inside.
            if t_in >= limit {
                continue;
            }
            let node = &self.nodes[i as usize];
            if node.count > 0 {
                let first = node.first as usize;
                for (k, tri) in self.triangles[first..first + node.count as usize]
                    .iter()
                    .enumerate()
                {
                    if let Some(t) = intersect(ray, tri) {
                        if t < limit {
                            limit = t;
                            best = Some((t, first + k));
                        }
                    }
                }
                continue;
            }
            let (a, b) = (node.first, node.first + 1);
            let ta = entry(ray, &self.nodes[a as usize].bounds, limit);
            let tb = entry(ray, &self.nodes[b as usize].bounds, limit);
            // The nearer child is visited first: pushed last.
            match (ta, tb) {
                (Some(x), Some(y)) if x <= y => {
                    stack.push((b, y));
                    stack.push((a, x));
                }
                (Some(x), Some(y)) => {
                    stack.push((a, x));
                    stack.push((b, y));
                }
                (Some(x), None) => stack.push((a, x)),
                (None, Some(y)) => stack.push((b, y)),
                (None, None) => {}
            }
        }
        best.map(|(t, i)| {
            let [a, b, c] = self.triangles[i];
            let n = cross(sub(b, a), sub(c, a));
            let len = dot(n, n).sqrt();
            TriangleHit {
                t,
                normal: if len > 0.0 { n.map(|x| x / len) } else { n },
            }
        })
    }

    /// The distance from `p` to the nearest triangle, if nearer than `limit` (else `limit`).
    pub fn distance(&self, p: Vec3, limit: f64) -> f64 {
        self.closest(p, limit).map_or(limit, |(_, d, _)| d)
    }

    /// The point of the triangles nearest `p`, its distance and its triangle (by its index in
    /// [`Bvh::triangles`]), if nearer than `limit`.
    pub fn closest(&self, p: Vec3, limit: f64) -> Option<(Vec3, f64, usize)> {
        let mut best2 = limit * limit;
        let mut best = None;
        let root = self.nodes.first()?;
        let mut stack = Stack::<(u32, f64)>::new();
        stack.push((0, box_distance2(&root.bounds, p)));
        while let Some((i, d2)) = stack.pop() {
            if d2 >= best2 {
                continue;
            }
            let node = &self.nodes[i as usize];
            if node.count > 0 {
                let first = node.first as usize;
                for (k, tri) in self.triangles[first..first + node.count as usize]
                    .iter()
                    .enumerate()
                {
                    let q = closest_on_triangle(p, tri);
                    let e = sub(p, q);
                    if dot(e, e) < best2 {
                        best2 = dot(e, e);
                        best = Some((q, first + k));
                    }
                }
                continue;
            }
            let (a, b) = (node.first, node.first + 1);
            let da = box_distance2(&self.nodes[a as usize].bounds, p);
            let db = box_distance2(&self.nodes[b as usize].bounds, p);
            if da <= db {
                stack.push((b, db));
                stack.push((a, da));
            } else {
                stack.push((a, da));
                stack.push((b, db));
            }
        }
        best.map(|(q, t)| (q, best2.sqrt(), t))
    }

    /// Whether `p` is inside the closed surface the triangles bound: an odd number of them
    /// crossed by a ray from `p` (along a direction no axis-aligned facet, edge or vertex of a
    /// voxel-made mesh lies on).
    pub fn contains(&self, p: Vec3) -> bool {
        let dir = normalized_dir([0.5773, 0.5779, 0.5767]);
        let ray = Ray { origin: p, dir };
        let mut crossings = 0usize;
        let Some(root) = self.nodes.first() else {
            return false;
        };
        if ray.clip(&root.bounds).is_none() {
            return false;
        }
        let mut stack = Stack::<u32>::new();
        stack.push(0);
        while let Some(i) = stack.pop() {
            let node = &self.nodes[i as usize];
            if node.count > 0 {
                let first = node.first as usize;
                crossings += self.triangles[first..first + node.count as usize]
                    .iter()
                    .filter(|t| intersect(&ray, t).is_some())
                    .count();
                continue;
            }
            for c in [node.first, node.first + 1] {
                if ray.clip(&self.nodes[c as usize].bounds).is_some() {
                    stack.push(c);
                }
            }
        }
        crossings % 2 == 1
    }
}

/// A traversal stack: 64 entries in place (no allocation per query), more on the heap.
struct Stack<T> {
    inline: [T; 64],
    len: usize,
    spill: Vec<T>,
}

impl<T: Copy + Default> Stack<T> {
    fn new() -> Self {
        Stack {
            inline: [T::default(); 64],
            len: 0,
            spill: Vec::new(),
        }
    }

    fn push(&mut self, x: T) {
        if self.len < self.inline.len() {
            self.inline[self.len] = x;
            self.len += 1;
        } else {
            self.spill.push(x);
        }
    }

    fn pop(&mut self) -> Option<T> {
        if let Some(x) = self.spill.pop() {
            return Some(x);
        }
        (self.len > 0).then(|| {
            self.len -= 1;
            self.inline[self.len]
        })
    }
}

fn normalized_dir(d: Vec3) -> Vec3 {
    let n = dot(d, d).sqrt();
    d.map(|x| x / n)
}

/// The squared distance from `p` to the box (0 inside).
fn box_distance2(b: &Aabb, p: Vec3) -> f64 {
    (0..3)
        .map(|a| {
            let d = (b.min[a] - p[a]).max(p[a] - b.max[a]).max(0.0);
            d * d
        })
        .sum()
}

/// The squared distance from `p` to the triangle (Ericson, Real-Time Collision Detection 5.1.5).
pub(crate) fn triangle_distance2(p: Vec3, t: &[Vec3; 3]) -> f64 {
    let q = closest_on_triangle(p, t);
    let d = sub(p, q);
    dot(d, d)
}

/// The point of the triangle `t` nearest `p` (Ericson, Real-Time Collision Detection 5.1.5).
pub(crate) fn closest_on_triangle(p: Vec3, t: &[Vec3; 3]) -> Vec3 {
    let [a, b, c] = *t;
    let (ab, ac, ap) = (sub(b, a), sub(c, a), sub(p, a));
    let (d1, d2) = (dot(ab, ap), dot(ac, ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        a
    } else {
        let bp = sub(p, b);
        let (d3, d4) = (dot(ab, bp), dot(ac, bp));
        if d3 >= 0.0 && d4 <= d3 {
            b
        } else {
            let vc = d1 * d4 - d3 * d2;
            if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
                let v = d1 / (d1 - d3);
                lerp(a, ab, v)
            } else {
                let cp = sub(p, c);
                let (d5, d6) = (dot(ab, cp), dot(ac, cp));
                if d6 >= 0.0 && d5 <= d6 {
                    c
                } else {
                    let vb = d5 * d2 - d1 * d6;
                    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
                        let w = d2 / (d2 - d6);
                        lerp(a, ac, w)
                    } else {
                        let va = d3 * d6 - d5 * d4;
                        if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
                            let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
                            lerp(b, sub(c, b), w)
                        } else {
                            let denom = 1.0 / (va + vb + vc);
                            let (v, w) = (vb * denom, vc * denom);
                            [0, 1, 2].map(|k| a[k] + ab[k] * v + ac[k] * w)
                        }
                    }
                }
            }
        }
    }
}

fn lerp(a: Vec3, d: Vec3, t: f64) -> Vec3 {
    [a[0] + d[0] * t, a[1] + d[1] * t, a[2] + d[2] * t]
}

fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn entry(ray: &Ray, b: &Aabb, limit: f64) -> Option<f64> {
    ray.clip(b).and_then(|(t0, _)| (t0 < limit).then_some(t0))
}

fn enters_before(ray: &Ray, b: &Aabb, limit: f64) -> bool {
    entry(ray, b, limit).is_some()
}

/// Möller–Trumbore: the distance at which the ray crosses the triangle, from either side.
fn intersect(ray: &Ray, tri: &[Vec3; 3]) -> Option<f64> {
    let e1 = sub(tri[1], tri[0]);
    let e2 = sub(tri[2], tri[0]);
    let p = cross(ray.dir, e2);
    let det = dot(e1, p);
    if det.abs() < 1e-300 {
        return None;
    }
    let inv = 1.0 / det;
    let s = sub(ray.origin, tri[0]);
    let u = dot(s, p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = cross(s, e1);
    let v = dot(ray.dir, q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = dot(e2, q) * inv;
    (t > 0.0).then_some(t)
}

fn centroid(t: &[Vec3; 3]) -> Vec3 {
    [0, 1, 2].map(|a| (t[0][a] + t[1][a] + t[2][a]) / 3.0)
}

/// Builds node `at` over `triangles[lo..hi]`, reordering them.
fn build(triangles: &mut [[Vec3; 3]], nodes: &mut Vec<Node>, at: usize, lo: usize, hi: usize) {
    let mut bounds = empty_box();
    let mut cbounds = empty_box();
    for t in &triangles[lo..hi] {
        for &p in t {
            grow(&mut bounds, p);
        }
        grow(&mut cbounds, centroid(t));
    }
    nodes[at].bounds = bounds;
    let n = hi - lo;
    let leaf = |nodes: &mut Vec<Node>| {
        nodes[at].first = lo as u32;
        nodes[at].count = n as u32;
    };
    if n <= LEAF {
        return leaf(nodes);
    }
    // The split of least surface-area cost over the bins of every axis.
    let mut best: Option<(f64, usize, f64)> = None;
    for axis in 0..3 {
        let (c0, c1) = (cbounds.min[axis], cbounds.max[axis]);
        if c1 - c0 <= 0.0 {
            continue;
        }
        let scale = BINS as f64 / (c1 - c0);
        let bin_of = |t: &[Vec3; 3]| (((centroid(t)[axis] - c0) * scale) as usize).min(BINS - 1);
        let mut counts = [0usize; BINS];
        let mut boxes = [empty_box(); BINS];
        for t in &triangles[lo..hi] {
            let b = bin_of(t);
            counts[b] += 1;
            for &p in t {
                grow(&mut boxes[b], p);
            }
        }
        let mut right_area = [0.0; BINS];
        let mut right_count = [0usize; BINS];
        let (mut acc, mut cnt) = (empty_box(), 0);
        for b in (1..BINS).rev() {
            acc = union(&acc, &boxes[b]);
            cnt += counts[b];
            right_area[b] = area(&acc);
            right_count[b] = cnt;
        }
        let (mut acc, mut cnt) = (empty_box(), 0);
        for b in 0..BINS - 1 {
            acc = union(&acc, &boxes[b]);
            cnt += counts[b];
            if cnt == 0 || right_count[b + 1] == 0 {
                continue;
            }
            let cost = area(&acc) * cnt as f64 + right_area[b + 1] * right_count[b + 1] as f64;
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, c0 + (b + 1) as f64 / scale));
            }
        }
    }
    let mid = match best {
        Some((_, axis, split)) => {
            let mut m = lo;
            for i in lo..hi {
                if centroid(&triangles[i])[axis] < split {
                    triangles.swap(i, m);
                    m += 1;
                }
            }
            m
        }
        None => lo + n / 2,
    };
    let mid = if mid == lo || mid == hi {
        lo + n / 2
    } else {
        mid
    };
    let first = nodes.len();
    let blank = Node {
        bounds: empty_box(),
        first: 0,
        count: 0,
    };
    nodes.push(blank);
    nodes.push(blank);
    nodes[at].first = first as u32;
    nodes[at].count = 0;
    build(triangles, nodes, first, lo, mid);
    build(triangles, nodes, first + 1, mid, hi);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every ray's nearest hit is the one found by testing every triangle.
    #[test]
    fn nearest_hit_is_the_brute_force_one() {
        // A cloud of small random triangles.
        let mut seed = 12345u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64) / (1u64 << 53) as f64
        };
        let mut mesh = Mesh::default();
        for i in 0..500u32 {
            let c = [rnd() * 10.0, rnd() * 10.0, rnd() * 10.0];
            for _ in 0..3 {
                for x in c {
                    mesh.positions.push((x + rnd() - 0.5) as f32);
                }
            }
            mesh.indices.extend([3 * i, 3 * i + 1, 3 * i + 2]);
        }
        let bvh = Bvh::new(&mesh);
        for _ in 0..500 {
            let origin = [rnd() * 14.0 - 2.0, rnd() * 14.0 - 2.0, rnd() * 14.0 - 2.0];
            let d = [rnd() - 0.5, rnd() - 0.5, rnd() - 0.5];
            let n = dot(d, d).sqrt();
            let ray = Ray {
                origin,
                dir: d.map(|x| x / n),
            };
            let brute = bvh
                .triangles
                .iter()
                .filter_map(|t| intersect(&ray, t))
                .fold(f64::INFINITY, f64::min);
            let got = bvh.hit(&ray, f64::INFINITY).map_or(f64::INFINITY, |h| h.t);
            assert_eq!(got, brute);
            // The nearest triangle's distance, as by testing every triangle.
            let brute = bvh
                .triangles
                .iter()
                .map(|t| triangle_distance2(origin, t))
                .fold(f64::INFINITY, f64::min)
                .sqrt();
            assert!((bvh.distance(origin, f64::INFINITY) - brute).abs() < 1e-12);
            assert_eq!(bvh.distance(origin, 0.5 * brute), 0.5 * brute);
        }
    }

    /// The distance to a triangle at points over its face, beyond its edges and its corners,
    /// against closed forms; and the inside of a closed box.
    #[test]
    fn distances_and_inside() {
        let t = [[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]];
        let d = |p: Vec3| triangle_distance2(p, &t).sqrt();
        assert!((d([1.0, 1.0, 3.0]) - 3.0).abs() < 1e-12);
        assert!((d([-3.0, -4.0, 0.0]) - 5.0).abs() < 1e-12);
        assert!((d([2.0, -2.0, 0.0]) - 2.0).abs() < 1e-12);
        assert!((d([3.0, 3.0, 0.0]) - 2.0f64.sqrt()).abs() < 1e-12);
        let mesh = Mesh::cuboid([0.0; 3], [10.0; 3]);
        let bvh = Bvh::new(&mesh);
        assert!(bvh.contains([5.0, 5.0, 5.0]) && bvh.contains([0.1, 9.9, 5.0]));
        assert!(!bvh.contains([11.0, 5.0, 5.0]) && !bvh.contains([-0.1, 5.0, 5.0]));
        assert!((bvh.distance([5.0, 5.0, 4.0], 100.0) - 4.0).abs() < 1e-12);
    }

    #[test]
    fn the_traversal_stack_is_last_in_first_out_past_its_inline_part() {
        let mut s = Stack::<u32>::new();
        for i in 0..200 {
            s.push(i);
        }
        for i in (150..200).rev() {
            assert_eq!(s.pop(), Some(i));
        }
        s.push(7);
        assert_eq!(s.pop(), Some(7));
        for i in (0..150).rev() {
            assert_eq!(s.pop(), Some(i));
        }
        assert_eq!(s.pop(), None);
    }
}
