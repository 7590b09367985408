//! OpenVDB's level-set smoothing, a translation unit of its own (`cpp/vdb_filter.cc`). Raw
//! declarations only; `crate::interpret::volume` wraps them safely.

#[cxx::bridge(namespace = "latvox")]
pub(crate) mod ffi {
    unsafe extern "C++" {
        include!("latvox/cpp/vdb_filter.h");

        type SmoothedLevelSet;

        fn vdb_smooth(
            values: &[f32],
            dims: &[u32],
            voxel_size: f64,
            origin: &[f64],
            outside: f32,
            mode: u32,
            iterations: u32,
        ) -> Result<UniquePtr<SmoothedLevelSet>>;
        fn vdb_smoothed_mesh(
            set: &SmoothedLevelSet,
            isovalue: f64,
            positions: &mut Vec<f32>,
            indices: &mut Vec<u32>,
        ) -> Result<()>;
    }
}
