#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

namespace msfem::massspring {

/// The data of a mass-spring model, stored as structure of arrays (one entry per node or per
/// spring) so that parameters can be changed between steps without touching the topology. Every
/// topology builder (three_tier, skeleton, single_layer, tet_edges) produces one of these; the
/// force field, integrators and solvers only read it.
struct SpringNetwork {
  // --- nodes ---
  Eigen::MatrixX3d rest_positions;  ///< n x 3, metres
  Eigen::VectorXd masses;           ///< n, kg (> 0)
  Eigen::VectorXd node_damping;     ///< n, N·s/m: force -c_i v_i (absolute, "air" damping)
  Eigen::VectorXi node_group;       ///< n, index into node_group_names (e.g. tier)
  std::vector<std::string> node_group_names;

  // --- springs between two nodes: Hooke spring plus a damper on the relative velocity ---
  Eigen::MatrixX2i springs;      ///< s x 2 node ids
  Eigen::VectorXd stiffness;     ///< s, N/m (>= 0)
  Eigen::VectorXd damping;       ///< s, N·s/m (>= 0), acts along the spring
  Eigen::VectorXd rest_length;   ///< s, metres (> 0)
  Eigen::VectorXi spring_group;  ///< s, index into spring_group_names
  std::vector<std::string> spring_group_names;

  // --- anchor springs: zero rest length, node tied to a fixed point (its rest position) ---
  Eigen::VectorXi anchor_node;       ///< a
  Eigen::MatrixX3d anchor_point;     ///< a x 3, metres
  Eigen::VectorXd anchor_stiffness;  ///< a, N/m
  Eigen::VectorXd anchor_damping;    ///< a, N·s/m

  // --- what the builder knows about the geometry ---
  std::vector<int> surface_nodes;      ///< outer (rendered, haptic) surface, in input vertex order
  Eigen::MatrixX3i surface_triangles;  ///< outer surface triangles in node ids
  std::vector<int> fixed_nodes;        ///< supports the variant implies (three_tier's tier 3)
  std::vector<std::string> warnings;   ///< e.g. an inner tier poking outside the outer surface

  int num_nodes() const { return static_cast<int>(rest_positions.rows()); }
  int num_springs() const { return static_cast<int>(springs.rows()); }
  int num_anchors() const { return static_cast<int>(anchor_node.size()); }

  /// Index of a spring group / node group by name; throws ModelError naming it when unknown.
  int spring_group_id(const std::string& name) const;
  int node_group_id(const std::string& name) const;
  /// Number of springs in each group.
  std::vector<int> spring_group_sizes() const;

  /// Checks sizes, index ranges and values; throws ModelError naming the first item at fault.
  void validate() const;
};

/// Appends springs with the given group name (created if new); rest lengths from rest_positions,
/// stiffness and damping zero. Returns the group id.
int add_springs(SpringNetwork& network, const std::vector<std::array<int, 2>>& pairs,
                const std::string& group_name);

/// Flattened node-major state vector (x0, y0, z0, x1, ...) of the rest positions.
Eigen::VectorXd flatten(const Eigen::MatrixX3d& points);
/// Inverse of flatten.
Eigen::MatrixX3d unflatten(const Eigen::VectorXd& state);

}  // namespace msfem::massspring
