// Topology builders: node and spring counts of every variant, masses, starting stiffness.

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <set>

#include "icosphere.hpp"
#include "msfem/massspring/analytic_stiffness.hpp"
#include "msfem/massspring/errors.hpp"
#include "msfem/massspring/surface_geometry.hpp"
#include "msfem/massspring/topology_builders.hpp"
#include "msfem/massspring_bench/benchmark_cases.hpp"

namespace msfem::massspring {
namespace {

using testing::icosphere;

TEST(Icosphere, CountsFollowTheSubdivisionFormula) {
  for (int level = 0; level <= 3; ++level) {
    const auto mesh = icosphere(level, 1.0);
    const int four_n = 1 << (2 * level);
    EXPECT_EQ(mesh.vertices.rows(), 10 * four_n + 2);
    EXPECT_EQ(mesh.triangles.rows(), 20 * four_n);
    EXPECT_EQ(static_cast<int>(unique_edges(mesh.triangles).size()), 30 * four_n);
    EXPECT_GT(enclosed_volume(mesh.vertices, mesh.triangles), 0.0);
  }
}

// The layered-brain seed's test sphere: 642 vertices per tier -> 1,926 nodes and 8,964 springs.
TEST(ThreeTier, ReproducesTheSeedSphere) {
  const auto mesh = icosphere(3, 0.05);
  const SpringNetwork network = build_three_tier(mesh.vertices, mesh.triangles);
  EXPECT_EQ(network.num_nodes(), 1926);
  EXPECT_EQ(network.num_springs(), 8964);
  EXPECT_EQ(network.spring_group_sizes(), (std::vector<int>{1920, 1920, 3840, 642, 642}));
  EXPECT_EQ(network.fixed_nodes.size(), 642u);
  EXPECT_EQ(network.surface_nodes.size(), 642u);
  EXPECT_TRUE(network.warnings.empty());
  // Tier 2 is the surface scaled by 1/1.2, tier 3 by 1/2 about the centroid (here the origin).
  EXPECT_NEAR(network.rest_positions.row(642 + 17).norm(), 0.05 / 1.2, 1e-12);
  EXPECT_NEAR(network.rest_positions.row(2 * 642 + 17).norm(), 0.05 / 2.0, 1e-12);
  // Masses lumped from the enclosed volume.
  const double volume = enclosed_volume(mesh.vertices, mesh.triangles);
  EXPECT_NEAR(network.masses.sum(), 1040.0 * volume, 1e-9 * 1040.0 * volume);
  EXPECT_TRUE((network.stiffness.array() > 0.0).all());
}

TEST(ThreeTier, NormalOffsetTiersOnASphereMatchScaling) {
  const auto mesh = icosphere(2, 0.05);
  ThreeTierOptions options;
  options.inner_tiers = InnerTierMethod::normal_offset;
  const SpringNetwork network = build_three_tier(mesh.vertices, mesh.triangles, options);
  EXPECT_EQ(network.num_nodes(), 3 * 162);
  EXPECT_EQ(network.num_springs(), 4 * 480 + 2 * 162);
  EXPECT_TRUE(network.warnings.empty());
  for (int i = 0; i < 162; ++i) {
    EXPECT_NEAR(network.rest_positions.row(162 + i).norm(), 0.05 / 1.2, 2e-4);
    EXPECT_NEAR(network.rest_positions.row(324 + i).norm(), 0.05 / 2.0, 2e-4);
  }
}

// Scaling a surface that is not star-shaped about its centroid pushes inner tiers outside.
TEST(ThreeTier, DetectsInnerTierOutsideAConcaveSurface) {
  const auto banana = testing::bent_banana(3, 0.05);
  const SpringNetwork scaled = build_three_tier(banana.vertices, banana.triangles);
  ASSERT_FALSE(scaled.warnings.empty());
  EXPECT_NE(scaled.warnings.front().find("outside"), std::string::npos);

  ThreeTierOptions reject;
  reject.reject_inner_tier_outside = true;
  EXPECT_THROW(build_three_tier(banana.vertices, banana.triangles, reject), ModelError);

  ThreeTierOptions offset;
  offset.inner_tiers = InnerTierMethod::normal_offset;
  offset.tier2_offset = 0.004;
  offset.tier3_offset = 0.008;
  const SpringNetwork offset_network = build_three_tier(banana.vertices, banana.triangles, offset);
  EXPECT_TRUE(offset_network.warnings.empty());
}

// An inner tier offset past the centre turns inside out, and its enclosed volume no longer sits
// inside the middle tier's (the brain's offset tier 3 folds the same way in its sulci). The shell's
// springs must keep a stiffness: from the vertex prisms, the same as an unfolded shell of equal
// thickness would get from its volume to within the prisms' approximation.
TEST(ThreeTier, FoldedInnerTierKeepsItsShellStiffness) {
  const auto mesh = icosphere(3, 0.05);
  ThreeTierOptions folded;
  folded.inner_tiers = InnerTierMethod::normal_offset;
  folded.tier2_offset = 0.01;   // tier 2 at r = 0.04
  folded.tier3_offset = 0.085;  // tier 3 through the centre: r = -0.035, inside out
  const SpringNetwork network = build_three_tier(mesh.vertices, mesh.triangles, folded);
  const int r23 = network.spring_group_id("tier23_radial");
  double sum = 0;
  int count = 0;
  for (int s = 0; s < network.num_springs(); ++s)
    if (network.spring_group[s] == r23) {
      EXPECT_GT(network.stiffness[s], 0.0) << s;
      sum += network.stiffness[s];
      ++count;
    }
  EXPECT_EQ(count, 642);
  EXPECT_TRUE(std::any_of(network.warnings.begin(), network.warnings.end(),
                          [](const auto& w) { return w.find("prisms") != std::string::npos; }));
  // Prism volume: Σ (A2 + A3)/2 × 0.075 with A2 = 4π 0.04², A3 = 4π 0.035² (areas of the tiers).
  const double prisms = 0.5 * 4 * M_PI * (0.04 * 0.04 + 0.035 * 0.035) * 0.075;
  const Eigen::VectorXd lengths = Eigen::VectorXd::Constant(642, 0.075);
  const double expected = isotropic_network_stiffness(3000.0, prisms, lengths)[0];
  EXPECT_NEAR(sum / count / expected, 1.0, 0.03);
  // The lumped mass stays the body's, ρV, although tier 3 encloses an inconsistent volume.
  const double body = 1040.0 * std::abs(enclosed_volume(mesh.vertices, mesh.triangles));
  EXPECT_NEAR(network.masses.sum() / body, 1.0, 1e-9);
}

// Splits every triangle whose centroid lies within `radius` of `point` at that centroid (a
// conforming local refinement that keeps the surface's shape).
testing::TriangleMesh refine_at(testing::TriangleMesh mesh, const Eigen::Vector3d& point,
                                double radius) {
  std::vector<Eigen::Vector3i> triangles;
  std::vector<Eigen::RowVector3d> added;
  const int nv = int(mesh.vertices.rows());
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    const Eigen::Vector3i f = mesh.triangles.row(t);
    const Eigen::RowVector3d c =
        (mesh.vertices.row(f[0]) + mesh.vertices.row(f[1]) + mesh.vertices.row(f[2])) / 3.0;
    if ((c.transpose() - point).norm() > radius) {
      triangles.push_back(f);
      continue;
    }
    const int m = nv + int(added.size());
    added.push_back(c);
    triangles.push_back({f[0], f[1], m});
    triangles.push_back({f[1], f[2], m});
    triangles.push_back({f[2], f[0], m});
  }
  mesh.vertices.conservativeResize(nv + Eigen::Index(added.size()), 3);
  for (std::size_t k = 0; k < added.size(); ++k)
    mesh.vertices.row(nv + Eigen::Index(k)) = added[k];
  mesh.triangles.resize(Eigen::Index(triangles.size()), 3);
  for (std::size_t k = 0; k < triangles.size(); ++k)
    mesh.triangles.row(Eigen::Index(k)) = triangles[k].transpose();
  return mesh;
}

// Σ k l² of a group's springs whose first node belongs to a surface vertex in the cap (node i of
// every tier to vertex i mod V), per unit of the cap's area: the network's modulus there
// (Σ k l² = 6 E V for the isotropic rule).
double modulus_density(const SpringNetwork& n, const testing::TriangleMesh& mesh,
                       const std::string& group, const Eigen::Vector3d& pole, double cap) {
  const int g = int(std::find(n.spring_group_names.begin(), n.spring_group_names.end(), group) -
                    n.spring_group_names.begin());
  const Eigen::VectorXd areas = vertex_areas(mesh.vertices, mesh.triangles);
  double sum = 0.0, area = 0.0;
  for (int s = 0; s < n.num_springs(); ++s) {
    const Eigen::Index vertex = n.springs(s, 0) % mesh.vertices.rows();
    if (n.spring_group[s] != g || (mesh.vertices.row(vertex).transpose() - pole).norm() > cap)
      continue;
    sum += n.stiffness[s] * n.rest_length[s] * n.rest_length[s];
  }
  for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v)
    if ((mesh.vertices.row(v).transpose() - pole).norm() <= cap) area += areas[v];
  return sum / area;
}

// Each spring's share of its shell's volume follows the vertex areas at its ends: a patch with
// nine times the triangles is as stiff per area as before (equal shares made it 7.7x stiffer).
TEST(ThreeTier, ALocallyRefinedPatchKeepsItsModulus) {
  const auto coarse = icosphere(3, 0.05);
  const Eigen::Vector3d pole(0, 0, 0.05);
  const auto fine = refine_at(refine_at(coarse, pole, 0.015), pole, 0.015);
  ASSERT_GT(fine.vertices.rows(), coarse.vertices.rows() + 60);
  const SpringNetwork a = build_three_tier(coarse.vertices, coarse.triangles);
  const SpringNetwork b = build_three_tier(fine.vertices, fine.triangles);
  for (const char* group : {"tier12_radial", "tier23_radial"}) {
    const double ratio =
        modulus_density(b, fine, group, pole, 0.01) / modulus_density(a, coarse, group, pole, 0.01);
    EXPECT_NEAR(ratio, 1.0, 0.1) << group;
  }
  // The surface's edges: every fine edge's share is its smaller end's area.
  const double edges = modulus_density(b, fine, "tier1_edges", pole, 0.01) /
                       modulus_density(a, coarse, "tier1_edges", pole, 0.01);
  EXPECT_GT(edges, 0.5);
  EXPECT_LT(edges, 1.5);
}

// Σ k (n·(v_a − v_b))²: the network's stiffness against the mode v at rest (springs untensioned).
double mode_stiffness(const SpringNetwork& n, const std::vector<Eigen::Vector3d>& v) {
  double sum = 0.0;
  for (int s = 0; s < n.num_springs(); ++s) {
    const int a = n.springs(s, 0), b = n.springs(s, 1);
    const Eigen::Vector3d axis =
        (n.rest_positions.row(b) - n.rest_positions.row(a)).transpose().normalized();
    const double stretch = axis.dot(v[std::size_t(b)] - v[std::size_t(a)]);
    sum += n.stiffness[s] * stretch * stretch;
  }
  return sum;
}

// The seed's tier 2 hangs on the fixed tier 3 by radial springs only: turning tiers 1 and 2 as a
// rigid body about the centre stretches no spring (to first order). The inner diagonals resist it.
TEST(ThreeTier, InnerDiagonalsResistTheOuterShellTurningAboutTheCore) {
  const auto mesh = icosphere(3, 0.05);
  ThreeTierOptions with;
  with.tier23_diagonals = true;
  const SpringNetwork seed = build_three_tier(mesh.vertices, mesh.triangles);
  const SpringNetwork braced = build_three_tier(mesh.vertices, mesh.triangles, with);
  EXPECT_EQ(seed.num_springs(), 8964);
  EXPECT_EQ(braced.num_springs(), 8964 + 2 * 1920);  // two per edge
  const int nv = 642;
  auto turn = [&](const SpringNetwork& n) {
    std::vector<Eigen::Vector3d> v(std::size_t(n.num_nodes()), Eigen::Vector3d::Zero());
    for (int i = 0; i < 2 * nv; ++i)  // tiers 1 and 2 about the x axis, tier 3 held
      v[std::size_t(i)] = Eigen::Vector3d::UnitX().cross(n.rest_positions.row(i).transpose());
    return v;
  };
  auto push = [&](const SpringNetwork& n) {  // tiers 1 and 2 pushed along z instead
    std::vector<Eigen::Vector3d> v(std::size_t(n.num_nodes()), Eigen::Vector3d::Zero());
    for (int i = 0; i < 2 * nv; ++i)
      v[std::size_t(i)] = 0.05 * Eigen::Vector3d::UnitZ();  // the same size as the turn's
    return v;
  };
  EXPECT_LT(mode_stiffness(seed, turn(seed)), 1e-12 * mode_stiffness(seed, push(seed)));
  // The diagonals lie within ~20° of the radial springs (a 17 mm shell, 6 mm edges): a turn meets
  // a few per cent of the stiffness of a push.
  EXPECT_GT(mode_stiffness(braced, turn(braced)), 0.01 * mode_stiffness(braced, push(braced)));
}

TEST(SingleLayer, SurfaceEdgesAndAnchors) {
  const auto mesh = icosphere(3, 0.05);
  const SpringNetwork network = build_single_layer(mesh.vertices, mesh.triangles);
  EXPECT_EQ(network.num_nodes(), 642);
  EXPECT_EQ(network.num_springs(), 1920);
  EXPECT_EQ(network.num_anchors(), 642);
  SingleLayerOptions no_anchors;
  no_anchors.anchor_to_rest = false;
  EXPECT_EQ(build_single_layer(mesh.vertices, mesh.triangles, no_anchors).num_anchors(), 0);
}

TEST(Skeleton, LinksEachSurfaceVertexToItsFourNearestControlPoints) {
  const auto surface = icosphere(3, 0.05);
  const auto control = icosphere(1, 0.05);  // stands in for a simplified surface: 42 vertices
  SkeletonOptions options;
  options.control_scale = 0.5;
  const SpringNetwork network = build_skeleton(surface.vertices, surface.triangles,
                                               control.vertices, control.triangles, options);
  EXPECT_EQ(network.num_nodes(), 642 + 42);
  EXPECT_EQ(network.num_springs(), 1920 + 120 + 4 * 642);
  EXPECT_EQ(network.spring_group_sizes(), (std::vector<int>{1920, 120, 4 * 642}));

  // Brute-force check of the k-d tree on every surface vertex.
  const int links = network.spring_group_id("links");
  for (int i = 0; i < 642; ++i) {
    std::vector<std::pair<double, int>> by_distance;
    for (int c = 0; c < 42; ++c)
      by_distance.emplace_back(
          (network.rest_positions.row(642 + c) - network.rest_positions.row(i)).squaredNorm(),
          642 + c);
    std::sort(by_distance.begin(), by_distance.end());
    std::set<int> expected, linked;
    for (int k = 0; k < 4; ++k)
      expected.insert(by_distance[k].second);
    for (int s = 0; s < network.num_springs(); ++s)
      if (network.spring_group[s] == links && network.springs(s, 0) == i)
        linked.insert(network.springs(s, 1));
    // Ties in distance may pick either of equally near points: compare distances, not ids.
    ASSERT_EQ(linked.size(), 4u);
    double farthest_linked = 0.0;
    for (int c : linked)
      farthest_linked =
          std::max(farthest_linked,
                   (network.rest_positions.row(c) - network.rest_positions.row(i)).squaredNorm());
    EXPECT_NEAR(farthest_linked, by_distance[3].first, 1e-15);
  }
}

TEST(TetEdges, KuhnCubeCountsMassesAndStiffness) {
  Eigen::MatrixX3d cube;
  Eigen::MatrixX4i tets;
  testing::kuhn_cube(cube, tets);
  TetEdgesOptions options;
  options.material.density = 1000.0;
  options.material.youngs_modulus = 5000.0;
  const SpringNetwork network = build_tet_edges(cube, tets, options);
  EXPECT_EQ(network.num_nodes(), 8);
  EXPECT_EQ(network.num_springs(), 19);
  EXPECT_EQ(network.surface_triangles.rows(), 12);
  EXPECT_EQ(network.surface_nodes.size(), 8u);
  EXPECT_NEAR(network.masses.sum(), 1000.0, 1e-9);
  EXPECT_GT(enclosed_volume(cube, network.surface_triangles), 0.0);  // outward boundary
  EXPECT_NEAR(enclosed_volume(cube, network.surface_triangles), 1.0, 1e-12);
  // The main diagonal 0-7 belongs to all six tetrahedra.
  for (int s = 0; s < network.num_springs(); ++s)
    if (network.springs(s, 0) == 0 && network.springs(s, 1) == 7) {
      EXPECT_NEAR(network.stiffness[s], 6.0 * lloyd_tet_edge_stiffness(5000.0, std::sqrt(3.0)),
                  1e-9);
    }

  options.stiffness_rule = TetStiffnessRule::van_gelder;
  const SpringNetwork gelder = build_tet_edges(cube, tets, options);
  for (int s = 0; s < gelder.num_springs(); ++s)
    if (gelder.springs(s, 0) == 0 && gelder.springs(s, 1) == 7) {
      EXPECT_NEAR(gelder.stiffness[s], 5000.0 * 1.0 / 3.0, 1e-9);  // E · (6 × 1/6) / 3
    }
}

TEST(GeodesicSphere, CountsAndTheSeedSphere) {
  for (int m : {1, 3, 8, 30}) {
    Eigen::MatrixX3d v;
    Eigen::MatrixX3i f;
    geodesic_sphere(m, 0.05, v, f);
    EXPECT_EQ(v.rows(), 10 * m * m + 2);
    EXPECT_EQ(f.rows(), 20 * m * m);
    EXPECT_EQ(static_cast<int>(unique_edges(f).size()), 30 * m * m);
    const double sphere = 4.0 / 3.0 * 3.14159265358979 * 0.05 * 0.05 * 0.05;
    EXPECT_LT(enclosed_volume(v, f), sphere);
    if (m == 30) {
      EXPECT_NEAR(enclosed_volume(v, f) / sphere, 1.0, 0.01);
    }
    EXPECT_GT(enclosed_volume(v, f), 0.0);
  }
  Eigen::MatrixX3d v;
  Eigen::MatrixX3i f;
  geodesic_sphere(8, 0.05, v, f);
  const SpringNetwork seed = build_three_tier(v, f);
  EXPECT_EQ(seed.num_nodes(), 1926);
  EXPECT_EQ(seed.num_springs(), 8964);
}

TEST(AnalyticStiffness, Formulas) {
  EXPECT_NEAR(lloyd_tet_edge_stiffness(3000.0, 0.01), 2.0 * std::sqrt(2.0) / 25.0 * 30.0, 1e-12);
  EXPECT_NEAR(van_gelder_stiffness(3000.0, 1e-6, 0.01), 30.0, 1e-12);
  Eigen::VectorXd lengths(2);
  lengths << 0.01, 0.02;
  const Eigen::VectorXd k = isotropic_network_stiffness(3000.0, 1e-6, lengths);
  EXPECT_NEAR((k.array() * lengths.array().square()).sum(), 6.0 * 3000.0 * 1e-6, 1e-15);
  // Shares: Σ k l² still 6 E V, split 1 : 3; equal shares are the rule above.
  Eigen::VectorXd shares(2);
  shares << 1.0, 3.0;
  const Eigen::VectorXd w = isotropic_network_stiffness(3000.0, 1e-6, lengths, shares);
  EXPECT_NEAR(w[0] * 1e-4, 0.25 * 6.0 * 3000.0 * 1e-6, 1e-15);
  EXPECT_NEAR(w[1] * 4e-4, 0.75 * 6.0 * 3000.0 * 1e-6, 1e-15);
  const Eigen::VectorXd equal =
      isotropic_network_stiffness(3000.0, 1e-6, lengths, Eigen::VectorXd::Constant(2, 7.0));
  EXPECT_NEAR((equal - k).norm(), 0.0, 1e-12 * k.norm());
  shares[1] = 0.0;
  EXPECT_THROW(isotropic_network_stiffness(3000.0, 1e-6, lengths, shares), ModelError);
  EXPECT_THROW(isotropic_network_stiffness(3000.0, 1e-6, lengths, Eigen::VectorXd::Ones(3)),
               ModelError);
}

}  // namespace
}  // namespace msfem::massspring
