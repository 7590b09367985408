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
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/helpers.h>

#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "latvox/src/ffi/cgal.rs.h"

namespace latvox {

namespace PMP = CGAL::Polygon_mesh_processing;
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Mesh = CGAL::Surface_mesh<K::Point_3>;

CgalReport cgal_check(rust::Slice<const float> positions, rust::Slice<const uint32_t> indices,
                      bool self_intersection) {
  if (positions.size() % 3 != 0 || indices.size() % 3 != 0)
    throw std::invalid_argument("positions and indices must come in triples");
  const std::size_t nv = positions.size() / 3;
  std::vector<K::Point_3> points;
  points.reserve(nv);
  for (std::size_t i = 0; i < nv; ++i)
    points.emplace_back(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]);
  std::vector<std::array<std::size_t, 3>> polygons;
  polygons.reserve(indices.size() / 3);
  for (std::size_t i = 0; i < indices.size(); i += 3) {
    if (indices[i] >= nv || indices[i + 1] >= nv || indices[i + 2] >= nv)
      throw std::out_of_range("triangle index past the vertex list");
    polygons.push_back({indices[i], indices[i + 1], indices[i + 2]});
  }

  CgalReport r{};
  r.valid_polygon_mesh = PMP::is_polygon_soup_a_polygon_mesh(polygons);
  if (!r.valid_polygon_mesh) {
    // Duplicate non-manifold vertices and reorient so CGAL can still build and measure it.
    PMP::orient_polygon_soup(points, polygons);
  }
  Mesh mesh;
  PMP::polygon_soup_to_polygon_mesh(points, polygons, mesh);
  std::vector<K::Point_3>().swap(points);
  std::vector<std::array<std::size_t, 3>>().swap(polygons);

  r.faces = mesh.number_of_faces();
  r.vertices = mesh.number_of_vertices();
  std::size_t border = 0;
  for (auto h : mesh.halfedges())
    if (mesh.is_border(h)) ++border;
  r.border_edges = border;
  r.closed = CGAL::is_closed(mesh);
  r.area = PMP::area(mesh);
  auto fcc = mesh.add_property_map<Mesh::Face_index, std::size_t>("f:cc").first;
  r.components = PMP::connected_components(mesh, fcc);
  if (r.closed && mesh.number_of_faces() > 0) {
    r.outward = PMP::is_outward_oriented(mesh);
    r.volume = PMP::volume(mesh);
  } else {
    r.outward = false;
    r.volume = std::numeric_limits<double>::quiet_NaN();
  }
  r.self_intersection_checked = self_intersection;
  r.self_intersecting =
      self_intersection && PMP::does_self_intersect<CGAL::Parallel_if_available_tag>(mesh);
  return r;
}

}  // namespace latvox
