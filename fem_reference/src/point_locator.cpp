#include "msfem/fem_reference/point_locator.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <boost/geometry.hpp>
#include <boost/geometry/index/rtree.hpp>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "msfem/fem_reference/closest_point.hpp"

namespace msfem::fem_reference {

namespace bg = boost::geometry;
namespace bgi = boost::geometry::index;

namespace {

using BoostPoint = bg::model::point<double, 3, bg::cs::cartesian>;
using Box = bg::model::box<BoostPoint>;
using Entry = std::pair<Box, Eigen::Index>;

}  // namespace

struct PointLocator::Index {
  VolumeMesh mesh;
  /// Inverse of [v1 - v0, v2 - v0, v3 - v0] per cell: the affine map's inverse.
  std::vector<Eigen::Matrix3d> inverse_jacobians;
  bgi::rtree<Entry, bgi::quadratic<16>> tree;

  Eigen::Vector3d vertex(Eigen::Index cell, int k) const {
    return mesh.vertices.row(mesh.tetrahedra(cell, k)).transpose();
  }
};

PointLocator::PointLocator(const VolumeMesh& mesh) : index_(std::make_unique<Index>()) {
  index_->mesh = mesh;
  const Eigen::Index n = mesh.num_tetrahedra();
  index_->inverse_jacobians.resize(std::size_t(n));
  std::vector<Entry> entries;
  entries.reserve(std::size_t(n));
  for (Eigen::Index e = 0; e < n; ++e) {
    Eigen::Matrix3d jacobian;
    for (int k = 0; k < 3; ++k)
      jacobian.col(k) = index_->vertex(e, k + 1) - index_->vertex(e, 0);
    index_->inverse_jacobians[std::size_t(e)] = jacobian.inverse();
    Eigen::Vector3d lower = index_->vertex(e, 0), upper = lower;
    for (int k = 1; k < 4; ++k) {
      lower = lower.cwiseMin(index_->vertex(e, k));
      upper = upper.cwiseMax(index_->vertex(e, k));
    }
    entries.emplace_back(Box(BoostPoint(lower.x(), lower.y(), lower.z()),
                             BoostPoint(upper.x(), upper.y(), upper.z())),
                         e);
  }
  index_->tree = bgi::rtree<Entry, bgi::quadratic<16>>(entries.begin(), entries.end());  // packed
}

PointLocator::~PointLocator() = default;

Eigen::Vector4d PointLocator::barycentric(Eigen::Index cell, const Eigen::Vector3d& x) const {
  const Eigen::Vector3d reference =
      index_->inverse_jacobians[std::size_t(cell)] * (x - index_->vertex(cell, 0));
  return Eigen::Vector4d(1.0 - reference.sum(), reference.x(), reference.y(), reference.z());
}

PointLocation PointLocator::locate(const Eigen::Vector3d& x) const {
  const BoostPoint p(x.x(), x.y(), x.z());
  // Inside: among the cells whose box holds x, the one with the largest smallest barycentric
  // coordinate (ties on shared faces are harmless: the field is continuous).
  PointLocation best;
  double best_min = -std::numeric_limits<double>::infinity();
  for (auto it = index_->tree.qbegin(bgi::intersects(p)); it != index_->tree.qend(); ++it) {
    const Eigen::Vector4d b = barycentric(it->second, x);
    if (b.minCoeff() > best_min) {
      best_min = b.minCoeff();
      best.cell = it->second;
      best.barycentric = b;
    }
  }
  constexpr double inside_tolerance = 1e-12;
  if (best.cell >= 0 && best_min >= -inside_tolerance) {
    best.barycentric = best.barycentric.cwiseMax(0.0);
    best.barycentric /= best.barycentric.sum();
    return best;
  }
  // Outside every cell: the closest point over cells in order of box distance, stopping when the
  // next box is farther than the best cell found.
  best = PointLocation();
  best.distance = std::numeric_limits<double>::infinity();
  Eigen::Vector3d best_point = x;
  for (auto it = index_->tree.qbegin(bgi::nearest(p, unsigned(index_->tree.size())));
       it != index_->tree.qend(); ++it) {
    if (bg::distance(p, it->first) > best.distance) break;
    const Eigen::Index e = it->second;
    static constexpr int faces[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
    for (const auto& f : faces) {
      const Eigen::Vector3d q = closest_point_on_triangle(
          x, index_->vertex(e, f[0]), index_->vertex(e, f[1]), index_->vertex(e, f[2]));
      const double d = (q - x).norm();
      if (d < best.distance) {
        best.distance = d;
        best.cell = e;
        best_point = q;
      }
    }
  }
  best.barycentric = barycentric(best.cell, best_point).cwiseMax(0.0);
  best.barycentric /= best.barycentric.sum();
  return best;
}

}  // namespace msfem::fem_reference
