// Rebuilds a mesh through a level set: meshToLevelSet turns the triangles into a narrow-band
// signed distance field (the sign comes from a flood fill of the exterior, so overlapping and
// self-intersecting parts simply merge and facet orientation does not matter), and volumeToMesh
// extracts its zero iso-surface — closed and manifold at that voxel size.
#include "vdb_remesh.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>
#include <openvdb/tools/VolumeToMesh.h>

#include <cmath>
#include <mutex>
#include <stdexcept>
#include <vector>

#include "latvox/src/ffi/vdb_remesh.rs.h"

namespace latvox {

namespace {
std::once_flag remesh_init;
}

RemeshStats vdb_remesh(rust::Slice<const float> positions, rust::Slice<const uint32_t> indices,
                       double voxel, double adaptivity, rust::Vec<float>& out_positions,
                       rust::Vec<uint32_t>& out_indices) {
  std::call_once(remesh_init, [] { openvdb::initialize(); });
  if (!(voxel > 0.0) || !std::isfinite(voxel))
    throw std::invalid_argument("voxel size must be positive and finite");
  if (positions.size() % 3 != 0 || indices.size() % 3 != 0)
    throw std::invalid_argument("positions and indices must come in triples");
  const std::size_t nv = positions.size() / 3;
  std::vector<openvdb::Vec3s> points(nv);
  for (std::size_t i = 0; i < nv; ++i)
    points[i] = openvdb::Vec3s(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]);
  std::vector<openvdb::Vec3I> tris(indices.size() / 3);
  for (std::size_t f = 0; f < tris.size(); ++f) {
    for (int k = 0; k < 3; ++k)
      if (indices[3 * f + k] >= nv) throw std::out_of_range("triangle index past the vertex list");
    tris[f] = openvdb::Vec3I(indices[3 * f], indices[3 * f + 1], indices[3 * f + 2]);
  }
  auto xform = openvdb::math::Transform::createLinearTransform(voxel);
  auto grid = openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(*xform, points, tris, 3.0f);
  RemeshStats stats{};
  stats.active_voxels = grid->activeVoxelCount();

  std::vector<openvdb::Vec3s> pts;
  std::vector<openvdb::Vec3I> out_tris;
  std::vector<openvdb::Vec4I> quads;
  openvdb::tools::volumeToMesh(*grid, pts, out_tris, quads, 0.0, adaptivity, true);
  if (pts.size() >= static_cast<std::size_t>(UINT32_MAX))
    throw std::length_error("remeshed part has more vertices than 32-bit indices can address");
  out_positions.reserve(3 * pts.size());
  for (const auto& p : pts) {
    out_positions.push_back(p.x());
    out_positions.push_back(p.y());
    out_positions.push_back(p.z());
  }
  out_indices.reserve(3 * (out_tris.size() + 2 * quads.size()));
  // volumeToMesh winds clockwise seen from outside: reverse every polygon.
  for (const auto& t : out_tris) {
    out_indices.push_back(t[2]);
    out_indices.push_back(t[1]);
    out_indices.push_back(t[0]);
  }
  for (const auto& q : quads) {
    // Cut each quad along its shorter diagonal.
    const bool d02 = (pts[q[0]] - pts[q[2]]).lengthSqr() <= (pts[q[1]] - pts[q[3]]).lengthSqr();
    const uint32_t a[6] = {q[2], q[1], q[0], q[3], q[2], q[0]};
    const uint32_t b[6] = {q[3], q[1], q[0], q[3], q[2], q[1]};
    const uint32_t* cut = d02 ? a : b;
    for (int i = 0; i < 6; ++i) out_indices.push_back(cut[i]);
  }
  return stats;
}

}  // namespace latvox
