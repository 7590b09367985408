// Reading a grid at arbitrary points: trilinear interpolation between voxel centres (BoxSampler)
// through one accessor per call, so a block of points shares the accessor's cached path down the
// tree. A distance field built from a mesh (vdb_from_mesh.cc) is read this way wherever a field
// combines it with others.
#include <openvdb/tools/Interpolation.h>

#include "vdb_internal.h"

namespace latvox {

void vdb_probe(const VdbGrid& grid, rust::Slice<const double> points, rust::Slice<float> values) {
  const openvdb::FloatGrid& g = *grid.impl->grid;
  // Not registered with the tree (no lock, no hash-map entry made and erased per call): the
  // grid is not changed while it is probed, and probes come one point at a time when tracing.
  openvdb::tree::ValueAccessor<const openvdb::FloatTree, false> acc(g.tree());
  const auto& xform = g.transform();
  const std::size_t n = std::min(points.size() / 3, values.size());
  for (std::size_t i = 0; i < n; ++i) {
    const openvdb::Vec3d w(points[3 * i], points[3 * i + 1], points[3 * i + 2]);
    values[i] = openvdb::tools::BoxSampler::sample(acc, xform.worldToIndex(w));
  }
}

}  // namespace latvox
