// Level-set smoothing through OpenVDB's own tools: copyFromDense (the sampled field), then
// levelSetRebuild (a proper narrow-band signed distance of its zero set), LevelSetFilter
// (Gaussian, mean-curvature, Laplacian or mean flow); then volumeToMesh at any iso-value, so
// the caller can offset the smoothed surface (to keep a volume) without smoothing again.
#include "vdb_filter.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>
#include <openvdb/tools/LevelSetFilter.h>
#include <openvdb/tools/LevelSetRebuild.h>
#include <openvdb/tools/VolumeToMesh.h>

#include <mutex>
#include <stdexcept>

#include "latvox/src/ffi/vdb_filter.rs.h"

namespace latvox {

struct SmoothedLevelSet::Impl {
  openvdb::FloatGrid::Ptr grid;
};
SmoothedLevelSet::SmoothedLevelSet() : impl(std::make_unique<Impl>()) {}
SmoothedLevelSet::~SmoothedLevelSet() = default;

namespace {
std::once_flag filter_init_flag;
}

std::unique_ptr<SmoothedLevelSet> vdb_smooth(rust::Slice<const float> values,
                                             rust::Slice<const uint32_t> dims, double voxel_size,
                                             rust::Slice<const double> origin, float outside,
                                             uint32_t mode, uint32_t iterations) {
  std::call_once(filter_init_flag, [] { openvdb::initialize(); });
  if (dims.size() != 3 || origin.size() != 3)
    throw std::invalid_argument("dims and origin need three entries");
  const std::size_t nx = dims[0], ny = dims[1], nz = dims[2];
  if (values.size() != nx * ny * nz) throw std::invalid_argument("values do not match dims");
  if (!(voxel_size > 0.0)) throw std::invalid_argument("voxel size must be positive");
  if (!(outside > 0.0f)) throw std::invalid_argument("the outside value must be positive");

  // One ring of `outside` around the samples, so the zero set closes at the array's faces.
  const openvdb::CoordBBox box(openvdb::Coord(-1, -1, -1),
                               openvdb::Coord(int(nx), int(ny), int(nz)));
  openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(box, outside);
  for (std::size_t k = 0; k < nz; ++k)
    for (std::size_t j = 0; j < ny; ++j)
      for (std::size_t i = 0; i < nx; ++i)
        dense.setValue(openvdb::Coord(int(i), int(j), int(k)),
                       values[(k * ny + j) * nx + i]);
  auto field = openvdb::FloatGrid::create(outside);
  auto xform = openvdb::math::Transform::createLinearTransform(voxel_size);
  xform->postTranslate(openvdb::Vec3d(origin[0] + 0.5 * voxel_size, origin[1] + 0.5 * voxel_size,
                                      origin[2] + 0.5 * voxel_size));
  field->setTransform(xform);
  openvdb::tools::copyFromDense(dense, *field, 0.0f);

  // A wide band, so the iso-surface can later be offset by a few voxels.
  auto ls = openvdb::tools::levelSetRebuild(*field, 0.0f, 6.0f, 6.0f);
  openvdb::tools::LevelSetFilter<openvdb::FloatGrid> filter(*ls);
  for (uint32_t it = 0; it < iterations; ++it) {
    switch (mode) {
      case 1: filter.gaussian(1); break;
      case 2: filter.meanCurvature(); break;
      case 3: filter.laplacian(); break;
      case 4: filter.mean(1); break;
      default: throw std::invalid_argument("unknown smoothing mode");
    }
  }

  auto out = std::make_unique<SmoothedLevelSet>();
  out->impl->grid = ls;
  return out;
}

void vdb_smoothed_mesh(const SmoothedLevelSet& set, double isovalue,
                       rust::Vec<float>& positions, rust::Vec<uint32_t>& indices) {
  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> tris;
  std::vector<openvdb::Vec4I> quads;
  openvdb::tools::volumeToMesh(*set.impl->grid, points, tris, quads, isovalue, 0.0, true);
  if (points.size() >= static_cast<std::size_t>(UINT32_MAX))
    throw std::length_error("mesh has more vertices than 32-bit indices can address");
  positions.reserve(points.size() * 3);
  for (const auto& p : points) {
    positions.push_back(p.x());
    positions.push_back(p.y());
    positions.push_back(p.z());
  }
  // OpenVDB winds clockwise seen from outside: reversed here. Quads split along the shorter
  // diagonal.
  indices.reserve((tris.size() + 2 * quads.size()) * 3);
  for (const auto& t : tris) {
    indices.push_back(t[2]);
    indices.push_back(t[1]);
    indices.push_back(t[0]);
  }
  for (const auto& q : quads) {
    const float d02 = (points[q[0]] - points[q[2]]).lengthSqr();
    const float d13 = (points[q[1]] - points[q[3]]).lengthSqr();
    const uint32_t a[6] = {q[2], q[1], q[0], q[3], q[2], q[0]};
    const uint32_t b[6] = {q[3], q[1], q[0], q[3], q[2], q[1]};
    const uint32_t* s = d02 <= d13 ? a : b;
    for (int k = 0; k < 6; ++k) indices.push_back(s[k]);
  }
}

}  // namespace latvox
