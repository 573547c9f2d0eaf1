#pragma once

// nanoflann over the rows of an n x 3 matrix (surface_geometry.cpp, surface_contact.cpp). Not
// installed: nanoflann stays a private dependency.

#include <Eigen/Core>
#include <cstddef>
#include <nanoflann.hpp>

namespace msfem::massspring::detail {

/// nanoflann's dataset adaptor over the rows of an n x 3 matrix (held by reference).
struct PointCloud {
  const Eigen::MatrixX3d& points;
  std::size_t kdtree_get_point_count() const { return static_cast<std::size_t>(points.rows()); }
  double kdtree_get_pt(std::size_t index, std::size_t dim) const {
    return points(static_cast<Eigen::Index>(index), static_cast<Eigen::Index>(dim));
  }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;
  }
};

using KdTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, PointCloud>,
                                                   PointCloud, 3, std::size_t>;

}  // namespace msfem::massspring::detail
