// What the translation units behind vdb.h share: the grid inside the opaque handle and
// OpenVDB's one-time initialisation. The generated bridge code does not include it, so only the
// units that use OpenVDB parse OpenVDB's headers.
#pragma once
#include <openvdb/openvdb.h>

#include <memory>

#include "vdb.h"

namespace latvox {

struct VdbGrid::Impl {
  openvdb::FloatGrid::Ptr grid;
};

// Registers OpenVDB's types, once per process. Every entry point that makes, reads or writes a
// grid calls it first.
void vdb_init();

// The handle Rust owns for `grid`.
std::unique_ptr<VdbGrid> vdb_handle(openvdb::FloatGrid::Ptr grid);

}  // namespace latvox
