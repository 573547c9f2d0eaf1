#pragma once

// Linear algebra of the static solver (internal): free-dof tangent stiffness with a fixed sparsity
// pattern, its LDLT factorisation with one symbolic analysis, and conjugate gradients
// preconditioned by an earlier factorisation.

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <functional>
#include <memory>
#include <vector>

#include "msfem/massspring/mechanical_system.hpp"
#include "msfem/massspring/static_solver.hpp"

namespace msfem::massspring::detail {

/// Maps full dofs to free dofs (-1 for constrained) and back.
struct FreeDofs {
  explicit FreeDofs(const MechanicalSystem& model);
  int size() const { return static_cast<int>(full_index.size()); }
  Eigen::VectorXd gather(const Eigen::VectorXd& full) const;
  void scatter_add(const Eigen::VectorXd& free, double scale, Eigen::VectorXd& full) const;

  std::vector<int> free_index;
  std::vector<int> full_index;
};

/// K = -∂f/∂x restricted to the free dofs. Every spring's blocks and every free node's diagonal
/// block are stored even when zero (a collapsed spring, contact
/// switched off), so the pattern depends only on the topology and the supports.
Eigen::SparseMatrix<double> free_stiffness(const MechanicalSystem& model, const Eigen::VectorXd& x,
                                           const FreeDofs& dofs, Linearisation mode);

/// y = K v on the free dofs without assembling K (a few ms on the brain against ~0.2 s assembly).
class TangentOperator {
 public:
  TangentOperator(const MechanicalSystem& model, const FreeDofs& dofs, const Eigen::VectorXd& x,
                  Linearisation mode);
  Eigen::VectorXd operator*(const Eigen::VectorXd& v) const;

 private:
  const MechanicalSystem& model_;
  const FreeDofs& dofs_;
  const Eigen::VectorXd& x_;
  Linearisation mode_;
  mutable Eigen::VectorXd full_dx_, full_df_;
};

/// SimplicialLDLT whose symbolic analysis (ordering, elimination tree) is done once and kept for
/// as long as the matrix pattern stays the same.
class TangentFactor {
 public:
  /// `plugged` replaces the SimplicialLDLT when given (StaticOptions::factorization).
  explicit TangentFactor(std::unique_ptr<SparseSpdFactor> plugged = nullptr)
      : plugged_(std::move(plugged)) {}
  /// Factorises k; false (and no usable factor) if k is not numerically positive definite.
  bool factorize(const Eigen::SparseMatrix<double>& k);
  bool valid() const { return valid_; }
  Eigen::VectorXd solve(const Eigen::VectorXd& r) const {
    return plugged_ ? plugged_->solve(r) : Eigen::VectorXd(ldlt_.solve(r));
  }
  int factorizations() const { return factorizations_; }

 private:
  bool same_pattern(const Eigen::SparseMatrix<double>& k) const;

  std::unique_ptr<SparseSpdFactor> plugged_;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt_;
  std::vector<int> outer_, inner_;  // pattern the analysis was made for
  bool analysed_ = false;
  bool valid_ = false;
  int factorizations_ = 0;
};

enum class KrylovOutcome { converged, negative_curvature, too_many_iterations };

/// Solves K d = r by conjugate gradients from d = 0, preconditioned by `factor`, until
/// |r - K d| <= absolute_tolerance. Stops at the first direction of non-positive curvature (K not
/// positive definite). Every iterate is a descent direction for the energy when K is definite.
KrylovOutcome preconditioned_cg(const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& k,
                                const TangentFactor& factor, const Eigen::VectorXd& r,
                                double absolute_tolerance, int max_iterations, Eigen::VectorXd& d,
                                int& iterations);

}  // namespace msfem::massspring::detail
