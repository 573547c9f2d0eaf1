#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "msfem/massspring/force_model.hpp"

namespace msfem::massspring {

class MassSpringModel;
class MechanicalSystem;

/// A rigid spherical tool tip.
struct SphereTool {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double radius = 0.0;
};

/// A sphere of radius r that touches the surface at `contact_point` from outside and is pushed by
/// `depth` along `inward_direction` (the design's tool indentation).
struct ToolIndentation {
  Eigen::Vector3d contact_point = Eigen::Vector3d::Zero();
  Eigen::Vector3d inward_direction = -Eigen::Vector3d::UnitZ();  ///< normalised on use
  double radius = 0.0;
  double depth = 0.0;

  /// The tool at full depth: centre = p + u (d - r).
  SphereTool tool() const;
};

/// A rigid tool's frictionless contact as a force field: what the model's contact slot holds, the
/// static solver and the integrators see as one more ForceModel, and a haptic loop reads back.
class ToolContact : public ForceField {
 public:
  virtual const SphereTool& tool() const = 0;
  // nodes(): the nodes the contact can push.
  /// A node's contact stiffness (N/m) when the tool presses on it: the node penalty, or for a
  /// surface contact the pressure penalty times a mean node's area. Preconditioners and the node
  /// relaxation use it; the forces come from add_force.
  virtual double penalty_stiffness() const = 0;
  /// A copy of this contact that its caller owns: a haptic loop puts it in its model's contact
  /// slot (MassSpringModel::set_field) and moves its sphere between steps with move_tool, leaving
  /// the field other copies of the model share untouched.
  virtual std::shared_ptr<ToolContact> clone() const = 0;
  /// Moves the sphere's centre (m). A stepper holding the field reads the new centre at its next
  /// force call; only for a field no other thread is reading at the time.
  virtual void move_tool(const Eigen::Vector3d& center) = 0;

  void add_dfdv_product(const Eigen::VectorXd&, const Eigen::VectorXd&,
                        Eigen::VectorXd&) const override {}
  void add_dfdv_triplets(const Eigen::VectorXd&, Triplets&) const override {}
};

/// Frictionless contact between a sphere and a set of nodes, regularised by a penalty: a node at
/// distance ρ < r from the centre is pushed out with f = k_p (r - ρ) (x - c)/ρ, U = ½ k_p (r - ρ)².
/// Penetration at equilibrium is |f_node| / k_p, so k_p is chosen stiff against the springs. A
/// tool smaller than the surface's cells can slip between nodes: SurfaceContactForceField cannot.
class SphereContactForceField : public ToolContact {
 public:
  SphereContactForceField(int num_nodes, std::vector<int> nodes, SphereTool tool,
                          double penalty_stiffness);

  int num_dofs() const override { return 3 * num_nodes_; }
  void add_force(const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                 Eigen::VectorXd& f) const override;
  double potential_energy(const Eigen::VectorXd& x) const override;
  void add_dfdx_product(const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                        const Eigen::VectorXd& dx, Eigen::VectorXd& df,
                        Linearisation mode = Linearisation::exact) const override;
  void add_dfdx_triplets(const Eigen::VectorXd& x, const Eigen::VectorXd& v, Triplets& triplets,
                         Linearisation mode = Linearisation::exact) const override;

  const SphereTool& tool() const override { return tool_; }
  const std::vector<int>& nodes() const override { return nodes_; }
  std::string name() const override { return "tool contact (nodes)"; }
  double penalty_stiffness() const override { return penalty_; }
  bool nodewise() const override { return true; }
  double add_node_term(int node, const Eigen::Vector3d& p, Eigen::Vector3d& f,
                       Eigen::Matrix3d& k) const override;
  std::shared_ptr<ToolContact> clone() const override {
    return std::make_shared<SphereContactForceField>(*this);
  }
  void move_tool(const Eigen::Vector3d& center) override { tool_.center = center; }

 private:
  Eigen::Matrix3d block(const Eigen::Vector3d& position, Linearisation mode) const;

  int num_nodes_;
  std::vector<int> nodes_;
  SphereTool tool_;
  double penalty_;
};

/// Prescribed-displacement version of the indentation: every surface node inside the tool at full
/// depth is moved along the push direction onto the sphere (and held there). Returns the patch.
std::vector<int> prescribe_contact_patch(MassSpringModel& model, const ToolIndentation& indent);

/// Frictionless version: activates penalty contact of the tool at full depth with the model's
/// surface nodes. penalty_stiffness <= 0 picks 1000 x the largest summed spring stiffness at a
/// surface node. Returns the penalty stiffness used.
double activate_sphere_contact(MassSpringModel& model, const ToolIndentation& indent,
                               double penalty_stiffness = 0.0);

/// The largest summed stiffness (springs and anchors) at a surface node, N/m: what a contact
/// penalty must dominate.
double stiffest_surface_node(const MassSpringModel& model);

/// Force the tissue exerts on the tool (what a haptic device renders), at state x (statics, v = 0):
/// with a prescribed patch, the sum over the patch of the internal and applied forces, which at
/// equilibrium balance the tool's push; with penalty contact, minus the sum of contact forces.
Eigen::Vector3d patch_reaction_force(const MechanicalSystem& model, const Eigen::VectorXd& x,
                                     const std::vector<int>& patch);
Eigen::Vector3d contact_reaction_force(const MechanicalSystem& model, const Eigen::VectorXd& x);

/// For dynamics: moves contact nodes inside the tool onto its surface (closest point) and removes
/// their velocity component towards the centre. Returns the number of nodes projected.
/// With a surface contact only the nodes are projected (a triangle's interior may stay inside).
int project_out_of_tool(const MechanicalSystem& model, Eigen::VectorXd& x, Eigen::VectorXd& v);

}  // namespace msfem::massspring
