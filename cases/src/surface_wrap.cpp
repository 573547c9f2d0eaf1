#include "surface_wrap.hpp"

#include <CGAL/alpha_wrap_3.h>

#include <array>
#include <vector>

#include "cgal_surface_mesh.hpp"

namespace msfem::cases::detail {

Surface alpha_wrap_surface(const Surface& soup, double alpha, double offset) {
  std::vector<Kernel::Point_3> points;
  points.reserve(static_cast<std::size_t>(soup.num_vertices()));
  for (Eigen::Index v = 0; v < soup.num_vertices(); ++v)
    points.emplace_back(soup.vertices(v, 0), soup.vertices(v, 1), soup.vertices(v, 2));
  std::vector<std::array<std::size_t, 3>> faces;
  faces.reserve(static_cast<std::size_t>(soup.num_triangles()));
  for (Eigen::Index t = 0; t < soup.num_triangles(); ++t)
    faces.push_back({static_cast<std::size_t>(soup.triangles(t, 0)),
                     static_cast<std::size_t>(soup.triangles(t, 1)),
                     static_cast<std::size_t>(soup.triangles(t, 2))});
  CgalMesh wrap;
  CGAL::alpha_wrap_3(points, faces, alpha, offset, wrap);
  return from_cgal(wrap);
}

}  // namespace msfem::cases::detail
