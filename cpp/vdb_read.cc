// A float grid read from a .vdb file as dense values over its active voxels' bounding box (the
// grid named `density` if the file has one, else its first float grid), for fields sampled by
// other tools (a density or fog volume). Only axis-aligned grids of cubic voxels are taken: the
// values are read trilinearly on the Rust side between voxel centres.
#include <openvdb/tools/Dense.h>

#include <stdexcept>
#include <string>

#include "latvox/src/ffi/vdb.rs.h"
#include "vdb_internal.h"

namespace latvox {

void vdb_read_dense(rust::Str path, uint64_t max_values, DenseValues& out) {
  vdb_init();
  openvdb::io::File file{std::string(path)};
  file.open();
  openvdb::GridBase::Ptr base;
  std::string names;
  for (auto it = file.beginName(); it != file.endName(); ++it) {
    names += (names.empty() ? "" : ", ") + it.gridName();
    auto g = file.readGrid(it.gridName());
    if (!g->isType<openvdb::FloatGrid>()) continue;
    if (!base || it.gridName() == "density") base = g;
  }
  file.close();
  if (!base)
    throw std::invalid_argument("it holds no float grid (grids: " +
                                (names.empty() ? std::string("none") : names) + ")");
  auto grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
  const auto& xform = grid->transform();
  const auto map = xform.baseMap();
  if (!(map->isType<openvdb::math::UniformScaleMap>() ||
        map->isType<openvdb::math::UniformScaleTranslateMap>()))
    throw std::invalid_argument("grid '" + grid->getName() +
                                "' is not axis-aligned with cubic voxels (its map is " +
                                map->type() + ")");
  const openvdb::CoordBBox box = grid->evalActiveVoxelBoundingBox();
  if (box.empty()) throw std::invalid_argument("grid '" + grid->getName() + "' has no active voxel");
  const openvdb::Coord dim = box.dim();
  const uint64_t n = uint64_t(dim.x()) * uint64_t(dim.y()) * uint64_t(dim.z());
  if (n > max_values)
    throw std::invalid_argument("grid '" + grid->getName() + "' spans " + std::to_string(n) +
                                " voxels, more than the " + std::to_string(max_values) +
                                " read densely");
  // LayoutZYX: z varies fastest, as latvox's node grids store values.
  openvdb::tools::Dense<float, openvdb::tools::LayoutZYX> dense(box);
  openvdb::tools::copyToDense(*grid, dense);
  out.name = grid->getName();
  const openvdb::Vec3d o = xform.indexToWorld(box.min());
  out.origin.clear();
  for (int a = 0; a < 3; ++a) out.origin.push_back(o[a]);
  out.step = xform.voxelSize()[0];
  out.dims.clear();
  for (int a = 0; a < 3; ++a) out.dims.push_back(uint64_t(dim[a]));
  out.values.clear();
  out.values.reserve(n);
  const float* v = dense.data();
  for (uint64_t i = 0; i < n; ++i) out.values.push_back(v[i]);
}

}  // namespace latvox
