#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "msfem/massspring/force_model.hpp"

namespace msfem::massspring {

/// What every solver sees of a model: n nodes with lumped masses, supports (nodes held at a
/// target) and a list of force fields summed in order. The springs and the nodal loads (gravity,
/// external forces) are fields like the others; a solver that has a faster path for a field finds
/// it by its type (find_field<SpringForceField>, find_field<NodalLoadField>) and treats every
/// other field through ForceField's calls alone. MassSpringModel is the implementation msfem
/// builds; a simulator may bring its own.
class MechanicalSystem : public ForceModel {
 public:
  using FieldList = std::vector<std::shared_ptr<const ForceField>>;

  virtual int num_nodes() const = 0;
  /// Node-major rest positions (x0, y0, z0, x1, ...).
  virtual Eigen::VectorXd rest_state() const = 0;
  /// Lumped mass per node, kg (> 0).
  virtual const Eigen::VectorXd& masses() const = 0;
  /// True for a node whose position is prescribed; solvers hold it at its target and ignore its
  /// force rows.
  virtual bool is_constrained(int node) const = 0;
  /// Where a constrained node is held.
  virtual Eigen::Vector3d constrained_target(int node) const = 0;
  /// Every force field, summed in this order.
  virtual const FieldList& fields() const = 0;

  /// The first field that is a `Field` (a class or an interface), or null.
  template <class Field>
  const Field* find_field() const {
    const int index = field_index<Field>();
    return index < 0 ? nullptr : dynamic_cast<const Field*>(fields()[index].get());
  }
  /// The list's place of the first field that is a `Field`, or -1.
  template <class Field>
  int field_index() const {
    const FieldList& list = fields();
    for (std::size_t i = 0; i < list.size(); ++i)
      if (dynamic_cast<const Field*>(list[i].get())) return static_cast<int>(i);
    return -1;
  }
  /// The fields' names (ForceField::name), comma-separated, for messages.
  std::string field_names() const;

  // --- ForceModel: the fields summed in list order ---
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

  // --- state helpers built on the calls above ---
  std::vector<int> constrained_nodes() const;
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
};

}  // namespace msfem::massspring
