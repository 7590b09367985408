// Distances from points to a triangle soup by CGAL's AABB tree (exact closest points on the
// facets, in double precision), queried in parallel; optionally which points lie inside the
// soup when it is a closed 2-manifold (Side_of_triangle_mesh, ray parity with exact
// predicates). Measures how far a repaired or remeshed part moved from its input; and how far
// rays from each facet travel through the part and in front of it (its walls and gaps).
#include "cgal.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/exceptions.h>

#include <tbb/parallel_for.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "latvox/src/ffi/cgal.rs.h"

namespace latvox {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Tri = K::Triangle_3;
using Iter = std::vector<Tri>::const_iterator;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, CGAL::AABB_triangle_primitive<K, Iter>>>;
using DMesh = CGAL::Surface_mesh<K::Point_3>;

// The facets of a soup that have an area, as triangles, and (in `of`) the index of each in the
// soup; checks the arrays first.
static std::vector<Tri> soup(rust::Slice<const float> positions,
                             rust::Slice<const uint32_t> indices, std::vector<std::size_t>& of) {
  if (positions.size() % 3 != 0 || indices.size() % 3 != 0)
    throw std::invalid_argument("positions and indices must come in triples");
  const std::size_t nv = positions.size() / 3, nf = indices.size() / 3;
  for (auto i : indices)
    if (i >= nv) throw std::out_of_range("triangle index past the vertex list");
  auto p = [&](std::size_t i) {
    return K::Point_3(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]);
  };
  std::vector<Tri> tris;
  tris.reserve(nf);
  for (std::size_t f = 0; f < nf; ++f) {
    Tri t(p(indices[3 * f]), p(indices[3 * f + 1]), p(indices[3 * f + 2]));
    if (!t.is_degenerate()) {
      tris.push_back(t);
      of.push_back(f);
    }
  }
  return tris;
}

PointDistances cgal_distances(rust::Slice<const float> positions,
                              rust::Slice<const uint32_t> indices,
                              rust::Slice<const double> points, bool classify) {
  if (points.size() % 3 != 0) throw std::invalid_argument("points must come in triples");
  const std::size_t nv = positions.size() / 3, nf = indices.size() / 3, np = points.size() / 3;
  auto p = [&](std::size_t i) {
    return K::Point_3(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]);
  };
  std::vector<std::size_t> of;
  const std::vector<Tri> tris = soup(positions, indices, of);
  PointDistances out{};
  if (tris.empty()) throw std::invalid_argument("no facet with an area to measure against");
  Tree tree(tris.begin(), tris.end());
  tree.accelerate_distance_queries();
  std::vector<double> d(np);
  tbb::parallel_for(std::size_t(0), np, [&](std::size_t i) {
    const K::Point_3 q(points[3 * i], points[3 * i + 1], points[3 * i + 2]);
    d[i] = std::sqrt(CGAL::to_double(tree.squared_distance(q)));
  });
  out.distances.reserve(np);
  for (double x : d) out.distances.push_back(x);
  if (!classify) return out;
  // Inside only means something for a closed 2-manifold: build one as given, or say nothing.
  DMesh mesh;
  for (std::size_t i = 0; i < nv; ++i) mesh.add_vertex(p(i));
  for (std::size_t f = 0; f < nf; ++f) {
    const DMesh::Vertex_index a(indices[3 * f]), b(indices[3 * f + 1]), c(indices[3 * f + 2]);
    if (a == b || b == c || a == c || mesh.add_face(a, b, c) == DMesh::null_face()) return out;
  }
  if (!CGAL::is_closed(mesh)) return out;
  try {
    CGAL::Side_of_triangle_mesh<DMesh, K> side(mesh);
    std::vector<char> in(np);
    tbb::parallel_for(std::size_t(0), np, [&](std::size_t i) {
      in[i] = side(K::Point_3(points[3 * i], points[3 * i + 1], points[3 * i + 2])) ==
              CGAL::ON_BOUNDED_SIDE;
    });
    out.inside.reserve(np);
    for (char x : in) out.inside.push_back(x != 0);
  } catch (const CGAL::Failure_exception&) {
    out.inside.clear();
  }
  return out;
}

rust::Vec<double> cgal_facet_reach(rust::Slice<const float> positions,
                                   rust::Slice<const uint32_t> indices) {
  const std::size_t nf = indices.size() / 3;
  std::vector<std::size_t> of;
  const std::vector<Tri> solid = soup(positions, indices, of);
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> reach(nf, inf);
  if (solid.empty()) {
    rust::Vec<double> out;
    for (double x : reach) out.push_back(x);
    return out;
  }
  Tree tree(solid.begin(), solid.end());
  tbb::parallel_for(std::size_t(0), solid.size(), [&](std::size_t i) {
    const Tri& t = solid[i];
    const K::Point_3 c = CGAL::centroid(t[0], t[1], t[2]);
    const K::Vector_3 n = CGAL::normal(t[0], t[1], t[2]);
    const Iter self = solid.begin() + static_cast<std::ptrdiff_t>(i);
    auto skip = [&](const Iter& id) { return id == self; };
    double best = inf;
    for (const K::Vector_3& d : {n, -n}) {
      try {
        auto hit = tree.first_intersection(K::Ray_3(c, d), skip);
        if (!hit) continue;
        if (const K::Point_3* q = boost::get<K::Point_3>(&hit->first))
          best = std::min(best, std::sqrt(CGAL::to_double(CGAL::squared_distance(c, *q))));
        else if (const K::Segment_3* s = boost::get<K::Segment_3>(&hit->first))
          best = std::min(best, std::sqrt(CGAL::to_double(CGAL::squared_distance(c, *s))));
      } catch (const CGAL::Failure_exception&) {
      }
    }
    reach[of[i]] = best;
  });
  rust::Vec<double> out;
  out.reserve(nf);
  for (double x : reach) out.push_back(x);
  return out;
}

}  // namespace latvox
