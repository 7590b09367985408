// CGAL side of the bridge: closed-mesh measures and validity checks on an indexed triangle soup.
#pragma once
#include <cstdint>
#include "rust/cxx.h"

namespace latvox {

struct CgalReport;

CgalReport cgal_check(rust::Slice<const float> positions, rust::Slice<const uint32_t> indices,
                      bool self_intersection, bool parallel);

rust::Vec<uint32_t> cgal_self_intersections(rust::Slice<const float> positions,
                                            rust::Slice<const uint32_t> indices,
                                            std::size_t limit);

}  // namespace latvox
