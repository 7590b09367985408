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
//! seen on printer platforms even with exact constructions): it runs in a fresh `latvox` process
//! given a time limit, 5 s and 0.5 ms per facet; past it the process is killed and the group is
//! remeshed.
//!
//! Costs: one self-intersection search (a hierarchical grid, about n log n), corefinement of the
//! intersecting groups only (each round linear in the group's facets and crossings up to a log
//! factor), remeshing proportional to the surface area over the voxel size squared; nothing
//! compares every shell with every other.

use super::remesh;
use crate::check::{check, CheckOptions};
use crate::error::Error;
use crate::error::Result;
use crate::ffi::cgal::ffi;
use crate::ffi::Backend;
use crate::geom::topology::{Shells, Topology, UnionFind};
use crate::geom::Mesh;
use crate::verify::self_intersect::soup_self_intersections;
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
    /// Active voxels of the level set a soup was made solid through (its open pieces more than
    /// strays: the whole made solid by its winding number); `None` otherwise.
    pub soup_active_voxels: Option<u64>,
    /// The mesh returned was searched for intersecting facet pairs and has none (the search the
    /// check of the written file may skip when the file holds the same facets).
    #[serde(skip)]
    pub searched_free: bool,
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
        rep.searched_free = true;
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
    let voxel = voxel.unwrap_or_else(|| remesh::auto_voxel_skipping(mesh, &crossing_itself));
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
        rep.searched_free = found.self_intersections == Some(0);
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

/// The hidden first argument that makes `latvox` run one union for [`union_within`] and exit.
pub const HELPER_ARG: &str = "__corefine";

/// The union of the shells of `sub` (`starts` as [`ffi::cgal_union`] takes them), or why there is
/// none: CGAL's reason, or that it did not finish within `limit`. The union runs in a fresh
/// `latvox` process ([`helper`]) that is killed past the limit; without a `latvox` executable to
/// run (the library inside another program) it runs here, with no limit.
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
    let Some(exe) = helper_exe() else {
        return Ok(as_mesh(
            ffi::cgal_union(&sub.positions, &sub.indices, starts).backend("CGAL corefinement")?,
        ));
    };
    let dir = tempfile::tempdir().map_err(|e| Error::io(std::env::temp_dir(), e))?;
    let (input, output) = (dir.path().join("shells.bin"), dir.path().join("union.bin"));
    std::fs::write(&input, encode_shells(sub, starts)).map_err(|e| Error::io(&input, e))?;
    let spawned = std::process::Command::new(&exe)
        .arg(HELPER_ARG)
        .arg(&input)
        .arg(&output)
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn();
    let mut child = match spawned {
        Ok(c) => c,
        Err(e) => return Err(Error::io(exe, e)),
    };
    let start = Instant::now();
    let finished = loop {
        match child.try_wait() {
            Ok(Some(_)) => break true,
            Ok(None) if start.elapsed() <= limit => std::thread::sleep(Duration::from_millis(2)),
            _ => break false,
        }
    };
    if !finished {
        let _ = child.kill();
        let _ = child.wait();
        return Ok(Err(format!(
            "CGAL's corefinement did not finish within {:.0} s",
            limit.as_secs_f64()
        )));
    }
    Ok(match std::fs::read(&output).ok().and_then(|b| decode(&b)) {
        Some(u) => as_mesh(u),
        None => Err("CGAL's corefinement ended without a result".to_string()),
    })
}

/// The `latvox` executable that runs unions: `LATVOX_EXE` if set, this program if it is latvox,
/// else a `latvox` beside it or one folder up (cargo's test and bench programs sit in `deps/`).
fn helper_exe() -> Option<std::path::PathBuf> {
    if let Some(p) = std::env::var_os("LATVOX_EXE") {
        return Some(p.into());
    }
    let me = std::env::current_exe().ok()?;
    if me.file_stem().is_some_and(|s| s == "latvox") {
        return Some(me);
    }
    let name = format!("latvox{}", std::env::consts::EXE_SUFFIX);
    me.ancestors()
        .skip(1)
        .take(2)
        .map(|d| d.join(&name))
        .find(|p| p.is_file())
}

/// Runs one union for [`union_within`] (`latvox __corefine SHELLS UNION`): reads the shells,
/// writes the union or CGAL's reason. Returns the exit code.
pub fn helper(input: &std::path::Path, output: &std::path::Path) -> i32 {
    let Some((sub, starts)) = std::fs::read(input).ok().and_then(|b| decode_shells(&b)) else {
        return 2;
    };
    let u = match ffi::cgal_union(&sub.positions, &sub.indices, &starts) {
        Ok(u) => u,
        Err(e) => ffi::ShellUnion {
            ok: false,
            reason: format!("CGAL's corefinement failed: {e}"),
            positions: Vec::new(),
            indices: Vec::new(),
        },
    };
    match std::fs::write(output, encode(&u)) {
        Ok(()) => 0,
        Err(_) => 3,
    }
}

/// Little-endian words with their counts: a reader over bytes written by [`put`].
struct Words<'a>(&'a [u8]);

impl Words<'_> {
    fn take(&mut self, n: usize) -> Option<&[u8]> {
        let (head, tail) = (self.0.get(..n)?, self.0.get(n..)?);
        self.0 = tail;
        Some(head)
    }
    /// A counted run of `W`-byte words.
    fn run<const W: usize, T>(&mut self, f: fn([u8; W]) -> T) -> Option<Vec<T>> {
        let n = u64::from_le_bytes(self.take(8)?.try_into().ok()?) as usize;
        let bytes = self.take(n.checked_mul(W)?)?;
        Some(
            bytes
                .chunks_exact(W)
                .map(|c| f(c.try_into().expect("W bytes")))
                .collect(),
        )
    }
}

/// Appends the count of `xs` and their bytes.
fn put<const W: usize, T: Copy>(b: &mut Vec<u8>, xs: &[T], f: fn(T) -> [u8; W]) {
    b.extend((xs.len() as u64).to_le_bytes());
    b.extend(xs.iter().flat_map(|&x| f(x)));
}

/// Shells for the helper: positions, indices, shell starts.
fn encode_shells(sub: &Mesh, starts: &[u32]) -> Vec<u8> {
    let mut b = Vec::new();
    put(&mut b, &sub.positions, f32::to_le_bytes);
    put(&mut b, &sub.indices, u32::to_le_bytes);
    put(&mut b, starts, u32::to_le_bytes);
    b
}

/// [`encode_shells`]'s inverse; `None` if the bytes are cut short.
fn decode_shells(b: &[u8]) -> Option<(Mesh, Vec<u32>)> {
    let mut w = Words(b);
    let positions = w.run(f32::from_le_bytes)?;
    let indices = w.run(u32::from_le_bytes)?;
    let starts = w.run(u32::from_le_bytes)?;
    Some((Mesh { positions, indices }, starts))
}

/// A union as bytes: ok, the reason, the positions and the indices.
fn encode(u: &ffi::ShellUnion) -> Vec<u8> {
    let mut b = vec![u.ok as u8];
    put(&mut b, u.reason.as_bytes(), |x: u8| [x]);
    put(&mut b, &u.positions, f64::to_le_bytes);
    put(&mut b, &u.indices, u32::to_le_bytes);
    b
}

/// [`encode`]'s inverse; `None` if the bytes are cut short.
fn decode(b: &[u8]) -> Option<ffi::ShellUnion> {
    let mut w = Words(b);
    let ok = w.take(1)?[0] == 1;
    let reason = String::from_utf8_lossy(&w.run(|[x]: [u8; 1]| x)?).into_owned();
    Some(ffi::ShellUnion {
        ok,
        reason,
        positions: w.run(f64::from_le_bytes)?,
        indices: w.run(u32::from_le_bytes)?,
    })
}
