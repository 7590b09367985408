//! Exact triangle tests: the orientation predicates (Shewchuk's adaptive-precision `orient3d` and
//! `orient2d`, from the `robust` crate, exact on the f32 coordinates meshes hold) and, built on
//! them alone, the triangle–triangle and triangle–segment tests of CGAL's kernel (Guigue and
//! Devillers, "Fast and robust triangle-triangle overlap test using orientation predicates",
//! 2003), ported branch for branch so that every answer is CGAL's. Facets that share a vertex or
//! an edge are decided as CGAL's `self_intersections` decides them: a shared edge intersects only
//! in a fold (coplanar, the third vertices on one side), a shared vertex only when an opposite
//! edge meets the other triangle.

use robust::{orient2d, orient3d, Coord, Coord3D};

/// A point.
pub type P = [f64; 3];

/// The sign of an orientation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sign {
    /// Negative (clockwise, below).
    Neg,
    /// Zero (collinear, coplanar).
    Zero,
    /// Positive (counter-clockwise, above).
    Pos,
}
use Sign::{Neg, Pos, Zero};

fn sign(x: f64) -> Sign {
    if x > 0.0 {
        Pos
    } else if x < 0.0 {
        Neg
    } else {
        Zero
    }
}

fn c3(p: &P) -> Coord3D<f64> {
    Coord3D {
        x: p[0],
        y: p[1],
        z: p[2],
    }
}

/// CGAL's `orientation(p, q, r, s)`: positive when `s` lies on the side of the plane `pqr` its
/// normal `(q − p) × (r − p)` points to. (Shewchuk's `orient3d` has the opposite sign.)
#[inline]
pub fn orientation(p: &P, q: &P, r: &P, s: &P) -> Sign {
    Plane::new(p, q, r).side(s, || [p, q, r])
}

fn sub(a: &P, b: &P) -> P {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// Bound on the rounding error of `det[u, v, d]` evaluated in f64 as `(u × v) · d` from points
/// held exactly in f64, relative to the permanent `Σ |u_i v_j d_k|`: each of the six terms
/// passes through at most eight roundings (three differences, a product, the cross product's
/// difference, the product with `d`, two sums), so the error is below `8ε + O(ε²)` of the
/// permanent, ε = 2⁻⁵³ (Shewchuk's orient3d error bound argues the same way).
const ORIENT_ERR: f64 = 1.0e-15;
/// Below this permanent, underflow could hide the error: the exact predicate decides.
const ORIENT_TINY: f64 = 1.0e-250;

/// The oriented plane of a triangle `pqr`, for the sign of CGAL's `orientation(p, q, r, s)` at
/// many points `s`: a floating-point filter with a proven error bound, and Shewchuk's adaptive
/// `orient3d` when the filter cannot decide (points on or within rounding of the plane).
#[derive(Debug, Clone, Copy)]
pub struct Plane {
    origin: P,
    normal: P,
    /// Component-wise `|u_y v_z| + |u_z v_y|` …, so the permanent is `perm · |d|`.
    perm: P,
}

impl Plane {
    /// The plane through `p, q, r`.
    #[inline]
    pub fn new(p: &P, q: &P, r: &P) -> Plane {
        let (u, v) = (sub(q, p), sub(r, p));
        Plane {
            origin: *p,
            normal: [
                u[1] * v[2] - u[2] * v[1],
                u[2] * v[0] - u[0] * v[2],
                u[0] * v[1] - u[1] * v[0],
            ],
            perm: [
                (u[1] * v[2]).abs() + (u[2] * v[1]).abs(),
                (u[2] * v[0]).abs() + (u[0] * v[2]).abs(),
                (u[0] * v[1]).abs() + (u[1] * v[0]).abs(),
            ],
        }
    }

    /// The sign of `orientation(p, q, r, s)`; `pqr` gives the plane's points for the exact
    /// fallback.
    #[inline]
    pub fn side<'a>(&self, s: &P, pqr: impl FnOnce() -> [&'a P; 3]) -> Sign {
        let d = sub(s, &self.origin);
        let n = &self.normal;
        let det = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
        let m = &self.perm;
        let perm = m[0] * d[0].abs() + m[1] * d[1].abs() + m[2] * d[2].abs();
        if det.abs() > ORIENT_ERR * perm && perm > ORIENT_TINY {
            return sign(det);
        }
        let [p, q, r] = pqr();
        // Four points in one axis-aligned plane (a part's flat faces): exactly coplanar.
        if (0..3).any(|i| p[i] == q[i] && p[i] == r[i] && p[i] == s[i]) {
            return Zero;
        }
        sign(-orient3d(c3(p), c3(q), c3(r), c3(s)))
    }
}

#[inline]
fn orient_xy(p: &P, q: &P, r: &P, (i, j): (usize, usize)) -> Sign {
    let c = |a: &P| Coord { x: a[i], y: a[j] };
    sign(orient2d(c(p), c(q), c(r)))
}

/// The projections CGAL's coplanar predicates try, in order: xy, yz, xz.
const PLANES: [(usize, usize); 3] = [(0, 1), (1, 2), (0, 2)];

/// CGAL's `coplanar_orientation(p, q, r)` for coplanar points: the orientation of `r` from the
/// line `pq`, read in the first projection where the three points are not collinear.
pub fn coplanar_orientation(p: &P, q: &P, r: &P) -> Sign {
    for plane in PLANES {
        let o = orient_xy(p, q, r, plane);
        if o != Zero {
            return o;
        }
    }
    Zero
}

/// CGAL's `coplanar_orientation(p, q, r, s)` (`p, q, r` not collinear): positive when `r` and `s`
/// lie on the same side of the line `pq` in their common plane, negative on opposite sides, zero
/// when `s` is on the line.
pub fn coplanar_orientation4(p: &P, q: &P, r: &P, s: &P) -> Sign {
    for plane in PLANES {
        let o = orient_xy(p, q, r, plane);
        if o != Zero {
            return mul(o, orient_xy(p, q, s, plane));
        }
    }
    Zero
}

fn mul(a: Sign, b: Sign) -> Sign {
    match (a, b) {
        (Zero, _) | (_, Zero) => Zero,
        (x, y) if x == y => Pos,
        _ => Neg,
    }
}

/// Whether the three points lie on one line (exactly): every projection collinear.
pub fn collinear(p: &P, q: &P, r: &P) -> bool {
    PLANES.iter().all(|&pl| orient_xy(p, q, r, pl) == Zero)
}

/// A facet: its vertex indices, its corners and its plane.
#[derive(Debug, Clone, Copy)]
pub struct Facet {
    /// Vertex indices.
    pub v: [u32; 3],
    /// Corners, in order.
    pub p: [P; 3],
    /// The plane through the corners, oriented by them.
    pub plane: Plane,
}

impl Facet {
    /// The facet with vertex indices `v` at corners `p`.
    #[inline]
    pub fn new(v: [u32; 3], p: [P; 3]) -> Facet {
        Facet {
            v,
            p,
            plane: Plane::new(&p[0], &p[1], &p[2]),
        }
    }

    /// The sign of `orientation(p0, p1, p2, s)`.
    #[inline]
    fn side(&self, s: &P) -> Sign {
        self.plane.side(s, || [&self.p[0], &self.p[1], &self.p[2]])
    }
}

/// Whether the closed triangles `pqr` and `abc` (neither degenerate) meet: CGAL's
/// `do_intersect(Triangle_3, Triangle_3)`.
pub fn triangles_meet(p: &P, q: &P, r: &P, a: &P, b: &P, c: &P) -> bool {
    facets_meet(
        &Facet::new([0, 1, 2], [*p, *q, *r]),
        &Facet::new([3, 4, 5], [*a, *b, *c]),
    )
}

/// [`triangles_meet`] for two facets (their indices play no part).
pub fn facets_meet(f: &Facet, g: &Facet) -> bool {
    let [p, q, r] = &f.p;
    let [a, b, c] = &g.p;
    // Where p, q and r lie against the plane of abc; which vertex is alone on its side.
    let (dp, dq, dr) = (g.side(p), g.side(q), g.side(r));
    let [s_min1, t_min1, s_max1, t_max1] = match isolate(dp, dq, dr, [p, q, r]) {
        Isolated::Apart => return false,
        Isolated::Coplanar => return coplanar_triangles_meet(p, q, r, a, b, c),
        Isolated::Points(x) => x,
    };
    let (da, db, dc) = (f.side(a), f.side(b), f.side(c));
    let [s_min2, t_min2, s_max2, t_max2] = match isolate(da, db, dc, [a, b, c]) {
        Isolated::Apart => return false,
        // Unreachable for triangles that are not flat (as in CGAL).
        Isolated::Coplanar => return coplanar_triangles_meet(p, q, r, a, b, c),
        Isolated::Points(x) => x,
    };
    orientation(s_min1, t_min1, s_min2, t_min2) != Pos
        && orientation(s_max1, t_max1, t_max2, s_max2) != Pos
}

enum Isolated<'a> {
    Apart,
    Coplanar,
    Points([&'a P; 4]),
}

/// The permutation step of Guigue and Devillers: from the signs of a triangle's three vertices
/// against the other's plane, the two edges that cross it (as `[s_min, t_min, s_max, t_max]`),
/// or that the triangle lies off the plane or in it.
fn isolate<'a>(dp: Sign, dq: Sign, dr: Sign, [p, q, r]: [&'a P; 3]) -> Isolated<'a> {
    use Isolated::Points;
    match (dp, dq, dr) {
        (Pos, Pos, Pos) | (Neg, Neg, Neg) => Isolated::Apart,
        (Zero, Zero, Zero) => Isolated::Coplanar,
        // r alone on the negative side
        (Pos, Pos, _) => Points([q, r, r, p]),
        // q alone on the negative side
        (Pos, _, Pos) => Points([p, q, q, r]),
        // p alone on the positive side
        (Pos, _, _) => Points([p, q, r, p]),
        // r alone on the positive side
        (Neg, Neg, _) => Points([r, p, q, r]),
        // q alone on the positive side
        (Neg, _, Neg) => Points([q, r, p, q]),
        // p alone on the negative side
        (Neg, _, _) => Points([r, p, p, q]),
        (Zero, Pos, Pos) => Points([r, p, p, q]),
        (Zero, Pos, _) => Points([q, r, p, q]),
        (Zero, Neg, Neg) => Points([p, q, r, p]),
        (Zero, Neg, _) => Points([p, q, q, r]),
        (Zero, Zero, Pos) => Points([r, p, q, r]),
        (Zero, Zero, Neg) => Points([q, r, r, p]),
    }
}

/// CGAL's `do_intersect_coplanar` for two triangles in one plane.
fn coplanar_triangles_meet(pp: &P, qq: &P, rr: &P, aa: &P, bb: &P, cc: &P) -> bool {
    let co = coplanar_orientation;
    let (p, mut q, mut r) = (pp, qq, rr);
    let (a, mut b, mut c) = (aa, bb, cc);
    // Both counter-clockwise.
    if co(pp, qq, rr) == Neg {
        (q, r) = (rr, qq);
    }
    if co(aa, bb, cc) == Neg {
        (b, c) = (cc, bb);
    }
    // Where p lies in the arrangement of the lines through abc's edges.
    if co(a, b, p) != Neg {
        if co(b, c, p) != Neg {
            if co(c, a, p) != Neg {
                return true; // p inside abc
            }
            return test_edge(p, q, r, a, b, c); // p sees ac
        }
        if co(c, a, p) != Neg {
            return test_edge(p, q, r, c, a, b); // p sees bc
        }
        return test_vertex(p, q, r, a, b, c); // p sees c
    }
    if co(b, c, p) != Neg {
        if co(c, a, p) != Neg {
            return test_edge(p, q, r, b, c, a); // p sees ab
        }
        return test_vertex(p, q, r, b, c, a); // p sees a
    }
    test_vertex(p, q, r, c, a, b) // p sees b
}

/// CGAL's `_intersection_test_vertex`: vertex p sees vertex c.
fn test_vertex(p: &P, q: &P, r: &P, a: &P, b: &P, c: &P) -> bool {
    let co = coplanar_orientation;
    if co(c, a, q) != Neg {
        if co(c, b, q) != Pos {
            if co(p, a, q) == Pos {
                return co(p, b, q) != Pos;
            }
            return co(p, a, r) != Neg && co(q, r, a) != Neg;
        }
        if co(p, b, q) != Pos {
            return co(c, b, r) != Pos && co(q, r, b) != Neg;
        }
        return false;
    }
    if co(c, a, r) != Neg {
        // qr straddles (ac)
        if co(q, r, c) != Neg {
            return co(p, a, r) != Neg;
        }
        return co(q, r, b) != Neg && co(c, r, b) != Neg;
    }
    false // ca separates
}

/// CGAL's `_intersection_test_edge`: vertex p sees edge ca.
fn test_edge(p: &P, q: &P, r: &P, a: &P, _b: &P, c: &P) -> bool {
    let co = coplanar_orientation;
    if co(c, a, q) != Neg {
        // pq straddles (ac)
        if co(p, a, q) != Neg {
            return co(p, q, c) != Neg;
        }
        return co(q, r, a) != Neg && co(r, p, a) != Neg;
    }
    if co(c, a, r) != Neg {
        return co(p, a, r) != Neg && (co(p, r, c) != Neg || co(q, r, c) != Neg);
    }
    false // ac separates
}

/// Whether the closed segment `pq` meets the closed triangle `abc` (neither degenerate): CGAL's
/// `do_intersect(Triangle_3, Segment_3)`.
pub fn segment_meets_triangle(a: &P, b: &P, c: &P, p: &P, q: &P) -> bool {
    segment_meets_facet(&Facet::new([0, 1, 2], [*a, *b, *c]), p, q)
}

/// [`segment_meets_triangle`] for a facet.
fn segment_meets_facet(t: &Facet, p: &P, q: &P) -> bool {
    let [a, b, c] = &t.p;
    let sees = |p: &P, q: &P| {
        orientation(p, q, a, b) != Pos
            && orientation(p, q, b, c) != Pos
            && orientation(p, q, c, a) != Pos
    };
    match (t.side(p), t.side(q)) {
        (Pos, Pos) | (Neg, Neg) => false,
        (Pos, _) => sees(p, q),
        (Neg, _) => sees(q, p),
        (Zero, Pos) => sees(q, p),
        (Zero, Neg) => sees(p, q),
        (Zero, Zero) => coplanar_segment_meets_triangle(a, b, c, p, q),
    }
}

/// CGAL's `do_intersect_coplanar(A, B, C, p, q)`.
fn coplanar_segment_meets_triangle(aa: &P, bb: &P, cc: &P, p: &P, q: &P) -> bool {
    let co = coplanar_orientation;
    let (a, mut b, mut c) = (aa, bb, cc);
    if co(aa, bb, cc) != Pos {
        (b, c) = (cc, bb);
    }
    let (pqa, pqb, pqc) = (co(p, q, a), co(p, q, b), co(p, q, c));
    match (pqa, pqb) {
        (Pos, Pos) => pqc != Pos && co(b, c, q) != Neg && co(c, a, p) != Neg,
        (Pos, Neg) | (Pos, Zero) => {
            if pqc == Pos {
                co(a, b, q) != Neg && co(b, c, p) != Neg
            } else {
                co(a, b, q) != Neg && co(c, a, p) != Neg
            }
        }
        (Neg, Pos) => {
            if pqc == Pos {
                co(a, b, p) != Neg && co(c, a, q) != Neg
            } else {
                co(a, b, p) != Neg && co(b, c, q) != Neg
            }
        }
        (Neg, Neg) => pqc != Neg && co(b, c, p) != Neg && co(c, a, q) != Neg,
        (Neg, Zero) => {
            if pqc == Neg {
                co(a, b, p) != Neg && co(b, c, q) != Neg
            } else {
                co(a, b, p) != Neg && co(c, a, q) != Neg
            }
        }
        (Zero, Pos) => {
            if pqc == Pos {
                co(a, b, p) != Neg && co(c, a, q) != Neg
            } else {
                co(a, b, p) != Neg && co(b, c, q) != Neg
            }
        }
        (Zero, Neg) => {
            if pqc == Neg {
                co(a, b, q) != Neg && co(c, a, p) != Neg
            } else {
                co(a, b, q) != Neg && co(b, c, p) != Neg
            }
        }
        (Zero, Zero) => {
            if pqc == Pos {
                co(b, c, p) != Neg && co(c, a, q) != Neg
            } else {
                co(b, c, q) != Neg && co(c, a, p) != Neg
            }
        }
    }
}

/// How many vertex indices facets `f` and `g` share, and at which corners of each.
#[inline]
pub fn sharing(f: &[u32; 3], g: &[u32; 3]) -> (usize, [usize; 3], [usize; 3]) {
    let mut shared = 0;
    let (mut fi, mut gj) = ([0usize; 3], [0usize; 3]);
    for (i, a) in f.iter().enumerate() {
        for (j, b) in g.iter().enumerate() {
            if a == b {
                fi[shared] = i;
                gj[shared] = j;
                shared += 1;
            }
        }
    }
    (shared, fi, gj)
}

/// Whether the pair of facets with vertex indices `f` and `g` is answered without looking at
/// their corners: duplicates (three shared vertices), and pairs sharing a vertex that `f_star`
/// (bit k for corner k of `f`) marks as a vertex whose facets hold no intersecting pair among
/// those sharing it (see [`super::fans`]): both facets lie in its fan, which projects one-to-one,
/// so they meet only in what they share (the vertex, or an edge from it).
#[inline]
pub fn settled_by_sharing(f: &[u32; 3], f_star: u8, g: &[u32; 3]) -> bool {
    // Bit i: corner i of f is a vertex of g.
    let shared = (0..3).fold(0u8, |m, i| {
        m | ((f[i] == g[0]) as u8 | (f[i] == g[1]) as u8 | (f[i] == g[2]) as u8) << i
    });
    shared == 7 || f_star & shared != 0
}

/// Whether facets `f` and `g` (neither degenerate) intersect in more than the vertices and edge
/// they share — CGAL's `do_faces_intersect`, with sharing read off the vertex indices. Facets
/// sharing all three vertices (duplicates) are not counted here: `check` reports them as
/// duplicate facets.
pub fn facets_intersect(f: &Facet, g: &Facet) -> bool {
    let (shared, fi, gj) = sharing(&f.v, &g.v);
    match shared {
        0 => facets_meet(f, g),
        1 => {
            // The edges opposite the shared vertex, each against the other triangle.
            let (i, j) = (fi[0], gj[0]);
            segment_meets_facet(f, &g.p[(j + 1) % 3], &g.p[(j + 2) % 3])
                || segment_meets_facet(g, &f.p[(i + 1) % 3], &f.p[(i + 2) % 3])
        }
        2 => {
            // A shared edge u–v: a fold when the third vertices are coplanar with it and on one
            // side of it.
            let (u, v) = (&f.p[fi[0]], &f.p[fi[1]]);
            let r = &f.p[3 - fi[0] - fi[1]];
            let s = &g.p[3 - gj[0] - gj[1]];
            f.side(s) == Zero && coplanar_orientation4(u, v, r, s) == Pos
        }
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orientation_has_cgal_sign() {
        let (p, q, r) = ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        assert_eq!(orientation(&p, &q, &r, &[0.0, 0.0, 1.0]), Pos);
        assert_eq!(orientation(&p, &q, &r, &[0.3, 0.3, -1.0]), Neg);
        assert_eq!(orientation(&p, &q, &r, &[5.0, -2.0, 0.0]), Zero);
        assert_eq!(coplanar_orientation(&p, &q, &r), Pos);
        assert_eq!(coplanar_orientation4(&p, &q, &r, &[0.5, 2.0, 0.0]), Pos);
        assert_eq!(coplanar_orientation4(&p, &q, &r, &[0.5, -2.0, 0.0]), Neg);
        assert!(collinear(&p, &q, &[3.0, 0.0, 0.0]));
        assert!(!collinear(&p, &q, &r));
    }

    #[test]
    fn triangles_crossing_touching_and_apart() {
        let t = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]];
        // Pierces the interior.
        let u = [[0.5, 0.5, -1.0], [0.5, 0.5, 1.0], [1.5, 1.5, 1.0]];
        assert!(triangles_meet(&t[0], &t[1], &t[2], &u[0], &u[1], &u[2]));
        // Touches with one vertex on t's edge.
        let v = [[1.0, 0.0, 0.0], [1.0, -1.0, 1.0], [1.0, -1.0, -1.0]];
        assert!(triangles_meet(&t[0], &t[1], &t[2], &v[0], &v[1], &v[2]));
        // Lifted off the plane.
        let w = [[0.2, 0.2, 0.1], [1.0, 0.2, 0.1], [0.2, 1.0, 0.2]];
        assert!(!triangles_meet(&t[0], &t[1], &t[2], &w[0], &w[1], &w[2]));
        // Coplanar, overlapping and apart.
        let x = [[0.5, 0.5, 0.0], [3.0, 0.5, 0.0], [0.5, 3.0, 0.0]];
        assert!(triangles_meet(&t[0], &t[1], &t[2], &x[0], &x[1], &x[2]));
        let y = [[2.0, 2.0, 0.0], [3.0, 2.0, 0.0], [2.0, 3.0, 0.0]];
        assert!(!triangles_meet(&t[0], &t[1], &t[2], &y[0], &y[1], &y[2]));
        // A segment through the interior, and one beside it.
        assert!(segment_meets_triangle(
            &t[0],
            &t[1],
            &t[2],
            &[0.3, 0.3, -1.0],
            &[0.3, 0.3, 1.0]
        ));
        assert!(!segment_meets_triangle(
            &t[0],
            &t[1],
            &t[2],
            &[3.0, 3.0, -1.0],
            &[3.0, 3.0, 1.0]
        ));
    }

    fn fi(f: [u32; 3], pf: [&P; 3], g: [u32; 3], pg: [&P; 3]) -> bool {
        facets_intersect(
            &Facet::new(f, pf.map(|x| *x)),
            &Facet::new(g, pg.map(|x| *x)),
        )
    }

    #[test]
    fn shared_edges_and_vertices() {
        let (a, b, c) = ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        // A flat neighbour across edge a–b: no intersection; folded onto abc: one.
        let d = [0.5, -1.0, 0.0];
        assert!(!fi([0, 1, 2], [&a, &b, &c], [1, 0, 3], [&b, &a, &d]));
        let e = [0.2, 0.5, 0.0];
        assert!(fi([0, 1, 2], [&a, &b, &c], [1, 0, 3], [&b, &a, &e]));
        // Bent neighbour: none.
        let f = [0.5, -1.0, 0.3];
        assert!(!fi([0, 1, 2], [&a, &b, &c], [1, 0, 3], [&b, &a, &f]));
        // Sharing vertex a: an opposite edge through abc counts, one beside it does not.
        let (g, h) = ([0.3, 0.3, -1.0], [0.3, 0.3, 1.0]);
        assert!(fi([0, 1, 2], [&a, &b, &c], [0, 4, 5], [&a, &g, &h]));
        let (g, h) = ([-0.3, -0.3, -1.0], [-0.3, -0.3, 1.0]);
        assert!(!fi([0, 1, 2], [&a, &b, &c], [0, 4, 5], [&a, &g, &h]));
    }
}
