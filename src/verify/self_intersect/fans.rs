//! Vertices whose facets provably hold no intersecting pair among those sharing that vertex —
//! most vertices of a smooth mesh — so the exact tests skip those pairs (on a mesh latvox makes,
//! nearly all the pairs whose boxes overlap).
//!
//! A vertex v qualifies when its facets (v, b, c) close into one fan that an axis projection
//! maps one-to-one: every facet has the same strict orientation in the projection (exact,
//! Shewchuk's `orient2d` on the f32 coordinates), each neighbour b starts exactly one link edge
//! b → c and ends exactly one, and the link edges wind once around v. With the projection's axes
//! ordered to make the orientations positive, the winding number is the count of link edges
//! b → c with `b.y ≤ v.y < c.y`: each facet spans a sector of less than half a turn, and such a
//! sector holds the direction +x (half-open) exactly when its first edge is in the closed lower
//! half-plane and its second in the open upper one — comparisons of coordinates only. Winding
//! once, the sectors tile the plane around v without overlap, so two facets that share no edge
//! meet in the projection only at v, and in space only at v: CGAL's test for a pair sharing one
//! vertex (does either opposite edge meet the other facet?) answers no for every such pair. Two
//! facets sharing an edge v–w lie on either side of it in the projection, so they meet only
//! along it: no fold. Any axis on which the facets agree will do; each is tried.
//!
//! All of it is read off bits computed once per facet, in facet order (no vertex's neighbours
//! fetched from memory): the sign of a projected triangle's orientation is the same from each of
//! its corners, and the `b.y ≤ v.y < c.y` tests are per corner, for each of the three axes `y`.

use rayon::prelude::*;
use robust::{orient2d, Coord};

/// Facet bits: `1 << (2a)` when the facet's projection along axis `a` is positive, `1 << (2a+1)`
/// when negative.
const SIGNS: u16 = 0x3f;
/// Corner bits (beside [`SIGNS`]): `1 << (6 + y)` when `b.y ≤ v.y < c.y` for the corner at v of
/// the facet (v, b, c).
const WINDING: u32 = 6;

/// The link edges of every vertex: for each corner of a facet (v, b, c) in winding order, the
/// edge b → c filed under v (a counting sort by vertex), and when asked for, the corner's bits
/// for the projection test.
pub struct Links {
    start: Vec<u32>,
    link: Vec<[u32; 2]>,
    bits: Vec<u16>,
}

impl Links {
    /// The links of `nv` vertices among the facets `indices` (vertex index triples, flat); with
    /// `positions`, the bits of the projection test too.
    pub fn new(nv: usize, indices: &[u32], positions: Option<&[f32]>) -> Links {
        let facet_bits: Vec<u16> = match positions {
            Some(p) => indices.par_chunks_exact(3).map(|t| bits(p, t)).collect(),
            None => Vec::new(),
        };
        let mut start = vec![0u32; nv + 1];
        for &v in indices {
            start[v as usize + 1] += 1;
        }
        for v in 0..nv {
            start[v + 1] += start[v];
        }
        let mut fill = start.clone();
        let mut link = vec![[0u32; 2]; indices.len()];
        let mut corner_bits = vec![
            0u16;
            if positions.is_some() {
                indices.len()
            } else {
                0
            }
        ];
        for (f, t) in indices.chunks_exact(3).enumerate() {
            for k in 0..3 {
                let s = &mut fill[t[k] as usize];
                link[*s as usize] = [t[(k + 1) % 3], t[(k + 2) % 3]];
                if let Some(&b) = facet_bits.get(f) {
                    let w = (b >> (WINDING + 3 * k as u32)) & 7;
                    corner_bits[*s as usize] = (b & SIGNS) | (w << WINDING);
                }
                *s += 1;
            }
        }
        Links {
            start,
            link,
            bits: corner_bits,
        }
    }

    /// Vertices.
    pub fn len(&self) -> usize {
        self.start.len() - 1
    }

    /// Whether there are no vertices.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The link edges of `v`.
    #[inline]
    pub fn of(&self, v: usize) -> &[[u32; 2]] {
        &self.link[self.start[v] as usize..self.start[v + 1] as usize]
    }

    /// Whether the facets of `v` — each neighbour starting one link edge and ending one, as a
    /// closed fan has — project one-to-one onto an axis plane around `v` (see the module's
    /// text); false when the links were built without positions.
    pub fn projects_one_to_one(&self, v: usize) -> bool {
        let bits = &self
            .bits
            .get(self.start[v] as usize..self.start[v + 1] as usize);
        let Some(bits) = bits.filter(|b| b.len() >= 3) else {
            return false;
        };
        let agree = bits.iter().fold(SIGNS, |m, b| m & b);
        (0..3).any(|a| {
            // Positive along a: (x, y) = (a+1, a+2); negative: swapped, to make it positive.
            [(2 * a, (a + 2) % 3), (2 * a + 1, (a + 1) % 3)]
                .into_iter()
                .any(|(sign, y)| {
                    agree & (1 << sign) != 0
                        && bits
                            .iter()
                            .filter(|&&b| b & (1 << (WINDING as usize + y)) != 0)
                            .count()
                            == 1
                })
        })
    }
}

/// The bits of the facet `t` (see [`SIGNS`] and [`WINDING`]; corner `k`'s winding bits at
/// `6 + 3k`).
fn bits(positions: &[f32], t: &[u32]) -> u16 {
    let p = [t[0], t[1], t[2]].map(|i| {
        let k = 3 * i as usize;
        [positions[k], positions[k + 1], positions[k + 2]]
    });
    let mut out = 0u16;
    for a in 0..3 {
        let (x, y) = ((a + 1) % 3, (a + 2) % 3);
        let c2 = |q: &[f32; 3]| Coord {
            x: q[x] as f64,
            y: q[y] as f64,
        };
        let o = orient2d(c2(&p[0]), c2(&p[1]), c2(&p[2]));
        if o > 0.0 {
            out |= 1 << (2 * a);
        } else if o < 0.0 {
            out |= 1 << (2 * a + 1);
        }
    }
    for k in 0..3 {
        let (v, b, c) = (&p[k], &p[(k + 1) % 3], &p[(k + 2) % 3]);
        for y in 0..3 {
            if b[y] <= v[y] && v[y] < c[y] {
                out |= 1 << (WINDING as usize + 3 * k + y);
            }
        }
    }
    out
}

/// Per vertex of `positions`, whether it qualifies (see the module's text) among the facets
/// `tris`.
pub fn star_vertices(positions: &[f32], tris: &[[u32; 3]]) -> Vec<bool> {
    let links = Links::new(positions.len() / 3, tris.as_flattened(), Some(positions));
    (0..links.len())
        .into_par_iter()
        .with_min_len(4096)
        .map(|v| star(&links, v))
        .collect()
}

/// Whether `v` qualifies (see the module's text): its fan sound and closed, and projecting
/// one-to-one.
fn star(links: &Links, v: usize) -> bool {
    links.of(v).len() >= 3 && fan(links.of(v)) == (false, 0) && links.projects_one_to_one(v)
}

/// Checks one vertex's link edges `b → c`: returns (defective, border half-edges). The fan is
/// sound when no vertex starts two link edges or ends two (each edge from the vertex traversed
/// once each way), and the link edges chain into one cycle, or one path where the fan meets a
/// border. A half-edge v → b without its twin b → v is a border half-edge (the link edge that
/// starts at b has no link edge ending at b).
pub fn fan(link: &[[u32; 2]]) -> (bool, u64) {
    let n = link.len();
    let starts_at = |x: u32| link.iter().filter(|e| e[0] == x).count();
    let ends_at = |x: u32| link.iter().filter(|e| e[1] == x).count();
    let mut border = 0u64;
    let mut bad = false;
    let mut path_start = None;
    for &[b, c] in link {
        if starts_at(b) != 1 || ends_at(c) != 1 {
            bad = true;
        }
        if ends_at(b) == 0 {
            border += 1;
            if path_start.replace(b).is_some() {
                bad = true; // two border paths meet here
            }
        }
    }
    if bad {
        return (true, border);
    }
    // Walk the chain from the path's start (or anywhere on a cycle); it must cover every facet.
    let first = path_start.unwrap_or(link[0][0]);
    let mut at = first;
    let mut steps = 0;
    while let Some(&[_, c]) = link.iter().find(|e| e[0] == at) {
        steps += 1;
        at = c;
        if at == first || steps > n {
            break;
        }
    }
    (steps != n, border)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fan of `n` facets around vertex 0 at the origin: link vertex k at angle `turns`·k/n of a
    /// full turn, radius 1, height `z(k)`; closed (the last facet back to vertex 1) when asked.
    fn fan(
        n: usize,
        turns: f64,
        z: impl Fn(usize) -> f32,
        closed: bool,
    ) -> (Vec<f32>, Vec<[u32; 3]>) {
        let mut p = vec![0.0f32, 0.0, 0.0];
        for k in 0..n {
            let a = std::f64::consts::TAU * turns * k as f64 / n as f64;
            p.extend([a.cos() as f32, a.sin() as f32, z(k)]);
        }
        let facets = if closed { n } else { n - 1 };
        let tris = (0..facets)
            .map(|k| [0, 1 + k as u32, 1 + ((k + 1) % n) as u32])
            .collect();
        (p, tris)
    }

    #[test]
    fn flat_and_saddle_fans_project_one_to_one() {
        let (p, t) = fan(6, 1.0, |_| 0.0, true);
        assert!(star_vertices(&p, &t)[0]);
        // A monkey saddle: up, down, up … still one sheet over the plane.
        let (p, t) = fan(6, 1.0, |k| if k % 2 == 0 { 0.5 } else { -0.5 }, true);
        assert!(star_vertices(&p, &t)[0]);
        // Seen from below (reversed winding): the negative projection, axes swapped.
        let (p, mut t) = fan(7, 1.0, |k| 0.1 * k as f32, true);
        t.iter_mut().for_each(|f| f.swap(1, 2));
        assert!(star_vertices(&p, &t)[0]);
        // A fan standing on its side projects along another axis.
        let (p, t) = fan(5, 1.0, |_| 0.0, true);
        let p: Vec<f32> = p.chunks(3).flat_map(|q| [q[2], q[0], q[1]]).collect();
        assert!(star_vertices(&p, &t)[0]);
    }

    #[test]
    fn folded_open_and_double_fans_do_not() {
        // Winding twice round (a helicoid): every facet positive, but the projections overlap.
        let (p, t) = fan(12, 2.0, |k| 0.3 * k as f32, true);
        assert!(!star_vertices(&p, &t)[0]);
        // One link vertex pulled across its neighbour: that facet flips.
        let (mut p, t) = fan(6, 1.0, |_| 0.0, true);
        p[3 * 2] = 1.2;
        p[3 * 2 + 1] = -0.3;
        assert!(!star_vertices(&p, &t)[0]);
        // An open fan (at a border) proves nothing.
        let (p, t) = fan(6, 1.0, |_| 0.0, false);
        assert!(!star_vertices(&p, &t)[0]);
        // A facet in the fan twice.
        let (p, mut t) = fan(6, 1.0, |_| 0.0, true);
        t.push(t[0]);
        assert!(!star_vertices(&p, &t)[0]);
        // A degenerate facet (zero area in every projection).
        let (mut p, t) = fan(6, 1.0, |_| 0.0, true);
        p[3 * 2..3 * 2 + 3].copy_from_slice(&[0.0, 0.0, 0.0]);
        assert!(!star_vertices(&p, &t)[0]);
    }
}
