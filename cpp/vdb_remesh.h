// OpenVDB remeshing ("shrink wrap"): triangles -> narrow-band level set -> closed mesh.
// Self-contained: plain slices in, plain vectors out.
#pragma once
#include <cstdint>
#include "rust/cxx.h"

namespace latvox {

struct RemeshStats;

RemeshStats vdb_remesh(rust::Slice<const float> positions, rust::Slice<const uint32_t> indices,
                       double voxel, double adaptivity, rust::Vec<float>& out_positions,
                       rust::Vec<uint32_t>& out_indices);

}  // namespace latvox
