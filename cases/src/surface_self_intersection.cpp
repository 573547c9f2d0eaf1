#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/shape_predicates.h>

#include <algorithm>
#include <iterator>

#include "cgal_surface_mesh.hpp"
#include "msfem/cases/surface_validation.hpp"

namespace msfem::cases {

std::vector<std::array<int, 2>> self_intersecting_pairs(const Surface& surface) {
  const detail::CgalMesh mesh = detail::to_cgal(surface);
  // CGAL's test is not defined for zero-area triangles; validation reports those separately.
  std::vector<detail::CgalMesh::Face_index> faces;
  for (auto f : mesh.faces())
    if (!CGAL::Polygon_mesh_processing::is_degenerate_triangle_face(f, mesh)) faces.push_back(f);
  std::vector<std::pair<detail::CgalMesh::Face_index, detail::CgalMesh::Face_index>> hits;
  CGAL::Polygon_mesh_processing::self_intersections(faces, mesh, std::back_inserter(hits));
  std::vector<std::array<int, 2>> pairs;
  pairs.reserve(hits.size());
  for (const auto& [f, g] : hits) {
    const int a = static_cast<int>(f.idx()), b = static_cast<int>(g.idx());
    pairs.push_back({std::min(a, b), std::max(a, b)});
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

}  // namespace msfem::cases
