//! Mesh repair: every defect `check` finds is mended where it can be, in an order where each
//! step leaves the next one a simpler mesh, and every change is counted by kind.
//!
//! 1. Remove facets with a repeated vertex, facets of zero area, and duplicate facets.
//! 2. Stitch borders that match: boundary vertices closer than the stitch tolerance merge.
//! 3. Split edges at T-junctions, so neighbours share whole edges.
//! 4. Separate shells that touch only at a vertex or along a non-manifold edge (vertices are
//!    duplicated per fan; facets around a shared edge are paired by the wedge they bound).
//! 5. Make the winding consistent in each shell (breadth-first across edges).
//! 6. Fill holes: planar loops by triangulating the loop, others by CGAL (triangulate, refine,
//!    fair).
//! 7. Turn every closed shell outward (a cavity inward), by nesting parity.
//! 8. Optionally drop the shells that are still open, and optionally remesh through OpenVDB.
//!
//! A mesh without defects passes through unchanged (same facets in the same order). A shell that
//! stays open is reported, never dropped unless asked. Normals are recomputed by the writers.

pub mod cgal;
mod file;
mod holes;
pub mod remesh;
mod split;

use crate::check::{self, zero_area};
use crate::error::Result;
use crate::mesh::topology::Topology;
use crate::mesh::{signed_volume, sub, Mesh};
use crate::progress::Progress;
use rayon::prelude::*;

pub use file::{repair_file, FileRepairReport};
pub use holes::PLANAR_REL;

/// How to repair.
#[derive(Debug, Clone, Copy)]
pub struct RepairOptions {
    /// Fill holes (planar ones by triangulating the loop, curved ones with CGAL).
    pub fill_holes: bool,
    /// Fair curved hole patches (CGAL); otherwise triangulate and refine only.
    pub fair: bool,
    /// Boundary vertices closer than this merge (mm); `None`: 10⁻⁶ of the bounding-box diagonal.
    pub stitch_tolerance: Option<f64>,
    /// Drop shells that are still open after repair.
    pub drop_open_shells: bool,
    /// Rebuild the part through an OpenVDB level set at this voxel size (mm).
    pub remesh: Option<f64>,
}

impl Default for RepairOptions {
    fn default() -> Self {
        RepairOptions {
            fill_holes: true,
            fair: true,
            stitch_tolerance: None,
            drop_open_shells: false,
            remesh: None,
        }
    }
}

/// One kind of change and how many times it was made.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Change {
    /// What was changed (e.g. `duplicate facets removed`).
    pub kind: &'static str,
    /// How many times.
    pub count: u64,
}

/// A shell repair could not close.
#[derive(Debug, Clone, serde::Serialize)]
pub struct OpenShell {
    /// Facets in the shell.
    pub facets: u64,
    /// Edges of the shell with only one facet.
    pub boundary_edges: u64,
    /// Closed loops of boundary edges (holes).
    pub hole_loops: u64,
    /// Whether the shell was dropped (`drop_open_shells`).
    pub dropped: bool,
}

/// What repair did.
#[derive(Debug, Clone, serde::Serialize)]
pub struct RepairReport {
    /// Every change made, by kind, in pipeline order (only kinds that happened).
    pub changes: Vec<Change>,
    /// Shells still open after repair.
    pub open_shells: Vec<OpenShell>,
    /// Shells that cannot be wound consistently (one-sided surfaces).
    pub non_orientable_shells: u64,
    /// Holes neither method could fill.
    pub holes_left: u64,
    /// Voxel size of the OpenVDB remesh, mm, when it ran.
    pub remesh_voxel: Option<f64>,
    /// Active voxels of the remesh's level set, when it ran.
    pub remesh_active_voxels: Option<u64>,
}

/// The mesh being repaired, with its topology cached until the next change.
struct Work {
    mesh: Mesh,
    topo: Option<Topology>,
    changes: Vec<Change>,
}

impl Work {
    /// The mesh and its (cached) topology.
    fn parts(&mut self) -> (&Mesh, &Topology) {
        if self.topo.is_none() {
            self.topo = Some(Topology::new(&self.mesh));
        }
        (&self.mesh, self.topo.as_ref().expect("just built"))
    }

    fn note(&mut self, kind: &'static str, count: u64) {
        if count == 0 {
            return;
        }
        self.topo = None;
        match self.changes.iter_mut().find(|c| c.kind == kind) {
            Some(c) => c.count += count,
            None => self.changes.push(Change { kind, count }),
        }
    }

    /// Keeps the facets `keep` selects, in order.
    fn retain(&mut self, keep: &[bool]) {
        let mut out = Vec::with_capacity(self.mesh.indices.len());
        for (f, t) in self.mesh.indices.chunks_exact(3).enumerate() {
            if keep[f] {
                out.extend_from_slice(t);
            }
        }
        self.mesh.indices = out;
        self.topo = None;
    }

    /// Step 1 (run again after steps that can collapse facets).
    fn remove_bad_facets(&mut self) {
        let nf = self.mesh.triangle_count();
        let active = self.parts().1.active.clone();
        let repeated = active.iter().filter(|a| !**a).count() as u64;
        let zero: Vec<bool> = (0..nf)
            .into_par_iter()
            .map(|f| active[f] && zero_area(&self.mesh, f))
            .collect();
        let zero_count = zero.iter().filter(|z| **z).count() as u64;
        let (mesh, topo) = self.parts();
        let dups = check::duplicate_facets(mesh, topo);
        if repeated + zero_count + dups.len() as u64 == 0 {
            return;
        }
        let mut keep: Vec<bool> = (0..nf).map(|f| active[f] && !zero[f]).collect();
        for &d in &dups {
            keep[d as usize] = false;
        }
        // A duplicate of a zero-area facet is counted once, as zero-area.
        let dup_count = dups.iter().filter(|&&d| !zero[d as usize]).count() as u64;
        self.retain(&keep);
        self.note("facets with a repeated vertex removed", repeated);
        self.note("zero-area facets removed", zero_count);
        self.note("duplicate facets removed", dup_count);
    }
}

/// Repairs `mesh`. Returns the repaired mesh and what was done.
pub fn repair(
    mesh: &Mesh,
    opts: &RepairOptions,
    progress: &Progress,
) -> Result<(Mesh, RepairReport)> {
    let mut w = Work {
        mesh: mesh.clone(),
        topo: None,
        changes: Vec::new(),
    };
    let diag = w
        .mesh
        .bounds()
        .map(|b| crate::mesh::norm(sub(b.max, b.min)))
        .unwrap_or(0.0);

    {
        let _s = progress.stage("removing degenerate and duplicate facets");
        w.remove_bad_facets();
    }

    {
        let _s = progress.stage("stitching borders");
        let tol = opts
            .stitch_tolerance
            .unwrap_or(check::T_JUNCTION_REL * diag);
        let merged = stitch(&mut w, tol);
        w.note("border vertices stitched", merged);
        if merged > 0 {
            w.remove_bad_facets();
        }
    }

    {
        let _s = progress.stage("splitting edges at T-junctions");
        let tol = opts.stitch_tolerance.unwrap_or(0.0);
        for _ in 0..4 {
            let (mesh, topo) = w.parts();
            let tjs = check::t_junctions(mesh, topo, tol);
            if tjs.is_empty() {
                break;
            }
            let n = split::split_t_junctions(&mut w.mesh, &tjs);
            w.topo = None;
            w.note("edges split at T-junctions", n);
            if n == 0 {
                break;
            }
        }
        w.remove_bad_facets();
    }

    {
        let _s = progress.stage("separating shells at non-manifold edges and vertices");
        let topo = w.topo.take().unwrap_or_else(|| Topology::new(&w.mesh));
        let (edges, copies) = split::split_non_manifold(&mut w.mesh, &topo);
        if copies == 0 {
            w.topo = Some(topo);
        }
        w.note(
            "non-manifold edges separated",
            if copies > 0 { edges } else { 0 },
        );
        w.note("vertices duplicated to separate touching shells", copies);
    }

    let non_orientable = {
        let _s = progress.stage("making winding consistent");
        orient_consistently(&mut w)
    };

    let mut holes_left = 0;
    if opts.fill_holes {
        let _s = progress.stage("filling holes");
        let nf = w.mesh.triangle_count();
        let (mesh, topo) = w.parts();
        let mut loops = topo.boundary_loops(mesh);
        if !loops.is_empty() {
            // A flat open sheet has no inside: filling its outline would only lay a second
            // sheet on it. Such shells stay open (and are reported).
            let (shell_of, n) = topo.shells(nf);
            let members = check::shell_members(&shell_of, n);
            let mut shell_of_vertex = vec![u32::MAX; mesh.vertex_count()];
            for (f, &s) in shell_of.iter().enumerate() {
                for k in 0..3 {
                    shell_of_vertex[mesh.indices[3 * f + k] as usize] = s;
                }
            }
            let flat: Vec<bool> = members.iter().map(|m| holes::is_flat(mesh, m)).collect();
            loops.retain(|l| {
                let s = shell_of_vertex[l.vertices[0] as usize];
                s == u32::MAX || !flat[s as usize]
            });
        }
        if !loops.is_empty() {
            let st = holes::fill(&mut w.mesh, &loops, opts.fair)?;
            w.topo = None;
            w.note("planar holes filled by triangulating the loop", st.planar);
            w.note(
                "curved holes filled by CGAL (triangulate, refine, fair)",
                st.curved,
            );
            w.note("facets added to fill holes", st.facets_added);
            holes_left = st.failed;
        }
    }

    {
        let _s = progress.stage("turning shells outward");
        let flipped = orient_outward(&mut w);
        w.note("shells turned outward", flipped);
    }

    let mut open_shells = Vec::new();
    {
        let nf = w.mesh.triangle_count();
        let (mesh, topo) = w.parts();
        let (shell_of, n) = topo.shells(nf);
        let mut boundary = vec![0u64; n];
        for e in 0..topo.edge_count() {
            let hs = topo.edge(e);
            if hs.len() != 2 {
                boundary[shell_of[(hs[0] / 3) as usize] as usize] += 1;
            }
        }
        let loops = topo.boundary_loops(mesh);
        let members = check::shell_members(&shell_of, n);
        let mut drop = vec![false; n];
        for s in 0..n {
            if boundary[s] > 0 {
                let vs: std::collections::HashSet<u32> = members[s]
                    .iter()
                    .flat_map(|&f| mesh.indices[3 * f as usize..3 * f as usize + 3].to_vec())
                    .collect();
                let hole_loops = loops
                    .iter()
                    .filter(|l| l.closed && vs.contains(&l.vertices[0]))
                    .count() as u64;
                open_shells.push(OpenShell {
                    facets: members[s].len() as u64,
                    boundary_edges: boundary[s],
                    hole_loops,
                    dropped: opts.drop_open_shells,
                });
                drop[s] = opts.drop_open_shells;
            }
        }
        if opts.drop_open_shells && drop.iter().any(|d| *d) {
            let keep: Vec<bool> = (0..nf)
                .map(|f| shell_of[f] != u32::MAX && !drop[shell_of[f] as usize])
                .collect();
            let dropped = keep.iter().filter(|k| !**k).count() as u64;
            w.retain(&keep);
            w.note("open shells dropped", open_shells.len() as u64);
            w.note("facets dropped with open shells", dropped);
        }
    }

    let mut remesh_active = None;
    if let Some(voxel) = opts.remesh {
        let _s = progress.stage("remeshing through OpenVDB");
        let before = w.mesh.triangle_count() as u64;
        let (m, active) = remesh::remesh(&w.mesh, voxel)?;
        w.mesh = m;
        w.topo = None;
        remesh_active = Some(active);
        w.note("facets replaced by remeshing", before);
        w.note("facets made by remeshing", w.mesh.triangle_count() as u64);
    }

    let removed = compact(&mut w.mesh);
    w.note("unreferenced vertices removed", removed);

    Ok((
        w.mesh,
        RepairReport {
            changes: w.changes,
            open_shells,
            non_orientable_shells: non_orientable,
            holes_left,
            remesh_voxel: opts.remesh,
            remesh_active_voxels: remesh_active,
        },
    ))
}

/// Merges boundary vertices within `tol` of each other. Returns vertices merged away.
fn stitch(w: &mut Work, tol: f64) -> u64 {
    if tol.is_nan() || tol <= 0.0 {
        return 0;
    }
    let (mesh, topo) = w.parts();
    let mut bv: Vec<u32> = Vec::new();
    for e in 0..topo.edge_count() {
        let hs = topo.edge(e);
        if hs.len() == 1 {
            let (a, b) = crate::mesh::topology::half_edge(mesh, hs[0]);
            bv.push(a);
            bv.push(b);
        }
    }
    if bv.is_empty() {
        return 0;
    }
    bv.sort_unstable();
    bv.dedup();
    let pts: Vec<[f64; 3]> = bv.iter().map(|&v| w.mesh.vertex(v)).collect();
    let rep = crate::io::weld::cluster(&pts, tol);
    let mut map: std::collections::HashMap<u32, u32> = Default::default();
    for (k, &r) in rep.iter().enumerate() {
        if r != k {
            map.insert(bv[k], bv[r]);
        }
    }
    if map.is_empty() {
        return 0;
    }
    for i in w.mesh.indices.iter_mut() {
        if let Some(&r) = map.get(i) {
            *i = r;
        }
    }
    w.topo = None;
    map.len() as u64
}

/// Flips facets so each shell is wound consistently with its first facet. Returns the number of
/// shells that cannot be oriented.
fn orient_consistently(w: &mut Work) -> u64 {
    let nf = w.mesh.triangle_count();
    let (mesh, topo) = w.parts();
    let (shell_of, n) = topo.shells(nf);
    let (mut flip, bad) = check::orientation(mesh, topo, &shell_of, n);
    // Flip the smaller side of each shell (fewest changes).
    let mut flipped = vec![0u64; n];
    let mut size = vec![0u64; n];
    for f in 0..nf {
        if shell_of[f] != u32::MAX {
            size[shell_of[f] as usize] += 1;
            flipped[shell_of[f] as usize] += flip[f] as u64;
        }
    }
    for f in 0..nf {
        let s = shell_of[f];
        if s != u32::MAX && 2 * flipped[s as usize] > size[s as usize] {
            flip[f] = !flip[f];
        }
    }
    let mut count = 0;
    for (f, fl) in flip.iter().enumerate() {
        if *fl {
            w.mesh.indices.swap(3 * f + 1, 3 * f + 2);
            count += 1;
        }
    }
    w.note("facets flipped for consistent winding", count);
    bad.iter().filter(|b| **b).count() as u64
}

/// Flips closed, consistently wound shells whose facing disagrees with their nesting depth.
fn orient_outward(w: &mut Work) -> u64 {
    let nf = w.mesh.triangle_count();
    let (mesh, topo) = w.parts();
    let (shell_of, n) = topo.shells(nf);
    let mut closed = vec![true; n];
    for e in 0..topo.edge_count() {
        let hs = topo.edge(e);
        let s = shell_of[(hs[0] / 3) as usize] as usize;
        let he = |h: u32| crate::mesh::topology::half_edge(mesh, h);
        if hs.len() != 2 || he(hs[0]) == he(hs[1]) {
            closed[s] = false;
        }
    }
    let members = check::shell_members(&shell_of, n);
    let depth = check::nesting(mesh, &members, &closed);
    let mut flipped = 0;
    for s in 0..n {
        let Some(d) = depth[s] else { continue };
        let vol: f64 = members[s]
            .iter()
            .map(|&f| {
                let [a, b, c] = w.mesh.triangle(f as usize);
                signed_volume(a, b, c)
            })
            .sum();
        if (vol > 0.0) != (d % 2 == 0) && vol != 0.0 {
            for &f in &members[s] {
                w.mesh.indices.swap(3 * f as usize + 1, 3 * f as usize + 2);
            }
            flipped += 1;
        }
    }
    if flipped > 0 {
        w.topo = None;
    }
    flipped
}

/// Drops vertices no facet uses, keeping the order of the rest. Returns how many were dropped.
fn compact(mesh: &mut Mesh) -> u64 {
    let nv = mesh.vertex_count();
    let mut used = vec![false; nv];
    for &i in &mesh.indices {
        used[i as usize] = true;
    }
    if used.iter().all(|u| *u) {
        return 0;
    }
    let mut id = vec![u32::MAX; nv];
    let mut positions = Vec::with_capacity(mesh.positions.len());
    for v in 0..nv {
        if used[v] {
            id[v] = (positions.len() / 3) as u32;
            positions.extend_from_slice(&mesh.positions[3 * v..3 * v + 3]);
        }
    }
    for i in mesh.indices.iter_mut() {
        *i = id[*i as usize];
    }
    mesh.positions = positions;
    (nv - used.iter().filter(|u| **u).count()) as u64
}
