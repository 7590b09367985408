// CGAL side of the bridge, on indexed triangle soups: closed-mesh measures and validity checks
// (cgal_check.cc); self-intersections of any soup and hole filling, the repair steps
// (cgal_repair.cc, compiled apart with its own CGAL settings); the union of closed shells by
// corefinement (cgal_boolean.cc); distances from points to a soup and rays from its facets
// (cgal_distance.cc); the Voronoi diagram of points, dual of their Delaunay triangulation
// (cgal_voronoi.cc). One header for the whole library.
#pragma once
#include <cstdint>
#include "rust/cxx.h"

namespace latvox {

struct CgalReport;
struct SoupIntersections;
struct HoleFill;
struct ShellUnion;
struct PointDistances;
struct VoronoiDiagram;

// cgal_check.cc
CgalReport cgal_check(rust::Slice<const float> positions, rust::Slice<const uint32_t> indices,
                      bool self_intersection, bool parallel);

// cgal_repair.cc
SoupIntersections cgal_soup_self_intersections(rust::Slice<const float> positions,
                                               rust::Slice<const uint32_t> indices,
                                               rust::Slice<const uint32_t> tile_faces,
                                               rust::Slice<const uint32_t> tile_starts,
                                               std::size_t limit);

HoleFill cgal_fill_holes(rust::Slice<const float> positions, rust::Slice<const uint32_t> indices,
                         rust::Slice<const uint32_t> hole_starts, bool fair);

// cgal_boolean.cc
ShellUnion cgal_union(rust::Slice<const float> positions, rust::Slice<const uint32_t> indices,
                      rust::Slice<const uint32_t> shell_starts);

// cgal_distance.cc
PointDistances cgal_distances(rust::Slice<const float> positions,
                              rust::Slice<const uint32_t> indices,
                              rust::Slice<const double> points, bool classify);
rust::Vec<double> cgal_facet_reach(rust::Slice<const float> positions,
                                   rust::Slice<const uint32_t> indices);

// cgal_voronoi.cc
VoronoiDiagram cgal_voronoi(rust::Slice<const double> points);

}  // namespace latvox
