#include "msfem/massspring/surface_geometry.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <string>

#include "kd_tree.hpp"
#include "msfem/massspring/errors.hpp"

namespace msfem::massspring {
using detail::KdTree;
using detail::PointCloud;

void check_surface(const Eigen::MatrixX3d& vertices, const Eigen::MatrixX3i& triangles,
                   const char* what) {
  const std::string name(what);
  if (vertices.rows() < 4 || triangles.rows() < 4)
    throw ModelError(name + ": " + std::to_string(vertices.rows()) + " vertices and " +
                     std::to_string(triangles.rows()) +
                     " triangles cannot form a closed surface (need at least 4 of each)");
  for (Eigen::Index i = 0; i < vertices.rows(); ++i)
    if (!vertices.row(i).allFinite())
      throw ModelError(name + " vertex " + std::to_string(i) + ": coordinate not finite");
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    for (int c = 0; c < 3; ++c)
      if (triangles(t, c) < 0 || triangles(t, c) >= vertices.rows())
        throw ModelError(name + " triangle " + std::to_string(t) + ": vertex id " +
                         std::to_string(triangles(t, c)) + " out of range [0, " +
                         std::to_string(vertices.rows()) + ")");
    if (triangles(t, 0) == triangles(t, 1) || triangles(t, 1) == triangles(t, 2) ||
        triangles(t, 0) == triangles(t, 2))
      throw ModelError(name + " triangle " + std::to_string(t) + ": repeated vertex");
  }
}

std::vector<std::array<int, 2>> unique_edges(const Eigen::MatrixX3i& triangles) {
  std::vector<std::array<int, 2>> edges;
  edges.reserve(3 * triangles.rows());
  for (Eigen::Index t = 0; t < triangles.rows(); ++t)
    for (int c = 0; c < 3; ++c) {
      const int a = triangles(t, c);
      const int b = triangles(t, (c + 1) % 3);
      edges.push_back({std::min(a, b), std::max(a, b)});
    }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  return edges;
}

double enclosed_volume(const Eigen::MatrixX3d& vertices, const Eigen::MatrixX3i& triangles) {
  double volume = 0.0;
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    const Eigen::Vector3d a = vertices.row(triangles(t, 0));
    const Eigen::Vector3d b = vertices.row(triangles(t, 1));
    const Eigen::Vector3d c = vertices.row(triangles(t, 2));
    volume += a.dot(b.cross(c)) / 6.0;
  }
  return volume;
}

Eigen::Vector3d vertex_centroid(const Eigen::MatrixX3d& vertices) {
  return vertices.colwise().mean().transpose();
}

Eigen::MatrixX3d vertex_normals(const Eigen::MatrixX3d& vertices,
                                const Eigen::MatrixX3i& triangles) {
  Eigen::MatrixX3d normals = Eigen::MatrixX3d::Zero(vertices.rows(), 3);
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    const Eigen::Vector3d a = vertices.row(triangles(t, 0));
    const Eigen::Vector3d b = vertices.row(triangles(t, 1));
    const Eigen::Vector3d c = vertices.row(triangles(t, 2));
    const Eigen::RowVector3d area_normal = 0.5 * (b - a).cross(c - a).transpose();  // |.| = area
    for (int k = 0; k < 3; ++k)
      normals.row(triangles(t, k)) += area_normal;
  }
  for (Eigen::Index i = 0; i < normals.rows(); ++i) {
    const double norm = normals.row(i).norm();
    if (norm > 0.0) normals.row(i) /= norm;
  }
  return normals;
}

Eigen::VectorXd vertex_areas(const Eigen::MatrixX3d& vertices, const Eigen::MatrixX3i& triangles) {
  Eigen::VectorXd areas = Eigen::VectorXd::Zero(vertices.rows());
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    const Eigen::Vector3d a = vertices.row(triangles(t, 0));
    const Eigen::Vector3d b = vertices.row(triangles(t, 1));
    const Eigen::Vector3d c = vertices.row(triangles(t, 2));
    const double third = 0.5 * (b - a).cross(c - a).norm() / 3.0;
    for (int k = 0; k < 3; ++k)
      areas[triangles(t, k)] += third;
  }
  return areas;
}

std::vector<std::vector<int>> nearest_points(const Eigen::MatrixX3d& points,
                                             const Eigen::MatrixX3d& queries, int k) {
  if (k < 1 || k > points.rows())
    throw ModelError("nearest points: asked for " + std::to_string(k) + " of " +
                     std::to_string(points.rows()) + " points");
  PointCloud cloud{points};
  KdTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  tree.buildIndex();
  std::vector<std::vector<int>> result(queries.rows());
  std::vector<std::size_t> ids(k);
  std::vector<double> distances(k);
  for (Eigen::Index q = 0; q < queries.rows(); ++q) {
    const double query[3] = {queries(q, 0), queries(q, 1), queries(q, 2)};
    const std::size_t found = tree.knnSearch(query, k, ids.data(), distances.data());
    result[q].assign(ids.begin(), ids.begin() + static_cast<std::ptrdiff_t>(found));
  }
  return result;
}

std::vector<int> points_outside_surface(const Eigen::MatrixX3d& points,
                                        const Eigen::MatrixX3d& vertices,
                                        const Eigen::MatrixX3i& triangles) {
  const Eigen::MatrixX3d normals = vertex_normals(vertices, triangles);
  const auto nearest = nearest_points(vertices, points, 1);
  std::vector<int> outside;
  for (Eigen::Index p = 0; p < points.rows(); ++p) {
    const int v = nearest[p][0];
    if ((points.row(p) - vertices.row(v)).dot(normals.row(v)) > 0.0)
      outside.push_back(static_cast<int>(p));
  }
  return outside;
}

}  // namespace msfem::massspring
