// Three-tier layered model (the brain seed): the surface, two inward copies, springs between them.

#include <cmath>
#include <string>
#include <utility>

#include "builder_support.hpp"
#include "inner_tiers.hpp"
#include "msfem/massspring/errors.hpp"
#include "msfem/massspring/surface_geometry.hpp"
#include "msfem/massspring/topology_builders.hpp"

namespace msfem::massspring {
namespace {

// The spring groups, named here once (spring_groups lists them for callers).
constexpr const char* tier1_group = "tier1_edges";
constexpr const char* tier2_group = "tier2_edges";
constexpr const char* tier12_diagonal_group = "tier12_diagonals";
constexpr const char* tier12_radial_group = "tier12_radial";
constexpr const char* tier23_radial_group = "tier23_radial";
constexpr const char* tier23_diagonal_group = "tier23_diagonals";

void check_options(const ThreeTierOptions& options) {
  if (options.inner_tiers != InnerTierMethod::normal_offset) {
    if (!std::isfinite(options.tier2_scale) || !(options.tier2_scale > 1.0))
      throw ModelError("three_tier tier2_scale " + std::to_string(options.tier2_scale) +
                       " must be finite and > 1");
    if (!std::isfinite(options.tier3_scale) || !(options.tier3_scale > options.tier2_scale))
      throw ModelError("three_tier tier3_scale " + std::to_string(options.tier3_scale) +
                       " must be finite and > tier2_scale");
  }
  if (options.inner_tiers != InnerTierMethod::scaling) {
    if (!std::isfinite(options.tier2_offset) || !std::isfinite(options.tier3_offset))
      throw ModelError("three_tier tier offsets must be finite");
    if (options.tier2_offset > 0.0 && options.tier3_offset > 0.0 &&
        !(options.tier3_offset > options.tier2_offset))
      throw ModelError("three_tier tier3_offset " + std::to_string(options.tier3_offset) +
                       " must exceed tier2_offset " + std::to_string(options.tier2_offset));
  }
}

// Tiers 2 and 3 by the chosen method. The depths along the normal default to those of the scaling
// on a sphere of the surface's mean radius about c.
detail::DistanceFieldTiers inner_tiers(const Eigen::MatrixX3d& vertices,
                                       const Eigen::MatrixX3i& triangles,
                                       const ThreeTierOptions& options,
                                       const Eigen::Vector3d& centroid) {
  const double scales[2] = {options.tier2_scale, options.tier3_scale};
  if (options.inner_tiers == InnerTierMethod::scaling) {
    const auto scaled = [&](double s) -> Eigen::MatrixX3d {
      return ((vertices.rowwise() - centroid.transpose()) / s).rowwise() + centroid.transpose();
    };
    return {scaled(scales[0]), scaled(scales[1]), {}};
  }
  const double mean_radius = (vertices.rowwise() - centroid.transpose()).rowwise().norm().mean();
  const double offsets[2] = {options.tier2_offset, options.tier3_offset};
  double depth[2];
  for (int k = 0; k < 2; ++k)
    depth[k] = offsets[k] > 0.0 ? offsets[k] : (1.0 - 1.0 / scales[k]) * mean_radius;
  const Eigen::MatrixX3d normals = vertex_normals(vertices, triangles);
  if (options.inner_tiers == InnerTierMethod::distance_field)
    return detail::distance_field_tiers(vertices, triangles, normals, depth[0], depth[1]);
  return {vertices - depth[0] * normals, vertices - depth[1] * normals, {}};
}

// Reports inner-tier nodes found outside the next outer tier.
// The volume a shell's springs share: the difference of the enclosed volumes, unless the inner tier
// is not nested in the outer one (a concave surface offset inward folds over, and its enclosed
// volume can exceed the outer's: the brain's tier 3 does), when the clamped difference would give
// the shell's springs no stiffness at all. Then the prisms between corresponding vertices, mean
// vertex area × distance, which are positive by construction.
double stiffness_volume(SpringNetwork& network, const Eigen::MatrixX3d& outer,
                        const Eigen::MatrixX3d& inner, const Eigen::MatrixX3i& triangles,
                        double enclosed_difference, const std::string& shell) {
  const Eigen::VectorXd outer_areas = vertex_areas(outer, triangles);
  const Eigen::VectorXd inner_areas = vertex_areas(inner, triangles);
  double prisms = 0.0;
  for (Eigen::Index i = 0; i < outer.rows(); ++i)
    prisms += 0.5 * (outer_areas[i] + inner_areas[i]) * (outer.row(i) - inner.row(i)).norm();
  if (enclosed_difference > 0.25 * prisms) return enclosed_difference;
  network.warnings.push_back("the shell between " + shell + " encloses " +
                             std::to_string(enclosed_difference) +
                             " m^3 by volume difference (tiers not nested); its springs' stiffness "
                             "uses the vertex prisms' volume, " +
                             std::to_string(prisms) + " m^3");
  return prisms;
}

void check_nesting(SpringNetwork& network, const Eigen::MatrixX3d& inner,
                   const Eigen::MatrixX3d& outer, const Eigen::MatrixX3i& triangles,
                   const char* inner_name, const char* outer_name, InnerTierMethod method,
                   bool reject) {
  const std::vector<int> outside = points_outside_surface(inner, outer, triangles);
  if (outside.empty()) return;
  const std::string message =
      std::string("three_tier: ") + std::to_string(outside.size()) + " of " +
      std::to_string(inner.rows()) + " " + inner_name + " nodes (first: vertex " +
      std::to_string(outside.front()) + ") lie outside " + outer_name +
      (method == InnerTierMethod::scaling
           ? "; scaling a concave surface does that, use InnerTierMethod::distance_field"
       : method == InnerTierMethod::normal_offset
           ? "; an inward offset deeper than the surface's folds are wide folds the tier over "
             "itself, use InnerTierMethod::distance_field"
           : "; the distance field's depth reduction could not mend it");
  if (reject) throw ModelError(message);
  network.warnings.push_back(message);
}

}  // namespace

SpringNetwork build_three_tier(const Eigen::MatrixX3d& vertices, const Eigen::MatrixX3i& triangles,
                               const ThreeTierOptions& options) {
  check_surface(vertices, triangles, "three_tier surface");
  detail::check_material(options.material);
  check_options(options);

  const int nv = static_cast<int>(vertices.rows());
  const Eigen::Vector3d centroid = options.center.value_or(vertex_centroid(vertices));
  detail::DistanceFieldTiers built = inner_tiers(vertices, triangles, options, centroid);
  const Eigen::MatrixX3d& tier2 = built.tier2;
  const Eigen::MatrixX3d& tier3 = built.tier3;

  SpringNetwork network;
  network.warnings = std::move(built.warnings);
  check_nesting(network, tier2, vertices, triangles, "tier 2", "tier 1", options.inner_tiers,
                options.reject_inner_tier_outside);
  check_nesting(network, tier3, tier2, triangles, "tier 3", "tier 2", options.inner_tiers,
                options.reject_inner_tier_outside);

  detail::add_nodes(network, vertices, "tier1");
  detail::add_nodes(network, tier2, "tier2");
  detail::add_nodes(network, tier3, "tier3");

  // Springs: 4E + 2V.
  const auto edges = unique_edges(triangles);
  std::vector<std::array<int, 2>> tier1_edges, tier2_edges, diagonals, radial12, radial23;
  for (const auto& [a, b] : edges) {
    tier1_edges.push_back({a, b});
    tier2_edges.push_back({nv + a, nv + b});
    diagonals.push_back({a, nv + b});  // two crossing diagonals of the quad a1 b1 b2 a2
    diagonals.push_back({b, nv + a});
  }
  for (int i = 0; i < nv; ++i) {
    radial12.push_back({i, nv + i});
    radial23.push_back({nv + i, 2 * nv + i});
  }
  const int g1 = add_springs(network, tier1_edges, tier1_group);
  const int g2 = add_springs(network, tier2_edges, tier2_group);
  const int g12 = add_springs(network, diagonals, tier12_diagonal_group);
  const int r12 = add_springs(network, radial12, tier12_radial_group);
  const int r23 = add_springs(network, radial23, tier23_radial_group);
  std::vector<int> shell23_groups = {r23};
  if (options.tier23_diagonals) {
    std::vector<std::array<int, 2>> inner;
    for (const auto& [a, b] : edges) {
      inner.push_back({nv + a, 2 * nv + b});
      inner.push_back({nv + b, 2 * nv + a});
    }
    shell23_groups.push_back(add_springs(network, inner, tier23_diagonal_group));
  }

  // Masses lumped from volume: half of each shell to each of its two tiers, by vertex area; the
  // core inside tier 3 to tier 3. Volumes of inverted (non-nested) tiers are clamped at zero.
  const double volume1 = std::abs(enclosed_volume(vertices, triangles));
  const double volume2 = std::abs(enclosed_volume(tier2, triangles));
  const double volume3 = std::abs(enclosed_volume(tier3, triangles));
  const double shell12 = std::max(volume1 - volume2, 0.0);
  const double shell23 = std::max(volume2 - volume3, 0.0);
  const double rho = options.material.density;
  const double total_mass = rho * volume1;
  // Tier 3 takes what is left of ρV, so the total is the body's mass even where folded inner tiers
  // make the enclosed volumes inconsistent (the brain's offset tier 3 encloses more than tier 2).
  const double tier_mass[3] = {rho * 0.5 * shell12, rho * 0.5 * (shell12 + shell23),
                               std::max(total_mass - rho * (shell12 + 0.5 * shell23), 0.0)};
  const Eigen::MatrixX3d* tiers[3] = {&vertices, &tier2, &tier3};
  const double floor_mass =
      1e-6 * total_mass / (3.0 * nv);  // keeps masses > 0 if a shell collapses
  for (int t = 0; t < 3; ++t) {
    const Eigen::VectorXd areas = vertex_areas(*tiers[t], triangles);
    const double area_sum = areas.sum();
    for (int i = 0; i < nv; ++i)
      network.masses[t * nv + i] =
          std::max(tier_mass[t] * (area_sum > 0.0 ? areas[i] / area_sum : 1.0 / nv), floor_mass);
  }

  const double modulus = options.material.youngs_modulus;
  // Every tier's node i stands for the same patch of the shells: tier 1's vertex area.
  const Eigen::VectorXd area = vertex_areas(vertices, triangles);
  const Eigen::VectorXd weight = (area / area.mean()).replicate(3, 1);
  detail::assign_network_stiffness(
      network, {g1, g2, g12, r12}, modulus,
      stiffness_volume(network, vertices, tier2, triangles, shell12, "tier 1 and tier 2"), weight);
  detail::assign_network_stiffness(
      network, shell23_groups, modulus,
      stiffness_volume(network, tier2, tier3, triangles, shell23, "tier 2 and tier 3"), weight);
  detail::assign_damping(network, options.material);

  for (int i = 0; i < nv; ++i) {
    network.surface_nodes.push_back(i);
    network.fixed_nodes.push_back(2 * nv + i);
  }
  network.surface_triangles = triangles;
  network.validate();
  return network;
}

std::vector<std::string> spring_groups(const ThreeTierOptions& options) {
  std::vector<std::string> groups = {tier1_group, tier2_group, tier12_diagonal_group,
                                     tier12_radial_group, tier23_radial_group};
  if (options.tier23_diagonals) groups.emplace_back(tier23_diagonal_group);
  return groups;
}

}  // namespace msfem::massspring
