// CGAL side of mesh repair: self-intersections of an arbitrary triangle soup, and hole filling
// (triangulate, refine and fair). Kept apart from cgal.cc so the checks stay small.
#pragma once
#include <cstdint>
#include "rust/cxx.h"

namespace latvox {

struct SoupIntersections;
struct HoleFill;

SoupIntersections cgal_soup_self_intersections(rust::Slice<const float> positions,
                                               rust::Slice<const uint32_t> indices,
                                               rust::Slice<const uint32_t> tile_faces,
                                               rust::Slice<const uint32_t> tile_starts,
                                               std::size_t limit);

HoleFill cgal_fill_holes(rust::Slice<const float> positions, rust::Slice<const uint32_t> indices,
                         rust::Slice<const uint32_t> hole_starts, bool fair);

}  // namespace latvox
