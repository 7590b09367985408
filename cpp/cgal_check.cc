// Builds a CGAL Surface_mesh from an indexed triangle soup and runs the Polygon Mesh Processing
// checks latvox reports on every mesh: closedness, outward orientation, self-intersection,
// and the enclosed volume and surface area.
#include "cgal.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/connected_components.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/shape_predicates.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/helpers.h>
#include <CGAL/exceptions.h>

#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>
#include <vector>

#include "latvox/src/ffi/cgal.rs.h"

namespace latvox {

namespace PMP = CGAL::Polygon_mesh_processing;
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Mesh = CGAL::Surface_mesh<K::Point_3>;

namespace {

// Bits of CgalReport::unchecked (src/ffi/cgal.rs).
constexpr uint8_t UNCHECKED_ORIENTATION = 1, UNCHECKED_SELF_INTERSECTION = 2,
                  UNCHECKED_MEASURES = 4;

// Builds a Surface_mesh from an indexed soup. Returns false (with a repaired mesh) when the soup
// is not an oriented 2-manifold as given.
bool build_mesh(rust::Slice<const float> positions, rust::Slice<const uint32_t> indices,
                Mesh& mesh) {
  if (positions.size() % 3 != 0 || indices.size() % 3 != 0)
    throw std::invalid_argument("positions and indices must come in triples");
  const std::size_t nv = positions.size() / 3;
  const std::size_t nf = indices.size() / 3;
  for (std::size_t i = 0; i < indices.size(); ++i)
    if (indices[i] >= nv) throw std::out_of_range("triangle index past the vertex list");
  // Fast path: add faces one by one; Surface_mesh refuses any face that would make an edge or
  // vertex non-manifold or flip against its neighbours.
  mesh.reserve(nv, nf * 3 / 2 + 16, nf);
  for (std::size_t i = 0; i < nv; ++i)
    mesh.add_vertex(K::Point_3(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]));
  bool valid = true;
  for (std::size_t f = 0; f < nf && valid; ++f) {
    const auto a = Mesh::Vertex_index(indices[3 * f]);
    const auto b = Mesh::Vertex_index(indices[3 * f + 1]);
    const auto c = Mesh::Vertex_index(indices[3 * f + 2]);
    if (a == b || b == c || a == c || mesh.add_face(a, b, c) == Mesh::null_face()) valid = false;
  }
  if (valid) return true;
  // Not an oriented 2-manifold as given: let CGAL duplicate non-manifold vertices and
  // reorient, so the mesh can still be measured.
  mesh.clear();
  std::vector<K::Point_3> points;
  points.reserve(nv);
  for (std::size_t i = 0; i < nv; ++i)
    points.emplace_back(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]);
  std::vector<std::array<std::size_t, 3>> polygons;
  polygons.reserve(nf);
  for (std::size_t f = 0; f < nf; ++f) {
    const auto a = indices[3 * f], b = indices[3 * f + 1], c = indices[3 * f + 2];
    if (a != b && b != c && a != c) polygons.push_back({a, b, c});
  }
  PMP::orient_polygon_soup(points, polygons);
  PMP::polygon_soup_to_polygon_mesh(points, polygons, mesh);
  return false;
}

}  // namespace

CgalReport cgal_check(rust::Slice<const float> positions, rust::Slice<const uint32_t> indices,
                      bool self_intersection, bool parallel) {
  CgalReport r{};
  Mesh mesh;
  r.valid_polygon_mesh = build_mesh(positions, indices, mesh);
  r.faces = mesh.number_of_faces();
  r.vertices = mesh.number_of_vertices();
  std::size_t border = 0;
  for (auto h : mesh.halfedges())
    if (mesh.is_border(h)) ++border;
  r.border_edges = border;
  r.closed = border == 0;
  // Each CGAL step states preconditions a hostile mesh can break (a closed shell with no inside,
  // facets back to back): a step whose precondition fails is reported as not checked, never
  // passed on as an error.
  auto guarded = [&r](uint8_t step, auto&& run) {
    try {
      run();
    } catch (const CGAL::Failure_exception&) {
      r.unchecked |= step;
    }
  };
  guarded(UNCHECKED_MEASURES, [&] {
    r.area = PMP::area(mesh);
    auto fcc = mesh.add_property_map<Mesh::Face_index, std::size_t>("f:cc").first;
    r.components = PMP::connected_components(mesh, fcc);
  });
  r.outward = false;
  r.volume = std::numeric_limits<double>::quiet_NaN();
  bool degenerate = false;
  for (auto f : mesh.faces()) degenerate = degenerate || PMP::is_degenerate_triangle_face(f, mesh);
  if (r.closed && mesh.number_of_faces() > 0) {
    if (degenerate)
      r.unchecked |= UNCHECKED_ORIENTATION;
    else
      guarded(UNCHECKED_ORIENTATION, [&] {
        r.outward = PMP::is_outward_oriented(mesh);
        r.volume = PMP::volume(mesh);
      });
    if (r.unchecked & UNCHECKED_ORIENTATION) {
      r.outward = false;
      r.volume = std::numeric_limits<double>::quiet_NaN();
    }
  }
  r.self_intersection_checked = false;
  if (self_intersection) {
    // TBB's parallel search costs about twice the CPU of the sequential one: worth it only when
    // nothing else needs the other cores.
    guarded(UNCHECKED_SELF_INTERSECTION, [&] {
      r.self_intersecting =
          parallel ? PMP::does_self_intersect<CGAL::Parallel_if_available_tag>(mesh)
                   : PMP::does_self_intersect<CGAL::Sequential_tag>(mesh);
      r.self_intersection_checked = true;
    });
  }
  return r;
}

}  // namespace latvox
