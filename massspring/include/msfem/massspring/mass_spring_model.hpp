#pragma once

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "msfem/massspring/force_model.hpp"
#include "msfem/massspring/spring_force_field.hpp"
#include "msfem/massspring/spring_network.hpp"
#include "msfem/massspring/surface_contact.hpp"
#include "msfem/massspring/tool_contact.hpp"
#include "msfem/massspring/volume_force_field.hpp"

namespace msfem::massspring {

/// A spring network with its loads and supports: the object a simulator embeds. As a ForceModel it
/// is the sum of the springs (SpringForceField), gravity m_i g, external nodal forces and a list of
/// named force fields (volume preservation, the tool's contact, ...). Supports are nodes whose
/// position is prescribed (fixed = zero displacement); integrators and solvers hold them at their
/// target and ignore their force rows. Parameters (k, d, m per group) can be changed between steps;
/// nothing is rebuilt.
class MassSpringModel : public ForceModel {
 public:
  /// Validates the network (throws ModelError) and fixes its `fixed_nodes`.
  explicit MassSpringModel(SpringNetwork network);

  const SpringNetwork& network() const { return network_; }
  int num_nodes() const { return network_.num_nodes(); }
  SpringForceField springs() const { return SpringForceField(network_); }

  // --- run-time parameters (the seed's menu) ---
  void set_group_stiffness(const std::string& spring_group, double stiffness);
  void scale_group_stiffness(const std::string& spring_group, double factor);
  void set_group_damping(const std::string& spring_group, double damping);
  void set_stiffness(const Eigen::VectorXd& stiffness);  ///< per spring
  void set_damping(const Eigen::VectorXd& damping);      ///< per spring
  void set_node_group_mass(const std::string& node_group, double mass_per_node);
  void set_masses(const Eigen::VectorXd& masses);
  void set_node_damping(double damping_per_node);
  void set_anchor_parameters(double stiffness, double damping);

  // --- loads ---
  void set_gravity(const Eigen::Vector3d& gravity) { gravity_ = gravity; }
  const Eigen::Vector3d& gravity() const { return gravity_; }
  void set_external_force(int node, const Eigen::Vector3d& force);
  void clear_external_forces();
  const Eigen::MatrixX3d& external_forces() const { return external_force_; }  ///< n x 3, N

  // --- supports ---
  void fix_node(int node) { prescribe_displacement(node, Eigen::Vector3d::Zero()); }
  void prescribe_displacement(int node, const Eigen::Vector3d& displacement);
  void release_node(int node);
  bool is_constrained(int node) const { return constrained_[check_node(node, "node")]; }
  std::vector<int> constrained_nodes() const;
  /// Where a constrained node is held: rest position + prescribed displacement.
  Eigen::Vector3d constrained_target(int node) const;

  // --- force fields beyond the springs, summed in list order, found by their type ---
  using FieldList = std::vector<std::shared_ptr<const ForceField>>;
  const FieldList& fields() const { return fields_; }
  /// Appends `field` to the list. Throws ModelError if it is not built for this model's nodes.
  void add_field(std::shared_ptr<const ForceField> field);
  /// Puts `field` in the list's place `index` (a fitted copy of the field there, say).
  void replace_field(std::size_t index, std::shared_ptr<const ForceField> field);
  /// The first field that is a `Field` (a class or an interface), or null.
  template <class Field>
  const Field* find_field() const {
    const int index = field_index<Field>();
    return index < 0 ? nullptr : dynamic_cast<const Field*>(fields_[index].get());
  }
  /// The list's place of the first field that is a `Field`, or -1.
  template <class Field>
  int field_index() const {
    for (std::size_t i = 0; i < fields_.size(); ++i)
      if (dynamic_cast<const Field*>(fields_[i].get())) return static_cast<int>(i);
    return -1;
  }
  /// Puts `field` in the place of the first field that is a `Field`, or appends it.
  template <class Field>
  void set_field(std::shared_ptr<const ForceField> field) {
    const int index = field_index<Field>();
    if (index < 0)
      add_field(std::move(field));
    else
      replace_field(static_cast<std::size_t>(index), std::move(field));
  }
  /// Removes every field that is a `Field`.
  template <class Field>
  void clear_fields() {
    for (int index = field_index<Field>(); index >= 0; index = field_index<Field>())
      fields_.erase(fields_.begin() + index);
  }
  /// The fields' names (ForceField::name), comma-separated, for messages.
  std::string field_names() const;

  // --- the two fields msfem builds ---
  /// Tool contact (penalty, frictionless): nodes only, or the surface's triangles; replaces the
  /// model's tool contact if it has one.
  void set_contact(const SphereContactForceField& contact);
  void set_contact(const SurfaceContactForceField& contact);
  void clear_contact() { clear_fields<ToolContact>(); }
  const ToolContact* contact() const { return find_field<ToolContact>(); }
  /// Volume preservation (the bulk stiffness central springs lack); replaces the model's.
  void set_volume(const VolumeForceField& volume);
  void clear_volume() { clear_fields<VolumeForceField>(); }
  const VolumeForceField* volume() const { return find_field<VolumeForceField>(); }

  // --- ForceModel ---
  int num_dofs() const override { return 3 * num_nodes(); }
  void add_force(const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                 Eigen::VectorXd& f) const override;
  double potential_energy(const Eigen::VectorXd& x) const override;
  void add_dfdx_product(const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                        const Eigen::VectorXd& dx, Eigen::VectorXd& df,
                        Linearisation mode = Linearisation::exact) const override;
  void add_dfdv_product(const Eigen::VectorXd& x, const Eigen::VectorXd& dv,
                        Eigen::VectorXd& df) const override;
  void add_dfdx_triplets(const Eigen::VectorXd& x, const Eigen::VectorXd& v, Triplets& triplets,
                         Linearisation mode = Linearisation::exact) const override;
  void add_dfdv_triplets(const Eigen::VectorXd& x, Triplets& triplets) const override;

  // --- state helpers ---
  Eigen::VectorXd rest_state() const { return flatten(network_.rest_positions); }
  /// Rest state with the constrained nodes at their targets.
  Eigen::VectorXd initial_state() const;
  /// Masses repeated per dof (the diagonal of the lumped mass matrix M).
  Eigen::VectorXd mass_per_dof() const;
  /// Puts constrained nodes at their targets with zero velocity.
  void enforce_constraints(Eigen::VectorXd& x, Eigen::VectorXd& v) const;
  /// Zeroes the constrained nodes' entries (the projection onto free dofs).
  void zero_constrained(Eigen::VectorXd& vector) const;
  /// a = M⁻¹ f(x, v) on free nodes, zero on constrained ones.
  Eigen::VectorXd acceleration(const Eigen::VectorXd& x, const Eigen::VectorXd& v) const;
  double kinetic_energy(const Eigen::VectorXd& v) const;
  double total_energy(const Eigen::VectorXd& x, const Eigen::VectorXd& v) const {
    return kinetic_energy(v) + potential_energy(x);
  }
  /// Surface node displacements (rows in network().surface_nodes order).
  Eigen::MatrixX3d surface_displacement(const Eigen::VectorXd& x) const;

 private:
  int check_node(int node, const char* what) const;
  std::vector<int> springs_in_group(const std::string& group) const;

  SpringNetwork network_;
  Eigen::Vector3d gravity_ = Eigen::Vector3d::Zero();
  Eigen::MatrixX3d external_force_;
  std::vector<char> constrained_;
  Eigen::MatrixX3d prescribed_displacement_;
  FieldList fields_;  ///< shared by copies: a field is immutable
};

}  // namespace msfem::massspring
