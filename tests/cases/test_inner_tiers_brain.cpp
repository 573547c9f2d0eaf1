// The three-tier model's inner tiers on the real cortex (cases/data/brain_icbm152_lh_9177_mm.obj):
// the fixed-depth tiers fold in its sulci, the distance field's do not.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <string>

#include "msfem/cases/surface_io.hpp"
#include "msfem/massspring/surface_geometry.hpp"
#include "msfem/massspring/topology_builders.hpp"
#include "msfem/massspring/volume_force_field.hpp"

namespace msfem::cases {
namespace {

namespace ms = msfem::massspring;

// Tetrahedra of the shell prisms (tier_prisms: every prism split all three ways) whose signed
// volume is not negative, the orientation of a shell under an outward surface.
int inverted_tetrahedra(const Eigen::MatrixX3d& positions, const Eigen::MatrixX3i& triangles) {
  const int nv = static_cast<int>(positions.rows() / 3);
  const ms::VolumeElements prisms = ms::tier_prisms(positions, triangles, nv, 3, 1.0);
  int inverted = 0;
  for (Eigen::Index t = 0; t < prisms.tets.rows(); ++t) {
    const auto p = [&](int k) -> Eigen::Vector3d {
      return positions.row(prisms.tets(t, k)).transpose();
    };
    if (!((p(1) - p(0)).cross(p(2) - p(0)).dot(p(3) - p(0)) < 0.0)) ++inverted;
  }
  return inverted;
}

ms::SpringNetwork brain_network(const Surface& brain, ms::InnerTierMethod method) {
  ms::ThreeTierOptions options;
  options.inner_tiers = method;
  return ms::build_three_tier(brain.vertices, brain.triangles, options);
}

TEST(BrainInnerTiers, TheDistanceFieldTiersNeitherFoldNorLeaveTheTierAbove) {
  const Surface brain = read_surface(
      std::string(MSFEM_CASES_DIR) + "/data/brain_icbm152_lh_9177_mm.obj", LengthUnit::millimetre);
  const Eigen::Index nv = brain.vertices.rows();
  ASSERT_EQ(nv, 9177);
  // What the fixed-depth tiers do here (the reason for the distance field).
  const ms::SpringNetwork offset = brain_network(brain, ms::InnerTierMethod::normal_offset);
  EXPECT_GT(inverted_tetrahedra(offset.rest_positions, brain.triangles), 10000);

  const ms::SpringNetwork network = brain_network(brain, ms::InnerTierMethod::distance_field);
  const auto edges = static_cast<Eigen::Index>(ms::unique_edges(brain.triangles).size());
  EXPECT_EQ(network.num_nodes(), 3 * nv);
  EXPECT_EQ(network.num_springs(), 4 * edges + 2 * nv);
  EXPECT_TRUE(network.warnings.empty()) << network.warnings.front();
  EXPECT_EQ(inverted_tetrahedra(network.rest_positions, brain.triangles), 0);
  const Eigen::MatrixX3d tier2 = network.rest_positions.middleRows(nv, nv);
  const Eigen::MatrixX3d tier3 = network.rest_positions.middleRows(2 * nv, nv);
  EXPECT_TRUE(ms::inverted_tier_prisms(brain.vertices, tier2, brain.triangles).empty());
  EXPECT_TRUE(ms::inverted_tier_prisms(tier2, tier3, brain.triangles).empty());
  EXPECT_TRUE(ms::points_outside_surface(tier2, brain.vertices, brain.triangles).empty());
  EXPECT_TRUE(ms::points_outside_surface(tier3, tier2, brain.triangles).empty());
  // Not collapsed onto the surface: the shells keep a volume (tier 3 about 2.5 mm deep on average).
  const double v1 = ms::enclosed_volume(brain.vertices, brain.triangles);
  EXPECT_LT(ms::enclosed_volume(tier2, brain.triangles), 0.9 * v1);
  EXPECT_LT(ms::enclosed_volume(tier3, brain.triangles), 0.6 * v1);
  EXPECT_GT((tier3 - brain.vertices).rowwise().norm().mean(), 2e-3);
}

}  // namespace
}  // namespace msfem::cases
