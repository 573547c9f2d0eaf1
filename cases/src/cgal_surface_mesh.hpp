#pragma once
// Conversion between msfem's array surface and CGAL's Surface_mesh (private to cases/).

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "msfem/cases/surface.hpp"

namespace msfem::cases::detail {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using CgalMesh = CGAL::Surface_mesh<Kernel::Point_3>;

/// Builds a Surface_mesh whose vertex and face indices equal the array rows. Throws
/// std::invalid_argument naming the triangle that Surface_mesh rejects (non-manifold or
/// inconsistently oriented configurations).
inline CgalMesh to_cgal(const Surface& s) {
  CgalMesh mesh;
  mesh.reserve(static_cast<CgalMesh::size_type>(s.num_vertices()),
               static_cast<CgalMesh::size_type>(3 * s.num_triangles()),
               static_cast<CgalMesh::size_type>(s.num_triangles()));
  for (Eigen::Index v = 0; v < s.num_vertices(); ++v)
    mesh.add_vertex(Kernel::Point_3(s.vertices(v, 0), s.vertices(v, 1), s.vertices(v, 2)));
  for (Eigen::Index t = 0; t < s.num_triangles(); ++t) {
    const auto f = mesh.add_face(CgalMesh::Vertex_index(s.triangles(t, 0)),
                                 CgalMesh::Vertex_index(s.triangles(t, 1)),
                                 CgalMesh::Vertex_index(s.triangles(t, 2)));
    if (f == CgalMesh::null_face())
      throw std::invalid_argument("triangle " + std::to_string(t) +
                                  " cannot be added to a 2-manifold, consistently oriented mesh");
  }
  return mesh;
}

/// Copies a (possibly garbage-collected) Surface_mesh back into arrays with dense indices.
inline Surface from_cgal(const CgalMesh& mesh) {
  Surface s;
  std::vector<int> new_id(mesh.number_of_vertices() + mesh.number_of_removed_vertices(), -1);
  s.vertices.resize(static_cast<Eigen::Index>(mesh.number_of_vertices()), 3);
  int next = 0;
  for (auto v : mesh.vertices()) {
    const auto& p = mesh.point(v);
    s.vertices.row(next) << p.x(), p.y(), p.z();
    new_id[v.idx()] = next++;
  }
  s.triangles.resize(static_cast<Eigen::Index>(mesh.number_of_faces()), 3);
  int row = 0;
  for (auto f : mesh.faces()) {
    int c = 0;
    for (auto v : CGAL::vertices_around_face(mesh.halfedge(f), mesh))
      s.triangles(row, c++) = new_id[v.idx()];
    ++row;
  }
  return s;
}

}  // namespace msfem::cases::detail
