// Three-tier inner tiers along the distance field: nested, unfolded, the seed's counts, and the
// scaled tiers on a sphere.

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <array>
#include <map>

#include "icosphere.hpp"
#include "msfem/massspring/surface_geometry.hpp"
#include "msfem/massspring/topology_builders.hpp"
#include "msfem/massspring/volume_force_field.hpp"

namespace msfem::massspring {
namespace {

using testing::icosphere;
using testing::TriangleMesh;

// The boundary of a union of unit cubes (cells (x, y, z) with solid(x, y, z)), two
// counter-clockwise triangles per exposed face, vertices shared by grid index, scaled by `h`.
template <typename Solid>
TriangleMesh voxel_surface(std::array<int, 3> cells, Solid solid, double h) {
  std::map<std::array<int, 3>, int> ids;
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3i> faces;
  const auto id = [&](std::array<int, 3> p) {
    const auto [it, added] = ids.emplace(p, static_cast<int>(points.size()));
    if (added) points.emplace_back(h * p[0], h * p[1], h * p[2]);
    return it->second;
  };
  const auto inside = [&](int x, int y, int z) {
    return x >= 0 && y >= 0 && z >= 0 && x < cells[0] && y < cells[1] && z < cells[2] &&
           solid(x, y, z);
  };
  for (int x = 0; x < cells[0]; ++x)
    for (int y = 0; y < cells[1]; ++y)
      for (int z = 0; z < cells[2]; ++z)
        for (int axis = 0; axis < 3 && inside(x, y, z); ++axis)
          for (int side : {0, 1}) {
            std::array<int, 3> next = {x, y, z};
            next[axis] += side ? 1 : -1;
            if (inside(next[0], next[1], next[2])) continue;
            // The face's corners, counter-clockwise seen from outside along +/- the axis.
            const int u = (axis + 1) % 3, v = (axis + 2) % 3;
            std::array<int, 3> c = {x, y, z};
            c[axis] += side;
            std::array<std::array<int, 3>, 4> q = {c, c, c, c};
            q[1][u] += 1;
            q[2][u] += 1;
            q[2][v] += 1;
            q[3][v] += 1;
            if (!side) std::swap(q[1], q[3]);
            faces.emplace_back(id(q[0]), id(q[1]), id(q[2]));
            faces.emplace_back(id(q[0]), id(q[2]), id(q[3]));
          }
  TriangleMesh mesh;
  mesh.vertices.resize(static_cast<Eigen::Index>(points.size()), 3);
  for (std::size_t i = 0; i < points.size(); ++i)
    mesh.vertices.row(static_cast<Eigen::Index>(i)) = points[i].transpose();
  mesh.triangles.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (std::size_t f = 0; f < faces.size(); ++f)
    mesh.triangles.row(static_cast<Eigen::Index>(f)) = faces[f].transpose();
  return mesh;
}

// A 1 cm block cut by two parallel slots 1 mm wide and 7 mm deep into fingers 2-3 mm wide: far
// thinner than the tier depths (about 1 and 3 mm at this block's mean radius), so a tier copied
// inwards by a fixed depth crosses the slots.
TriangleMesh deep_groove() {
  return voxel_surface(
      {10, 6, 10}, [](int x, int, int z) { return !(z >= 3 && (x == 3 || x == 6)); }, 1e-3);
}

ThreeTierOptions with(InnerTierMethod method) {
  ThreeTierOptions options;
  options.inner_tiers = method;
  return options;
}

// Tier k of a three-tier network (node rows k·V .. k·V + V - 1).
Eigen::MatrixX3d tier(const SpringNetwork& network, int k, Eigen::Index nv) {
  return network.rest_positions.middleRows(k * nv, nv);
}

// The shell prisms' tetrahedra (tier_prisms, all three splits) without the orientation of a shell
// under an outward surface (signed volume < 0), counted apart from inverted_tier_prisms.
int inverted_tetrahedra(const SpringNetwork& network, const Eigen::MatrixX3i& triangles) {
  const int nv = static_cast<int>(network.num_nodes() / 3);
  const VolumeElements prisms = tier_prisms(network.rest_positions, triangles, nv, 3, 1.0);
  int inverted = 0;
  for (Eigen::Index t = 0; t < prisms.tets.rows(); ++t) {
    const auto p = [&](int k) -> Eigen::Vector3d {
      return network.rest_positions.row(prisms.tets(t, k)).transpose();
    };
    if (!((p(1) - p(0)).cross(p(2) - p(0)).dot(p(3) - p(0)) < 0.0)) ++inverted;
  }
  return inverted;
}

int outside_counts(const SpringNetwork& network, const Eigen::MatrixX3i& triangles) {
  const Eigen::Index nv = network.num_nodes() / 3;
  return static_cast<int>(
      points_outside_surface(tier(network, 1, nv), tier(network, 0, nv), triangles).size() +
      points_outside_surface(tier(network, 2, nv), tier(network, 1, nv), triangles).size());
}

TEST(DistanceFieldTiers, ADeepGrooveFoldsTheFixedDepthTiersButNotThese) {
  const TriangleMesh groove = deep_groove();
  const Eigen::Index nv = groove.vertices.rows();
  const auto edges = static_cast<int>(unique_edges(groove.triangles).size());
  for (auto method : {InnerTierMethod::scaling, InnerTierMethod::normal_offset}) {
    const SpringNetwork folded = build_three_tier(groove.vertices, groove.triangles, with(method));
    EXPECT_GT(inverted_tetrahedra(folded, groove.triangles), 0);
  }
  const SpringNetwork network =
      build_three_tier(groove.vertices, groove.triangles, with(InnerTierMethod::distance_field));
  EXPECT_EQ(network.num_nodes(), 3 * nv);
  EXPECT_EQ(network.num_springs(), 4 * edges + 2 * nv);
  EXPECT_TRUE(network.warnings.empty()) << network.warnings.front();
  EXPECT_EQ(inverted_tetrahedra(network, groove.triangles), 0);
  EXPECT_TRUE(
      inverted_tier_prisms(tier(network, 0, nv), tier(network, 1, nv), groove.triangles).empty());
  EXPECT_TRUE(
      inverted_tier_prisms(tier(network, 1, nv), tier(network, 2, nv), groove.triangles).empty());
  EXPECT_EQ(outside_counts(network, groove.triangles), 0);
  // The tiers stay inside the fingers (tier 3 less than 1.5 mm deep) but off the surface.
  const Eigen::VectorXd depth3 = (tier(network, 2, nv) - groove.vertices).rowwise().norm();
  EXPECT_LT(depth3.maxCoeff(), 1.5e-3);
  EXPECT_GT(depth3.minCoeff(), 1e-4);
}

TEST(DistanceFieldTiers, OnASphereTheyAreTheScaledTiers) {
  const TriangleMesh mesh = icosphere(3, 0.05);
  const Eigen::Index nv = mesh.vertices.rows();
  const SpringNetwork scaled = build_three_tier(mesh.vertices, mesh.triangles);
  const SpringNetwork network =
      build_three_tier(mesh.vertices, mesh.triangles, with(InnerTierMethod::distance_field));
  EXPECT_EQ(network.num_nodes(), 1926);
  EXPECT_EQ(network.num_springs(), 8964);
  EXPECT_TRUE(network.warnings.empty());
  for (int k : {1, 2}) {
    const Eigen::VectorXd depth = (tier(network, k, nv) - mesh.vertices).rowwise().norm();
    const Eigen::VectorXd seed = (tier(scaled, k, nv) - mesh.vertices).rowwise().norm();
    EXPECT_LT((depth - seed).cwiseAbs().maxCoeff(), 1e-3 * seed.mean()) << "tier " << k + 1;
    // Along the vertex normal, which is radial to 0.3 %.
    const Eigen::VectorXd radius = tier(network, k, nv).rowwise().norm();
    EXPECT_LT((radius.array() - 0.05 / (k == 1 ? 1.2 : 2.0)).abs().maxCoeff(), 2e-4)
        << "tier " << k + 1;
  }
  EXPECT_EQ(inverted_tetrahedra(network, mesh.triangles), 0);
}

TEST(DistanceFieldTiers, TheInvertedPrismCheckSeesAFold) {
  const TriangleMesh mesh = icosphere(2, 0.05);
  Eigen::MatrixX3d inner = mesh.vertices * 0.8;
  EXPECT_TRUE(inverted_tier_prisms(mesh.vertices, inner, mesh.triangles).empty());
  inner.row(0) = mesh.vertices.row(0) * 1.1;  // one copy above its vertex
  const std::vector<int> folded = inverted_tier_prisms(mesh.vertices, inner, mesh.triangles);
  EXPECT_EQ(folded.size(), 5u);  // the five triangles around an icosahedron vertex
}

}  // namespace
}  // namespace msfem::massspring
