// Inner tiers along the distance field: each vertex's copies sit on its inward normal, short of
// the medial axis, at depths limited so that no shell prism folds
// (InnerTierMethod::distance_field). Here in massspring, not beside CGAL in cases, so that a
// simulator builds the same tiers. The medial depth is the largest ball that holds no other
// *vertex* (nanoflann suffices): a ball tangent at a vertex of a polyhedron always cuts the
// triangles around it, so an exact point-to-triangle distance would put the medial axis at depth 0
// at every convex vertex.

#include "inner_tiers.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <queue>
#include <utility>

#include "geometry/kd_tree.hpp"
#include "msfem/massspring/surface_geometry.hpp"
#include "msfem/massspring/topology_builders.hpp"

namespace msfem::massspring {
namespace detail {
namespace {

// Tier 3 stops at this fraction of the way to the medial axis: short of it, so that the copies of
// the two walls of a fold stay apart (at 1 they would meet), and deep, so that the fixed tier 3
// does not sit just under the surface of a narrow gyrus. On a sphere the target depth (half the
// radius) is reached first and the fraction does not matter.
constexpr double medial_fraction = 0.8;
// The largest change of tier 3's depth per unit length along the surface (tier 2's is δ_2/δ_3 of
// it): where the fold limit changes from vertex to vertex, a steeper tier shears its prisms over.
constexpr double depth_slope = 0.5;
// Each pass shortens the copies of the vertices of a folded prism or of a node outside its outer
// tier by this factor; a copy at depth → 0 lies on its vertex, where no prism folds whose
// triangle's normal agrees with its vertex normals.
constexpr double repair_factor = 0.8;
constexpr int max_repair_passes = 80;

double shrink_ball(const KdTree& tree, const Eigen::MatrixX3d& vertices, Eigen::Index i,
                   const Eigen::Vector3d& inward, double radius) {
  const Eigen::Vector3d p = vertices.row(i).transpose();
  for (int pass = 0; pass < 64 && radius > 0.0; ++pass) {
    const Eigen::Vector3d centre = p + radius * inward;
    std::size_t id = 0;
    double squared = 0.0;
    tree.knnSearch(centre.data(), 1, &id, &squared);
    const Eigen::Vector3d w = vertices.row(static_cast<Eigen::Index>(id)).transpose() - p;
    // The ball is empty when its nearest vertex is on its boundary (the vertex itself, or a tie).
    if (static_cast<Eigen::Index>(id) == i || std::sqrt(squared) >= radius * (1.0 - 1e-12))
      return radius;
    const double along = w.dot(inward);
    if (!(along > 0.0)) return 0.0;  // a duplicate vertex: no ball fits
    // The ball tangent at p through the intruding vertex: smaller than the last, and free of it.
    radius = w.squaredNorm() / (2.0 * along);
  }
  return radius;
}

// Unit face normals of the triangles around each vertex.
std::vector<std::vector<Eigen::Vector3d>> face_normals_around(const Eigen::MatrixX3d& vertices,
                                                              const Eigen::MatrixX3i& triangles) {
  std::vector<std::vector<Eigen::Vector3d>> around(static_cast<std::size_t>(vertices.rows()));
  for (Eigen::Index f = 0; f < triangles.rows(); ++f) {
    const Eigen::Vector3d a = vertices.row(triangles(f, 0)).transpose();
    const Eigen::Vector3d normal = (vertices.row(triangles(f, 1)).transpose() - a)
                                       .cross(vertices.row(triangles(f, 2)).transpose() - a)
                                       .normalized();
    for (int k = 0; k < 3; ++k)
      around[triangles(f, k)].push_back(normal);
  }
  return around;
}

double worst_agreement(const Eigen::Vector3d& direction, const std::vector<Eigen::Vector3d>& faces,
                       const Eigen::Vector3d** worst) {
  double lowest = 2.0;
  for (const auto& normal : faces)
    if (const double d = direction.dot(normal); d < lowest) {
      lowest = d;
      *worst = &normal;
    }
  return lowest;
}

// A copy moved along d keeps its prisms' orientation at small depth only if d agrees with every
// triangle around the vertex (d · n_f > 0). The area-weighted normal does not at a pinched vertex
// of a tight fold (the brain has a few), so there d is turned toward its worst triangle until the
// least agreement is as large as it gets (a subgradient ascent of min_f d · n_f).
Eigen::MatrixX3d copy_directions(const Eigen::MatrixX3d& vertices,
                                 const Eigen::MatrixX3i& triangles,
                                 const Eigen::MatrixX3d& normals) {
  constexpr double enough = 0.2;
  const auto around = face_normals_around(vertices, triangles);
  Eigen::MatrixX3d directions = normals;
  for (Eigen::Index i = 0; i < vertices.rows(); ++i) {
    Eigen::Vector3d d = normals.row(i).transpose(), best = d;
    const Eigen::Vector3d* worst = nullptr;
    double best_agreement = worst_agreement(d, around[i], &worst);
    for (int step = 1; step <= 200 && best_agreement < enough; ++step) {
      d = (d + (0.5 / std::sqrt(step)) * (*worst - worst->dot(d) * d)).normalized();
      if (const double a = worst_agreement(d, around[i], &worst); a > best_agreement) {
        best_agreement = a;
        best = d;
      }
    }
    directions.row(i) = best.transpose();
  }
  return directions;
}

// Lowers depths until neighbours differ by at most `slope` × their distance (Dijkstra's order,
// shallowest first, so that each depth is final when it is popped).
void limit_slope(Eigen::VectorXd& depth, const Eigen::MatrixX3d& vertices,
                 const std::vector<std::vector<int>>& neighbours, double slope) {
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
  for (int i = 0; i < depth.size(); ++i)
    queue.push({depth[i], i});
  while (!queue.empty()) {
    const auto [d, i] = queue.top();
    queue.pop();
    if (d > depth[i]) continue;
    for (int j : neighbours[i]) {
      const double limit = d + slope * (vertices.row(i) - vertices.row(j)).norm();
      if (limit < depth[j]) {
        depth[j] = limit;
        queue.push({limit, j});
      }
    }
  }
}

std::vector<std::vector<int>> vertex_neighbours(const Eigen::MatrixX3i& triangles, Eigen::Index n) {
  std::vector<std::vector<int>> neighbours(static_cast<std::size_t>(n));
  for (const auto& [a, b] : unique_edges(triangles)) {
    neighbours[a].push_back(b);
    neighbours[b].push_back(a);
  }
  return neighbours;
}

// The vertices of folded prisms between the tiers and of nodes outside the tier above.
std::vector<int> faulty_vertices(const Eigen::MatrixX3d& tier1, const Eigen::MatrixX3d& tier2,
                                 const Eigen::MatrixX3d& tier3, const Eigen::MatrixX3i& triangles,
                                 std::array<std::size_t, 4>& counts) {
  const std::vector<int> folded12 = inverted_tier_prisms(tier1, tier2, triangles);
  const std::vector<int> folded23 = inverted_tier_prisms(tier2, tier3, triangles);
  std::vector<int> faulty = points_outside_surface(tier2, tier1, triangles);
  const std::vector<int> outside3 = points_outside_surface(tier3, tier2, triangles);
  counts = {folded12.size(), folded23.size(), faulty.size(), outside3.size()};
  faulty.insert(faulty.end(), outside3.begin(), outside3.end());
  for (const auto* folded : {&folded12, &folded23})
    for (int f : *folded)
      for (int k = 0; k < 3; ++k)
        faulty.push_back(triangles(f, k));
  return faulty;
}

std::string describe_faults(const std::array<std::size_t, 4>& counts) {
  return "three_tier distance_field: after " + std::to_string(max_repair_passes) +
         " depth reductions " + std::to_string(counts[0]) + " tier 1-2 and " +
         std::to_string(counts[1]) + " tier 2-3 prisms are still folded, " +
         std::to_string(counts[2]) + " tier 2 nodes lie outside tier 1 and " +
         std::to_string(counts[3]) +
         " tier 3 nodes outside tier 2 (a vertex normal against its own triangles?)";
}

}  // namespace

Eigen::VectorXd inscribed_radii(const Eigen::MatrixX3d& vertices, const Eigen::MatrixX3d& normals,
                                double cap) {
  PointCloud cloud{vertices};
  KdTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  tree.buildIndex();
  Eigen::VectorXd radii(vertices.rows());
  for (Eigen::Index i = 0; i < vertices.rows(); ++i)
    radii[i] = shrink_ball(tree, vertices, i, -normals.row(i).transpose(), cap);
  return radii;
}

DistanceFieldTiers distance_field_tiers(const Eigen::MatrixX3d& vertices,
                                        const Eigen::MatrixX3i& triangles,
                                        const Eigen::MatrixX3d& area_normals, double depth2,
                                        double depth3) {
  const Eigen::MatrixX3d normals = copy_directions(vertices, triangles, area_normals);
  // Tier 3's depth: the target, or short of the medial axis where that is nearer.
  Eigen::VectorXd depth =
      (medial_fraction * inscribed_radii(vertices, normals, depth3 / medial_fraction))
          .cwiseMin(depth3);
  const auto neighbours = vertex_neighbours(triangles, vertices.rows());
  DistanceFieldTiers tiers;
  std::array<std::size_t, 4> counts{};
  for (int pass = 0;; ++pass) {
    limit_slope(depth, vertices, neighbours, depth_slope);
    tiers.tier3 = vertices - normals.cwiseProduct(depth.replicate(1, 3));
    tiers.tier2 = vertices - normals.cwiseProduct((depth2 / depth3 * depth).replicate(1, 3));
    const std::vector<int> faulty =
        faulty_vertices(vertices, tiers.tier2, tiers.tier3, triangles, counts);
    if (faulty.empty()) return tiers;
    if (pass == max_repair_passes) break;
    for (int v : faulty)
      depth[v] *= repair_factor;  // a vertex met twice shrinks once per meeting, which is harmless
  }
  tiers.warnings.push_back(describe_faults(counts));
  return tiers;
}

}  // namespace detail

std::vector<int> inverted_tier_prisms(const Eigen::MatrixX3d& outer, const Eigen::MatrixX3d& inner,
                                      const Eigen::MatrixX3i& triangles) {
  const auto at = [&](int tier, int v) -> Eigen::Vector3d {
    return (tier == 0 ? outer : inner).row(v).transpose();
  };
  // Six times the signed volume; a shell prism under an outward surface has it negative.
  const auto volume6 = [](const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                          const Eigen::Vector3d& r,
                          const Eigen::Vector3d& s) { return (q - p).cross(r - p).dot(s - p); };
  std::vector<int> folded;
  for (Eigen::Index f = 0; f < triangles.rows(); ++f) {
    const int v[3] = {triangles(f, 0), triangles(f, 1), triangles(f, 2)};
    const Eigen::Vector3d outer_normal =
        (at(0, v[1]) - at(0, v[0])).cross(at(0, v[2]) - at(0, v[0]));
    const Eigen::Vector3d inner_normal =
        (at(1, v[1]) - at(1, v[0])).cross(at(1, v[2]) - at(1, v[0]));
    double longest = 0.0;
    for (int k = 0; k < 3; ++k)
      longest = std::max({longest, (at(0, v[k]) - at(0, v[(k + 1) % 3])).norm(),
                          (at(0, v[k]) - at(1, v[k])).norm()});
    // A tetrahedron of numerically zero volume counts as folded: it has no orientation to keep.
    const double sliver = -1e-9 * longest * longest * longest;
    bool bad = !(outer_normal.dot(inner_normal) > 0.0);
    for (int r = 0; r < 3 && !bad; ++r) {
      const int a = v[r], b = v[(r + 1) % 3], c = v[(r + 2) % 3];
      bad = !(volume6(at(0, a), at(0, b), at(0, c), at(1, a)) < sliver) ||
            !(volume6(at(0, b), at(0, c), at(1, a), at(1, b)) < sliver) ||
            !(volume6(at(0, c), at(1, a), at(1, b), at(1, c)) < sliver);
    }
    if (bad) folded.push_back(static_cast<int>(f));
  }
  return folded;
}

}  // namespace msfem::massspring
