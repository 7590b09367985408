// Triangles to a level set: meshToLevelSet turns them into a narrow-band signed distance field
// whose sign comes from a flood fill of the exterior, so overlapping and self-intersecting parts
// simply merge and facet orientation does not matter. Meshing its zero iso-surface (vdb_mesh.cc)
// gives a closed, manifold rebuild of the part at that voxel size.
#include <openvdb/tools/MeshToVolume.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "vdb_internal.h"

namespace latvox {

std::unique_ptr<VdbGrid> vdb_grid_from_mesh(rust::Slice<const float> positions,
                                            rust::Slice<const uint32_t> indices,
                                            double voxel_size, float exterior_width,
                                            float interior_width) {
  vdb_init();
  if (!(voxel_size > 0.0) || !std::isfinite(voxel_size))
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
  auto xform = openvdb::math::Transform::createLinearTransform(voxel_size);
  if (!(exterior_width >= 1.0f) || !(interior_width >= 1.0f) || !std::isfinite(exterior_width) ||
      !std::isfinite(interior_width))
    throw std::invalid_argument("band widths must be at least one voxel");
  // Beyond the bands the grid holds +exterior outside and -interior inside (inactive tiles): a
  // lower bound on the distance either way.
  const std::vector<openvdb::Vec4I> quads;
  return vdb_handle(openvdb::tools::meshToSignedDistanceField<openvdb::FloatGrid>(
      *xform, points, tris, quads, exterior_width, interior_width));
}

}  // namespace latvox
