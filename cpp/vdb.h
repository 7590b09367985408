// OpenVDB side of the bridge: sparse narrow-band level sets built from Rust-sampled leaf blocks,
// meshed with volumeToMesh. Only plain slices and opaque handles cross the boundary.
#pragma once
#include <cstdint>
#include <memory>
#include "rust/cxx.h"

namespace latvox {

// Opaque handle: the OpenVDB grid lives in Impl, defined only in vdb.cc.
struct VdbGrid {
  struct Impl;
  std::unique_ptr<Impl> impl;
  VdbGrid();
  ~VdbGrid();
};

void vdb_set_threads(std::size_t threads);

std::unique_ptr<VdbGrid> vdb_grid_from_leaves(double voxel_size, rust::Slice<const double> origin,
                                              float half_width,
                                              rust::Slice<const int32_t> leaf_origins,
                                              rust::Slice<const float> values);

struct Extraction;

void vdb_volume_to_mesh(const VdbGrid& grid, double adaptivity, rust::Vec<float>& positions,
                        rust::Vec<uint32_t>& indices);

void vdb_extract(const VdbGrid& grid, Extraction& out);

uint64_t vdb_active_voxels(const VdbGrid& grid);
uint64_t vdb_leaf_count(const VdbGrid& grid);
uint64_t vdb_memory_bytes(const VdbGrid& grid);
void vdb_write(const VdbGrid& grid, rust::Str path);

}  // namespace latvox
