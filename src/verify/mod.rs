//! Verification: the proof that a mesh is a valid solid — closed, manifold, consistently wound
//! and facing out, free of self-intersections — that every mesh latvox writes carries, with its
//! volume and area. [`crate::check`] (above the meshing pipeline) counts every defect of any
//! mesh instead; this stage only says whether the properties hold, fast enough to run on every
//! part made.
//!
//! - [`verify`]: latvox's own checks at meshing speed, read off the vertex indices in linear
//!   time (each vertex's fan of facets), and the exact self-intersection search of
//!   [`self_intersect`] (a grid broad phase, CGAL's triangle tests on Shewchuk's predicates).
//! - [`cgal`]: CGAL's Polygon Mesh Processing checks of the same properties
//!   ([`Verify::Cgal`]): an independent second opinion, and the oracle the tests compare
//!   latvox's checks with.
//! - [`Verdict`]: the one rule every command applies to what the checks found (a valid closed,
//!   outward solid, and the part's own targets met) and its exit code.

pub mod cgal;
pub mod self_intersect;
pub(crate) mod verdict;

pub use verdict::Verdict;

use crate::error::Result;
use crate::geom::topology::UnionFind;
use crate::geom::Mesh;
use crate::geom::{cross, norm, ordered_sum, signed_volume, sub};
use crate::progress::Progress;
use crate::verify::cgal::Verification;
use crate::verify::self_intersect::fans::{fan, Links};
use crate::verify::self_intersect::{soup_self_intersections_shown, Stars};
use rayon::prelude::*;

/// How a made part is verified.
#[derive(
    Debug,
    Clone,
    Copy,
    PartialEq,
    Eq,
    Default,
    clap::ValueEnum,
    serde::Serialize,
    serde::Deserialize,
)]
#[serde(rename_all = "snake_case")]
pub enum Verify {
    /// Closed, manifold, outward, and no two facets intersecting (exact predicates): the whole
    /// written part, whatever the route.
    #[default]
    Full,
    /// Closed, manifold and outward, with volume and area; no self-intersection search.
    Fast,
    /// No checks: the report's checks say `checked_by: nobody`, and the verdict rests on the
    /// density and the pieces alone.
    None,
    /// CGAL's own checks (Polygon Mesh Processing: closedness, orientation, self-intersection,
    /// volume): an independent second opinion, several times slower.
    Cgal,
}

impl Verify {
    /// Whether self-intersections are searched for.
    pub fn self_intersection(self) -> bool {
        matches!(self, Verify::Full | Verify::Cgal)
    }

    /// Who checks, as reports name it.
    pub fn by(self) -> &'static str {
        match self {
            Verify::Full | Verify::Fast => "latvox",
            Verify::Cgal => "CGAL",
            Verify::None => "nobody",
        }
    }
}

/// Verifies `mesh` as `how` asks; a bar counts the self-intersection search's progress.
pub fn verify(mesh: &Mesh, how: Verify, progress: &Progress) -> Result<Verification> {
    match how {
        Verify::Cgal => crate::verify::cgal::verify(mesh, true),
        Verify::None => Ok(unchecked(mesh)),
        Verify::Full => {
            // The fans are checked beside the search's bucketing (it needs their star vertices
            // only to search), the components measured beside the whole search.
            let fans = std::sync::OnceLock::new();
            let stars = Stars::Beside(Box::new(|| {
                let mut f = vertex_fans(mesh, true);
                let star = std::mem::take(&mut f.star);
                let _ = fans.set(f);
                star
            }));
            let (m, pairs) = rayon::join(
                || measures(mesh),
                || {
                    let all: Vec<u32> = (0..mesh.triangle_count() as u32)
                        .into_par_iter()
                        .filter(|&f| !crate::geom::topology::repeats_vertex(mesh, f as usize))
                        .collect();
                    soup_self_intersections_shown(mesh, &all, 0, stars, progress).0
                },
            );
            // A search of fewer than two facets asks for no star vertices.
            let fans = fans
                .into_inner()
                .unwrap_or_else(|| vertex_fans(mesh, false));
            Ok(verification(mesh, how, assemble(&fans, &m), Some(pairs)))
        }
        Verify::Fast => Ok(verification(mesh, how, topology(mesh), None)),
    }
}

/// The verification `how` gave: the fans' verdict, and with `pairs`, the intersecting pairs'.
fn verification(mesh: &Mesh, how: Verify, topo: Fans, pairs: Option<u64>) -> Verification {
    Verification {
        checked_by: how.by(),
        manifold: topo.manifold,
        closed: topo.border_edges == 0 && topo.manifold,
        outward: topo.outward,
        self_intersection_checked: pairs.is_some(),
        self_intersecting: pairs.is_some_and(|n| n > 0),
        volume: (topo.border_edges == 0 && topo.manifold).then_some(topo.volume),
        area: topo.area,
        faces: mesh.triangle_count() as u64,
        vertices: topo.vertices,
        border_edges: topo.border_edges,
        components: topo.components,
        not_checked: None,
    }
}

/// A verification that checked nothing: no property found failing (the verdict stands on the
/// other checks), `checked_by` says nobody looked.
fn unchecked(mesh: &Mesh) -> Verification {
    Verification {
        checked_by: Verify::None.by(),
        manifold: true,
        closed: true,
        outward: true,
        self_intersection_checked: false,
        self_intersecting: false,
        volume: None,
        area: 0.0,
        faces: mesh.triangle_count() as u64,
        vertices: mesh.vertex_count() as u64,
        border_edges: 0,
        components: 0,
        not_checked: None,
    }
}

/// What the vertex fans say about a mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fans {
    /// Every facet has three distinct vertices; every edge is traversed at most once in each
    /// direction and has at most two facets, traversed in opposite directions; every vertex's
    /// facets form one fan (CGAL builds such a mesh as given).
    pub manifold: bool,
    /// Half-edges without a twin (edges with one facet).
    pub border_edges: u64,
    /// Closed, manifold, and facing out: the volume is positive, and every component enclosing
    /// negative volume (a cavity) lies within the bounds of a larger positive one.
    pub outward: bool,
    /// Signed volume enclosed (divergence theorem), mm³.
    pub volume: f64,
    /// Surface area, mm².
    pub area: f64,
    /// Connected components (facets joined through shared vertices).
    pub components: u64,
    /// Vertices used by some facet.
    pub vertices: u64,
}

/// The fans, volume, area and components of `mesh`, in time linear in its size: a counting sort
/// of the corners by vertex, then each vertex on its own (in parallel) — the facets around it
/// must chain into one cycle (or one path at a border), each edge from it met once in each
/// direction.
pub fn topology(mesh: &Mesh) -> Fans {
    let (fans, m) = rayon::join(|| vertex_fans(mesh, false), || measures(mesh));
    assemble(&fans, &m)
}

/// What the vertices' fans say.
struct VertexFans {
    /// Some facet repeats a vertex, or some vertex's fan is unsound.
    bad: bool,
    /// Half-edges without a twin.
    border: u64,
    /// Vertices used by some facet.
    used: u64,
    /// Per vertex, when asked for: its closed fan projects one-to-one onto an axis plane (see
    /// [`crate::verify::self_intersect::fans`]); empty otherwise.
    star: Vec<bool>,
}

/// Each vertex's link edges b → c (facet v, b, c in winding order) checked as one fan, and
/// with `stars`, whether that fan projects one-to-one.
fn vertex_fans(mesh: &Mesh, stars: bool) -> VertexFans {
    let nv = mesh.vertex_count();
    let repeated = (0..mesh.triangle_count())
        .into_par_iter()
        .any(|f| crate::geom::topology::repeats_vertex(mesh, f));
    let links = Links::new(nv, &mesh.indices, stars.then_some(&mesh.positions[..]));
    const CHUNK: usize = 4096;
    let mut star = vec![false; if stars { nv } else { 0 }];
    let check = |chunk: usize, out: &mut [bool]| {
        let (mut bad, mut border, mut used) = (false, 0u64, 0u64);
        for v in chunk * CHUNK..((chunk + 1) * CHUNK).min(nv) {
            let link = links.of(v);
            if link.is_empty() {
                continue;
            }
            used += 1;
            let (b_fan, b_border) = fan(link);
            bad |= b_fan;
            border += b_border;
            if !out.is_empty() && !b_fan && b_border == 0 {
                out[v - chunk * CHUNK] = links.projects_one_to_one(v);
            }
        }
        (bad, border, used)
    };
    let sum = |x: (bool, u64, u64), y: (bool, u64, u64)| (x.0 || y.0, x.1 + y.1, x.2 + y.2);
    let (bad, border, used) = if stars {
        star.par_chunks_mut(CHUNK)
            .enumerate()
            .map(|(chunk, out)| check(chunk, out))
            .reduce(|| (false, 0, 0), sum)
    } else {
        (0..nv.div_ceil(CHUNK))
            .into_par_iter()
            .map(|chunk| check(chunk, &mut []))
            .reduce(|| (false, 0, 0), sum)
    };
    VertexFans {
        bad: bad || repeated,
        border,
        used,
        star,
    }
}

/// The components of a mesh, its volume and area.
struct Measures {
    /// Connected components (facets joined through shared vertices).
    components: u64,
    /// Signed volume enclosed, mm³.
    volume: f64,
    /// Surface area, mm².
    area: f64,
    /// Every component enclosing negative volume lies within the bounds of a larger positive
    /// one.
    cavities_enclosed: bool,
}

/// The fans' verdict with the measures.
fn assemble(fans: &VertexFans, m: &Measures) -> Fans {
    let manifold = !fans.bad;
    Fans {
        manifold,
        border_edges: fans.border,
        outward: manifold && fans.border == 0 && m.volume > 0.0 && m.cavities_enclosed,
        volume: m.volume,
        area: m.area,
        components: m.components,
        vertices: fans.used,
    }
}

/// The components, volume and area of `mesh`.
fn measures(mesh: &Mesh) -> Measures {
    let nv = mesh.vertex_count();
    let idx = &mesh.indices;
    // Components through shared vertices; volume and area per component.
    let mut uf = UnionFind::new(nv);
    for t in idx.chunks_exact(3) {
        uf.union(t[0], t[1]);
        uf.union(t[0], t[2]);
    }
    let mut used = vec![false; nv];
    for &v in idx.iter() {
        used[v as usize] = true;
    }
    let root: Vec<u32> = (0..nv as u32).map(|v| uf.find(v)).collect();
    let mut comp = vec![u32::MAX; nv];
    let mut components = 0u32;
    for v in 0..nv {
        if used[v] {
            let r = root[v] as usize;
            if comp[r] == u32::MAX {
                comp[r] = components;
                components += 1;
            }
        }
    }
    // Positions from a point of the mesh, so that far-off parts lose no precision.
    let o = if nv > 0 {
        [0, 1, 2].map(|i| mesh.positions[i] as f64)
    } else {
        [0.0; 3]
    };
    let p = |v: u32| {
        let i = 3 * v as usize;
        [
            mesh.positions[i] as f64 - o[0],
            mesh.positions[i + 1] as f64 - o[1],
            mesh.positions[i + 2] as f64 - o[2],
        ]
    };
    let nc = components as usize;
    // Per component: volume and bounds (for the cavity test).
    let empty = || {
        (
            vec![0.0f64; nc],
            vec![[f64::INFINITY; 3]; nc],
            vec![[f64::NEG_INFINITY; 3]; nc],
        )
    };
    let (vols, lo, hi) = idx
        .par_chunks_exact(3)
        .fold(empty, |(mut vols, mut lo, mut hi), t| {
            let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
            let k = comp[root[t[0] as usize] as usize] as usize;
            vols[k] += signed_volume(a, b, c);
            for q in [a, b, c] {
                for i in 0..3 {
                    lo[k][i] = lo[k][i].min(q[i]);
                    hi[k][i] = hi[k][i].max(q[i]);
                }
            }
            (vols, lo, hi)
        })
        .reduce(empty, |mut x, y| {
            for k in 0..nc {
                x.0[k] += y.0[k];
                for i in 0..3 {
                    x.1[k][i] = x.1[k][i].min(y.1[k][i]);
                    x.2[k][i] = x.2[k][i].max(y.2[k][i]);
                }
            }
            x
        });
    // The totals added in a fixed order (the fold's split depends on scheduling), so the volume
    // reported for a part does not change from run to run.
    let tri = |i: usize| (p(idx[3 * i]), p(idx[3 * i + 1]), p(idx[3 * i + 2]));
    let volume = ordered_sum(idx.len() / 3, |i| {
        let (a, b, c) = tri(i);
        signed_volume(a, b, c)
    });
    let area = ordered_sum(idx.len() / 3, |i| {
        let (a, b, c) = tri(i);
        0.5 * norm(cross(sub(b, a), sub(c, a)))
    });
    let inside = |k: usize, j: usize| (0..3).all(|i| lo[j][i] <= lo[k][i] && hi[k][i] <= hi[j][i]);
    let cavities_enclosed = (0..nc)
        .filter(|&k| vols[k] < 0.0)
        .all(|k| (0..nc).any(|j| vols[j] > 0.0 && vols[j] > -vols[k] && inside(k, j)));
    Measures {
        components: components as u64,
        volume,
        area,
        cavities_enclosed,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tetra() -> Mesh {
        Mesh {
            positions: vec![0., 0., 0., 1., 0., 0., 0., 1., 0., 0., 0., 1.],
            indices: vec![0, 2, 1, 0, 1, 3, 1, 2, 3, 0, 3, 2],
        }
    }

    #[test]
    fn a_tetrahedron_is_a_closed_outward_solid() {
        let t = topology(&tetra());
        assert!(t.manifold && t.outward, "{t:?}");
        assert_eq!(t.border_edges, 0);
        assert!((t.volume - 1.0 / 6.0).abs() < 1e-12);
        assert_eq!(t.components, 1);
    }

    #[test]
    fn meshes_of_no_facet_or_one_are_verified_in_full() {
        let one = Mesh {
            positions: vec![0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0],
            indices: vec![0, 1, 2],
        };
        let v = verify(&one, Verify::Full, &Progress::hidden()).unwrap();
        assert!(!v.closed && v.manifold && !v.self_intersecting, "{v:?}");
        assert_eq!(v.border_edges, 3);
        let none = Mesh {
            positions: vec![],
            indices: vec![],
        };
        let v = verify(&none, Verify::Full, &Progress::hidden()).unwrap();
        assert!(!v.self_intersecting && v.faces == 0, "{v:?}");
    }

    #[test]
    fn holes_flips_and_fins_are_found() {
        let mut open = tetra();
        open.indices.truncate(9);
        let t = topology(&open);
        assert!(t.manifold && !t.outward);
        assert_eq!(t.border_edges, 3);
        let mut flipped = tetra();
        flipped.indices.swap(0, 1);
        assert!(!topology(&flipped).manifold);
        let mut inward = tetra();
        for f in inward.indices.chunks_exact_mut(3) {
            f.swap(1, 2);
        }
        let t = topology(&inward);
        assert!(t.manifold && !t.outward && t.volume < 0.0);
        let mut fin = tetra();
        fin.positions.extend_from_slice(&[1., 1., 1.]);
        fin.indices.extend_from_slice(&[0, 1, 4]);
        assert!(!topology(&fin).manifold);
    }
}
