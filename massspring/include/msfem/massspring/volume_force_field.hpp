#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "msfem/massspring/force_model.hpp"

namespace msfem::massspring {

namespace detail {
struct VolumeBatches;
}

/// Volume elements of a network: element e has the volume V_e = Σ w_t V_t over the tetrahedra
/// t = tet_start[e] .. tet_start[e + 1] - 1 (rows of `tets`, 4 node ids each, weights
/// `tet_weight`), a signed rest volume and a modulus κ_e (Pa). A tetrahedron of a volume mesh is
/// an element of one tetrahedron of weight 1. A three-tier shell prism between a surface triangle
/// and its inner copy is an element of its three 3-tetrahedron decompositions (one starting at
/// each corner), weight 1/3 each: one decomposition alone depends on the vertex order, which made
/// the response differ from one tool position to another.
struct VolumeElements {
  Eigen::MatrixX4i tets;
  Eigen::VectorXd tet_weight;     ///< per tetrahedron
  std::vector<int> tet_start{0};  ///< size elements + 1
  Eigen::VectorXd rest_volume;    ///< per element, m³ (signed)
  Eigen::VectorXd modulus;        ///< per element, Pa (>= 0)

  int num_elements() const { return static_cast<int>(tet_start.size()) - 1; }
};

/// Volume preservation: U = Σ_e ½ κ_e (V_e − V_e⁰)² / |V_e⁰|. For small strains V/V⁰ − 1 = tr ε, so
/// this is the continuum's ½ κ (tr ε)² per unit volume: it adds the bulk stiffness that a network
/// of central springs lacks (its Poisson's ratio is pinned at 1/4 by the Cauchy relations), with
/// κ = λ(E, ν) − λ(E, 1/4) as the analytic start for a tissue of Poisson's ratio ν.
class VolumeForceField : public ForceField {
 public:
  /// Throws ModelError for node ids outside [0, num_nodes), a degenerate rest volume, a negative or
  /// non-finite modulus, or inconsistent sizes.
  VolumeForceField(int num_nodes, VolumeElements elements);

  int num_dofs() const override { return 3 * num_nodes_; }
  void add_force(const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                 Eigen::VectorXd& f) const override;
  /// Part `part` of `parts` of the elements: threads that each take a part into their own f sum
  /// to add_force.
  void add_force_part(const Eigen::VectorXd& x, const Eigen::VectorXd& v, Eigen::VectorXd& f,
                      int part, int parts) const override;
  double potential_energy(const Eigen::VectorXd& x) const override;
  void add_dfdx_product(const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                        const Eigen::VectorXd& dx, Eigen::VectorXd& df,
                        Linearisation mode = Linearisation::exact) const override;
  /// Part `part` of `parts` of the elements.
  void add_dfdx_product_part(const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                             const Eigen::VectorXd& dx, Eigen::VectorXd& df, Linearisation mode,
                             int part, int parts) const override;
  void add_diagonal_blocks(const Eigen::VectorXd& x, const Eigen::VectorXd& v, double cx, double cv,
                           std::vector<Eigen::Matrix3d>& blocks, Linearisation mode) const override;
  void add_dfdv_product(const Eigen::VectorXd&, const Eigen::VectorXd&,
                        Eigen::VectorXd&) const override {}
  void add_dfdx_triplets(const Eigen::VectorXd& x, const Eigen::VectorXd& v, Triplets& triplets,
                         Linearisation mode = Linearisation::exact) const override;
  void add_dfdv_triplets(const Eigen::VectorXd&, Triplets&) const override {}
  /// The definite tangent keeps each element's gradient, so that a product is a gather and a
  /// scatter instead of nine tetrahedra's cross products per element; exact: the default.
  std::unique_ptr<Tangent> tangent(const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                                   Linearisation mode) const override;

  /// The nodes of its elements.
  const std::vector<int>& nodes() const override { return nodes_; }
  /// "volume": every element's modulus.
  std::string name() const override { return "volume preservation"; }
  std::vector<std::string> coefficient_groups() const override { return {"volume"}; }
  /// The elements' moduli (Pa).
  std::vector<double> coefficients(const std::string& group) const override;
  std::string coefficient_unit(const std::string&) const override { return "Pa"; }
  std::shared_ptr<const ForceField> scaled(const std::string& group, double factor) const override;

  const VolumeElements& elements() const { return elements_; }
  void set_modulus(const Eigen::VectorXd& modulus);  ///< per element, Pa
  void scale_modulus(double factor);
  /// Current signed volume of element e at x.
  double volume(const Eigen::VectorXd& x, int e) const;

 private:
  friend class DefiniteVolumeTangent;
  static constexpr int kMaxElementNodes = 16;
  void index_element_nodes();
  /// Element e's volume at x, with g = −6 ∂V/∂x per distinct node of the element.
  double element_gradient(int e, const double* x, Eigen::Vector3d (&g)[kMaxElementNodes]) const;
  std::pair<int, int> element_range(int part, int parts) const;
  void add_exact_product(const Eigen::VectorXd& x, const Eigen::VectorXd& dx, Eigen::VectorXd& df,
                         int first, int last) const;

  int num_nodes_;
  VolumeElements elements_;
  std::vector<int> nodes_;  ///< of its elements, ascending
  // Each element's distinct nodes (as offsets 3·id into x and f) and its tetrahedra's corners as
  // indices into them, so that add_force reads and writes each node of an element once: a shell
  // prism's nine tetrahedra touch its six nodes 36 times per pass.
  std::vector<int> element_node_start_{0};
  std::vector<int> element_node_offset_;
  std::vector<std::array<std::uint8_t, 4>> local_tets_;
  // The elements in lane groups of one shape each (volume_batches.hpp), for the force pass and the
  // kept tangent's gradients; shared by copies (it holds no modulus).
  std::shared_ptr<const detail::VolumeBatches> batches_;
};

/// The prisms between a triangle mesh's tiers: for every triangle (a, b, c) of `triangles` and
/// every pair of consecutive tiers (node id = tier · `nodes_per_tier` + vertex), one element (see
/// VolumeElements), with its rest volume from `rest_positions` and the given modulus.
VolumeElements tier_prisms(const Eigen::MatrixX3d& rest_positions,
                           const Eigen::MatrixX3i& triangles, int nodes_per_tier, int tiers,
                           double modulus);

/// One element per tetrahedron of a volume mesh (tet_edges), with the given modulus.
VolumeElements tetrahedron_elements(const Eigen::MatrixX3d& rest_positions,
                                    const Eigen::MatrixX4i& tets, double modulus);

/// Removes the elements that cannot keep a volume at rest: those whose signed rest volume is
/// against the majority's orientation (a folded tier: an inner copy of a concave surface crosses
/// the outer one) or flat, |V⁰| < `min_shape` × (longest edge)³ (a regular tetrahedron has 0.118;
/// κ/|V⁰| would make a sliver far stiffer than anything around it, and Newton stalled on the
/// brain's folded tiers). Scale-free, so a graded mesh keeps its small elements. Returns how many
/// were removed.
int remove_degenerate_elements(VolumeElements& elements, const Eigen::MatrixX3d& rest_positions,
                               double min_shape);

/// κ to add to a central-spring network so that it has the bulk response of an isotropic solid
/// of Young's modulus E and Poisson's ratio ν: λ(E, ν) − λ(E, 1/4) (0 for ν ≤ 1/4).
double volume_modulus_for(double youngs_modulus, double poisson_ratio);

}  // namespace msfem::massspring
