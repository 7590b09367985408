// Builds an OpenVDB FloatGrid level set from 8^3 leaf blocks sampled in Rust and meshes it.
//
// Leaves are constructed in parallel (TBB), attached serially, then signedFloodFill gives the
// culled interior its negative sign so volumeToMesh sees one closed surface.
#include "vdb.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/SignedFloodFill.h>
#include <openvdb/tools/VolumeToMesh.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <array>
#include <atomic>
#include <cmath>
#include <mutex>
#include <stdexcept>
#include <string>

#include "latvox/src/ffi/vdb.rs.h"

namespace latvox {

struct VdbGrid::Impl {
  openvdb::FloatGrid::Ptr grid;
};
VdbGrid::VdbGrid() : impl(std::make_unique<Impl>()) {}
VdbGrid::~VdbGrid() = default;

namespace {
std::once_flag init_flag;
void ensure_init() {
  std::call_once(init_flag, [] { openvdb::initialize(); });
}
std::unique_ptr<tbb::global_control> thread_control;
}  // namespace

void vdb_set_threads(std::size_t threads) {
  if (threads == 0) {
    thread_control.reset();
  } else {
    thread_control = std::make_unique<tbb::global_control>(
        tbb::global_control::max_allowed_parallelism, threads);
  }
}

std::unique_ptr<VdbGrid> vdb_grid_from_leaves(double voxel_size, rust::Slice<const double> origin,
                                              float half_width,
                                              rust::Slice<const int32_t> leaf_origins,
                                              rust::Slice<const float> values) {
  using LeafT = openvdb::FloatTree::LeafNodeType;
  ensure_init();
  if (!(voxel_size > 0.0) || !std::isfinite(voxel_size))
    throw std::invalid_argument("voxel size must be positive and finite");
  if (origin.size() != 3) throw std::invalid_argument("origin needs three coordinates");
  const std::size_t n = leaf_origins.size() / 3;
  if (leaf_origins.size() != 3 * n || values.size() != n * LeafT::SIZE)
    throw std::invalid_argument("leaf data does not hold 512 values per leaf origin");

  const float background = half_width * static_cast<float>(voxel_size);
  auto grid = openvdb::FloatGrid::create(background);
  grid->setGridClass(openvdb::GRID_LEVEL_SET);
  grid->setName("latvox");
  // Voxel (i,j,k) holds the sample taken at origin + (i + 1/2) h: box faces fall between samples.
  auto xform = openvdb::math::Transform::createLinearTransform(voxel_size);
  xform->postTranslate(openvdb::Vec3d(origin[0] + 0.5 * voxel_size, origin[1] + 0.5 * voxel_size,
                                      origin[2] + 0.5 * voxel_size));
  grid->setTransform(xform);

  std::vector<LeafT*> leaves(n, nullptr);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      openvdb::Coord c(leaf_origins[3 * i], leaf_origins[3 * i + 1], leaf_origins[3 * i + 2]);
      auto* leaf = new LeafT(c, background, false);
      const float* v = values.data() + i * LeafT::SIZE;
      for (openvdb::Index k = 0; k < LeafT::SIZE; ++k) {
        const float x = v[k];
        leaf->setValueOnly(k, x);
        if (std::fabs(x) < background) leaf->setValueOn(k);
      }
      leaves[i] = leaf;
    }
  });
  auto& tree = grid->tree();
  for (auto* leaf : leaves) tree.addLeaf(leaf);
  openvdb::tools::signedFloodFill(tree);
  auto out = std::make_unique<VdbGrid>();
  out->impl->grid = grid;
  return out;
}

void vdb_volume_to_mesh(const VdbGrid& g, double adaptivity, rust::Vec<float>& positions,
                        rust::Vec<uint32_t>& indices) {
  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> tris;
  std::vector<openvdb::Vec4I> quads;
  openvdb::tools::volumeToMesh(*g.impl->grid, points, tris, quads, 0.0, adaptivity, true);
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

  out.voxels.reserve(3 * np);
  out.groups.reserve(np);
  out.offsets.reserve(3 * np);
  for (std::size_t i = 0; i < np; ++i) {
    const auto& p = pts[i];
    if (!(std::fabs(p.x()) < 4096.f && std::fabs(p.y()) < 4096.f && std::fabs(p.z()) < 4096.f))
      throw std::range_error("index-space point too far from the grid origin to decode");
    for (int a = 0; a < 3; ++a) out.voxels.push_back(static_cast<int32_t>(std::floor(p[a])));
    // Points of one voxel come out consecutively, one per edge group in group order.
    const bool same = i > 0 && out.voxels[3 * i] == out.voxels[3 * i - 3] &&
                      out.voxels[3 * i + 1] == out.voxels[3 * i - 2] &&
                      out.voxels[3 * i + 2] == out.voxels[3 * i - 1];
    out.groups.push_back(same ? static_cast<uint8_t>(out.groups[i - 1] + 1) : 0);
    for (int a = 0; a < 3; ++a) out.offsets.push_back(0.0);
  }

  std::atomic<bool> mismatch{false};
  std::mutex msg_mutex;
  std::string msg;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, np),
                    [&](const tbb::blocked_range<std::size_t>& r) {
    auto acc = grid->getConstAccessor();
    std::array<double, 8> values;
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const openvdb::Coord ijk(out.voxels[3 * i], out.voxels[3 * i + 1], out.voxels[3 * i + 2]);
      vi::getCellVertexValues(acc, ijk, values);
      uint8_t signs = vi::computeSignFlags(values, 0.0);
      // As volumeToMesh does: an ambiguous face takes its neighbour's reading.
      if (const uint8_t face = vi::sAmbiguousFace[signs])
        vi::correctCellSigns(signs, face, acc, ijk, 0.0f);
      const unsigned group = out.groups[i] + 1u;
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
        out.offsets[3 * i + a] = o[a];
      }
    }
  });
  if (mismatch)
    throw std::logic_error("a volumeToMesh point could not be matched to its voxel: " + msg);

  std::size_t nq = 0;
  const auto& pools = mesher.polygonPoolList();
  for (std::size_t n = 0; n < mesher.polygonPoolListSize(); ++n) {
    if (pools[n].numTriangles() != 0)
      throw std::logic_error("volumeToMesh made triangles at adaptivity 0");
    nq += pools[n].numQuads();
  }
  out.quads.reserve(4 * nq);
  for (std::size_t n = 0; n < mesher.polygonPoolListSize(); ++n)
    for (std::size_t q = 0; q < pools[n].numQuads(); ++q)
      for (int k = 0; k < 4; ++k) out.quads.push_back(pools[n].quad(q)[k]);
}

uint64_t vdb_active_voxels(const VdbGrid& g) { return g.impl->grid->activeVoxelCount(); }
uint64_t vdb_leaf_count(const VdbGrid& g) { return g.impl->grid->tree().leafCount(); }
uint64_t vdb_memory_bytes(const VdbGrid& g) { return g.impl->grid->memUsage(); }

void vdb_write(const VdbGrid& g, rust::Str path) {
  openvdb::io::File file{std::string(path)};
  openvdb::GridPtrVec grids{g.impl->grid};
  file.write(grids);
  file.close();
}

}  // namespace latvox
