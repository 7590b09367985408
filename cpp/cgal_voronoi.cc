// The Voronoi diagram of points, as the dual of CGAL's 3D Delaunay triangulation: each finite
// Delaunay cell's circumcentre is a Voronoi vertex, each facet between two finite cells a
// Voronoi edge (the segment between their circumcentres), each Delaunay edge whose cells around
// it are all finite a Voronoi face (the polygon of those cells' circumcentres, in the order the
// cells turn around the edge) between the edge's two points. Parts of the diagram that reach
// infinity (the cells of points on the hull) are left out: callers seed beyond the region they
// use, so only the finite diagram reaches into it.
#include "cgal.h"

#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Delaunay_triangulation_cell_base_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <cmath>
#include <stdexcept>
#include <unordered_map>
#include <utility>
#include <vector>

#include "latvox/src/ffi/cgal.rs.h"

namespace latvox {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb = CGAL::Triangulation_vertex_base_with_info_3<uint32_t, K>;
using Cb = CGAL::Delaunay_triangulation_cell_base_3<K>;
using Tds = CGAL::Triangulation_data_structure_3<Vb, Cb>;
using Delaunay = CGAL::Delaunay_triangulation_3<K, Tds>;

VoronoiDiagram cgal_voronoi(rust::Slice<const double> points) {
  if (points.size() % 3 != 0) throw std::invalid_argument("points must come in triples");
  const std::size_t n = points.size() / 3;
  std::vector<std::pair<K::Point_3, uint32_t>> input;
  input.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double x = points[3 * i], y = points[3 * i + 1], z = points[3 * i + 2];
    if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z))
      throw std::invalid_argument("a seed is not a finite point");
    input.emplace_back(K::Point_3(x, y, z), static_cast<uint32_t>(i));
  }
  // Spatially sorted insertion; duplicates are merged into the first (their cells are empty).
  Delaunay dt(input.begin(), input.end());

  VoronoiDiagram out;
  out.seeds_used = dt.number_of_vertices();
  std::unordered_map<Delaunay::Cell_handle, uint32_t> index;
  index.reserve(dt.number_of_finite_cells());
  for (auto c = dt.finite_cells_begin(); c != dt.finite_cells_end(); ++c) {
    const K::Point_3 p = dt.dual(c);
    index.emplace(c, static_cast<uint32_t>(out.vertices.size() / 3));
    out.vertices.push_back(p.x());
    out.vertices.push_back(p.y());
    out.vertices.push_back(p.z());
  }
  for (auto f = dt.finite_facets_begin(); f != dt.finite_facets_end(); ++f) {
    const auto c = f->first;
    const auto d = c->neighbor(f->second);
    if (dt.is_infinite(c) || dt.is_infinite(d)) continue;
    out.edges.push_back(index.at(c));
    out.edges.push_back(index.at(d));
  }
  out.face_starts.push_back(0);
  for (auto e = dt.finite_edges_begin(); e != dt.finite_edges_end(); ++e) {
    const auto c = e->first;
    const uint32_t a = c->vertex(e->second)->info(), b = c->vertex(e->third)->info();
    std::vector<uint32_t> ring;
    bool bounded = true;
    auto start = dt.incident_cells(*e), it = start;
    do {
      if (dt.is_infinite(it)) {
        bounded = false;
        break;
      }
      ring.push_back(index.at(it));
    } while (++it != start);
    if (!bounded) continue;
    out.face_seeds.push_back(a);
    out.face_seeds.push_back(b);
    for (auto v : ring) out.face_vertices.push_back(v);
    out.face_starts.push_back(static_cast<uint32_t>(out.face_vertices.size()));
  }
  return out;
}

}  // namespace latvox
