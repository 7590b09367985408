// Level-set smoothing through OpenVDB's own tools: levelSetRebuild (a proper narrow-band signed
// distance of the grid's zero set, as wide as the caller asks, so that an offset of the smoothed
// surface can be meshed later without smoothing again), then LevelSetFilter (Gaussian,
// mean-curvature, Laplacian or mean flow).
#include <openvdb/tools/LevelSetFilter.h>
#include <openvdb/tools/LevelSetRebuild.h>

#include <stdexcept>

#include "latvox/src/ffi/vdb.rs.h"
#include "vdb_internal.h"

namespace latvox {

std::unique_ptr<VdbGrid> vdb_smoothed(const VdbGrid& g, SmoothingMode mode,
                                      uint32_t iterations, float half_width) {
  vdb_init();
  if (!(half_width >= 1.0f)) throw std::invalid_argument("the band must be at least one voxel");
  auto ls = openvdb::tools::levelSetRebuild(*g.impl->grid, 0.0f, half_width, half_width);
  openvdb::tools::LevelSetFilter<openvdb::FloatGrid> filter(*ls);
  for (uint32_t it = 0; it < iterations; ++it) {
    switch (mode) {
      case SmoothingMode::Gaussian: filter.gaussian(1); break;
      case SmoothingMode::MeanCurvature: filter.meanCurvature(); break;
      case SmoothingMode::Laplacian: filter.laplacian(); break;
      case SmoothingMode::Mean: filter.mean(1); break;
      default: throw std::invalid_argument("unknown smoothing mode");
    }
  }
  return vdb_handle(ls);
}

}  // namespace latvox
