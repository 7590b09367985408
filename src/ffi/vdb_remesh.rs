//! The OpenVDB remeshing bridge (cpp/vdb_remesh.cc). Raw declarations only;
//! `crate::repair::remesh` wraps it safely.

#[cxx::bridge(namespace = "latvox")]
pub(crate) mod ffi {
    struct RemeshStats {
        active_voxels: u64,
    }

    unsafe extern "C++" {
        include!("latvox/cpp/vdb_remesh.h");

        fn vdb_remesh(
            positions: &[f32],
            indices: &[u32],
            voxel: f64,
            adaptivity: f64,
            out_positions: &mut Vec<f32>,
            out_indices: &mut Vec<u32>,
        ) -> Result<RemeshStats>;
    }
}
