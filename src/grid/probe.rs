//! A grid read at arbitrary points (OpenVDB's trilinear BoxSampler), so that a distance field
//! built from a mesh can take part in a [`crate::field::Field`].

use super::Grid;
use crate::ffi::vdb::ffi;

/// The trilinear interpolation of a distance field's samples changes by at most √3 per mm (each
/// axis' slope is at most 1): a value's magnitude over this bounds the distance to its zero set.
const TRILINEAR_LIPSCHITZ: f64 = 1.75;

/// A lower bound on the distance from a point to the zero set of a distance grid interpolated
/// trilinearly, from the interpolated value `d` there, on voxels of `voxel` mm: `|d|/√3` (the
/// interpolant's slope), or `|d| − √3·voxel` (the interpolant is within half a voxel diagonal
/// of the true distance, which is 1-Lipschitz, at the point and on the zero set) — the samples
/// being the distance where the grid is exact, a bound of the same sign beyond its bands.
pub fn distance_clearance(d: f64, voxel: f64) -> f64 {
    (d.abs() / TRILINEAR_LIPSCHITZ).max(d.abs() - TRILINEAR_LIPSCHITZ * voxel)
}

/// Voxels of exact distance kept beyond what the field reads (the band, the skin, the blend):
/// enough that, beyond them, [`distance_clearance`] clears a whole leaf block and its band (a
/// block's half diagonal, 3.5·√3 voxels, and the band's 3), so that the blocks wholly inside
/// or outside the part are skipped, not sampled.
pub const SPARE_VOXELS: f64 = 10.0;

impl Grid {
    /// The grid's values at `points` (xyz triples, mm), interpolated trilinearly between voxel
    /// centres, into `values` (one per point).
    pub fn probe(&self, points: &[f64], values: &mut [f32]) {
        assert_eq!(points.len(), 3 * values.len(), "one value per point");
        ffi::vdb_probe(&self.inner, points, values);
    }

    /// The grid's value at `p`, mm.
    pub fn value_at(&self, p: [f64; 3]) -> f64 {
        let mut v = [0.0f32];
        self.probe(&p, &mut v);
        v[0] as f64
    }
}

#[cfg(test)]
mod tests {
    use crate::field::{Aabb, Field};
    use crate::grid::{Grid, GridSpec};

    /// A box's mesh as a distance grid, read between voxels: within a tenth of a voxel of the
    /// box's exact distance inside the bands (at points off its faces: OpenVDB's mesh of the box
    /// rounds its edges), and the bands' bounds beyond them.
    #[test]
    fn a_mesh_distance_reads_back_as_the_exact_distance() {
        let b = Aabb {
            min: [0.0; 3],
            max: [4.0, 6.0, 8.0],
        };
        let spec = GridSpec::covering(&b.grown(1.0), 0.25, 3.0);
        let mesh = Grid::sample(&b, spec).unwrap().to_mesh(0.0).unwrap();
        let v = 0.2;
        let g = Grid::distance_to_mesh(&mesh, v, 3.0, 8.0).unwrap();
        for p in [
            [2.0, 3.0, 4.0],
            [1.03, 2.71, 0.4],
            [3.9, 5.55, 7.1],
            [-0.3, 3.3, 4.4],
            [4.27, 3.0, 5.0],
        ] {
            let exact = b.value(p);
            if exact.abs() < 2.5 * v || (exact < 0.0 && -exact < 7.5 * v) {
                assert!(
                    (g.value_at(p) - exact).abs() < 0.1 * v,
                    "{p:?}: {} against {exact}",
                    g.value_at(p)
                );
            }
        }
        // Deep inside: the interior band's bound; far outside: the exterior's.
        assert!((g.value_at([2.0, 3.0, 4.0]) + 8.0 * v).abs() < 1e-4);
        assert!((g.value_at([20.0, 3.0, 4.0]) - 3.0 * v).abs() < 1e-4);
    }
}
