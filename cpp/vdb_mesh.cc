// Meshing a level set with OpenVDB's volumeToMesh, two ways:
//  - vdb_volume_to_mesh: any iso-surface at any adaptivity, as outward-wound triangles (every
//    path that wants a plain mesh: sampled parts, smoothed fields, remeshed parts);
//  - vdb_extract: the zero iso-surface in index space at adaptivity 0, with each point's voxel
//    and edge group recovered, for meshing a part in pieces that weld exactly.
#include <openvdb/tools/VolumeToMesh.h>
#include <tbb/parallel_for.h>

#include <array>
#include <atomic>
#include <cmath>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include "latvox/src/ffi/vdb.rs.h"
#include "vdb_internal.h"

namespace latvox {

void vdb_volume_to_mesh(const VdbGrid& g, double isovalue, double adaptivity,
                        rust::Vec<float>& positions, rust::Vec<uint32_t>& indices) {
  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> tris;
  std::vector<openvdb::Vec4I> quads;
  openvdb::tools::volumeToMesh(*g.impl->grid, points, tris, quads, isovalue, adaptivity, true);
  if (points.size() >= static_cast<std::size_t>(UINT32_MAX))
    throw std::length_error("mesh has more vertices than 32-bit indices can address");

  positions.reserve(points.size() * 3);
  for (const auto& p : points) {
    positions.push_back(p.x());
    positions.push_back(p.y());
    positions.push_back(p.z());
  }
  std::vector<openvdb::Vec3s>().swap(points);
  indices.reserve((tris.size() + 2 * quads.size()) * 3);
  // OpenVDB winds its polygons clockwise seen from outside; emit them reversed (outward, CCW).
  for (const auto& t : tris) {
    indices.push_back(t[2]);
    indices.push_back(t[1]);
    indices.push_back(t[0]);
  }
  auto at = [&](uint32_t i) {
    return openvdb::Vec3f(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]);
  };
  for (const auto& q : quads) {
    // Split along the shorter diagonal: better triangles, fewer near-degenerate slivers.
    const float d02 = (at(q[0]) - at(q[2])).lengthSqr();
    const float d13 = (at(q[1]) - at(q[3])).lengthSqr();
    if (d02 <= d13) {
      indices.push_back(q[2]); indices.push_back(q[1]); indices.push_back(q[0]);
      indices.push_back(q[3]); indices.push_back(q[2]); indices.push_back(q[0]);
    } else {
      indices.push_back(q[3]); indices.push_back(q[1]); indices.push_back(q[0]);
      indices.push_back(q[3]); indices.push_back(q[2]); indices.push_back(q[1]);
    }
  }
}

void vdb_extract(const VdbGrid& g, Extraction& out) {
  namespace vi = openvdb::tools::volume_to_mesh_internal;
  // Mesh in index space: points then carry their voxel in their integer part. Sample values are
  // kept at least 1/64 voxel from zero (grid.rs), so every edge crossing, and hence every point,
  // lies at least 1/2304 voxel inside its voxel: far more than float rounding at these
  // coordinates (|x| < 2^12), so floor() recovers the voxel exactly.
  auto grid = g.impl->grid->copy();
  grid->setTransform(openvdb::math::Transform::createLinearTransform(1.0));
  openvdb::tools::VolumeToMesh mesher(0.0, 0.0, false);
  mesher(*grid);
  const std::size_t np = mesher.pointListSize();
  const auto& pts = mesher.pointList();
  const auto& pools = mesher.polygonPoolList();
  const std::size_t npools = mesher.polygonPoolListSize();
  std::vector<std::size_t> first_quad(npools + 1, 0);
  for (std::size_t n = 0; n < npools; ++n) {
    if (pools[n].numTriangles() != 0)
      throw std::logic_error("volumeToMesh made triangles at adaptivity 0");
    first_quad[n + 1] = first_quad[n] + pools[n].numQuads();
  }
  for (std::size_t i = 0; i < np; ++i) {
    const auto& p = pts[i];
    if (!(std::fabs(p.x()) < 4096.f && std::fabs(p.y()) < 4096.f && std::fabs(p.z()) < 4096.f))
      throw std::range_error("index-space point too far from the grid origin to decode");
  }
  extraction_resize(out, np, first_quad[npools]);
  int32_t* voxels = out.voxels.data();
  uint8_t* groups = out.groups.data();
  double* offsets = out.offsets.data();
  uint32_t* quads = out.quads.data();
  auto voxel_of = [&](std::size_t i) {
    return openvdb::Coord(static_cast<int32_t>(std::floor(pts[i][0])),
                          static_cast<int32_t>(std::floor(pts[i][1])),
                          static_cast<int32_t>(std::floor(pts[i][2])));
  };

  std::atomic<bool> mismatch{false};
  std::mutex msg_mutex;
  std::string msg;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, np),
                    [&](const tbb::blocked_range<std::size_t>& r) {
    auto acc = grid->getConstAccessor();
    std::array<double, 8> values;
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const openvdb::Coord ijk = voxel_of(i);
      for (int a = 0; a < 3; ++a) voxels[3 * i + a] = ijk[a];
      // Points of one voxel come out consecutively, one per edge group in group order.
      unsigned g = 0;
      while (g < i && voxel_of(i - g - 1) == ijk) ++g;
      groups[i] = static_cast<uint8_t>(g);
      vi::getCellVertexValues(acc, ijk, values);
      uint8_t signs = vi::computeSignFlags(values, 0.0);
      // As volumeToMesh does: an ambiguous face takes its neighbour's reading.
      if (const uint8_t face = vi::sAmbiguousFace[signs])
        vi::correctCellSigns(signs, face, acc, ijk, 0.0f);
      const unsigned group = g + 1u;
      if (group > vi::sEdgeGroupTable[signs][0]) {
        std::lock_guard<std::mutex> lock(msg_mutex);
        if (msg.empty())
          msg = "point " + std::to_string(i) + " at (" + std::to_string(pts[i][0]) + ", " +
                std::to_string(pts[i][1]) + ", " + std::to_string(pts[i][2]) + ") is group " +
                std::to_string(group) + " of a voxel with " +
                std::to_string(int(vi::sEdgeGroupTable[signs][0]));
        mismatch = true;
        continue;
      }
      const openvdb::Vec3d o = vi::computePoint(values, signs, static_cast<uint8_t>(group), 0.0);
      // The recomputed point must be the one OpenVDB placed (up to float rounding).
      for (int a = 0; a < 3; ++a) {
        if (std::fabs(o[a] + ijk[a] - pts[i][a]) > 1e-3) {
          std::lock_guard<std::mutex> lock(msg_mutex);
          if (msg.empty())
            msg = "point " + std::to_string(i) + " axis " + std::to_string(a) + " at " +
                  std::to_string(pts[i][a]) + " recomputed as " + std::to_string(o[a] + ijk[a]);
          mismatch = true;
        }
        offsets[3 * i + a] = o[a];
      }
    }
  });
  if (mismatch)
    throw std::logic_error("a volumeToMesh point could not be matched to its voxel: " + msg);

  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, npools),
                    [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t n = r.begin(); n != r.end(); ++n)
      for (std::size_t q = 0; q < pools[n].numQuads(); ++q)
        for (int k = 0; k < 4; ++k) quads[4 * (first_quad[n] + q) + k] = pools[n].quad(q)[k];
  });
}

}  // namespace latvox
