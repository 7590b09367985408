//! Topology of an indexed triangle mesh, read off the vertex indices: undirected edges with the
//! facets that use them, shells (facets connected through shared edges) with the edge counts that
//! say whether each is closed, vertex fans, and the loops that bound holes. `check` counts with it; `repair` decides with it.
//!
//! Edges come from grouping the 3F half-edges by their (smaller, larger) vertex pair — a counting
//! sort on the smaller vertex, then a sort of each small bucket — in linear time, faster than
//! hashing at a million facets, and in a deterministic order (by vertex pair). Facets with a repeated vertex index take no part (they have no proper
//! edges); `check` counts them separately.

use super::Mesh;
use rayon::prelude::*;

/// Edges and incidences of a mesh.
pub struct Topology {
    /// Facets with three distinct vertex indices.
    pub active: Vec<bool>,
    /// Half-edge ids `3f + k` (the edge from corner k to corner k+1 of facet f), grouped by
    /// undirected edge.
    pub half: Vec<u32>,
    /// Start of each undirected edge's group in `half`; one extra entry closes the last group.
    pub edge_start: Vec<u32>,
}

/// Disjoint sets with path halving and union by index (smaller root wins, so roots are stable).
#[derive(Debug, Clone, Default)]
pub struct UnionFind(pub Vec<u32>);

impl UnionFind {
    /// `n` singleton sets, `0..n`.
    pub fn new(n: usize) -> Self {
        UnionFind((0..n as u32).collect())
    }

    /// The root of `x`'s set.
    pub fn find(&mut self, mut x: u32) -> u32 {
        while self.0[x as usize] != x {
            let p = self.0[x as usize];
            self.0[x as usize] = self.0[p as usize];
            x = p;
        }
        x
    }

    /// Joins the sets of `a` and `b`.
    pub fn union(&mut self, a: u32, b: u32) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            let (lo, hi) = if ra < rb { (ra, rb) } else { (rb, ra) };
            self.0[hi as usize] = lo;
        }
    }
}

/// Vertex indices of half-edge `h`: (from, to).
pub fn half_edge(mesh: &Mesh, h: u32) -> (u32, u32) {
    let f = (h / 3) as usize;
    let k = (h % 3) as usize;
    (mesh.indices[3 * f + k], mesh.indices[3 * f + (k + 1) % 3])
}

/// Whether facet `f` repeats a vertex index.
pub fn repeats_vertex(mesh: &Mesh, f: usize) -> bool {
    let t = &mesh.indices[3 * f..3 * f + 3];
    t[0] == t[1] || t[1] == t[2] || t[0] == t[2]
}

impl Topology {
    /// The topology of `mesh`.
    pub fn new(mesh: &Mesh) -> Self {
        let nf = mesh.triangle_count();
        let active: Vec<bool> = (0..nf)
            .into_par_iter()
            .map(|f| !repeats_vertex(mesh, f))
            .collect();
        // Counting sort by the smaller vertex, then each (small) bucket by the larger one.
        let nv = mesh.vertex_count();
        let mut start = vec![0u32; nv + 1];
        for (f, t) in mesh.indices.chunks_exact(3).enumerate() {
            if active[f] {
                for k in 0..3 {
                    start[t[k].min(t[(k + 1) % 3]) as usize + 1] += 1;
                }
            }
        }
        for v in 0..nv {
            start[v + 1] += start[v];
        }
        let total = start[nv] as usize;
        let mut fill = start.clone();
        let mut keyed = vec![(0u32, 0u32); total];
        for (f, t) in mesh.indices.chunks_exact(3).enumerate() {
            if active[f] {
                for k in 0..3 {
                    let (a, b) = (t[k], t[(k + 1) % 3]);
                    let slot = &mut fill[a.min(b) as usize];
                    keyed[*slot as usize] = (a.max(b), (3 * f + k) as u32);
                    *slot += 1;
                }
            }
        }
        let mut edge_start = Vec::with_capacity(total / 2 + 1);
        for v in 0..nv {
            let bucket = &mut keyed[start[v] as usize..start[v + 1] as usize];
            bucket.sort_unstable();
            for i in 0..bucket.len() {
                if i == 0 || bucket[i].0 != bucket[i - 1].0 {
                    edge_start.push(start[v] + i as u32);
                }
            }
        }
        edge_start.push(total as u32);
        let half = keyed.into_iter().map(|(_, h)| h).collect();
        Topology {
            active,
            half,
            edge_start,
        }
    }

    /// Number of undirected edges.
    pub fn edge_count(&self) -> usize {
        self.edge_start.len() - 1
    }

    /// The half-edges (one per incident facet) of undirected edge `e`.
    pub fn edge(&self, e: usize) -> &[u32] {
        &self.half[self.edge_start[e] as usize..self.edge_start[e + 1] as usize]
    }

    /// Undirected edge id of every half-edge (`u32::MAX` for inactive facets).
    pub fn edge_of_half(&self, facets: usize) -> Vec<u32> {
        let mut out = vec![u32::MAX; 3 * facets];
        for e in 0..self.edge_count() {
            for &h in self.edge(e) {
                out[h as usize] = e as u32;
            }
        }
        out
    }

    /// Shell of every facet (facets joined through any shared edge), numbered from 0 in order of
    /// each shell's first facet; inactive facets get `u32::MAX`. Returns (shell ids, count).
    pub fn shells(&self, facets: usize) -> (Vec<u32>, usize) {
        self.shells_through(facets, |_| true)
    }

    /// Like [`Topology::shells`], joining facets only through the edges `join` accepts.
    pub fn shells_through(
        &self,
        facets: usize,
        join: impl Fn(&[u32]) -> bool,
    ) -> (Vec<u32>, usize) {
        let mut uf = UnionFind::new(facets);
        for e in 0..self.edge_count() {
            let hs = self.edge(e);
            if hs.len() >= 2 && join(hs) {
                for w in hs.windows(2) {
                    uf.union(w[0] / 3, w[1] / 3);
                }
            }
        }
        let mut id = vec![u32::MAX; facets];
        let mut root_id = vec![u32::MAX; facets];
        let mut n = 0u32;
        for (f, slot) in id.iter_mut().enumerate() {
            if !self.active[f] {
                continue;
            }
            let r = uf.find(f as u32) as usize;
            if root_id[r] == u32::MAX {
                root_id[r] = n;
                n += 1;
            }
            *slot = root_id[r];
        }
        (id, n as usize)
    }

    /// Fans: corners `3f + k` around the same vertex joined through edges with exactly two
    /// facets. A vertex whose corners form more than one fan is non-manifold (shells or sheets
    /// touching at that vertex). Returns the fan root of every corner.
    pub fn fans(&self, mesh: &Mesh) -> Vec<u32> {
        let mut uf = UnionFind::new(mesh.indices.len());
        for e in 0..self.edge_count() {
            let hs = self.edge(e);
            if hs.len() != 2 {
                continue;
            }
            let (a, b) = half_edge(mesh, hs[0]);
            let (f, g) = (hs[0] / 3, hs[1] / 3);
            for v in [a, b] {
                uf.union(corner_of(mesh, f, v), corner_of(mesh, g, v));
            }
        }
        (0..mesh.indices.len() as u32).map(|c| uf.find(c)).collect()
    }

    /// Loops of boundary edges (edges with one facet), each as the vertex sequence of the
    /// polygon that would fill the hole (wound so that the filling facets agree with their
    /// neighbours). A chain that cannot be closed (at non-manifold vertices) is returned with
    /// `closed = false`.
    pub fn boundary_loops(&self, mesh: &Mesh) -> Vec<BoundaryLoop> {
        use std::collections::HashMap;
        // Hole edges run opposite to the facet's half-edge: facet a→b leaves hole edge b→a.
        let mut out_edges: HashMap<u32, Vec<u32>> = HashMap::new();
        let mut hole_edges: Vec<(u32, u32)> = Vec::new();
        for e in 0..self.edge_count() {
            let hs = self.edge(e);
            if hs.len() == 1 {
                let (a, b) = half_edge(mesh, hs[0]);
                out_edges
                    .entry(b)
                    .or_default()
                    .push(hole_edges.len() as u32);
                hole_edges.push((b, a));
            }
        }
        let mut used = vec![false; hole_edges.len()];
        let mut loops = Vec::new();
        for start in 0..hole_edges.len() {
            if used[start] {
                continue;
            }
            used[start] = true;
            let origin = hole_edges[start].0;
            let mut verts = vec![origin];
            let mut cur = hole_edges[start].1;
            let mut closed = false;
            loop {
                if cur == origin {
                    closed = true;
                    break;
                }
                verts.push(cur);
                let next = out_edges
                    .get(&cur)
                    .and_then(|l| l.iter().copied().find(|&i| !used[i as usize]));
                match next {
                    Some(i) => {
                        used[i as usize] = true;
                        cur = hole_edges[i as usize].1;
                    }
                    None => break,
                }
            }
            loops.push(BoundaryLoop {
                vertices: verts,
                closed,
            });
        }
        loops
    }
}

/// Edge counts of one shell: whether it is closed, and wound consistently.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ShellEdges {
    /// Distinct edges of the shell.
    pub edges: u64,
    /// Edges with only one facet.
    pub boundary: u64,
    /// Edges shared by three or more facets.
    pub non_manifold: u64,
    /// Edges whose two facets traverse them in the same direction.
    pub inconsistent: u64,
}

impl ShellEdges {
    /// Every edge in exactly two facets: no boundary and no non-manifold edge.
    pub fn closed(&self) -> bool {
        self.boundary == 0 && self.non_manifold == 0
    }

    /// Closed and wound consistently: a shell with an inside, facing out or in.
    pub fn solid(&self) -> bool {
        self.closed() && self.inconsistent == 0
    }
}

/// The shells of a mesh (facets connected through shared edges): each facet's shell, each
/// shell's facets and its edge counts.
#[derive(Debug, Clone)]
pub struct Shells {
    /// Shell of every facet, numbered as [`Topology::shells`] numbers them (`u32::MAX` for
    /// facets with a repeated vertex).
    pub of_facet: Vec<u32>,
    /// Each shell's facets, in order.
    pub members: Vec<Vec<u32>>,
    /// Each shell's edge counts.
    pub edges: Vec<ShellEdges>,
}

impl Shells {
    /// The shells of `mesh`, whose topology is `topo`.
    pub fn new(mesh: &Mesh, topo: &Topology) -> Shells {
        let (of_facet, n) = topo.shells(mesh.triangle_count());
        let mut members = vec![Vec::new(); n];
        for (f, &s) in of_facet.iter().enumerate() {
            if s != u32::MAX {
                members[s as usize].push(f as u32);
            }
        }
        // Every facet of an edge is active, so every edge belongs to its first facet's shell.
        let mut edges = vec![ShellEdges::default(); n];
        for e in 0..topo.edge_count() {
            let hs = topo.edge(e);
            let c = &mut edges[of_facet[(hs[0] / 3) as usize] as usize];
            c.edges += 1;
            match hs.len() {
                1 => c.boundary += 1,
                2 => c.inconsistent += u64::from(half_edge(mesh, hs[0]) == half_edge(mesh, hs[1])),
                _ => c.non_manifold += 1,
            }
        }
        Shells {
            of_facet,
            members,
            edges,
        }
    }

    /// Number of shells.
    pub fn count(&self) -> usize {
        self.members.len()
    }

    /// The whole mesh's edge counts: every edge belongs to exactly one shell.
    pub fn total(&self) -> ShellEdges {
        self.edges
            .iter()
            .fold(ShellEdges::default(), |t, e| ShellEdges {
                edges: t.edges + e.edges,
                boundary: t.boundary + e.boundary,
                non_manifold: t.non_manifold + e.non_manifold,
                inconsistent: t.inconsistent + e.inconsistent,
            })
    }
}

/// A hole's outline.
#[derive(Debug, Clone)]
pub struct BoundaryLoop {
    /// The vertices in order, wound as the filling facets would be.
    pub vertices: Vec<u32>,
    /// Whether the chain closes (false at non-manifold vertices).
    pub closed: bool,
}

/// The corner (`3f + k`) of facet `f` at vertex `v`.
pub fn corner_of(mesh: &Mesh, f: u32, v: u32) -> u32 {
    let t = &mesh.indices[3 * f as usize..3 * f as usize + 3];
    let k = t.iter().position(|&x| x == v).unwrap_or(0);
    3 * f + k as u32
}
