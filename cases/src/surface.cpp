#include "msfem/cases/surface.hpp"

#include <algorithm>

namespace msfem::cases {

std::vector<Edge> unique_edges(const Surface& surface) {
  std::vector<Edge> edges;
  edges.reserve(3 * static_cast<std::size_t>(surface.num_triangles()));
  for (Eigen::Index t = 0; t < surface.num_triangles(); ++t) {
    for (int c = 0; c < 3; ++c) {
      const int a = surface.triangles(t, c);
      const int b = surface.triangles(t, (c + 1) % 3);
      edges.push_back({std::min(a, b), std::max(a, b)});
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  return edges;
}

double signed_volume(const Surface& surface) {
  // Sum of signed tetrahedra (origin, a, b, c); exact for any closed surface, independent of
  // origin. The origin is moved to the first vertex to limit cancellation for meshes far from 0.
  if (surface.num_vertices() == 0) return 0.0;
  const Eigen::Vector3d o = surface.vertices.row(0).transpose();
  double six_volume = 0.0;
  for (Eigen::Index t = 0; t < surface.num_triangles(); ++t) {
    const Eigen::Vector3d a = surface.vertices.row(surface.triangles(t, 0)).transpose() - o;
    const Eigen::Vector3d b = surface.vertices.row(surface.triangles(t, 1)).transpose() - o;
    const Eigen::Vector3d c = surface.vertices.row(surface.triangles(t, 2)).transpose() - o;
    six_volume += a.dot(b.cross(c));
  }
  return six_volume / 6.0;
}

double area(const Surface& surface) {
  double twice_area = 0.0;
  for (Eigen::Index t = 0; t < surface.num_triangles(); ++t) {
    const Eigen::Vector3d a = surface.vertices.row(surface.triangles(t, 0)).transpose();
    const Eigen::Vector3d b = surface.vertices.row(surface.triangles(t, 1)).transpose();
    const Eigen::Vector3d c = surface.vertices.row(surface.triangles(t, 2)).transpose();
    twice_area += (b - a).cross(c - a).norm();
  }
  return twice_area / 2.0;
}

Eigen::Vector3d vertex_centroid(const Surface& surface) {
  if (surface.num_vertices() == 0) return Eigen::Vector3d::Zero();
  return surface.vertices.colwise().mean().transpose();
}

Eigen::Matrix<double, 2, 3> bounding_box(const Surface& surface) {
  Eigen::Matrix<double, 2, 3> box = Eigen::Matrix<double, 2, 3>::Zero();
  if (surface.num_vertices() == 0) return box;
  box.row(0) = surface.vertices.colwise().minCoeff();
  box.row(1) = surface.vertices.colwise().maxCoeff();
  return box;
}

Eigen::MatrixX3d vertex_normals(const Surface& surface) {
  Eigen::MatrixX3d normals = Eigen::MatrixX3d::Zero(surface.num_vertices(), 3);
  for (Eigen::Index t = 0; t < surface.num_triangles(); ++t) {
    const Eigen::Vector3d a = surface.vertices.row(surface.triangles(t, 0)).transpose();
    const Eigen::Vector3d b = surface.vertices.row(surface.triangles(t, 1)).transpose();
    const Eigen::Vector3d c = surface.vertices.row(surface.triangles(t, 2)).transpose();
    const Eigen::RowVector3d twice_area_normal = (b - a).cross(c - a).transpose();
    for (int k = 0; k < 3; ++k)
      normals.row(surface.triangles(t, k)) += twice_area_normal;
  }
  for (Eigen::Index i = 0; i < normals.rows(); ++i) {
    const double n = normals.row(i).norm();
    if (n > 0) normals.row(i) /= n;
  }
  return normals;
}

void scale(Surface& surface, double factor) {
  surface.vertices *= factor;
}

}  // namespace msfem::cases
