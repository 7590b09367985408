//! The OpenVDB bridge (`cpp/vdb.h`, implemented by `cpp/vdb_*.cc`). Raw declarations and the
//! owned grid handle only; `crate::grid` wraps them safely.

#[cxx::bridge(namespace = "latvox")]
pub(crate) mod ffi {
    /// volumeToMesh's output in index space, with each point's voxel and edge group recovered.
    #[derive(Default)]
    struct Extraction {
        /// Lower-corner sample of each point's voxel, xyz triples, in the grid's index frame.
        voxels: Vec<i32>,
        /// Edge group of each point within its voxel (OpenVDB's group numbering, from 0).
        groups: Vec<u8>,
        /// Each point within its voxel, in [0, 1]³: OpenVDB's average of the group's edge
        /// crossings, recomputed from the voxel's corner values in double precision.
        offsets: Vec<f64>,
        /// Quads as OpenVDB winds them (inward), four point indices each.
        quads: Vec<u32>,
    }

    /// A float grid of a `.vdb` file copied densely over its active voxels' bounding box.
    #[derive(Default)]
    struct DenseValues {
        /// The grid's name.
        name: String,
        /// World position of the box's first voxel (its centre), mm.
        origin: Vec<f64>,
        /// Voxel size, mm (the same along each axis).
        step: f64,
        /// Voxels along x, y, z.
        dims: Vec<u64>,
        /// The values, z fastest, then y, then x.
        values: Vec<f32>,
    }

    /// One pass of OpenVDB's `LevelSetFilter`.
    #[repr(u8)]
    enum SmoothingMode {
        Gaussian,
        MeanCurvature,
        Laplacian,
        Mean,
    }

    extern "Rust" {
        /// Sizes `out` for `points` points and `quads` quads (zero-filled), so that the C++ side
        /// fills it in parallel.
        fn extraction_resize(out: &mut Extraction, points: usize, quads: usize);
    }

    unsafe extern "C++" {
        include!("latvox/cpp/vdb.h");

        type VdbGrid;
        type VdbFile;

        fn vdb_set_threads(threads: usize);
        fn vdb_grid_from_leaves(
            voxel_size: f64,
            origin: &[f64],
            half_width: f32,
            leaf_origins: &[i32],
            values: &[f32],
            inside_tiles: &[i32],
        ) -> Result<UniquePtr<VdbGrid>>;
        fn vdb_grid_from_mesh(
            positions: &[f32],
            indices: &[u32],
            voxel_size: f64,
            exterior_width: f32,
            interior_width: f32,
        ) -> Result<UniquePtr<VdbGrid>>;
        fn vdb_csg(a: &VdbGrid, b: &VdbGrid, difference: bool) -> Result<UniquePtr<VdbGrid>>;
        fn vdb_probe(grid: &VdbGrid, points: &[f64], values: &mut [f32]);
        fn vdb_smoothed(
            grid: &VdbGrid,
            mode: SmoothingMode,
            iterations: u32,
            half_width: f32,
        ) -> Result<UniquePtr<VdbGrid>>;
        fn vdb_volume_to_mesh(
            grid: &VdbGrid,
            isovalue: f64,
            adaptivity: f64,
            positions: &mut Vec<f32>,
            indices: &mut Vec<u32>,
        ) -> Result<()>;
        fn vdb_extract(grid: &VdbGrid, out: &mut Extraction) -> Result<()>;
        fn vdb_active_voxels(grid: &VdbGrid) -> u64;
        fn vdb_leaf_origins(grid: &VdbGrid) -> Vec<i32>;
        fn vdb_memory_bytes(grid: &VdbGrid) -> u64;
        fn vdb_write(grid: &VdbGrid, path: &str) -> Result<()>;
        fn vdb_values_from_leaves(
            voxel_size: f64,
            origin: &[f64],
            background: f32,
            fog: bool,
            leaf_origins: &[i32],
            values: &[f32],
        ) -> Result<UniquePtr<VdbGrid>>;
        fn vdb_file_new() -> UniquePtr<VdbFile>;
        fn vdb_read_dense(path: &str, max_values: u64, out: &mut DenseValues) -> Result<()>;
        fn vdb_file_add(file: Pin<&mut VdbFile>, grid: &VdbGrid, name: &str);
        fn vdb_file_write(file: &VdbFile, path: &str) -> Result<()>;
    }
}

fn extraction_resize(out: &mut ffi::Extraction, points: usize, quads: usize) {
    out.voxels.resize(3 * points, 0);
    out.groups.resize(points, 0);
    out.offsets.resize(3 * points, 0.0);
    out.quads.resize(4 * quads, 0);
}

// SAFETY: an OpenVDB grid is immutable once built here; const methods are thread-safe.
unsafe impl Send for ffi::VdbGrid {}
unsafe impl Sync for ffi::VdbGrid {}

/// An OpenVDB grid owned by Rust. Dereferences to the opaque grid the bridge functions take.
pub(crate) struct OwnedGrid(cxx::UniquePtr<ffi::VdbGrid>);

impl From<cxx::UniquePtr<ffi::VdbGrid>> for OwnedGrid {
    fn from(p: cxx::UniquePtr<ffi::VdbGrid>) -> Self {
        OwnedGrid(p)
    }
}

impl std::ops::Deref for OwnedGrid {
    type Target = ffi::VdbGrid;
    fn deref(&self) -> &ffi::VdbGrid {
        // Never null: the C++ side returns a new grid or throws.
        &self.0
    }
}
