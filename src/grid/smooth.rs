//! Level-set smoothing (OpenVDB's LevelSetFilter).

use super::{Grid, GridSpec};
use crate::error::Result;
use crate::ffi::vdb::ffi;
use crate::ffi::Backend;

/// OpenVDB's level-set smoothing flows (`LevelSetFilter`), for [`Grid::smoothed`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Smoothing {
    /// Gaussian filter of the level set (OpenVDB's `gaussian`).
    Gaussian,
    /// Mean-curvature flow (`meanCurvature`).
    MeanCurvature,
    /// Laplacian flow (`laplacian`).
    Laplacian,
    /// Mean (box) filter (`mean`).
    Mean,
}

impl Grid {
    /// This level set smoothed by `iterations` passes of OpenVDB's `LevelSetFilter`, after
    /// OpenVDB rebuilds it as a signed distance `half_width` voxels each side of its zero set
    /// (the filter needs a distance field, and the band bounds the offsets that can be meshed
    /// afterwards with [`Grid::to_mesh_at`]).
    pub fn smoothed(&self, mode: Smoothing, iterations: u32, half_width: f64) -> Result<Grid> {
        let mode = match mode {
            Smoothing::Gaussian => ffi::SmoothingMode::Gaussian,
            Smoothing::MeanCurvature => ffi::SmoothingMode::MeanCurvature,
            Smoothing::Laplacian => ffi::SmoothingMode::Laplacian,
            Smoothing::Mean => ffi::SmoothingMode::Mean,
        };
        let inner = ffi::vdb_smoothed(&self.inner, mode, iterations, half_width as f32)
            .backend("smoothing the level set (OpenVDB LevelSetFilter)")?;
        Ok(Grid {
            inner: inner.into(),
            spec: GridSpec {
                half_width,
                ..self.spec
            },
            ..*self
        })
    }
}
