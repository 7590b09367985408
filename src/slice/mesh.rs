//! Sections of a triangle mesh by parallel planes, after Minetto et al., "An optimal algorithm for
//! 3D triangle mesh slicing" (Computer-Aided Design 92, 2017): the planes sorted, each facet
//! bucketed once to the planes its height range spans (a binary search), and the segments of a
//! plane chained into loops through the mesh's own edges — never by matching nearby endpoints.
//!
//! A facet crosses the plane at height `z` when some corner lies below (`h < z`) and some at or
//! above (`h ≥ z`): corners exactly on the plane count as above, a symbolic perturbation that
//! leaves no special case. A crossing facet then has exactly one edge going from above to below
//! and one from below to above (in its winding); its segment runs from the first crossing to the
//! second, which for an outward mesh leaves the solid on the left seen from `+d`. Both facets of
//! an edge name its crossing by the same key — (the corner below, the corner above) — and compute
//! it from the same two corners, so a segment's end is bit-for-bit the next one's start, and a
//! closed, manifold mesh gives only closed loops. Facets lying in the plane are above it; the
//! loops then run round the flat region, once. Chains that cannot close (a hole or a
//! non-manifold edge crosses the plane) are kept as open chains and reported.

use super::Frame;
use crate::geom::contour::{Loop, Section};
use crate::geom::Mesh;
use rayon::prelude::*;

/// A mesh prepared for slicing along one build direction.
pub struct MeshSlicer<'a> {
    mesh: &'a Mesh,
    frame: Frame,
    /// Height of every vertex along the build direction.
    heights: Vec<f64>,
}

/// Facets per plane, as offsets into one list (each facet listed under every plane it crosses).
pub struct Buckets {
    start: Vec<usize>,
    facets: Vec<u32>,
}

impl Buckets {
    /// The facets crossing plane `k`.
    pub fn of(&self, k: usize) -> &[u32] {
        &self.facets[self.start[k]..self.start[k + 1]]
    }

    /// Segments in all (facet–plane crossings).
    pub fn len(&self) -> usize {
        self.facets.len()
    }

    /// Whether no facet crosses any plane.
    pub fn is_empty(&self) -> bool {
        self.facets.is_empty()
    }
}

impl<'a> MeshSlicer<'a> {
    /// Prepares `mesh` for slicing along `frame.d`.
    pub fn new(mesh: &'a Mesh, frame: Frame) -> Self {
        let heights = mesh
            .positions
            .par_chunks_exact(3)
            .map(|p| frame.height([p[0] as f64, p[1] as f64, p[2] as f64]))
            .collect();
        MeshSlicer {
            mesh,
            frame,
            heights,
        }
    }

    /// The mesh sliced.
    pub fn mesh(&self) -> &Mesh {
        self.mesh
    }

    /// The build frame.
    pub fn frame(&self) -> &Frame {
        &self.frame
    }

    /// Lowest and highest vertex heights; `None` for an empty mesh.
    pub fn range(&self) -> Option<(f64, f64)> {
        let lo = self
            .heights
            .par_iter()
            .copied()
            .reduce(|| f64::INFINITY, f64::min);
        let hi = self
            .heights
            .par_iter()
            .copied()
            .reduce(|| f64::NEG_INFINITY, f64::max);
        (lo <= hi).then_some((lo, hi))
    }

    /// Lowest and highest corner heights of facet `f`.
    pub fn facet_range(&self, f: usize) -> (f64, f64) {
        let i = &self.mesh.indices[3 * f..3 * f + 3];
        let h = [
            self.heights[i[0] as usize],
            self.heights[i[1] as usize],
            self.heights[i[2] as usize],
        ];
        (h[0].min(h[1]).min(h[2]), h[0].max(h[1]).max(h[2]))
    }

    /// `|n · d|` of facet `f`'s unit normal (0 for a degenerate facet).
    pub fn facet_slope_cos(&self, f: usize) -> f64 {
        let [a, b, c] = self.mesh.triangle(f);
        let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let e2 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let n = [
            e1[1] * e2[2] - e1[2] * e2[1],
            e1[2] * e2[0] - e1[0] * e2[2],
            e1[0] * e2[1] - e1[1] * e2[0],
        ];
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        if len > 0.0 {
            (self.frame.height(n) / len).abs()
        } else {
            0.0
        }
    }

    /// Buckets the facets by the planes at `zs` (ascending) they cross: plane `z` is crossed
    /// when `min h < z ≤ max h` over the facet's corners.
    pub fn buckets(&self, zs: &[f64]) -> Buckets {
        debug_assert!(zs.windows(2).all(|w| w[0] <= w[1]));
        let facets = self.mesh.triangle_count();
        let span = |f: usize| {
            let (lo, hi) = self.facet_range(f);
            (
                zs.partition_point(|&z| z <= lo),
                zs.partition_point(|&z| z <= hi),
            )
        };
        let spans: Vec<(u32, u32)> = (0..facets)
            .into_par_iter()
            .map(|f| {
                let (a, b) = span(f);
                (a as u32, b as u32)
            })
            .collect();
        let mut start = vec![0usize; zs.len() + 1];
        for &(a, b) in &spans {
            for k in a..b {
                start[k as usize + 1] += 1;
            }
        }
        for k in 0..zs.len() {
            start[k + 1] += start[k];
        }
        let mut fill = start.clone();
        let mut list = vec![0u32; start[zs.len()]];
        for (f, &(a, b)) in spans.iter().enumerate() {
            for k in a..b {
                list[fill[k as usize]] = f as u32;
                fill[k as usize] += 1;
            }
        }
        Buckets {
            start,
            facets: list,
        }
    }

    /// Every plane's section (planes at `zs`, ascending), in parallel.
    pub fn sections(&self, zs: &[f64]) -> Vec<Section> {
        let b = self.buckets(zs);
        (0..zs.len())
            .into_par_iter()
            .map(|k| self.section(zs[k], b.of(k)))
            .collect()
    }

    /// The section at height `z`, from the facets that cross it (any superset will do).
    pub fn section(&self, z: f64, facets: &[u32]) -> Section {
        let segs = self.segments(z, facets);
        let chains = chain(&segs);
        let mut out = Section::default();
        for (links, closed) in chains {
            let mut pts: Vec<[f64; 2]> =
                links.iter().map(|&s| self.crossing(segs[s].0, z)).collect();
            if closed {
                let l = clean(pts, true);
                if l.len() >= 3 {
                    out.loops.push(l);
                }
            } else {
                pts.push(self.crossing(segs[*links.last().unwrap()].1, z));
                out.open.push(clean(pts, false));
            }
        }
        out
    }

    /// The area of the section at `z` (Green's theorem over the unordered segments: no chaining),
    /// from the facets that cross it (any superset will do).
    pub fn area_at(&self, z: f64, facets: &[u32]) -> f64 {
        let segs = self.segments(z, facets);
        let Some(&(k0, _)) = segs.first() else {
            return 0.0;
        };
        // Relative to one crossing point, for less cancellation far from the origin.
        let o = self.crossing(k0, z);
        0.5 * segs
            .iter()
            .map(|&(a, b)| {
                let (p, q) = (self.crossing(a, z), self.crossing(b, z));
                (p[0] - o[0]) * (q[1] - o[1]) - (q[0] - o[0]) * (p[1] - o[1])
            })
            .sum::<f64>()
    }

    /// The segments at height `z`: (key of the edge it starts on, key of the edge it ends on).
    fn segments(&self, z: f64, facets: &[u32]) -> Vec<(u64, u64)> {
        let mut segs = Vec::with_capacity(facets.len());
        for &f in facets {
            let i = &self.mesh.indices[3 * f as usize..3 * f as usize + 3];
            if i[0] == i[1] || i[1] == i[2] || i[2] == i[0] {
                continue;
            }
            let above = [
                self.heights[i[0] as usize] >= z,
                self.heights[i[1] as usize] >= z,
                self.heights[i[2] as usize] >= z,
            ];
            if above[0] == above[1] && above[1] == above[2] {
                continue;
            }
            let (mut from, mut to) = (0, 0);
            for k in 0..3 {
                let (p, q) = (i[k], i[(k + 1) % 3]);
                match (above[k], above[(k + 1) % 3]) {
                    (true, false) => from = key(q, p),
                    (false, true) => to = key(p, q),
                    _ => {}
                }
            }
            segs.push((from, to));
        }
        segs
    }

    /// Where the edge named by `key` (corner below, corner above) crosses height `z`, in layer
    /// coordinates. Computed from the key alone, so both facets of the edge agree exactly.
    fn crossing(&self, key: u64, z: f64) -> [f64; 2] {
        let (a, b) = ((key >> 32) as u32, key as u32);
        let (ha, hb) = (self.heights[a as usize], self.heights[b as usize]);
        let t = (z - ha) / (hb - ha);
        let (pa, pb) = (self.mesh.vertex(a), self.mesh.vertex(b));
        let p = [
            pa[0] + t * (pb[0] - pa[0]),
            pa[1] + t * (pb[1] - pa[1]),
            pa[2] + t * (pb[2] - pa[2]),
        ];
        self.frame.plane(p)
    }
}

/// Facets by height, for the questions adaptive layers ask at any height: bins of equal height,
/// each listing the facets whose height range meets it.
pub struct HeightIndex<'s, 'a> {
    slicer: &'s MeshSlicer<'a>,
    lo: f64,
    bin: f64,
    start: Vec<usize>,
    facets: Vec<u32>,
}

impl<'s, 'a> HeightIndex<'s, 'a> {
    /// Indexes `slicer`'s facets in bins about `bin` high (wider where a bin would list too many
    /// facets in all: tall facets meet many bins).
    pub fn new(slicer: &'s MeshSlicer<'a>, bin: f64) -> Self {
        let (lo, hi) = slicer.range().unwrap_or((0.0, 0.0));
        let facets = slicer.mesh.triangle_count();
        let mut n = (((hi - lo) / bin).ceil() as usize).clamp(1, 1 << 20);
        let ranges: Vec<(f64, f64)> = (0..facets)
            .into_par_iter()
            .map(|f| slicer.facet_range(f))
            .collect();
        loop {
            let w = (hi - lo).max(1e-300) / n as f64;
            let span = |r: (f64, f64)| {
                let a = (((r.0 - lo) / w) as usize).min(n - 1);
                let b = (((r.1 - lo) / w) as usize).min(n - 1);
                (a, b)
            };
            let total: usize = ranges
                .par_iter()
                .map(|&r| {
                    let (a, b) = span(r);
                    b - a + 1
                })
                .sum();
            if total > 8 * facets + (1 << 20) && n > 1 {
                n = n.div_ceil(2);
                continue;
            }
            let mut start = vec![0usize; n + 1];
            for &r in &ranges {
                let (a, b) = span(r);
                for k in a..=b {
                    start[k + 1] += 1;
                }
            }
            for k in 0..n {
                start[k + 1] += start[k];
            }
            let mut fill = start.clone();
            let mut list = vec![0u32; start[n]];
            for (f, &r) in ranges.iter().enumerate() {
                let (a, b) = span(r);
                for k in a..=b {
                    list[fill[k]] = f as u32;
                    fill[k] += 1;
                }
            }
            return HeightIndex {
                slicer,
                lo,
                bin: w,
                start,
                facets: list,
            };
        }
    }

    fn bin_of(&self, z: f64) -> usize {
        let n = self.start.len() - 1;
        (((z - self.lo) / self.bin).max(0.0) as usize).min(n - 1)
    }

    fn bin(&self, k: usize) -> &[u32] {
        &self.facets[self.start[k]..self.start[k + 1]]
    }
}

impl super::plan::Profile for HeightIndex<'_, '_> {
    fn area(&self, z: f64) -> f64 {
        self.slicer.area_at(z, self.bin(self.bin_of(z)))
    }

    fn steepest_cos(&self, z0: f64, z1: f64) -> f64 {
        let mut best = 0.0f64;
        for k in self.bin_of(z0)..=self.bin_of(z1) {
            for &f in self.bin(k) {
                let (a, b) = self.slicer.facet_range(f as usize);
                // Facets meeting the open layer: one only touching its top or bottom plane
                // leaves no step in it.
                if a < z1 && b > z0 {
                    best = best.max(self.slicer.facet_slope_cos(f as usize));
                }
            }
        }
        best
    }
}

fn key(below: u32, above: u32) -> u64 {
    (below as u64) << 32 | above as u64
}

/// Chains segments `(from, to)` by matching a segment's `to` with another's `from`: returns the
/// chains as segment indices, each with whether it closed. Chains with a free start are walked
/// first (so an open chain is whole), then the cycles.
fn chain(segs: &[(u64, u64)]) -> Vec<(Vec<usize>, bool)> {
    let n = segs.len();
    let mut by_from: Vec<u32> = (0..n as u32).collect();
    by_from.sort_unstable_by_key(|&s| segs[s as usize].0);
    const NONE: u32 = u32::MAX;
    let mut next = vec![NONE; n];
    let mut has_pred = vec![false; n];
    for (s, &(_, to)) in segs.iter().enumerate() {
        let i = by_from.partition_point(|&t| segs[t as usize].0 < to);
        if i < n && segs[by_from[i] as usize].0 == to {
            let t = by_from[i];
            // A non-manifold edge offers several successors: the first free one is taken.
            if !has_pred[t as usize] {
                next[s] = t;
                has_pred[t as usize] = true;
            } else if let Some(&u) = by_from[i..]
                .iter()
                .take_while(|&&u| segs[u as usize].0 == to)
                .find(|&&u| !has_pred[u as usize])
            {
                next[s] = u;
                has_pred[u as usize] = true;
            }
        }
    }
    let mut seen = vec![false; n];
    let mut out = Vec::new();
    let starts = (0..n).filter(|&s| !has_pred[s]).chain(0..n);
    for s0 in starts {
        if seen[s0] {
            continue;
        }
        let mut links = Vec::new();
        let mut s = s0;
        let closed = loop {
            seen[s] = true;
            links.push(s);
            let t = next[s];
            if t == NONE {
                break false;
            }
            if t as usize == s0 {
                break true;
            }
            if seen[t as usize] {
                break false;
            }
            s = t as usize;
        };
        out.push((links, closed));
    }
    out
}

/// Drops repeated points (a crossing at a corner on the plane is shared by several edges) and
/// spikes (a point visited and left the way it came, where the plane grazes a ridge), so a loop
/// that encloses nothing shrinks below three points.
fn clean(pts: Vec<[f64; 2]>, closed: bool) -> Loop {
    let mut out: Loop = Vec::with_capacity(pts.len());
    for p in pts {
        if out.last() == Some(&p) {
            continue;
        }
        if out.len() >= 2 && out[out.len() - 2] == p {
            out.pop();
            continue;
        }
        out.push(p);
    }
    if closed {
        // The same across the seam.
        loop {
            let n = out.len();
            if n >= 2 && out[0] == out[n - 1] {
                out.pop();
            } else if n >= 3 && out[n - 2] == out[0] {
                out.pop();
                out.pop();
            } else if n >= 3 && out[1] == out[n - 1] {
                out.remove(0);
                out.pop();
            } else {
                break;
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::contour::signed_area;

    fn cube() -> Mesh {
        Mesh::cuboid([0.0; 3], [1.0; 3])
    }

    #[test]
    fn a_cube_gives_one_counter_clockwise_square_at_every_height_even_on_its_faces() {
        let m = cube();
        assert!(m.volume() > 0.0);
        let s = MeshSlicer::new(&m, Frame::new([0.0, 0.0, 1.0]).unwrap());
        // On the bottom face the plane sees nothing (corners there count as above); on the top
        // face, the face itself; a vertex plane in between is an ordinary cut.
        let zs = [0.0, 0.25, 0.5, 1.0];
        let secs = s.sections(&zs);
        assert!(secs[0].loops.is_empty());
        for sec in &secs[1..] {
            assert_eq!(sec.loops.len(), 1, "{sec:?}");
            assert!(sec.open.is_empty());
            assert!((signed_area(&sec.loops[0]) - 1.0).abs() < 1e-12);
        }
        // Tilted along the main diagonal, the cut through the centre is the regular hexagon
        // with side √2/2 through six edge midpoints.
        let s = MeshSlicer::new(&m, Frame::new([1.0, 1.0, 1.0]).unwrap());
        let z = 1.5 / 3f64.sqrt();
        let secs = s.sections(&[z]);
        assert_eq!(secs[0].loops.len(), 1);
        let side = 0.5f64.sqrt();
        let hex = 1.5 * 3f64.sqrt() * side * side;
        assert!((signed_area(&secs[0].loops[0]) - hex).abs() < 1e-9);
        // Six corners, and six points where the faces' diagonals cross between them.
        assert_eq!(secs[0].loops[0].len(), 12);
        assert!((s.area_at(z, &(0..12).collect::<Vec<_>>()) - hex).abs() < 1e-9);
    }

    #[test]
    fn a_hole_in_the_mesh_leaves_an_open_chain() {
        let mut m = cube();
        m.indices.truncate(m.indices.len() - 3);
        let s = MeshSlicer::new(&m, Frame::new([0.0, 0.0, 1.0]).unwrap());
        let sec = &s.sections(&[0.5])[0];
        assert!(sec.loops.is_empty());
        assert_eq!(sec.open.len(), 1);
    }
}
