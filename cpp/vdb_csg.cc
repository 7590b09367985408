// Boolean operations on level sets (OpenVDB's Composite.h: csgUnion, csgDifference). Both
// operands are copied, so the grids Rust holds are left as they were; they must share a
// transform (grids built at the same voxel size from index (0, 0, 0) do).
#include <openvdb/tools/Composite.h>

#include <stdexcept>

#include "vdb_internal.h"

namespace latvox {

std::unique_ptr<VdbGrid> vdb_csg(const VdbGrid& a, const VdbGrid& b, bool difference) {
  vdb_init();
  const auto& ga = *a.impl->grid;
  const auto& gb = *b.impl->grid;
  if (ga.transform() != gb.transform())
    throw std::invalid_argument("level sets of different voxels cannot be combined");
  auto out = ga.deepCopy();
  auto other = gb.deepCopy();
  if (difference)
    openvdb::tools::csgDifference(*out, *other);
  else
    openvdb::tools::csgUnion(*out, *other);
  return vdb_handle(out);
}

}  // namespace latvox
