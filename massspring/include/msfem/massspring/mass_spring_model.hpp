#pragma once

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "msfem/massspring/force_model.hpp"
#include "msfem/massspring/mechanical_system.hpp"
#include "msfem/massspring/nodal_load_field.hpp"
#include "msfem/massspring/spring_force_field.hpp"
#include "msfem/massspring/spring_network.hpp"
#include "msfem/massspring/surface_contact.hpp"
#include "msfem/massspring/tool_contact.hpp"
#include "msfem/massspring/volume_force_field.hpp"

namespace msfem::massspring {

/// A spring network with its loads and supports: the MechanicalSystem msfem builds and a simulator
/// embeds. Its fields are the springs (a SpringForceField over its own network, always first), the
/// nodal loads (a NodalLoadField over its masses, gravity and external forces, always second) and
/// then the fields added to it (volume preservation, the tool's contact, ...). Supports are nodes
/// whose position is prescribed (fixed = zero displacement). Parameters (k, d, m per group) and
/// loads can be changed between steps; nothing is rebuilt.
class MassSpringModel : public MechanicalSystem {
 public:
  /// Validates the network (throws ModelError) and fixes its `fixed_nodes`.
  explicit MassSpringModel(SpringNetwork network);
  // A copy's springs field views the copy's own network.
  MassSpringModel(const MassSpringModel& other);
  MassSpringModel& operator=(const MassSpringModel& other);

  const SpringNetwork& network() const { return network_; }
  const SpringForceField& springs() const { return *springs_; }
  const NodalLoadField& loads() const { return *loads_; }

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
  bool is_constrained(int node) const override { return constrained_[check_node(node, "node")]; }
  /// Where a constrained node is held: rest position + prescribed displacement.
  Eigen::Vector3d constrained_target(int node) const override;

  // --- force fields: the springs, the loads, then the fields added here, found by type ---
  const FieldList& fields() const override { return fields_; }
  /// Appends `field` to the list. Throws ModelError if it is not built for this model's nodes.
  void add_field(std::shared_ptr<const ForceField> field);
  /// Puts `field` in the list's place `index` (a fitted copy of the field there, say); the springs'
  /// and the loads' places are refused: they change through the parameters above.
  void replace_field(std::size_t index, std::shared_ptr<const ForceField> field);
  /// Puts `field` in the place of the first field that is a `Field`, or appends it.
  template <class Field>
  void set_field(std::shared_ptr<const ForceField> field) {
    const int index = field_index<Field>();
    if (index < 0)
      add_field(std::move(field));
    else
      replace_field(static_cast<std::size_t>(index), std::move(field));
  }
  /// Removes every field that is a `Field`, the model's springs and loads aside.
  template <class Field>
  void clear_fields() {
    for (std::size_t i = fields_.size(); i-- > own_fields;)
      if (dynamic_cast<const Field*>(fields_[i].get())) fields_.erase(fields_.begin() + i);
  }
  /// True when fields beyond the springs and the loads were added.
  bool has_added_fields() const { return fields_.size() > own_fields; }

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

  // --- MechanicalSystem ---
  int num_nodes() const override { return network_.num_nodes(); }
  Eigen::VectorXd rest_state() const override { return flatten(network_.rest_positions); }
  const Eigen::VectorXd& masses() const override { return network_.masses; }

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
  static constexpr std::size_t own_fields = 2;  ///< the springs and the loads
  void bind_own_fields();  ///< the springs and the loads over this model's members

  std::shared_ptr<const SpringForceField> springs_;  ///< over network_, fields_[0]
  std::shared_ptr<const NodalLoadField> loads_;      ///< over masses, gravity_, external_force_
  FieldList fields_;  ///< beyond the first two shared by copies: a field is immutable
};

}  // namespace msfem::massspring
