//! Simplify: fewer triangles where the surface is flat, every triangle kept within a tolerance of
//! the exact surface it stands for.
//!
//! A uniform mesh spends two triangles on every voxel the surface crosses, whatever its
//! curvature. Here the mesh is coarsened by *half-edge collapses* (a vertex merged into a
//! neighbour, Hoppe's "Progressive meshes", 1996), cheapest first by the quadric error metric
//! (Garland & Heckbert, "Surface simplification using quadric error metrics", 1997). Every
//! vertex that remains is one of the input's, so it keeps its place on the exact surface; what a
//! collapse can move away from the surface is the inside of its triangles, and that is what each
//! collapse is checked for, against the exact field (which no mesh-only decimator has):
//!
//! * **distance**: points on every triangle the collapse makes (a barycentric grid a voxel
//!   apart, the centroid always) lie within the tolerance of the surface, by the
//!   field's first-order distance `|f| / |∇f|` (the box's faces by their exact distance); and
//!   the removed vertex lies within the tolerance of the triangles that replace its fan;
//! * **shape**: no triangle turns over or away from the surface's normal by more than
//!   [`MAX_NORMAL_DEGREES`], none becomes a sliver (quality under [`MIN_QUALITY`] of the
//!   equilateral's, unless it was one already), and none grows an edge longer than
//!   [`MAX_EDGE_VOXELS`] voxels;
//! * **topology**: the link condition (the two vertices share exactly the two neighbours of
//!   their edge), no vertex left with fewer than three neighbours, so the mesh stays a closed
//!   2-manifold of the same genus and pieces;
//! * **the box**: a vertex on a face of the clipping box only merges into a vertex on the same
//!   faces; one on the sharp edge where the lattice meets a face only along that edge, so the
//!   box's faces stay flat and its cut edges sharp.
//!
//! Self-intersections cannot be ruled out locally at an affordable cost: the result is searched
//! exactly ([`crate::verify::self_intersect`]); where two triangles cross, every input vertex
//! that was merged into their corners is locked and the mesh simplified again from the input,
//! until none cross (after [`MAX_ROUNDS`] rounds the input itself is returned).

use crate::field::{Aabb, Field, Vec3};
use crate::geom::bvh::triangle_distance2;
use crate::geom::{cross, dot, norm, sub, Mesh};

/// A new triangle's normal may turn from the surface's (at its centroid) by at most this.
pub const MAX_NORMAL_DEGREES: f64 = 45.0;

/// A collapse may not make a triangle of quality below this share of the equilateral's (unless
/// the triangle it replaces was already below it).
pub const MIN_QUALITY: f64 = 0.1;

/// Tries of [`within`] at most, each at ¾ of the previous one's aim.
pub const TRIES: usize = 3;

/// Rounds of simplification at most (each after the previous one's crossings were locked).
pub const MAX_ROUNDS: usize = 4;

/// A new triangle's longest edge may be at most this many voxels: the samples a collapse is
/// checked on grow with a triangle's area (a flat face of a part remeshed from a CAD file would
/// otherwise merge into triangles of thousands of samples each).
pub const MAX_EDGE_VOXELS: f64 = 12.0;

/// The surface a mesh stands for: a field clipped by a box.
#[derive(Clone, Copy)]
pub struct Surface<'a> {
    /// The solid's field (negative inside), unclipped.
    pub field: &'a dyn Field,
    /// The clipping box.
    pub clip: Aabb,
}

impl Surface<'_> {
    /// Distance from `p` to the clipped solid's surface, to first order: the larger of the
    /// field's value over its gradient's length and the box's exact distance.
    pub fn distance(&self, p: Vec3) -> f64 {
        self.signed(p).abs()
    }

    fn signed(&self, p: Vec3) -> f64 {
        let (f, g) = self.field.implicit_with_gradient(p);
        let gl = norm(g);
        let a = if gl > 1e-12 { f / gl } else { f };
        a.max(self.clip.value(p))
    }

    /// The outward normal of the surface nearest `p` (of the box where its face is nearer).
    fn normal(&self, p: Vec3) -> Option<Vec3> {
        let (f, g) = self.field.implicit_with_gradient(p);
        let gl = norm(g);
        let a = if gl > 1e-12 { f / gl } else { f };
        let b = self.clip.value(p);
        if b > a {
            let (lo, hi) = (self.clip.min, self.clip.max);
            let mut best = (f64::NEG_INFINITY, [0.0; 3]);
            for k in 0..3 {
                let (d0, d1) = (lo[k] - p[k], p[k] - hi[k]);
                if d0 > best.0 {
                    best = (d0, unit(k, -1.0));
                }
                if d1 > best.0 {
                    best = (d1, unit(k, 1.0));
                }
            }
            Some(best.1)
        } else if gl > 1e-12 {
            Some(g.map(|x| x / gl))
        } else {
            None
        }
    }
}

fn unit(k: usize, s: f64) -> Vec3 {
    let mut v = [0.0; 3];
    v[k] = s;
    v
}

/// How a mesh is simplified.
#[derive(Debug, Clone, Copy)]
pub struct Settings {
    /// The largest distance allowed between the mesh and the exact surface, mm.
    pub tolerance: f64,
    /// The voxel the mesh was made on, mm: triangles are sampled a voxel apart.
    pub voxel: f64,
}

/// What simplification did.
#[derive(Debug, Clone, Copy, Default, serde::Serialize)]
pub struct SimplifyStats {
    /// The tolerance asked, mm.
    pub tolerance: f64,
    /// Triangles before.
    pub triangles_before: u64,
    /// Triangles after.
    pub triangles_after: u64,
    /// Rounds taken (more than one where crossings were locked).
    pub rounds: u64,
    /// Input vertices locked because triangles made of them crossed.
    pub locked: u64,
    /// How far the vertices off the box's faces were moved along the surface's normal to
    /// restore the volume, mm (positive: outward).
    pub offset: f64,
    /// Whether the input was returned unsimplified (crossings remained after every round, or
    /// no try kept within the bound).
    pub gave_up: bool,
    /// Seconds spent.
    pub seconds: f64,
}

/// How the mesh was simplified, and how far it lies from the exact surface.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Simplified {
    /// What simplification did.
    #[serde(flatten)]
    pub stats: SimplifyStats,
    /// The largest distance from points sampled on the written mesh (a quarter voxel apart) to
    /// the exact surface, mm.
    pub deviation: f64,
    /// The voxel the simplified mesh was made on, mm: finer than the part's where its uniform
    /// mesh strayed further than the tolerance.
    pub voxel: f64,
    /// The largest deviation of the uniform mesh on the part's voxels, mm.
    pub uniform_deviation: f64,
    /// Triangles of the uniform mesh on the part's voxels.
    pub uniform_triangles: u64,
    /// Whether the tolerance was the default mesh's deviation (`--tolerance auto`: half a voxel,
    /// or the uniform mesh's deviation where larger).
    pub auto: bool,
}

/// A mesh simplified by [`within`].
pub struct Within {
    /// The simplified mesh.
    pub mesh: Mesh,
    /// What simplification did.
    pub stats: SimplifyStats,
    /// Its measured deviation from the surface ([`deviation`], a quarter voxel apart), mm.
    pub deviation: f64,
    /// Whether that deviation is within the bound asked.
    pub kept: bool,
}

/// Simplifies `mesh` (made on `voxel` mm) within `tolerance` of `surface`, its volume restored
/// to `volume`, and measures the result's deviation four times finer than each collapse is
/// checked; where that exceeds `bound` (the tolerance, or the uniform mesh's own deviation where
/// that is larger), simplified again at ¾ of the aim, `tries` at most. The last try is
/// returned when none kept within `bound`.
pub fn within(
    mesh: &Mesh,
    surface: Surface<'_>,
    voxel: f64,
    (tolerance, bound): (f64, f64),
    volume: Option<f64>,
    most: usize,
) -> Within {
    let start = std::time::Instant::now();
    let mut aim = tolerance;
    let mut tries = 0;
    loop {
        tries += 1;
        let settings = Settings {
            tolerance: aim,
            voxel,
        };
        let (out, stats) = simplify(mesh, surface, settings, volume);
        let deviation = self::deviation(&out, surface, 0.25 * voxel);
        let kept = deviation <= bound;
        if kept || tries >= most {
            return Within {
                mesh: out,
                stats: SimplifyStats {
                    tolerance,
                    seconds: start.elapsed().as_secs_f64(),
                    ..stats
                },
                deviation,
                kept,
            };
        }
        aim *= 0.75;
    }
}

/// A finished mesh (made on `voxel` mm) simplified within `tolerance` of the `surface` it
/// stands for, its volume kept: for meshes that are written as they are made (no finer
/// remeshing, no fallback to the uniform mesh), such as a repair's remesh, a scan's part or a
/// density field's solid.
pub fn mesh_within(
    mesh: &Mesh,
    surface: Surface<'_>,
    voxel: f64,
    tolerance: f64,
) -> (Mesh, Simplified) {
    let uniform = deviation(mesh, surface, 0.25 * voxel);
    let w = within(
        mesh,
        surface,
        voxel,
        (tolerance, tolerance.max(uniform)),
        Some(mesh.volume()),
        TRIES,
    );
    (
        w.mesh,
        Simplified {
            stats: w.stats,
            deviation: w.deviation,
            voxel,
            uniform_deviation: uniform,
            uniform_triangles: mesh.triangle_count() as u64,
            auto: false,
        },
    )
}

/// Simplifies `mesh` (closed, manifold, outward) within `settings.tolerance` of `surface`;
/// with `volume`, the result is offset along the surface's normal to enclose that volume
/// ([`restore_volume`]).
pub fn simplify(
    mesh: &Mesh,
    surface: Surface<'_>,
    settings: Settings,
    volume: Option<f64>,
) -> (Mesh, SimplifyStats) {
    let t = std::time::Instant::now();
    let mut locked = vec![false; mesh.vertex_count()];
    let mut stats = SimplifyStats {
        tolerance: settings.tolerance,
        triangles_before: mesh.triangle_count() as u64,
        ..Default::default()
    };
    for round in 1..=MAX_ROUNDS {
        stats.rounds = round as u64;
        let mut c = Collapser::new(mesh, surface, settings, &locked);
        c.run();
        let (simplified, root) = c.finish();
        // The offset can push the two sides of a narrow valley into each other: vertices of
        // triangles that cross after it stay where they are, and the rest carries the offset.
        let mut still = vec![false; simplified.vertex_count()];
        let (mut out, mut crossing, mut pairs);
        loop {
            out = simplified.clone();
            if let Some(v) = volume {
                stats.offset = restore_volume(&mut out, surface, settings.voxel, v, &still);
            }
            let all: Vec<u32> = (0..out.triangle_count() as u32).collect();
            (crossing, pairs) =
                crate::verify::self_intersect::soup_self_intersections(&out, &all, usize::MAX);
            let mut more = false;
            for &(a, b) in &pairs {
                for f in [a, b] {
                    for k in 0..3 {
                        let w = out.indices[3 * f as usize + k] as usize;
                        more |= !still[w];
                        still[w] = true;
                    }
                }
            }
            if crossing == 0 || volume.is_none() || !more {
                break;
            }
        }
        if crossing == 0 {
            stats.triangles_after = out.triangle_count() as u64;
            stats.locked = locked.iter().filter(|&&l| l).count() as u64;
            stats.seconds = t.elapsed().as_secs_f64();
            return (out, stats);
        }
        // Lock every input vertex merged into a corner of a crossing triangle.
        let mut hit = vec![false; out.vertex_count()];
        for (a, b) in pairs {
            for f in [a, b] {
                for k in 0..3 {
                    hit[out.indices[3 * f as usize + k] as usize] = true;
                }
            }
        }
        for (v, r) in root.iter().enumerate() {
            if let Some(r) = r {
                if hit[*r as usize] {
                    locked[v] = true;
                }
            }
        }
    }
    stats.triangles_after = stats.triangles_before;
    stats.gave_up = true;
    let mut out = mesh.clone();
    if let Some(v) = volume {
        let still = vec![false; out.vertex_count()];
        stats.offset = restore_volume(&mut out, surface, settings.voxel, v, &still);
    }
    stats.seconds = t.elapsed().as_secs_f64();
    (out, stats)
}

/// Moves the vertices off the box's faces (and those on one face, along it) by one distance
/// `h` along the surface's normal so that `mesh` encloses `target` mm³: the volume the uniform
/// mesh had, which its level was found for. Chords of a curved surface lie on one side of it,
/// so collapses change the volume by about the tolerance times the area where the surface bends
/// one way; an offset of a small share of the tolerance gives it back. Returns `h`, mm.
pub fn restore_volume(
    mesh: &mut Mesh,
    surface: Surface<'_>,
    voxel: f64,
    target: f64,
    still: &[bool],
) -> f64 {
    let nv = mesh.vertex_count();
    let start: Vec<Vec3> = (0..nv as u32).map(|v| mesh.vertex(v)).collect();
    let planes = box_planes(&start, &surface.clip, voxel);
    let dirs: Vec<Vec3> = start
        .iter()
        .zip(&planes)
        .zip(still)
        .map(|((p, m), still)| {
            // Not on a box edge, nor where two curved surfaces meet (a normal there would push
            // the two sides of a valley into each other).
            if *still || m.count_ones() > 1 || !surface.field.smooth_near(*p, voxel) {
                return [0.0; 3];
            }
            let (_, g) = surface.field.implicit_with_gradient(*p);
            let l = norm(g);
            if l <= 1e-12 {
                return [0.0; 3];
            }
            let mut n = g.map(|x| x / l);
            if *m != 0 {
                let k = m.trailing_zeros() as usize / 2;
                n[k] = 0.0;
            }
            n
        })
        .collect();
    // d(volume)/dh: each vertex's direction against a third of its triangles' area vectors.
    let mut rate = 0.0;
    for t in mesh.indices.chunks_exact(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|v| start[v as usize]);
        let n = cross(sub(b, a), sub(c, a));
        for &v in t {
            rate += dot(dirs[v as usize], n) / 6.0;
        }
    }
    if rate.abs() < 1e-12 {
        return 0.0;
    }
    let mut h = 0.0;
    for _ in 0..3 {
        let miss = target - mesh.volume();
        h += miss / rate;
        for (v, (p, d)) in start.iter().zip(&dirs).enumerate() {
            for k in 0..3 {
                mesh.positions[3 * v + k] = (p[k] + h * d[k]) as f32;
            }
        }
    }
    h
}

/// Per vertex, the box faces it lies on (bit 2k: the lower face of axis k, 2k + 1: the upper),
/// within single precision's rounding.
fn box_planes(pos: &[Vec3], b: &Aabb, voxel: f64) -> Vec<u8> {
    let far = (0..3)
        .map(|k| b.min[k].abs().max(b.max[k].abs()))
        .fold(0.0, f64::max);
    let eps = 1e-5 * voxel + 4.0 * f32::EPSILON as f64 * far;
    pos.iter()
        .map(|p| {
            let mut m = 0u8;
            for (k, x) in p.iter().enumerate() {
                if (x - b.min[k]).abs() <= eps {
                    m |= 1 << (2 * k);
                }
                if (x - b.max[k]).abs() <= eps {
                    m |= 1 << (2 * k + 1);
                }
            }
            m
        })
        .collect()
}

/// The largest distance from points sampled on `mesh`'s triangles (corners, edge midpoints,
/// centroid, and a grid at `spacing` on large ones) to `surface`, mm.
pub fn deviation(mesh: &Mesh, surface: Surface<'_>, spacing: f64) -> f64 {
    use rayon::prelude::*;
    (0..mesh.triangle_count())
        .into_par_iter()
        .map(|t| {
            let tri = mesh.triangle(t);
            let mut worst: f64 = 0.0;
            for_samples(&tri, spacing, true, |p| {
                worst = worst.max(surface.distance(p))
            });
            worst
        })
        .reduce(|| 0.0, f64::max)
}

/// Calls `f` on a barycentric grid over `tri` whose steps are at most `spacing` (at least the
/// edge midpoints), and on the centroid; corners only when `corners`.
fn for_samples(tri: &[Vec3; 3], spacing: f64, corners: bool, mut f: impl FnMut(Vec3)) {
    let longest = (0..3)
        .map(|k| norm(sub(tri[(k + 1) % 3], tri[k])))
        .fold(0.0, f64::max);
    let n = ((longest / spacing).ceil() as usize).clamp(2, 24);
    let [a, b, c] = *tri;
    for i in 0..=n {
        for j in 0..=n - i {
            let k = n - i - j;
            if !corners && (i == n || j == n || k == n) {
                continue;
            }
            let (u, v, w) = (
                i as f64 / n as f64,
                j as f64 / n as f64,
                k as f64 / n as f64,
            );
            f([0, 1, 2].map(|d| u * a[d] + v * b[d] + w * c[d]));
        }
    }
    f([0, 1, 2].map(|d| (a[d] + b[d] + c[d]) / 3.0));
}

/// A quadric: the sum of squared distances to planes, as the symmetric 4×4 matrix's upper half.
type Quadric = [f64; 10];

fn plane_quadric(n: Vec3, d: f64, w: f64) -> Quadric {
    let [a, b, c] = n;
    [
        w * a * a,
        w * a * b,
        w * a * c,
        w * a * d,
        w * b * b,
        w * b * c,
        w * b * d,
        w * c * c,
        w * c * d,
        w * d * d,
    ]
}

fn eval(q: &Quadric, p: Vec3) -> f64 {
    let [x, y, z] = p;
    q[0] * x * x
        + 2.0 * q[1] * x * y
        + 2.0 * q[2] * x * z
        + 2.0 * q[3] * x
        + q[4] * y * y
        + 2.0 * q[5] * y * z
        + 2.0 * q[6] * y
        + q[7] * z * z
        + 2.0 * q[8] * z
        + q[9]
}

struct Collapser<'a> {
    surface: Surface<'a>,
    settings: Settings,
    pos: Vec<Vec3>,
    tris: Vec<[u32; 3]>,
    alive: Vec<bool>,
    faces: Vec<Vec<u32>>,
    quadric: Vec<Quadric>,
    /// Per vertex: the box faces it lies on (bit 2k: min of axis k, 2k + 1: max).
    planes: Vec<u8>,
    /// Per vertex: the box faces along whose cut edge it lies (it also has neighbours off them).
    crease: Vec<u8>,
    locked: &'a [bool],
    /// Vertex merged into (itself while it remains).
    parent: Vec<u32>,
}

impl<'a> Collapser<'a> {
    fn new(mesh: &Mesh, surface: Surface<'a>, settings: Settings, locked: &'a [bool]) -> Self {
        let nv = mesh.vertex_count();
        let pos: Vec<Vec3> = (0..nv as u32).map(|v| mesh.vertex(v)).collect();
        let tris: Vec<[u32; 3]> = mesh
            .indices
            .chunks_exact(3)
            .map(|t| [t[0], t[1], t[2]])
            .collect();
        let mut faces = vec![Vec::new(); nv];
        for (f, t) in tris.iter().enumerate() {
            for &v in t {
                faces[v as usize].push(f as u32);
            }
        }
        let planes = box_planes(&pos, &surface.clip, settings.voxel);
        let mut crease = vec![0u8; nv];
        for t in &tris {
            for k in 0..3 {
                let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
                crease[a] |= planes[a] & !planes[b];
                crease[b] |= planes[b] & !planes[a];
            }
        }
        let mut quadric = vec![[0.0; 10]; nv];
        for t in &tris {
            let [a, b, c] = t.map(|v| pos[v as usize]);
            let n = cross(sub(b, a), sub(c, a));
            let l = norm(n);
            if l <= 0.0 {
                continue;
            }
            let n = n.map(|x| x / l);
            let q = plane_quadric(n, -dot(n, a), 0.5 * l);
            for &v in t {
                for (x, y) in quadric[v as usize].iter_mut().zip(q.iter()) {
                    *x += y;
                }
            }
        }
        Collapser {
            surface,
            settings,
            pos,
            alive: vec![true; tris.len()],
            tris,
            faces,
            quadric,
            planes,
            crease,
            locked,
            parent: (0..nv as u32).collect(),
        }
    }

    fn neighbours(&self, v: u32) -> Vec<u32> {
        let mut n: Vec<u32> = self.faces[v as usize]
            .iter()
            .flat_map(|&f| self.tris[f as usize])
            .filter(|&w| w != v)
            .collect();
        n.sort_unstable();
        n.dedup();
        n
    }

    /// Collapses in passes, as meshoptimizer's simplifier does: each pass orders the vertices
    /// by the quadric cost of their cheapest collapse and merges each, in that order, into the
    /// cheapest neighbour that keeps every promise. A vertex none of whose collapses was allowed
    /// is tried again only once something around it changed. Stops when a pass merges nothing.
    fn run(&mut self) {
        let n = self.pos.len();
        // Pass in which each vertex's neighbourhood last changed, and in which it was last
        // found to have no allowed collapse.
        let mut changed = vec![1u32; n];
        let mut refused = vec![0u32; n];
        for pass in 1u32.. {
            let mut order: Vec<(f64, u32)> = (0..n as u32)
                .filter(|&u| {
                    let i = u as usize;
                    self.parent[i] == u
                        && !self.locked[i]
                        && changed[i] > refused[i]
                        && !self.faces[i].is_empty()
                })
                .map(|u| {
                    let best = self.candidates(u).first().map_or(f64::INFINITY, |c| c.0);
                    (best, u)
                })
                .filter(|c| c.0.is_finite())
                .collect();
            if order.is_empty() {
                break;
            }
            order.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            let mut made = 0u64;
            for (_, u) in order {
                if self.parent[u as usize] != u {
                    continue;
                }
                let into = self
                    .candidates(u)
                    .into_iter()
                    .map(|c| c.1)
                    .find(|&v| self.allowed(u, v));
                match into {
                    Some(v) => {
                        self.collapse(u, v);
                        changed[v as usize] = pass + 1;
                        for w in self.neighbours(v) {
                            changed[w as usize] = pass + 1;
                        }
                        made += 1;
                    }
                    None => refused[u as usize] = pass,
                }
            }
            if made == 0 {
                break;
            }
        }
    }

    /// `u`'s possible collapses, cheapest first: (quadric cost, neighbour).
    fn candidates(&self, u: u32) -> Vec<(f64, u32)> {
        let q = &self.quadric[u as usize];
        let mut c: Vec<(f64, u32)> = self
            .neighbours(u)
            .into_iter()
            .filter(|&v| !self.locked[v as usize])
            .map(|v| (eval(q, self.pos[v as usize]).max(0.0), v))
            .collect();
        c.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        c
    }

    /// Whether merging `u` into `v` keeps every promise.
    fn allowed(&self, u: u32, v: u32) -> bool {
        let (ui, vi) = (u as usize, v as usize);
        // The box: u's faces are v's, and a cut-edge vertex moves only along its cut edge.
        if self.planes[ui] & !self.planes[vi] != 0 {
            return false;
        }
        // The two triangles of the edge, and the others around u.
        let mut shared = [0u32; 2];
        let mut n_shared = 0;
        for &f in &self.faces[ui] {
            if self.tris[f as usize].contains(&v) {
                if n_shared == 2 {
                    return false;
                }
                shared[n_shared] = f;
                n_shared += 1;
            }
        }
        if n_shared != 2 {
            return false;
        }
        let opposite = shared.map(|f| {
            *self.tris[f as usize]
                .iter()
                .find(|&&w| w != u && w != v)
                .expect("a triangle has three vertices")
        });
        if opposite[0] == opposite[1] {
            return false;
        }
        let cu = self.crease[ui];
        if cu != 0 {
            if cu & !self.crease[vi] != 0 {
                return false;
            }
            // Along the cut edge: of the edge's two triangles, one lies on each such face.
            for k in 0..6 {
                if cu & (1 << k) == 0 {
                    continue;
                }
                let on = |f: u32| {
                    self.tris[f as usize]
                        .iter()
                        .all(|&w| self.planes[w as usize] & (1 << k) != 0)
                };
                if on(shared[0]) == on(shared[1]) {
                    return false;
                }
            }
        }
        // The link condition, and no vertex left with under three neighbours.
        let (nu, nv) = (self.neighbours(u), self.neighbours(v));
        let common = nu.iter().filter(|w| nv.binary_search(w).is_ok()).count();
        if common != 2 || (nu.len() <= 3 && nv.len() <= 3) {
            return false;
        }
        if opposite.iter().any(|&w| self.faces[w as usize].len() <= 3) {
            return false;
        }
        // Geometry of every triangle that changes.
        let tol = self.settings.tolerance;
        let spacing = self.settings.voxel;
        let cos_max = MAX_NORMAL_DEGREES.to_radians().cos();
        let pv = self.pos[vi];
        let mut nearest = f64::INFINITY;
        for &f in &self.faces[ui] {
            let t = self.tris[f as usize];
            if t.contains(&v) {
                continue;
            }
            let old = t.map(|w| self.pos[w as usize]);
            let new = t.map(|w| if w == u { pv } else { self.pos[w as usize] });
            let (n_old, n_new) = (normal(&old), normal(&new));
            let l = norm(n_new);
            if l <= 1e-12 * spacing * spacing || dot(n_old, n_new) <= 0.0 {
                return false;
            }
            let q_new = quality(&new);
            if q_new < MIN_QUALITY * EQUILATERAL && q_new < quality(&old) {
                return false;
            }
            let longest = (0..3)
                .map(|k| norm(sub(new[k], new[(k + 1) % 3])))
                .fold(0.0, f64::max);
            if longest > MAX_EDGE_VOXELS * spacing {
                return false;
            }
            let centroid = [0, 1, 2].map(|d| (new[0][d] + new[1][d] + new[2][d]) / 3.0);
            if let Some(s) = self.surface.normal(centroid) {
                if dot(s, n_new) < cos_max * l {
                    return false;
                }
            }
            let mut far = false;
            for_samples(&new, spacing, false, |p| {
                far = far || self.surface.distance(p) > tol
            });
            if far {
                return false;
            }
            nearest = nearest.min(triangle_distance2(self.pos[ui], &new));
        }
        nearest.sqrt() <= tol
    }

    fn collapse(&mut self, u: u32, v: u32) {
        let (ui, vi) = (u as usize, v as usize);
        let around = std::mem::take(&mut self.faces[ui]);
        for f in around {
            let t = &mut self.tris[f as usize];
            if t.contains(&v) {
                self.alive[f as usize] = false;
                let t = *t;
                for w in t {
                    if w != u {
                        self.faces[w as usize].retain(|&g| g != f);
                    }
                }
            } else {
                for w in t.iter_mut() {
                    if *w == u {
                        *w = v;
                    }
                }
                self.faces[vi].push(f);
            }
        }
        let qu = self.quadric[ui];
        for (x, y) in self.quadric[vi].iter_mut().zip(qu.iter()) {
            *x += y;
        }
        self.parent[ui] = v;
    }

    /// The simplified mesh (vertices renumbered in their input order) and, per input vertex,
    /// the output vertex it was merged into (`None` for none: a vertex no triangle used).
    fn finish(mut self) -> (Mesh, Vec<Option<u32>>) {
        let nv = self.pos.len();
        let mut used = vec![false; nv];
        for (t, a) in self.tris.iter().zip(&self.alive) {
            if *a {
                for &v in t {
                    used[v as usize] = true;
                }
            }
        }
        let mut index = vec![u32::MAX; nv];
        let mut positions = Vec::new();
        for v in 0..nv {
            if used[v] {
                index[v] = (positions.len() / 3) as u32;
                positions.extend(self.pos[v].map(|x| x as f32));
            }
        }
        let indices = self
            .tris
            .iter()
            .zip(&self.alive)
            .filter(|(_, a)| **a)
            .flat_map(|(t, _)| t.map(|v| index[v as usize]))
            .collect();
        let root = (0..nv)
            .map(|v| {
                let mut r = v;
                while self.parent[r] as usize != r {
                    r = self.parent[r] as usize;
                }
                // Path compression keeps long merge chains cheap.
                let mut w = v;
                while self.parent[w] as usize != r {
                    let next = self.parent[w] as usize;
                    self.parent[w] = r as u32;
                    w = next;
                }
                (index[r] != u32::MAX).then_some(index[r])
            })
            .collect();
        (Mesh { positions, indices }, root)
    }
}

/// Quality of the equilateral triangle by [`crate::mesh::extract::quality`].
const EQUILATERAL: f64 = 0.288_675_134_594_812_9; // √3 / 6

fn normal(t: &[Vec3; 3]) -> Vec3 {
    cross(sub(t[1], t[0]), sub(t[2], t[0]))
}

/// [`crate::mesh::extract::quality`] of a triangle given as its corners.
fn quality(t: &[Vec3; 3]) -> f64 {
    crate::mesh::extract::quality(t[0], t[1], t[2])
}
