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
//! 9. For a solid (`--solid`): drop the open shells, join shells that intersect or overlap
//!    (CGAL's corefinement, or a remesh of their group) — see [`solid`]; or, where the open
//!    shells enclose something together (a soup of open and overlapping pieces), make the whole
//!    solid by its generalised winding number — see [`soup`].
//!
//! A mesh without defects passes through unchanged (same facets in the same order). A shell that
//! stays open is reported, never dropped unless asked. Normals are recomputed by the writers.

pub mod cgal;
mod file;
mod holes;
pub mod remesh;
pub mod solid;
pub mod soup;
mod split;

use crate::check;
use crate::error::Result;
use crate::field::Aabb;
use crate::geom::topology::{BoundaryLoop, Shells, Topology};
use crate::geom::{signed_volume, sub, Mesh};
use crate::progress::Progress;

pub use file::{repair_file, FileRepairReport};
pub use holes::PLANAR_REL;
pub use solid::SolidReport;

/// With `solid`, open shells whose winding number exceeds ½ where the closed shells' does not,
/// in at least this many cells of a grid of [`SOUP_GRID`]³ over them, enclose material that
/// dropping them would lose: the part is a soup, made solid whole by its winding number.
/// Otherwise they are strays beside the closed shells (or inside them), dropped, and the closed
/// shells are joined exactly.
pub const SOUP_CELLS: usize = 8;
/// Cells per axis of the grid the open shells' enclosure is tested on.
pub const SOUP_GRID: usize = 24;

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
    /// Rebuild the part through an OpenVDB level set (with `solid`: the voxel size of the
    /// remeshes the solid needs, if any).
    pub remesh: Option<Remesh>,
    /// End in one valid closed solid: drop open shells, join intersecting ones ([`solid`]).
    pub solid: bool,
    /// Simplify what a remesh made within this distance of the input's surface, mm (see
    /// [`crate::mesh::simplify`]; the input's surface is its triangles, signed by their winding
    /// number, [`soup`]).
    pub tolerance: Option<f64>,
}

/// The voxel size of a remesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Remesh {
    /// Chosen from the part ([`remesh::auto_voxel`]).
    Auto,
    /// This size, mm.
    Voxel(f64),
}

impl Default for RepairOptions {
    fn default() -> Self {
        RepairOptions {
            fill_holes: true,
            fair: true,
            stitch_tolerance: None,
            drop_open_shells: false,
            remesh: None,
            solid: false,
            tolerance: None,
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
    /// Its facets' area, mm².
    pub area: f64,
    /// Whether the shell was dropped (`drop_open_shells`, or `solid` where open shells are
    /// strays beside the closed ones).
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
    /// What making a solid did (`--solid`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub solid: Option<solid::SolidReport>,
    /// How a remesh was simplified within the tolerance asked (`tolerance`), and how far it
    /// lies from the input's surface.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub simplified: Option<crate::mesh::pipeline::Simplified>,
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

    /// Counts `count` changes of `kind` (none: nothing changed, the topology stays valid).
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
        // Zero-area facets whose middle vertex lies inside their longest edge are folded into
        // the facet across that edge first: cutting them out would leave a hole whose only
        // filling is another sliver.
        for _ in 0..3 {
            let (mesh, topo) = self.parts();
            let bad = check::FacetDefects::find(mesh, topo);
            let folded = fold_caps(&mut self.mesh, &bad);
            self.note("zero-area facets folded into their neighbours", folded);
            if folded == 0 {
                break;
            }
        }
        let (mesh, topo) = self.parts();
        let bad = check::FacetDefects::find(mesh, topo);
        let zero_count = bad.zero_area_count();
        if bad.repeated_vertex + zero_count + bad.duplicates.len() as u64 == 0 {
            return;
        }
        let zero = &bad.zero_area;
        let mut keep: Vec<bool> = (0..zero.len())
            .map(|f| topo.active[f] && !zero[f])
            .collect();
        for &d in &bad.duplicates {
            keep[d as usize] = false;
        }
        // A duplicate of a zero-area facet is counted once, as zero-area.
        let dup_count = bad
            .duplicates
            .iter()
            .filter(|&&d| !zero[d as usize])
            .count() as u64;
        self.retain(&keep);
        self.note("facets with a repeated vertex removed", bad.repeated_vertex);
        self.note("zero-area facets removed", zero_count);
        self.note("duplicate facets removed", dup_count);
    }

    /// Step 2: merges boundary vertices within `tol` of each other.
    fn stitch_borders(&mut self, tol: f64) {
        let merged = stitch(self, tol);
        self.note("border vertices stitched", merged);
        if merged > 0 {
            self.remove_bad_facets();
        }
    }

    /// Step 3: splits edges at T-junctions found with tolerance `tol` (a few rounds: a split
    /// can leave a vertex on another edge).
    fn split_t_junctions(&mut self, tol: f64) {
        for _ in 0..4 {
            let (mesh, topo) = self.parts();
            let tjs = check::t_junctions(mesh, topo, tol);
            if tjs.is_empty() {
                break;
            }
            let n = split::split_t_junctions(&mut self.mesh, &tjs);
            self.topo = None;
            self.note("edges split at T-junctions", n);
            if n == 0 {
                break;
            }
        }
        self.remove_bad_facets();
    }

    /// Step 4: separates shells that touch at a vertex or along a non-manifold edge.
    fn separate_shells(&mut self) {
        let topo = self
            .topo
            .take()
            .unwrap_or_else(|| Topology::new(&self.mesh));
        let (edges, copies) = split::split_non_manifold(&mut self.mesh, &topo);
        if copies == 0 {
            self.topo = Some(topo);
        }
        self.note(
            "non-manifold edges separated",
            if copies > 0 { edges } else { 0 },
        );
        self.note("vertices duplicated to separate touching shells", copies);
    }

    /// Step 6: fills the holes of shells with an inside; returns the holes neither method could
    /// fill.
    fn fill_holes(&mut self, fair: bool) -> Result<u64> {
        let (mesh, topo) = self.parts();
        let loops = holes_to_fill(mesh, topo);
        if loops.is_empty() {
            return Ok(0);
        }
        let st = holes::fill(&mut self.mesh, &loops, fair)?;
        self.topo = None;
        self.note("planar holes filled by triangulating the loop", st.planar);
        self.note(
            "curved holes filled by CGAL (triangulate, refine, fair)",
            st.curved,
        );
        self.note("facets added to fill holes", st.facets_added);
        Ok(st.failed)
    }

    /// Whether dropping the shells still open would lose material: their winding number over
    /// ½ (they enclose something together) where the closed shells' is not, in [`SOUP_CELLS`]
    /// cells or more of a grid over them.
    fn open_shells_enclose(&mut self) -> bool {
        let (mesh, topo) = self.parts();
        let shells = Shells::new(mesh, topo);
        let (mut open, mut closed) = (Vec::new(), Vec::new());
        for f in 0..mesh.triangle_count() {
            match shells.of_facet[f] {
                u32::MAX => {}
                s if shells.edges[s as usize].closed() => closed.push(mesh.triangle(f)),
                _ => open.push(mesh.triangle(f)),
            }
        }
        if open.is_empty() {
            return false;
        }
        let corner = |pick: fn(f64, f64) -> f64, start: f64| {
            [0, 1, 2].map(|a| {
                open.iter()
                    .flat_map(|t| t.iter().map(move |p| p[a]))
                    .fold(start, pick)
            })
        };
        let (lo, hi) = (
            corner(f64::min, f64::INFINITY),
            corner(f64::max, f64::NEG_INFINITY),
        );
        let open_w = crate::geom::winding::Winding::of_triangles(&open);
        let closed_w = crate::geom::winding::Winding::of_triangles(&closed);
        let n = SOUP_GRID;
        use rayon::prelude::*;
        let lost = (0..n * n * n)
            .into_par_iter()
            .filter(|&i| {
                let c = [i / (n * n), (i / n) % n, i % n];
                let p = [0, 1, 2].map(|a| lo[a] + (hi[a] - lo[a]) * (c[a] as f64 + 0.5) / n as f64);
                open_w.at(p) > 0.5 && closed_w.at(p) < 0.5
            })
            .count();
        lost >= SOUP_CELLS
    }

    /// Step 8: the shells still open, each with its holes; dropped with their facets when
    /// `drop` is set.
    fn open_shells(&mut self, drop: bool) -> Vec<OpenShell> {
        let (mesh, topo) = self.parts();
        let shells = Shells::new(mesh, topo);
        let loops = topo.boundary_loops(mesh);
        let mut open = Vec::new();
        let mut dropped = vec![false; shells.count()];
        for (s, e) in shells.edges.iter().enumerate() {
            if e.closed() {
                continue;
            }
            let fs = &shells.members[s];
            let vs: std::collections::HashSet<u32> = fs
                .iter()
                .flat_map(|&f| mesh.indices[3 * f as usize..3 * f as usize + 3].to_vec())
                .collect();
            let hole_loops = loops
                .iter()
                .filter(|l| l.closed && vs.contains(&l.vertices[0]))
                .count() as u64;
            let area = fs
                .iter()
                .map(|&f| {
                    let [a, b, c] = mesh.triangle(f as usize);
                    crate::geom::triangle_area(a, b, c)
                })
                .sum();
            open.push(OpenShell {
                facets: fs.len() as u64,
                boundary_edges: e.boundary + e.non_manifold,
                hole_loops,
                area,
                dropped: drop,
            });
            dropped[s] = drop;
        }
        if drop && !open.is_empty() {
            let keep: Vec<bool> = (shells.of_facet.iter())
                .map(|&s| s != u32::MAX && !dropped[s as usize])
                .collect();
            let facets = keep.iter().filter(|k| !**k).count() as u64;
            self.retain(&keep);
            self.note("open shells dropped", open.len() as u64);
            self.note("facets dropped with open shells", facets);
        }
        open
    }

    /// Step 8, when asked: rebuilds the part through an OpenVDB level set with voxels of
    /// `voxel` mm; returns the level set's active voxels.
    fn remesh(&mut self, voxel: f64) -> Result<u64> {
        let before = self.mesh.triangle_count() as u64;
        let (m, active) = remesh::remesh(&self.mesh, voxel)?;
        self.mesh = m;
        self.topo = None;
        self.note("facets replaced by remeshing", before);
        self.note(
            "facets made by remeshing",
            self.mesh.triangle_count() as u64,
        );
        Ok(active)
    }
}

/// Folds each zero-area facet `(a, b, c)` whose vertex `c` lies inside its longest edge `ab`
/// (a "cap") into the facet `g` across that edge: `g = (x, y, d)` on the edge `{a, b}` becomes
/// `(x, c, d)` and `(c, y, d)`, which keep `g`'s winding and split its edge at `c`, and the cap
/// goes. The neighbours of the cap's other two edges then meet those two facets instead: the
/// surface is the same and closed where it was. Facets whose vertices coincide ("needles"),
/// stray caps (a short edge meets no other facet) and caps without a facet across, or whose
/// facet there is degenerate too, are left (and removed as before). Returns the caps folded.
fn fold_caps(mesh: &mut Mesh, bad: &check::FacetDefects) -> u64 {
    use std::collections::HashMap;
    let n = mesh.triangle_count();
    let tri = |m: &Mesh, f: usize| [m.indices[3 * f], m.indices[3 * f + 1], m.indices[3 * f + 2]];
    let mut by_edge: HashMap<(u32, u32), Vec<u32>> = HashMap::new();
    for f in 0..n {
        let t = tri(mesh, f);
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            by_edge
                .entry((a.min(b), a.max(b)))
                .or_default()
                .push(f as u32);
        }
    }
    let mut touched = vec![false; n];
    let mut gone = vec![false; n];
    let mut added: Vec<u32> = Vec::new();
    let mut folded = 0;
    for f in 0..n {
        if !bad.zero_area[f] || touched[f] {
            continue;
        }
        let t = tri(mesh, f);
        let p = t.map(|v| mesh.vertex(v));
        let len = |k: usize| crate::geom::norm(sub(p[(k + 1) % 3], p[k]));
        let k = (0..3)
            .max_by(|&i, &j| len(i).total_cmp(&len(j)))
            .expect("three edges");
        let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
        // A needle: c on a or b, nothing to split.
        let short = len((k + 1) % 3).min(len((k + 2) % 3));
        if short <= 1e-6 * len(k) {
            continue;
        }
        // Only a cap that is part of the surface: its short edges meet other facets (a stray
        // degenerate facet is removed instead).
        let shared = |p: u32, q: u32| by_edge[&(p.min(q), p.max(q))].len() >= 2;
        if !shared(a, c) || !shared(c, b) {
            continue;
        }
        let Some(&g) = by_edge[&(a.min(b), a.max(b))]
            .iter()
            .find(|&&g| g as usize != f && !touched[g as usize] && !bad.zero_area[g as usize])
        else {
            continue;
        };
        let gt = tri(mesh, g as usize);
        let Some(i) = (0..3).find(|&i| {
            let (x, y) = (gt[i], gt[(i + 1) % 3]);
            (x == a && y == b) || (x == b && y == a)
        }) else {
            continue;
        };
        let (x, y, d) = (gt[i], gt[(i + 1) % 3], gt[(i + 2) % 3]);
        if d == c {
            continue;
        }
        mesh.indices[3 * g as usize..3 * g as usize + 3].copy_from_slice(&[x, c, d]);
        added.extend_from_slice(&[c, y, d]);
        gone[f] = true;
        touched[f] = true;
        touched[g as usize] = true;
        folded += 1;
    }
    if folded > 0 {
        let mut out = Vec::with_capacity(mesh.indices.len() + added.len());
        for (f, gone) in gone.iter().enumerate() {
            if !gone {
                out.extend_from_slice(&tri(mesh, f));
            }
        }
        out.extend_from_slice(&added);
        mesh.indices = out;
    }
    folded
}

/// `mesh` (made on `voxel` mm: a remesh, or any part meshed from a grid) simplified within
/// `tolerance` of `surface`'s triangles (their winding-signed distance, so `surface` may be
/// open or a soup), its volume kept, and how far it lies from them.
pub fn simplify_to_mesh(
    mesh: &Mesh,
    surface: &Mesh,
    voxel: f64,
    tolerance: f64,
) -> (Mesh, crate::mesh::simplify::Simplified) {
    use crate::mesh::simplify::{self, Surface};
    let bounds = surface
        .bounds()
        .into_iter()
        .chain(mesh.bounds())
        .reduce(|a, b| a.union(&b))
        .unwrap_or(Aabb {
            min: [0.0; 3],
            max: [0.0; 3],
        });
    let spec = crate::grid::GridSpec::covering(&bounds, voxel, 3.0);
    let field = soup::SoupField::new(surface, spec);
    // The box lies beyond the part: nothing is on its faces.
    let clip = bounds.grown(4.0 * voxel + 1.0);
    let surface = Surface {
        field: &field,
        clip,
    };
    simplify::mesh_within(mesh, surface, voxel, tolerance)
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
        .map(|b| crate::geom::norm(sub(b.max, b.min)))
        .unwrap_or(0.0);
    {
        let _s = progress.stage("removing degenerate and duplicate facets");
        w.remove_bad_facets();
    }
    {
        let _s = progress.stage("stitching borders");
        w.stitch_borders(
            opts.stitch_tolerance
                .unwrap_or(check::T_JUNCTION_REL * diag),
        );
    }
    {
        let _s = progress.stage("splitting edges at T-junctions");
        w.split_t_junctions(opts.stitch_tolerance.unwrap_or(0.0));
    }
    {
        let _s = progress.stage("separating shells at non-manifold edges and vertices");
        w.separate_shells();
    }
    let non_orientable = {
        let _s = progress.stage("making winding consistent");
        orient_consistently(&mut w)
    };
    let holes_left = if opts.fill_holes {
        let _s = progress.stage("filling holes");
        w.fill_holes(opts.fair)?
    } else {
        0
    };
    {
        let _s = progress.stage("turning shells outward");
        let flipped = orient_outward(&mut w);
        w.note("shells turned outward", flipped);
    }
    // A solid from a soup: where the open shells together enclose something the closed ones do
    // not, they are part of the part, and the whole is made solid by its winding number;
    // otherwise they are strays beside the closed shells.
    let soup = opts.solid && w.open_shells_enclose();
    let open_shells = w.open_shells(opts.drop_open_shells || (opts.solid && !soup));
    // The surface a remesh is simplified against: the repaired facets, before any remesh.
    let before_remesh = opts.tolerance.map(|_| w.mesh.clone());
    let fixed_voxel = match opts.remesh {
        Some(Remesh::Voxel(v)) => Some(v),
        _ => None,
    };
    let mut remesh_voxel = None;
    let solid_report = if soup {
        let _s = progress.stage("making the pieces solid by their winding number");
        let voxel = fixed_voxel.unwrap_or_else(|| remesh::voxel_for(&w.mesh, true, opts.tolerance));
        let (m, active) = remesh::solidify(&w.mesh, voxel)?;
        w.mesh = m;
        w.topo = None;
        w.note(
            "open pieces made solid with the rest by their winding number",
            open_shells.len() as u64,
        );
        remesh_voxel = Some(voxel);
        if w.mesh.triangle_count() == 0 {
            return Err(crate::error::Error::invalid(
                "no solid: the pieces enclose nothing (their winding number is nowhere over ½: open sheets with no inside)",
            ));
        }
        Some(SolidReport {
            soup_active_voxels: Some(active),
            voxel: Some(voxel),
            ..SolidReport::default()
        })
    } else if opts.solid {
        if w.mesh.triangle_count() == 0 {
            return Err(crate::error::Error::invalid(
                "no solid: nothing is closed enough to have an inside (every shell is open or degenerate)",
            ));
        }
        let _s = progress.stage("joining intersecting shells");
        let (m, rep) = solid::unite(&w.mesh, fixed_voxel)?;
        if rep.intersecting_groups > 0 {
            w.mesh = m;
            w.topo = None;
        }
        w.note(
            "overlapping shells joined by CGAL's corefinement",
            rep.shells_united,
        );
        w.note(
            "intersecting shells remeshed through OpenVDB",
            rep.shells_remeshed,
        );
        w.note(
            "whole part remeshed (last resort)",
            rep.whole_part_remeshed as u64,
        );
        remesh_voxel = rep.voxel;
        if w.mesh.triangle_count() == 0 {
            return Err(crate::error::Error::invalid(format!(
                "no solid: the closed shells are thinner than the remesh voxel ({:.4} mm) and vanished",
                rep.voxel.unwrap_or(0.0)
            )));
        }
        Some(rep)
    } else {
        None
    };
    let remesh_active = match (opts.remesh, opts.solid) {
        (Some(_), false) => {
            let _s = progress.stage("remeshing through OpenVDB");
            let voxel =
                fixed_voxel.unwrap_or_else(|| remesh::voxel_for(&w.mesh, false, opts.tolerance));
            remesh_voxel = Some(voxel);
            Some(w.remesh(voxel)?)
        }
        _ => None,
    };
    let remeshed = remesh_active.is_some()
        || solid_report.as_ref().is_some_and(|r| {
            r.soup_active_voxels.is_some() || r.shells_remeshed > 0 || r.whole_part_remeshed
        });
    let simplified = match (opts.tolerance, before_remesh, remesh_voxel) {
        (Some(tolerance), Some(surface), Some(voxel)) if remeshed => {
            let _s = progress.stage("simplifying the remesh");
            let (m, s) = simplify_to_mesh(&w.mesh, &surface, voxel, tolerance);
            w.mesh = m;
            w.topo = None;
            Some(s)
        }
        _ => None,
    };
    let removed = compact(&mut w.mesh);
    w.note("unreferenced vertices removed", removed);

    Ok((
        w.mesh,
        RepairReport {
            changes: w.changes,
            open_shells,
            non_orientable_shells: non_orientable,
            holes_left,
            remesh_voxel,
            remesh_active_voxels: remesh_active,
            solid: solid_report,
            simplified,
        },
    ))
}

/// The boundary loops to fill: every one but the outlines of flat open sheets. A flat open sheet
/// has no inside: filling its outline would only lay a second sheet on it. Such shells stay open
/// (and are reported).
fn holes_to_fill(mesh: &Mesh, topo: &Topology) -> Vec<BoundaryLoop> {
    let mut loops = topo.boundary_loops(mesh);
    if loops.is_empty() {
        return loops;
    }
    let shells = Shells::new(mesh, topo);
    let mut shell_of_vertex = vec![u32::MAX; mesh.vertex_count()];
    for (f, &s) in shells.of_facet.iter().enumerate() {
        for k in 0..3 {
            shell_of_vertex[mesh.indices[3 * f + k] as usize] = s;
        }
    }
    let flat: Vec<bool> = (shells.members.iter())
        .map(|m| holes::is_flat(mesh, m))
        .collect();
    loops.retain(|l| {
        let s = shell_of_vertex[l.vertices[0] as usize];
        s == u32::MAX || !flat[s as usize]
    });
    loops
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
            let (a, b) = crate::geom::topology::half_edge(mesh, hs[0]);
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
    let (mesh, topo) = w.parts();
    let shells = Shells::new(mesh, topo);
    let solid: Vec<bool> = shells.edges.iter().map(|e| e.solid()).collect();
    let depth = check::nesting(mesh, &shells.members, &solid);
    let mut flipped = 0;
    for (fs, d) in shells.members.iter().zip(depth) {
        let Some(d) = d else { continue };
        let vol: f64 = fs
            .iter()
            .map(|&f| {
                let [a, b, c] = w.mesh.triangle(f as usize);
                signed_volume(a, b, c)
            })
            .sum();
        if (vol > 0.0) != (d % 2 == 0) && vol != 0.0 {
            for &f in fs {
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
