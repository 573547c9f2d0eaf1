#pragma once

// Nonlinear Gauss-Seidel on single nodes for the static solver (internal).

#include <Eigen/Core>
#include <vector>

#include "msfem/massspring/mechanical_system.hpp"
#include "msfem/massspring/nodal_load_field.hpp"
#include "msfem/massspring/spring_force_field.hpp"

namespace msfem::massspring::detail {

/// Minimises the potential energy over one node at a time, the others held, for the free nodes
/// that carry the largest residual forces. Each move lowers the energy, so it can follow any
/// Newton step without spoiling the line search's guarantee.
///
/// Why: on the brain, tier 2 folds in the sulci and leaves springs a few microns long whose
/// stiffness (∝ 1/l0²) is 10⁴ × their neighbours'. A Newton step moves the two ends of such a
/// spring along straight lines, so turning it stretches it by |Δ⊥|²/2l, and that stretch, times
/// its stiffness, is then most of the residual: Newton crawls along the curved valley for tens of
/// iterations. Putting each such node back at its own minimum costs microseconds and removes it.
class NodeRelaxation {
 public:
  explicit NodeRelaxation(const MechanicalSystem& model);

  /// Relaxes the free nodes whose |f_i| is at least `fraction` × max |f_i| (f given on all dofs,
  /// zero on constrained ones), `sweeps` times. Returns the number of nodes visited per sweep.
  int relax(Eigen::VectorXd& x, const Eigen::VectorXd& f, double fraction, int sweeps) const;

 private:
  // Node i's share of the energy (its springs, anchors, load and nodewise fields) at position p,
  // with the others at x; also its force and a positive semi-definite stiffness when asked.
  double local(const Eigen::VectorXd& x, int i, const Eigen::Vector3d& p, Eigen::Vector3d* force,
               Eigen::Matrix3d* stiffness) const;
  void relax_node(Eigen::VectorXd& x, int i) const;

  const MechanicalSystem& model_;
  const SpringForceField* springs_field_ = nullptr;  // the system's springs, if it has them
  const SpringNetwork* network_ = nullptr;           // theirs, or an empty one
  const NodalLoadField* loads_ = nullptr;            // relaxed first, as each node's load
  std::vector<int> spring_start_, springs_;          // springs at each node (CSR)
  std::vector<int> anchor_start_, anchors_;          // anchors at each node (CSR)
  std::vector<int> node_term_start_, node_term_;     // nodewise fields' terms at each node (CSR)
  std::vector<const ForceField*> node_term_field_;   // each term's field
  std::vector<char> left_to_newton_;  // node's energy is not local (volume, surface contact)
};

}  // namespace msfem::massspring::detail
