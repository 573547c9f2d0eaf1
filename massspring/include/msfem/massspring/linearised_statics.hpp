#pragma once
// A spring model linearised at rest, for calibration's fast path: with the stiffness split into
// parts (a fitted group each, and the rest), J(w) = Σ_p w_p J_p, so each new set of weights costs
// one sparse Cholesky factorisation (its ordering computed once) instead of a Newton solve. Exact
// for small displacements.

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <functional>
#include <memory>
#include <vector>

#include "msfem/massspring/mechanical_system.hpp"
#include "msfem/massspring/static_solver.hpp"

namespace msfem::massspring {

namespace detail {
class TangentFactor;
}

class LinearisedStatics {
 public:
  /// `parts[p]` is a per-spring stiffness vector (zero outside the part; anchors, if any, belong to
  /// part 0, whose weight should stay 1) of the system's springs (its SpringForceField); the
  /// constraints (supports and the tool's prescribed patch) and loads (its NodalLoadField) are
  /// those of `model`. Each of its other force fields (volume preservation, ...) is one more part,
  /// after the given ones and in the system's field order, holding that field alone: its weight
  /// scales the field's Jacobian and its force at rest (a field that pulls at rest, as a grasper
  /// does, is linear in its weight). `factorization` makes the sparse Cholesky factor (empty:
  /// Eigen's SimplicialLDLT), as StaticOptions::factorization.
  LinearisedStatics(const MechanicalSystem& model, const std::vector<Eigen::VectorXd>& parts,
                    std::function<std::unique_ptr<SparseSpdFactor>()> factorization = {});
  ~LinearisedStatics();
  LinearisedStatics(const LinearisedStatics&) = delete;
  LinearisedStatics& operator=(const LinearisedStatics&) = delete;

  /// The number of weights solve() takes: the parts, plus one per force field beside the springs
  /// and the loads.
  int num_parts() const { return static_cast<int>(jacobians_.size()); }

  struct Solution {
    Eigen::MatrixX3d surface_displacement;                  ///< in surface vertex order, m
    Eigen::Vector3d patch_force = Eigen::Vector3d::Zero();  ///< Σ f over the constrained patch
  };
  /// Throws std::runtime_error if the linearised stiffness is not positive definite (a mechanism
  /// only the deformed state stiffens, e.g. a shell free to turn about the tool's axis).
  Solution solve(const std::vector<double>& weights, const std::vector<int>& patch);

 private:
  const MechanicalSystem& model_;
  std::vector<Eigen::SparseMatrix<double>> jacobians_;       ///< ∂f/∂x of each part, all dofs
  std::vector<Eigen::SparseMatrix<double>> free_stiffness_;  ///< −∂f/∂x of each part, free dofs
  std::vector<Eigen::VectorXd> free_load_;  ///< each part's force from the prescribed u, free dofs
  Eigen::SparseMatrix<double> select_;      ///< free dofs × all dofs
  Eigen::VectorXd rest_force_;              ///< f at rest (gravity, external, the fields')
  std::vector<Eigen::VectorXd> field_rest_force_;  ///< each part's field's f at rest (or empty)
  Eigen::VectorXd prescribed_;                     ///< u on the constrained dofs, 0 elsewhere
  std::unique_ptr<detail::TangentFactor> cholesky_;
};

}  // namespace msfem::massspring
