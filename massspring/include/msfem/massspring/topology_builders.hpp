#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "msfem/massspring/spring_network.hpp"

namespace msfem::massspring {

/// Material the builders turn into starting masses and stiffnesses (SI).
struct Material {
  double youngs_modulus = 3000.0;  ///< Pa (brain ≈ 1.4-3 kPa)
  double density = 1040.0;         ///< kg/m³
  double spring_damping = 0.0;     ///< N·s/m on every spring (relative velocity)
  double node_damping = 0.0;       ///< N·s/m on every node (absolute velocity)
};

/// --- three_tier (layered brain seed) ---
/// Tier 1 = the surface; tiers 2 and 3 are copies moved inwards, tier 3 fixed. Springs: edges of
/// tiers 1 and 2, two crossing diagonals per edge between tiers 1 and 2 (a1-b2, b1-a2), one radial
/// spring per vertex between tiers 1-2 and 2-3: 4E + 2V springs, 3V nodes.
enum class InnerTierMethod {
  scaling,        ///< x_k = c + (x - c) / s_k about the vertex centroid c (the seed)
  normal_offset,  ///< x_k = x - δ_k n(x) along the inward vertex normal
  /// x_k = x - t_k(x) n(x): the distance field's gradient flow from the vertex inwards, which
  /// runs straight along the inward normal n until it meets the medial axis at the depth r(x) of
  /// the largest ball inside the surface that touches x (a ball that holds no other surface
  /// vertex, found by shrinking). Tier 3 stops at t_3 = min(δ_3, 0.8 r), short of the medial axis,
  /// so the copies of a fold's two walls never meet and no node is merged (3V nodes and 4E + 2V
  /// springs, as the seed's); tier 2 at t_2 = (δ_2/δ_3) t_3, the same fraction of its own depth.
  /// δ_k are the normal_offset depths, so on a sphere (r = the radius) these are the scaled
  /// tiers; in a narrow fold (the cortex's gyri) the tiers stay inside the fold and are shallow.
  /// The depths vary from vertex to vertex, so t_3 may change by at most half the distance along
  /// the surface, and where a shell prism still has a tetrahedron of non-positive volume or a tier
  /// triangle turned against its tier-1 triangle (inverted_tier_prisms), or a node lies outside
  /// the tier above (points_outside_surface), its vertices' depths shrink until none does. At a
  /// pinched vertex whose normal disagrees with one of its own triangles the copy moves along the
  /// direction that agrees best with all of them. A fault that remains is a warning.
  distance_field
};

struct ThreeTierOptions {
  InnerTierMethod inner_tiers = InnerTierMethod::scaling;
  double tier2_scale = 1.2;
  double tier3_scale = 2.0;
  /// Normal offsets in metres; a value <= 0 picks (1 - 1/s_k) × the mean vertex distance to c,
  /// i.e. the same depth as the scaling on a sphere.
  double tier2_offset = 0.0;
  double tier3_offset = 0.0;
  /// An inner-tier node outside the outer surface (scaling a concave surface can do that) is always
  /// reported in SpringNetwork::warnings; with this set it throws ModelError instead.
  bool reject_inner_tier_outside = false;
  /// The point the tiers are scaled about (c above); unset: the vertex centroid. A surface refined
  /// near a tool has its vertex centroid pulled toward the tool, so its caller passes the
  /// unrefined surface's to keep tier 3 where the support expects it.
  std::optional<Eigen::Vector3d> center;
  /// Crossing diagonals between tier 2 and tier 3 as between tiers 1 and 2 (group
  /// "tier23_diagonals"). The seed links tier 2 to the fixed tier 3 by radial springs only, which
  /// resist a rigid turn of the outer shell about the core at second order only: a lateral push
  /// turns it freely.
  bool tier23_diagonals = false;
  Material material;
};

/// Node order: tier 1 (ids 0..V-1, = input vertex ids), tier 2 (V..2V-1), tier 3 (2V..3V-1).
/// Spring groups: "tier1_edges", "tier2_edges", "tier12_diagonals", "tier12_radial",
/// "tier23_radial". Node groups: "tier1", "tier2", "tier3".
/// Masses: density × volume; each shell between tiers is lumped half to each bounding tier,
/// spread by vertex area, and the core inside tier 3 goes to tier 3. Stiffness: the isotropic
/// network rule (analytic_stiffness.hpp) per shell, each spring's share of the shell's volume
/// following the vertex areas at its ends (so a locally refined surface is not stiffer there).
SpringNetwork build_three_tier(const Eigen::MatrixX3d& vertices, const Eigen::MatrixX3i& triangles,
                               const ThreeTierOptions& options = {});
/// The spring groups build_three_tier gives with `options`, in its order: what a caller checks
/// group names against before it builds (the builder names its groups from the same list).
std::vector<std::string> spring_groups(const ThreeTierOptions& options);

/// The triangles f whose prism between `outer` and `inner` (tier_prisms' nine tetrahedra, all
/// three splits) has a tetrahedron whose volume does not have the orientation of a shell below an
/// outward-oriented surface, or whose inner triangle turns against the outer one: a folded prism.
std::vector<int> inverted_tier_prisms(const Eigen::MatrixX3d& outer, const Eigen::MatrixX3d& inner,
                                      const Eigen::MatrixX3i& triangles);

/// --- single_layer ---
/// Surface edges only (group "surface_edges"). With anchor_to_rest, every node is also tied to its
/// rest position by a zero-length spring of stiffness anchor_ratio × the summed stiffness of its
/// edges × its area over the mean vertex area (the usual fix when no surface node is supported;
/// drop it when supports exist).
struct SingleLayerOptions {
  bool anchor_to_rest = true;
  double anchor_ratio = 0.1;
  Material material;
};
SpringNetwork build_single_layer(const Eigen::MatrixX3d& vertices,
                                 const Eigen::MatrixX3i& triangles,
                                 const SingleLayerOptions& options = {});
std::vector<std::string> spring_groups(const SingleLayerOptions& options);

/// --- skeleton (pancreas seed) ---
/// Control points = the vertices of a coarse control mesh (a simplification of the surface, made by
/// the caller) drawn toward the surface's vertex centroid c: p' = c + control_scale (p - c).
/// Springs: surface edges ("surface_edges"), control-mesh edges ("skeleton_edges") and each surface
/// vertex to its `links_per_vertex` nearest control points ("links", k-d tree).
/// Node order: surface vertices, then control points. Node groups "surface", "skeleton".
struct SkeletonOptions {
  double control_scale = 0.5;
  int links_per_vertex = 4;
  bool fix_control_points = false;
  /// The point control points are drawn toward (c above); unset: the vertex centroid.
  std::optional<Eigen::Vector3d> center;
  Material material;
};
SpringNetwork build_skeleton(const Eigen::MatrixX3d& vertices, const Eigen::MatrixX3i& triangles,
                             const Eigen::MatrixX3d& control_vertices,
                             const Eigen::MatrixX3i& control_triangles,
                             const SkeletonOptions& options = {});
std::vector<std::string> spring_groups(const SkeletonOptions& options);

/// --- tet_edges (volumetric baseline) ---
/// A spring on every edge of a tetrahedral mesh (group "tet_edges"); masses ρ V_t / 4 per corner;
/// the boundary faces become surface_triangles and their vertices surface_nodes (ascending ids).
enum class TetStiffnessRule { lloyd, van_gelder };
struct TetEdgesOptions {
  TetStiffnessRule stiffness_rule = TetStiffnessRule::lloyd;
  Material material;
};
SpringNetwork build_tet_edges(const Eigen::MatrixX3d& vertices, const Eigen::MatrixX4i& tetrahedra,
                              const TetEdgesOptions& options = {});
std::vector<std::string> spring_groups(const TetEdgesOptions& options);

}  // namespace msfem::massspring
