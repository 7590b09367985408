// The grid itself: OpenVDB's initialisation and thread pool, a FloatGrid level set built from
// 8^3 leaf blocks sampled in Rust, what it holds, and .vdb output.
//
// Leaves are constructed in parallel (TBB), attached serially, then signedFloodFill gives the
// culled interior its negative sign so volumeToMesh sees one closed surface — or, when the caller
// knows which culled blocks are inside (an inside test of its own), they become inside tiles.
#include <openvdb/tools/SignedFloodFill.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include "vdb_internal.h"

namespace latvox {

VdbGrid::VdbGrid() : impl(std::make_unique<Impl>()) {}
VdbGrid::~VdbGrid() = default;

namespace {
std::once_flag init_flag;
std::unique_ptr<tbb::global_control> thread_control;
}  // namespace

void vdb_init() {
  std::call_once(init_flag, [] { openvdb::initialize(); });
}

std::unique_ptr<VdbGrid> vdb_handle(openvdb::FloatGrid::Ptr grid) {
  grid->setName("latvox");
  auto out = std::make_unique<VdbGrid>();
  out->impl->grid = std::move(grid);
  return out;
}

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
                                              rust::Slice<const float> values,
                                              rust::Slice<const int32_t> inside_tiles) {
  using LeafT = openvdb::FloatTree::LeafNodeType;
  vdb_init();
  if (!(voxel_size > 0.0) || !std::isfinite(voxel_size))
    throw std::invalid_argument("voxel size must be positive and finite");
  if (origin.size() != 3) throw std::invalid_argument("origin needs three coordinates");
  const std::size_t n = leaf_origins.size() / 3;
  if (leaf_origins.size() != 3 * n || values.size() != n * LeafT::SIZE)
    throw std::invalid_argument("leaf data does not hold 512 values per leaf origin");

  const float background = half_width * static_cast<float>(voxel_size);
  auto grid = openvdb::FloatGrid::create(background);
  grid->setGridClass(openvdb::GRID_LEVEL_SET);
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
  // The caller knows the inside: the blocks it names are inside, every other unsampled block
  // outside (the background). (OpenVDB's signed flood fill from the band gives a whole internal
  // node with no band in it the sign of its neighbour in key order, which can be wrong.)
  for (std::size_t i = 0; i + 2 < inside_tiles.size(); i += 3) {
    const openvdb::Coord c(inside_tiles[i], inside_tiles[i + 1], inside_tiles[i + 2]);
    tree.addTile(1, c, -background, false);
  }
  tree.prune();
  return vdb_handle(grid);
}

rust::Vec<int32_t> vdb_leaf_origins(const VdbGrid& g) {
  rust::Vec<int32_t> out;
  for (auto leaf = g.impl->grid->tree().cbeginLeaf(); leaf; ++leaf) {
    const auto o = leaf->origin();
    out.push_back(o.x());
    out.push_back(o.y());
    out.push_back(o.z());
  }
  return out;
}

uint64_t vdb_active_voxels(const VdbGrid& g) { return g.impl->grid->activeVoxelCount(); }
uint64_t vdb_memory_bytes(const VdbGrid& g) { return g.impl->grid->memUsage(); }

void vdb_write(const VdbGrid& g, rust::Str path) {
  vdb_init();
  openvdb::io::File file{std::string(path)};
  openvdb::GridPtrVec grids{g.impl->grid};
  file.write(grids);
  file.close();
}

}  // namespace latvox
