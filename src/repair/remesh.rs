//! Remeshing through OpenVDB (the print shop's "shrink wrap"): the facets become a narrow-band
//! level set at the given voxel size and its zero iso-surface becomes the new mesh. Whatever
//! cannot be mended locally — self-intersections, overlapping shells, slivers — disappears; the
//! result is closed and manifold at that resolution, and features smaller than a voxel are lost.
//!
//! Volume-to-mesh alone is not always a valid mesh as a file holds it: where the input's faces
//! lie on voxel planes (CAD parts at round voxel sizes) samples read exactly zero, OpenVDB's
//! points of neighbouring voxels meet on their common face, and once written in single
//! precision (and welded by position, as STL readers do) they are one vertex, their facets
//! degenerate. So the part is meshed on a grid shifted by an irrational fraction of a voxel (no
//! face on a voxel plane), the result is welded exactly as a file will hold it, facets that
//! collapsed are dropped, and the whole is checked (closed, manifold, no degenerate facet); a
//! result that fails is meshed again on another shift.

use crate::check::{check, CheckOptions};
use crate::error::{Error, Result};
use crate::geom::Mesh;
use crate::grid::Grid;

/// Sub-voxel shifts of the grid, tried in turn (fractions of a voxel, far from simple ratios).
const SHIFTS: [[f64; 3]; 3] = [
    [0.381_966, 0.236_068, 0.145_898],
    [0.618_034, 0.472_136, 0.291_796],
    [0.090_170, 0.708_204, 0.527_864],
];

/// Rebuilds `mesh` at `voxel` mm (adaptivity 0: uniform triangles). Returns the new mesh and the
/// number of active voxels used. The mesh is closed, manifold and free of degenerate facets as
/// written in single precision, or (should no shift give one) the last one tried, its defects
/// left for the caller's check to report.
pub fn remesh(mesh: &Mesh, voxel: f64) -> Result<(Mesh, u64)> {
    rebuilt(mesh, voxel, |m| Grid::from_mesh(m, voxel, 3.0))
}

/// [`remesh`] of a soup (open, overlapping or non-manifold pieces): the solid where its
/// generalised winding number exceeds ½ ([`super::soup`]).
pub fn solidify(mesh: &Mesh, voxel: f64) -> Result<(Mesh, u64)> {
    rebuilt(mesh, voxel, |m| {
        let b = m
            .bounds()
            .ok_or_else(|| Error::invalid("no solid: the mesh has no facets"))?;
        super::soup::SoupField::new(m, crate::grid::GridSpec::covering(&b, voxel, 3.0)).grid()
    })
}

/// `mesh` rebuilt at `voxel` mm through the level set `grid_of` makes of it (moved by a
/// sub-voxel shift), on each shift in turn until the result is valid.
fn rebuilt(
    mesh: &Mesh,
    voxel: f64,
    grid_of: impl Fn(&Mesh) -> Result<Grid>,
) -> Result<(Mesh, u64)> {
    if !(voxel > 0.0 && voxel.is_finite()) {
        return Err(Error::invalid(
            "remesh voxel size must be a positive length in mm",
        ));
    }
    if let Some(b) = mesh.bounds() {
        let s = b.size();
        let cells = s.iter().map(|x| x / voxel).fold(0.0, f64::max);
        if cells > 100_000.0 {
            return Err(Error::invalid(format!(
                "remesh voxel {voxel} mm is too fine for a part {:.1} mm across ({cells:.0} voxels per axis)",
                s.iter().fold(0.0f64, |m, x| m.max(*x))
            )));
        }
    }
    let mut last = None;
    for shift in SHIFTS {
        let d = shift.map(|s| s * voxel);
        let grid = grid_of(&translated(mesh, d))?;
        let mut out = grid.to_mesh(0.0)?;
        out = translated(&out, d.map(|x| -x));
        let out = crate::io::weld::weld_indexed(&out.positions, &out.indices)?;
        let out = drop_collapsed(out);
        let found = check(
            &out,
            None,
            &CheckOptions {
                self_intersections: false,
                ..CheckOptions::default()
            },
        )?;
        let valid = found.defects().is_empty() || out.triangle_count() == 0;
        last = Some((out, grid.active_voxels()));
        if valid {
            break;
        }
    }
    Ok(last.expect("at least one shift"))
}

/// `mesh` moved by `d` mm.
fn translated(mesh: &Mesh, d: [f64; 3]) -> Mesh {
    let mut m = mesh.clone();
    for p in m.positions.chunks_exact_mut(3) {
        for k in 0..3 {
            p[k] = (p[k] as f64 + d[k]) as f32;
        }
    }
    m
}

/// Drops facets left with a repeated vertex by welding, and the vertices no facet uses.
fn drop_collapsed(mut mesh: Mesh) -> Mesh {
    let mut kept = Vec::with_capacity(mesh.indices.len());
    for t in mesh.indices.chunks_exact(3) {
        if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
            kept.extend_from_slice(t);
        }
    }
    mesh.indices = kept;
    super::compact(&mut mesh);
    mesh
}

/// Most active voxels an automatic voxel size may need (the narrow band is about six voxels
/// thick): about 0.75 GB at the peak of a remesh (measured on a 300 mm printer bed: 4.0 million
/// active voxels, 0.74 GB), about a million facets out.
const AUTO_MAX_ACTIVE: f64 = 4.0e6;

/// The voxel size `--remesh auto` uses, mm: a quarter of the part's smallest feature, and at
/// most 1/64 of its largest extent; but no finer than keeps the narrow band (about six voxels
/// thick over the surface) within [`AUTO_MAX_ACTIVE`] voxels, nor than 1/1000 of the extent. The
/// smallest feature is the shortest reach of a ray cast from a facet of a closed shell, along
/// its normal or against it, to another facet of the same shell (CGAL's AABB tree): a plate's
/// thickness, a rod's or a hole's diameter, the gap of a slot. Shells are measured apart, so
/// overlapping shells (which the remesh joins) do not count as thin.
pub fn auto_voxel(mesh: &Mesh) -> f64 {
    voxel_of(mesh, &[], false, None)
}

/// [`auto_voxel`], its open shells measured too when `open` (a soup: a ray from one of their
/// facets that meets no other facet of the shell says nothing), and where a `tolerance` is
/// asked, no coarser than keeps the remesh within it (a voxel level set rounds a sharp edge by
/// about half a voxel: the voxel is the tolerance over [`EDGE_ROUNDING`]) — within the same
/// memory bound.
pub fn voxel_for(mesh: &Mesh, open: bool, tolerance: Option<f64>) -> f64 {
    voxel_of(mesh, &[], open, tolerance)
}

/// How far a voxel level set's mesh rounds a sharp edge of the solid, in voxels: measured on
/// boxes remeshed at 0.47 mm (0.25 mm from the exact surface).
pub const EDGE_ROUNDING: f64 = 0.6;

/// [`auto_voxel`], with the shells marked in `skip` (by [`crate::geom::topology::Shells`] index)
/// left out of the smallest feature: a shell crossing itself has reaches down to nothing where
/// it crosses, which say nothing of its features.
pub fn auto_voxel_skipping(mesh: &Mesh, skip: &[bool]) -> f64 {
    voxel_of(mesh, skip, false, None)
}

/// The automatic voxel, the shells marked in `skip` left out, open shells measured when `open`,
/// no coarser than keeps the remesh within `tolerance` where one is given.
fn voxel_of(mesh: &Mesh, skip: &[bool], open: bool, tolerance: Option<f64>) -> f64 {
    use crate::geom::topology::{Shells, Topology};
    let Some(b) = mesh.bounds() else {
        return 1.0;
    };
    let extent = b.size().iter().fold(0.0f64, |m, x| m.max(*x));
    if extent <= 0.0 {
        return 1.0;
    }
    let topo = Topology::new(mesh);
    let shells = Shells::new(mesh, &topo);
    let area = |f: u32| {
        let [a, b, c] = mesh.triangle(f as usize);
        0.5 * crate::geom::norm(crate::geom::cross(
            crate::geom::sub(b, a),
            crate::geom::sub(c, a),
        ))
    };
    let area_total: f64 = shells.members.iter().flatten().map(|&f| area(f)).sum();
    let mut smallest = f64::INFINITY;
    for (s, (members, edges)) in shells.members.iter().zip(&shells.edges).enumerate() {
        if !(open || edges.closed()) || skip.get(s).copied().unwrap_or(false) {
            continue;
        }
        let indices: Vec<u32> = members
            .iter()
            .flat_map(|&f| {
                mesh.indices[3 * f as usize..3 * f as usize + 3]
                    .iter()
                    .copied()
            })
            .collect();
        let reach = crate::check::reach::facet_reach(&mesh.positions, &indices);
        smallest = reach
            .into_iter()
            .filter(|&r| r > 1e-9 * extent)
            .fold(smallest, f64::min);
    }
    let wanted = (smallest / 4.0)
        .min(extent / 64.0)
        .min(tolerance.map_or(f64::INFINITY, |t| t / EDGE_ROUNDING));
    wanted
        .max((6.0 * area_total / AUTO_MAX_ACTIVE).sqrt())
        .max(extent / 1000.0)
}
