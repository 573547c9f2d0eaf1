#pragma once

// Three-tier inner tiers along the distance field (InnerTierMethod::distance_field), internal to
// massspring.

#include <Eigen/Core>
#include <string>
#include <vector>

namespace msfem::massspring::detail {

struct DistanceFieldTiers {
  Eigen::MatrixX3d tier2, tier3;
  std::vector<std::string> warnings;  ///< prisms or nodes the depth reduction could not mend
};

/// Tier k at depth t_k(x) = δ_k s(x) along the inward vertex normal, δ_2 < δ_3 the target depths
/// (what scaling gives on a sphere), s ∈ (0, 1] the same fraction for both tiers (see
/// InnerTierMethod::distance_field).
DistanceFieldTiers distance_field_tiers(const Eigen::MatrixX3d& vertices,
                                        const Eigen::MatrixX3i& triangles,
                                        const Eigen::MatrixX3d& area_normals, double depth2,
                                        double depth3);

/// Per vertex, the radius of the largest ball inside the surface that touches the vertex with
/// its centre on the inward normal and holds no other vertex, capped at `cap`.
Eigen::VectorXd inscribed_radii(const Eigen::MatrixX3d& vertices, const Eigen::MatrixX3d& normals,
                                double cap);

}  // namespace msfem::massspring::detail
