// Mesh repair steps done by CGAL's Polygon Mesh Processing:
//  - self-intersections of any triangle soup (non-manifold or inconsistently wound input is first
//    made a valid Surface_mesh by orient_polygon_soup, which only duplicates vertices and flips
//    faces, so face i stays polygon i; pairs that share an input vertex are touching, not
//    crossing, and are left out). The search runs on spatial tiles of the one mesh given by the
//    caller (facets whose boxes meet share a tile), each tile by CGAL's sequential box
//    intersection and exact predicates, the tiles in parallel (TBB); pairs found in several tiles
//    are counted once. Same mesh, same predicates: the same pairs as one whole-mesh search;
//  - hole filling: triangulate_refine_and_fair_hole on the border cycles named by the caller,
//    returning only what was added, so the caller keeps its own vertex and facet numbering.
// Compiled apart from cgal_check.cc, with CGAL's precondition checks off (see build.rs).
#include "cgal.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/exceptions.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <iterator>
#include <stdexcept>
#include <utility>
#include <vector>

#include "latvox/src/ffi/cgal.rs.h"

namespace latvox {

namespace PMP = CGAL::Polygon_mesh_processing;
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using SMesh = CGAL::Surface_mesh<K::Point_3>;

namespace {

void check_soup(rust::Slice<const float> positions, rust::Slice<const uint32_t> indices) {
  if (positions.size() % 3 != 0 || indices.size() % 3 != 0)
    throw std::invalid_argument("positions and indices must come in triples");
  const std::size_t nv = positions.size() / 3;
  for (std::size_t i = 0; i < indices.size(); ++i)
    if (indices[i] >= nv) throw std::out_of_range("triangle index past the vertex list");
}

K::Point_3 point(rust::Slice<const float> positions, std::size_t i) {
  return K::Point_3(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]);
}

// Adds the triangles as given; false if Surface_mesh refuses one (non-manifold or flipped).
bool add_as_given(rust::Slice<const float> positions, rust::Slice<const uint32_t> indices,
                  SMesh& mesh) {
  const std::size_t nv = positions.size() / 3, nf = indices.size() / 3;
  mesh.reserve(nv, nf * 3 / 2 + 16, nf);
  for (std::size_t i = 0; i < nv; ++i) mesh.add_vertex(point(positions, i));
  for (std::size_t f = 0; f < nf; ++f) {
    const SMesh::Vertex_index a(indices[3 * f]), b(indices[3 * f + 1]), c(indices[3 * f + 2]);
    if (a == b || b == c || a == c) throw std::invalid_argument("degenerate triangle");
    if (mesh.add_face(a, b, c) == SMesh::null_face()) return false;
  }
  return true;
}

}  // namespace

SoupIntersections cgal_soup_self_intersections(rust::Slice<const float> positions,
                                               rust::Slice<const uint32_t> indices,
                                               rust::Slice<const uint32_t> tile_faces,
                                               rust::Slice<const uint32_t> tile_starts,
                                               std::size_t limit) {
  check_soup(positions, indices);
  const std::size_t nf = indices.size() / 3;
  if (tile_starts.empty() || tile_starts[tile_starts.size() - 1] != tile_faces.size())
    throw std::invalid_argument("tile starts must end at the number of tiled facets");
  for (std::size_t t = 0; t + 1 < tile_starts.size(); ++t)
    if (tile_starts[t] > tile_starts[t + 1]) throw std::invalid_argument("tile starts decrease");
  for (auto f : tile_faces)
    if (f >= nf) throw std::out_of_range("tiled facet past the facet list");
  SoupIntersections out{};
  if (nf == 0) return out;
  SMesh mesh;
  if (!add_as_given(positions, indices, mesh)) {
    mesh.clear();
    std::vector<K::Point_3> points;
    points.reserve(positions.size() / 3);
    for (std::size_t i = 0; i < positions.size() / 3; ++i) points.push_back(point(positions, i));
    std::vector<std::array<std::size_t, 3>> polygons(nf);
    for (std::size_t f = 0; f < nf; ++f)
      polygons[f] = {indices[3 * f], indices[3 * f + 1], indices[3 * f + 2]};
    PMP::orient_polygon_soup(points, polygons);
    if (polygons.size() != nf)
      throw std::runtime_error("orienting the soup changed its facet count");
    PMP::polygon_soup_to_polygon_mesh(points, polygons, mesh);
    if (mesh.number_of_faces() != nf)
      throw std::runtime_error("the soup could not be made a polygon mesh");
  }
  using FacePair = std::pair<SMesh::Face_index, SMesh::Face_index>;
  const std::size_t tiles = tile_starts.size() - 1;
  std::vector<std::vector<FacePair>> found(tiles);
  tbb::parallel_for(std::size_t(0), tiles, [&](std::size_t t) {
    std::vector<SMesh::Face_index> range;
    range.reserve(tile_starts[t + 1] - tile_starts[t]);
    for (std::size_t i = tile_starts[t]; i < tile_starts[t + 1]; ++i)
      range.push_back(SMesh::Face_index(tile_faces[i]));
    PMP::self_intersections<CGAL::Sequential_tag>(range, mesh, std::back_inserter(found[t]));
  });
  std::vector<FacePair> pairs;
  for (auto& f : found) {
    for (auto p : f) pairs.push_back(p.first < p.second ? p : FacePair(p.second, p.first));
    std::vector<FacePair>().swap(f);
  }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  auto shares_vertex = [&](std::size_t f, std::size_t g) {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        if (indices[3 * f + i] == indices[3 * g + j]) return true;
    return false;
  };
  for (const auto& p : pairs) {
    std::size_t f = static_cast<std::size_t>(p.first), g = static_cast<std::size_t>(p.second);
    if (f > g) std::swap(f, g);
    // Faces are polygons in input order. Two facets that share an input vertex but no vertex
    // of the oriented mesh were pulled apart at a non-manifold vertex: they touch there, and
    // that contact is counted as non-manifoldness, not as an intersection.
    if (shares_vertex(f, g)) {
      std::array<SMesh::Vertex_index, 3> vf, vg;
      int k = 0;
      for (auto v : vertices_around_face(mesh.halfedge(SMesh::Face_index(f)), mesh)) vf[k++] = v;
      k = 0;
      for (auto v : vertices_around_face(mesh.halfedge(SMesh::Face_index(g)), mesh)) vg[k++] = v;
      bool common = false;
      for (auto x : vf)
        for (auto y : vg) common = common || x == y;
      if (!common) continue;
    }
    ++out.total;
    if (out.pairs.size() < 2 * limit) {
      out.pairs.push_back(static_cast<uint32_t>(f));
      out.pairs.push_back(static_cast<uint32_t>(g));
    }
  }
  return out;
}

HoleFill cgal_fill_holes(rust::Slice<const float> positions, rust::Slice<const uint32_t> indices,
                         rust::Slice<const uint32_t> hole_starts, bool fair) {
  check_soup(positions, indices);
  if (hole_starts.size() % 2 != 0)
    throw std::invalid_argument("hole starts come as (from, to) vertex pairs");
  SMesh mesh;
  if (!add_as_given(positions, indices, mesh))
    throw std::invalid_argument("hole filling needs an oriented 2-manifold mesh");
  const std::size_t nv = mesh.number_of_vertices(), nf = mesh.number_of_faces();
  HoleFill out{};
  for (std::size_t i = 0; i < hole_starts.size(); i += 2) {
    const SMesh::Vertex_index a(hole_starts[i]), b(hole_starts[i + 1]);
    if (static_cast<std::size_t>(a) >= nv || static_cast<std::size_t>(b) >= nv)
      throw std::out_of_range("hole vertex past the vertex list");
    const auto h = mesh.halfedge(a, b);
    if (h == SMesh::null_halfedge() || !mesh.is_border(h)) {
      out.filled.push_back(false);
      out.faired.push_back(false);
      continue;
    }
    std::vector<SMesh::Face_index> new_faces;
    std::vector<SMesh::Vertex_index> new_vertices;
    bool faired = false;
    // A hole whose border breaks a precondition of CGAL's (a pinched or self-crossing loop)
    // stays open and is reported, like one the triangulation could not close.
    try {
      if (fair) {
        faired = std::get<0>(PMP::triangulate_refine_and_fair_hole(
            mesh, h, std::back_inserter(new_faces), std::back_inserter(new_vertices)));
      } else {
        PMP::triangulate_and_refine_hole(mesh, h, std::back_inserter(new_faces),
                                         std::back_inserter(new_vertices));
      }
    } catch (const CGAL::Failure_exception&) {
      faired = false;
    }
    out.filled.push_back(!new_faces.empty() && !mesh.is_border(h));
    out.faired.push_back(faired);
  }
  if (mesh.has_garbage()) throw std::runtime_error("hole filling removed elements");
  for (std::size_t v = nv; v < mesh.number_of_vertices(); ++v) {
    const auto& p = mesh.point(SMesh::Vertex_index(v));
    out.positions.push_back(static_cast<float>(p.x()));
    out.positions.push_back(static_cast<float>(p.y()));
    out.positions.push_back(static_cast<float>(p.z()));
  }
  for (std::size_t f = nf; f < mesh.number_of_faces(); ++f) {
    auto h = mesh.halfedge(SMesh::Face_index(f));
    for (int k = 0; k < 3; ++k, h = mesh.next(h))
      out.indices.push_back(static_cast<uint32_t>(mesh.source(h)));
  }
  return out;
}

}  // namespace latvox
