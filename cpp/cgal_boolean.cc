// The union of closed shells by CGAL's corefinement (Polygon Mesh Processing,
// corefine_and_compute_union, with exact constructions): each shell must be a closed, outward, self-intersection-free
// 2-manifold bounding a volume (checked here: does_self_intersect, does_bound_a_volume); the
// shells are joined pairwise in a balanced tree (log2 S rounds for S shells), so no shell is
// corefined against the growing union S times over. Any failed
// precondition, non-manifold result (shells touching along an edge or at a point) or CGAL
// exception is returned as a reason, never thrown: the caller falls back to a remesh. The result
// is rounded to single precision (as files hold it) and cleaned of the facets that rounding
// made degenerate.
// Compiled apart (corefinement's headers are the heaviest CGAL parses).
#include "cgal.h"

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/corefinement.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/shape_predicates.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/exceptions.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "latvox/src/ffi/cgal.rs.h"

namespace latvox {

namespace PMP = CGAL::Polygon_mesh_processing;
// Exact constructions: with rounded intersection points, corefinement of an assembly whose parts
// share coplanar faces can build inconsistent patches (and loop).
using K = CGAL::Exact_predicates_exact_constructions_kernel;
using BMesh = CGAL::Surface_mesh<K::Point_3>;

ShellUnion cgal_union(rust::Slice<const float> positions, rust::Slice<const uint32_t> indices,
                      rust::Slice<const uint32_t> shell_starts) {
  if (positions.size() % 3 != 0 || indices.size() % 3 != 0)
    throw std::invalid_argument("positions and indices must come in triples");
  const std::size_t nv = positions.size() / 3, nf = indices.size() / 3;
  for (auto i : indices)
    if (i >= nv) throw std::out_of_range("triangle index past the vertex list");
  if (shell_starts.size() < 2 || shell_starts[shell_starts.size() - 1] != nf)
    throw std::invalid_argument("shell starts must end at the number of facets");
  ShellUnion out{};
  const std::size_t shells = shell_starts.size() - 1;
  std::vector<BMesh> meshes(shells);
  std::string reason;
  auto fail = [&](std::string why) {
    if (reason.empty()) reason = std::move(why);
  };
  for (std::size_t s = 0; s < shells; ++s) {
    const std::size_t a = shell_starts[s], b = shell_starts[s + 1];
    if (a > b || b > nf) throw std::invalid_argument("shell starts decrease");
    BMesh& m = meshes[s];
    std::vector<BMesh::Vertex_index> local(nv, BMesh::null_vertex());
    for (std::size_t f = a; f < b; ++f) {
      BMesh::Vertex_index v[3];
      for (int k = 0; k < 3; ++k) {
        const uint32_t g = indices[3 * f + k];
        if (local[g] == BMesh::null_vertex())
          local[g] = m.add_vertex(
              K::Point_3(positions[3 * g], positions[3 * g + 1], positions[3 * g + 2]));
        v[k] = local[g];
      }
      if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2] ||
          m.add_face(v[0], v[1], v[2]) == BMesh::null_face()) {
        out.reason = "shell " + std::to_string(s) + " is not an oriented 2-manifold";
        return out;
      }
    }
  }
  // One thread: the exact kernel's lazily evaluated numbers are shared by reference counts that
  // are not meant to be touched from several threads.
  for (std::size_t s = 0; s < shells; ++s) {
    try {
      if (!CGAL::is_closed(meshes[s]))
        fail("shell " + std::to_string(s) + " is open");
      else if (PMP::does_self_intersect(meshes[s]))
        fail("shell " + std::to_string(s) + " intersects itself");
      else if (!PMP::does_bound_a_volume(meshes[s]))
        fail("shell " + std::to_string(s) + " does not bound a volume");
    } catch (const CGAL::Failure_exception& e) {
      fail(std::string("CGAL refused shell ") + std::to_string(s) + ": " + e.what());
    }
  }
  while (reason.empty() && meshes.size() > 1) {
    const std::size_t pairs = meshes.size() / 2;
    std::vector<BMesh> next(pairs + meshes.size() % 2);
    for (std::size_t p = 0; p < pairs && reason.empty(); ++p) {
      try {
        if (!PMP::corefine_and_compute_union(meshes[2 * p], meshes[2 * p + 1], next[p]))
          fail("the union is not a 2-manifold (shells touch along an edge or at a point)");
        // Checked before it enters the next round, whose preconditions these are.
        else if (!CGAL::is_valid_polygon_mesh(next[p]) || !CGAL::is_closed(next[p]) ||
                 PMP::does_self_intersect(next[p]))
          fail("a partial union is not a clean closed surface");
      } catch (const CGAL::Failure_exception& e) {
        fail(std::string("CGAL's corefinement failed: ") + e.what());
      }
    }
    if (meshes.size() % 2) next.back() = std::move(meshes.back());
    meshes = std::move(next);
  }
  if (!reason.empty()) {
    out.reason = reason;
    return out;
  }
  BMesh& u = meshes.front();
  // The union is written in single precision: rounded there, the slivers corefinement leaves
  // along the intersection curves can lose their area, or cross a neighbour. The rounded result
  // must be a valid closed surface free of degenerate facets and of self-intersections, or the
  // caller remeshes the group instead.
  try {
    u.collect_garbage();
    if (!CGAL::is_valid_polygon_mesh(u) || !CGAL::is_closed(u)) {
      out.reason = "the union is not a valid closed surface";
      return out;
    }
    for (auto v : u.vertices()) {
      const auto& q = u.point(v);
      u.point(v) = K::Point_3(static_cast<float>(CGAL::to_double(q.x())),
                              static_cast<float>(CGAL::to_double(q.y())),
                              static_cast<float>(CGAL::to_double(q.z())));
    }
    bool degenerate = false;
    for (auto f : u.faces()) degenerate = degenerate || PMP::is_degenerate_triangle_face(f, u);
    if (degenerate || !CGAL::is_closed(u) || PMP::does_self_intersect(u)) {
      out.reason = "the union, rounded to single precision, has degenerate or crossing facets";
      return out;
    }
  } catch (const CGAL::Failure_exception& e) {
    out.reason = std::string("checking the union failed: ") + e.what();
    return out;
  }
  for (auto v : u.vertices()) {
    const auto& p = u.point(v);
    out.positions.push_back(CGAL::to_double(p.x()));
    out.positions.push_back(CGAL::to_double(p.y()));
    out.positions.push_back(CGAL::to_double(p.z()));
  }
  for (auto f : u.faces()) {
    auto h = u.halfedge(f);
    for (int k = 0; k < 3; ++k, h = u.next(h)) out.indices.push_back(static_cast<uint32_t>(u.source(h)));
  }
  out.ok = true;
  return out;
}

}  // namespace latvox
