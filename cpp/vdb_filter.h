// OpenVDB level-set smoothing: a dense scalar field (negative inside) is rebuilt as a narrow-band
// level set, smoothed with LevelSetFilter, and meshed. Only plain slices cross the boundary.
#pragma once
#include <cstdint>
#include <memory>
#include "rust/cxx.h"

namespace latvox {

// Opaque: the smoothed OpenVDB level set lives in Impl, defined only in vdb_filter.cc.
struct SmoothedLevelSet {
  struct Impl;
  std::unique_ptr<Impl> impl;
  SmoothedLevelSet();
  ~SmoothedLevelSet();
};

// values: dims[0] x dims[1] x dims[2] samples, x fastest; sample (i,j,k) sits at
// origin + (i + 1/2, j + 1/2, k + 1/2) * voxel_size. The surface is values == 0; outside the
// array counts as `outside` (a positive value). mode: 1 gaussian, 2 mean curvature,
// 3 laplacian, 4 mean; `iterations` passes.
std::unique_ptr<SmoothedLevelSet> vdb_smooth(rust::Slice<const float> values,
                                             rust::Slice<const uint32_t> dims, double voxel_size,
                                             rust::Slice<const double> origin, float outside,
                                             uint32_t mode, uint32_t iterations);

// Meshes the iso-surface `isovalue` (world units: an offset of the surface) of a smoothed set.
void vdb_smoothed_mesh(const SmoothedLevelSet& set, double isovalue,
                       rust::Vec<float>& positions, rust::Vec<uint32_t>& indices);

}  // namespace latvox
