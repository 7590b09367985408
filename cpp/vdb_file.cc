// Grids of plain values (a distance, a material fraction) built from 8^3 leaf blocks sampled in
// Rust, and .vdb files holding several named grids.
//
// A values grid is not a level set: its voxels are active where Rust gave a number and inactive
// (the background) where it gave NaN, and nothing is flood filled. A leaf whose 512 voxels are
// all active with one value becomes a tile, as OpenVDB stores constant regions.
#include <cmath>
#include <stdexcept>
#include <string>

#include "vdb_internal.h"

namespace latvox {

struct VdbFile::Impl {
  openvdb::GridPtrVec grids;
};
VdbFile::VdbFile() : impl(std::make_unique<Impl>()) {}
VdbFile::~VdbFile() = default;

std::unique_ptr<VdbGrid> vdb_values_from_leaves(double voxel_size, rust::Slice<const double> origin,
                                                float background, bool fog,
                                                rust::Slice<const int32_t> leaf_origins,
                                                rust::Slice<const float> values) {
  using LeafT = openvdb::FloatTree::LeafNodeType;
  vdb_init();
  if (!(voxel_size > 0.0) || !std::isfinite(voxel_size))
    throw std::invalid_argument("voxel size must be positive and finite");
  if (origin.size() != 3) throw std::invalid_argument("origin needs three coordinates");
  const std::size_t n = leaf_origins.size() / 3;
  if (leaf_origins.size() != 3 * n || values.size() != n * LeafT::SIZE)
    throw std::invalid_argument("leaf data does not hold 512 values per leaf origin");
  auto grid = openvdb::FloatGrid::create(background);
  grid->setGridClass(fog ? openvdb::GRID_FOG_VOLUME : openvdb::GRID_UNKNOWN);
  auto xform = openvdb::math::Transform::createLinearTransform(voxel_size);
  xform->postTranslate(openvdb::Vec3d(origin[0] + 0.5 * voxel_size, origin[1] + 0.5 * voxel_size,
                                      origin[2] + 0.5 * voxel_size));
  grid->setTransform(xform);
  auto& tree = grid->tree();
  for (std::size_t i = 0; i < n; ++i) {
    const openvdb::Coord c(leaf_origins[3 * i], leaf_origins[3 * i + 1], leaf_origins[3 * i + 2]);
    const float* v = values.data() + i * LeafT::SIZE;
    bool constant = !std::isnan(v[0]);
    for (openvdb::Index k = 1; constant && k < LeafT::SIZE; ++k) constant = v[k] == v[0];
    if (constant) {
      tree.addTile(1, c, v[0], true);
      continue;
    }
    auto* leaf = new LeafT(c, background, false);
    for (openvdb::Index k = 0; k < LeafT::SIZE; ++k) {
      if (!std::isnan(v[k])) leaf->setValueOn(k, v[k]);
    }
    tree.addLeaf(leaf);
  }
  tree.prune();
  return vdb_handle(grid);
}

std::unique_ptr<VdbFile> vdb_file_new() { return std::make_unique<VdbFile>(); }

void vdb_file_add(VdbFile& file, const VdbGrid& grid, rust::Str name) {
  // A shallow copy: it shares the tree, so the file holds the grid however long Rust keeps it.
  auto copy = grid.impl->grid->copyGrid();
  copy->setName(std::string(name));
  file.impl->grids.push_back(copy);
}

void vdb_file_write(const VdbFile& file, rust::Str path) {
  vdb_init();
  openvdb::io::File out{std::string(path)};
  out.write(file.impl->grids);
  out.close();
}

}  // namespace latvox
