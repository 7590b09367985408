//! A grid read at arbitrary points (OpenVDB's trilinear BoxSampler), so that a distance field
//! built from a mesh can take part in a [`crate::field::Field`].

use super::Grid;
use crate::ffi::vdb::ffi;

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
