//! Repair to a solid (`repair --solid`): after the topological repair, what still keeps the part
//! from being one valid solid is mended by geometry.
//!
//! 1. Shells still open (single stray facets, slivers, sheets whose holes could not be filled)
//!    have no inside: they are dropped and counted. Nothing closed left: no solid exists.
//! 2. Intersecting facet pairs (latvox's exact search) group the shells: two shells that cross
//!    or overlap are one group (union–find over the pairs), and a shell crossing itself marks its
//!    group.
//! 3. A group of closed, outward shells that are each free of self-intersection becomes their
//!    union by CGAL's corefinement (exact for the overlapping boxes of an assembly; a balanced
//!    tree of pairwise unions, log₂ S rounds for S shells). Any other group — a shell crossing
//!    itself, a cavity, a union that would not be a 2-manifold (shells touching along an edge)
//!    — is remeshed through OpenVDB on its own (see [`super::remesh`]); the other shells are
//!    kept as they are.
//! 4. The result, welded as a file holds it, is checked whole (closed, manifold, outward, no
//!    degenerate facet, no self-intersection). If anything remains the whole part is remeshed:
//!    the last resort, always closed and manifold.
//!
//! CGAL 5.5's corefinement can loop for ever on some assemblies (parts sharing coplanar faces,
//! seen on printer platforms even with exact constructions): it runs in a child process (fork)
//! given a time limit, 5 s and 0.5 ms per facet; past it the child is killed and the group is
//! remeshed.
//!
//! Costs: one self-intersection search (a hierarchical grid, about n log n), corefinement of the
//! intersecting groups only (each round linear in the group's facets and crossings up to a log
//! factor), remeshing proportional to the surface area over the voxel size squared; nothing
//! compares every shell with every other.

use super::remesh;
use crate::check::self_intersect::soup_self_intersections;
use crate::check::{check, CheckOptions};
use crate::error::Error;
use crate::error::Result;
use crate::ffi::cgal::ffi;
#[cfg(not(unix))]
use crate::ffi::Backend;
use crate::mesh::topology::{Shells, Topology, UnionFind};
use crate::mesh::Mesh;
use std::time::{Duration, Instant};

/// What making a solid did after the topological repair.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct SolidReport {
    /// Groups of intersecting or overlapping shells found.
    pub intersecting_groups: u64,
    /// Shells joined into their union by CGAL's corefinement.
    pub shells_united: u64,
    /// Shells remeshed through OpenVDB because corefinement did not apply to their group.
    pub shells_remeshed: u64,
    /// Why corefinement did not apply, one line per remeshed group (up to 8).
    pub remesh_reasons: Vec<String>,
    /// The whole part was remeshed as the last resort (something remained after the groups).
    pub whole_part_remeshed: bool,
    /// The voxel size of the remeshes, mm, when one ran.
    pub voxel: Option<f64>,
}

/// Joins intersecting shells of the closed, outward `mesh` into a solid; `voxel` is the remesh
/// voxel (mm) for groups corefinement cannot join, chosen by [`remesh::auto_voxel`] when `None`.
pub fn unite(mesh: &Mesh, voxel: Option<f64>) -> Result<(Mesh, SolidReport)> {
    let mut rep = SolidReport::default();
    let topo = Topology::new(mesh);
    let shells = Shells::new(mesh, &topo);
    let all: Vec<u32> = (0..mesh.triangle_count() as u32)
        .filter(|&f| topo.active[f as usize])
        .collect();
    let (count, pairs) = soup_self_intersections(mesh, &all, usize::MAX);
    if count == 0 {
        return Ok((mesh.clone(), rep));
    }
    let ns = shells.count();
    let mut uf = UnionFind::new(ns);
    let mut crossing_itself = vec![false; ns];
    for (a, b) in pairs {
        let (sa, sb) = (shells.of_facet[a as usize], shells.of_facet[b as usize]);
        if sa == sb {
            crossing_itself[sa as usize] = true;
        } else {
            uf.union(sa, sb);
        }
    }
    let mut groups: std::collections::BTreeMap<u32, Vec<u32>> = Default::default();
    for s in 0..ns as u32 {
        groups.entry(uf.find(s)).or_default().push(s);
    }
    let solid: Vec<bool> = shells.edges.iter().map(|e| e.solid()).collect();
    let depth = crate::check::nesting(mesh, &shells.members, &solid);
    let voxel = voxel.unwrap_or_else(|| remesh::auto_voxel(mesh));
    let mut keep = vec![true; mesh.triangle_count()];
    let mut parts: Vec<Mesh> = Vec::new();
    for g in groups.values() {
        if g.len() < 2 && !crossing_itself[g[0] as usize] {
            continue;
        }
        rep.intersecting_groups += 1;
        let (sub, starts) = gather(mesh, &shells, g);
        for &s in g {
            for &f in &shells.members[s as usize] {
                keep[f as usize] = false;
            }
        }
        let why = if let Some(&s) = g.iter().find(|&&s| crossing_itself[s as usize]) {
            Some(format!(
                "a shell of {} facets crosses itself",
                shells.members[s as usize].len()
            ))
        } else if g.iter().any(|&s| depth[s as usize] != Some(0)) {
            Some("the group holds a cavity or a shell inside another".to_string())
        } else {
            match union_within(&sub, &starts, union_time_limit(sub.triangle_count()))? {
                Ok(m) => {
                    rep.shells_united += g.len() as u64;
                    parts.push(m);
                    None
                }
                Err(why) => Some(why),
            }
        };
        if let Some(why) = why {
            if rep.remesh_reasons.len() < 8 {
                rep.remesh_reasons.push(why);
            }
            rep.shells_remeshed += g.len() as u64;
            rep.voxel = Some(voxel);
            parts.push(remesh::remesh(&sub, voxel)?.0);
        }
    }
    let mut out = Mesh {
        positions: mesh.positions.clone(),
        indices: Vec::new(),
    };
    for (f, t) in mesh.indices.chunks_exact(3).enumerate() {
        if keep[f] {
            out.indices.extend_from_slice(t);
        }
    }
    for p in parts {
        let base = out.vertex_count() as u32;
        out.positions.extend_from_slice(&p.positions);
        out.indices.extend(p.indices.iter().map(|i| i + base));
    }
    super::compact(&mut out);
    // As a file will hold it: vertices at one position are one vertex.
    let out = crate::io::weld::weld_indexed(&out.positions, &out.indices)?;
    let found = check(&out, None, &CheckOptions::default())?;
    if found.defects().is_empty() {
        return Ok((out, rep));
    }
    rep.whole_part_remeshed = true;
    rep.voxel = Some(voxel);
    Ok((remesh::remesh(mesh, voxel)?.0, rep))
}

/// The facets of shells `g` as a mesh of their own, shell after shell, with each shell's first
/// facet (and the facet count at the end).
fn gather(mesh: &Mesh, shells: &Shells, g: &[u32]) -> (Mesh, Vec<u32>) {
    let mut sub = Mesh {
        positions: mesh.positions.clone(),
        indices: Vec::new(),
    };
    let mut starts = vec![0u32];
    for &s in g {
        for &f in &shells.members[s as usize] {
            sub.indices
                .extend_from_slice(&mesh.indices[3 * f as usize..3 * f as usize + 3]);
        }
        starts.push((sub.indices.len() / 3) as u32);
    }
    super::compact(&mut sub);
    (sub, starts)
}

/// How long corefinement of `facets` facets may take before its group is remeshed instead.
fn union_time_limit(facets: usize) -> Duration {
    Duration::from_secs_f64(5.0 + 5e-4 * facets as f64)
}

/// The union of the shells of `sub` (`starts` as [`ffi::cgal_union`] takes them), or why there is
/// none: CGAL's reason, or that it did not finish within `limit`.
fn union_within(
    sub: &Mesh,
    starts: &[u32],
    limit: Duration,
) -> Result<std::result::Result<Mesh, String>> {
    let as_mesh = |u: ffi::ShellUnion| {
        if u.ok {
            Ok(Mesh {
                positions: u.positions.iter().map(|&x| x as f32).collect(),
                indices: u.indices,
            })
        } else {
            Err(u.reason)
        }
    };
    #[cfg(not(unix))]
    {
        let _ = limit;
        return Ok(as_mesh(
            ffi::cgal_union(&sub.positions, &sub.indices, starts).backend("CGAL corefinement")?,
        ));
    }
    #[cfg(unix)]
    {
        use std::sync::atomic::{AtomicU64, Ordering};
        static NEXT: AtomicU64 = AtomicU64::new(0);
        let path = std::env::temp_dir().join(format!(
            "latvox-union-{}-{}.bin",
            std::process::id(),
            NEXT.fetch_add(1, Ordering::Relaxed)
        ));
        // SAFETY: the child only runs CGAL's single-threaded union on memory it inherited,
        // writes one file and leaves with _exit (no destructors, no other thread's locks).
        let pid = unsafe { libc::fork() };
        if pid < 0 {
            return Err(Error::Backend {
                context: "CGAL corefinement",
                message: "could not start a process".into(),
            });
        }
        if pid == 0 {
            let code = std::panic::catch_unwind(|| {
                let bytes = match ffi::cgal_union(&sub.positions, &sub.indices, starts) {
                    Ok(u) => encode(&u),
                    Err(e) => encode(&ffi::ShellUnion {
                        ok: false,
                        reason: format!("CGAL's corefinement failed: {e}"),
                        positions: Vec::new(),
                        indices: Vec::new(),
                    }),
                };
                std::fs::write(&path, bytes).is_ok()
            });
            // SAFETY: ends the child at once.
            unsafe { libc::_exit(if matches!(code, Ok(true)) { 0 } else { 1 }) };
        }
        let start = Instant::now();
        let mut status = 0;
        let finished = loop {
            // SAFETY: waits on our own child without blocking.
            let r = unsafe { libc::waitpid(pid, &mut status, libc::WNOHANG) };
            if r == pid {
                break true;
            }
            if r < 0 || start.elapsed() > limit {
                break false;
            }
            std::thread::sleep(Duration::from_millis(5));
        };
        if !finished {
            // SAFETY: our own child, then reaped.
            unsafe {
                libc::kill(pid, libc::SIGKILL);
                libc::waitpid(pid, &mut status, 0);
            }
            let _ = std::fs::remove_file(&path);
            return Ok(Err(format!(
                "CGAL's corefinement did not finish within {:.0} s",
                limit.as_secs_f64()
            )));
        }
        let bytes = std::fs::read(&path);
        let _ = std::fs::remove_file(&path);
        let decoded = bytes.ok().and_then(|b| decode(&b));
        Ok(match decoded {
            Some(u) => as_mesh(u),
            None => Err("CGAL's corefinement ended without a result".to_string()),
        })
    }
}

/// A union as bytes: ok, the reason, the positions and the indices, each with its length.
#[cfg(unix)]
fn encode(u: &ffi::ShellUnion) -> Vec<u8> {
    let mut b = vec![u.ok as u8];
    b.extend((u.reason.len() as u64).to_le_bytes());
    b.extend(u.reason.as_bytes());
    b.extend((u.positions.len() as u64).to_le_bytes());
    b.extend(u.positions.iter().flat_map(|x| x.to_le_bytes()));
    b.extend((u.indices.len() as u64).to_le_bytes());
    b.extend(u.indices.iter().flat_map(|x| x.to_le_bytes()));
    b
}

/// [`encode`]'s inverse; `None` if the bytes are cut short.
#[cfg(unix)]
fn decode(b: &[u8]) -> Option<ffi::ShellUnion> {
    let mut at = 1usize;
    let mut take = |n: usize| {
        let s = b.get(at..at + n)?;
        at += n;
        Some(s)
    };
    let len = |s: &[u8]| u64::from_le_bytes(s.try_into().expect("8 bytes")) as usize;
    let n = len(take(8)?);
    let reason = String::from_utf8_lossy(take(n)?).into_owned();
    let n = len(take(8)?);
    let positions = take(8 * n)?
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")))
        .collect();
    let n = len(take(8)?);
    let indices = take(4 * n)?
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes(c.try_into().expect("4 bytes")))
        .collect();
    Some(ffi::ShellUnion {
        ok: *b.first()? == 1,
        reason,
        positions,
        indices,
    })
}
