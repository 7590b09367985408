//! A triangle mesh to a level set (OpenVDB's meshToLevelSet).

use super::{Grid, GridSpec};
use crate::error::Result;
use crate::ffi::vdb::ffi;
use crate::ffi::Backend;
use crate::geom::Mesh;

impl Grid {
    /// The level set of a triangle mesh at `voxel` mm, by OpenVDB's meshToLevelSet: a signed
    /// distance `half_width` voxels each side of the surface, its sign found by flood-filling the
    /// outside, so overlapping shells merge and facet orientation does not matter. OpenVDB's index
    /// (0, 0, 0) sits at the coordinate origin.
    pub fn from_mesh(mesh: &Mesh, voxel: f64, half_width: f64) -> Result<Grid> {
        Self::distance_to_mesh(mesh, voxel, half_width, half_width)
    }

    /// The signed distance to a triangle mesh at `voxel` mm, as [`Grid::from_mesh`], exact
    /// `exterior` voxels outside the surface and `interior` voxels inside it; beyond, the grid
    /// holds `±exterior·voxel` and `−interior·voxel` (lower bounds on the distance).
    pub fn distance_to_mesh(mesh: &Mesh, voxel: f64, exterior: f64, interior: f64) -> Result<Grid> {
        let inner = ffi::vdb_grid_from_mesh(
            &mesh.positions,
            &mesh.indices,
            voxel,
            exterior as f32,
            interior as f32,
        )
        .backend("building a level set from the mesh (OpenVDB meshToSignedDistanceField)")?;
        // Sample `frame + i` of the spec is OpenVDB's voxel `i`, at `i·voxel` mm.
        let (lo, hi) = match mesh.bounds() {
            Some(b) => (
                b.min.map(|x| (x / voxel).floor() as i64),
                b.max.map(|x| (x / voxel).ceil() as i64),
            ),
            None => ([0; 3], [0; 3]),
        };
        let spec = GridSpec {
            origin: lo.map(|i| (i as f64 - 0.5) * voxel),
            voxel,
            dims: [0, 1, 2].map(|a| hi[a] - lo[a] + 1),
            half_width: exterior,
        };
        Ok(Grid {
            inner: inner.into(),
            spec,
            frame: lo.map(|i| -i),
            blocks_tested: 0,
            blocks_sampled: 0,
        })
    }
}

impl Grid {
    /// The level set of the solid a closed, outward mesh bounds, at `voxel` mm, its enclosed
    /// voids kept: OpenVDB's meshToLevelSet finds the sign by flood-filling the outside, so a
    /// void no path from outside reaches would be filled. The shells facing in (negative
    /// volume: the voids' walls) are made a level set of their own and taken away
    /// (csgDifference), and the shells facing out that lie inside a void (islands) are added
    /// back (csgUnion). A void inside an island inside a void is filled.
    pub fn of_solid(mesh: &Mesh, voxel: f64, half_width: f64) -> Result<Grid> {
        use crate::geom::topology::{Shells, Topology};
        let shells = Shells::new(mesh, &Topology::new(mesh));
        let corner = |i: u32| {
            let i = 3 * i as usize;
            [0, 1, 2].map(|a| mesh.positions[i + a] as f64)
        };
        let facets = |f: u32| &mesh.indices[3 * f as usize..3 * f as usize + 3];
        let volume = |s: &[u32]| -> f64 {
            s.iter()
                .map(|&f| {
                    let t = facets(f);
                    crate::geom::signed_volume(corner(t[0]), corner(t[1]), corner(t[2]))
                })
                .sum()
        };
        let (walls, solids): (Vec<&Vec<u32>>, Vec<&Vec<u32>>) =
            shells.members.iter().partition(|s| volume(s) < 0.0);
        if walls.is_empty() {
            return Self::from_mesh(mesh, voxel, half_width);
        }
        let part = |of: &[&Vec<u32>]| Mesh {
            positions: mesh.positions.clone(),
            indices: of
                .iter()
                .flat_map(|s| s.iter().flat_map(|&f| facets(f).iter().copied()))
                .collect(),
        };
        let voids = Self::from_mesh(&part(&walls), voxel, half_width)?;
        // A shell's point furthest along x lies outside every void the shell encloses.
        let (islands, outer): (Vec<&Vec<u32>>, Vec<&Vec<u32>>) = solids.iter().partition(|s| {
            let p = s
                .iter()
                .flat_map(|&f| facets(f).iter().map(|&i| corner(i)))
                .fold(
                    [f64::NEG_INFINITY; 3],
                    |m, p| if p[0] > m[0] { p } else { m },
                );
            voids.value_at(p) < 0.0
        });
        let mut grid = Self::from_mesh(&part(&outer), voxel, half_width)?;
        grid.inner = ffi::vdb_csg(&grid.inner, &voids.inner, true)
            .backend("taking the voids from the level set (OpenVDB csgDifference)")?
            .into();
        if !islands.is_empty() {
            let islands = Self::from_mesh(&part(&islands), voxel, half_width)?;
            grid.inner = ffi::vdb_csg(&grid.inner, &islands.inner, false)
                .backend("adding the islands to the level set (OpenVDB csgUnion)")?
                .into();
        }
        Ok(grid)
    }
}
