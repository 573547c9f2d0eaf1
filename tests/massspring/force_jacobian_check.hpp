#pragma once

// One finite-difference checker for every ForceModel (in the spirit of SOFA's ForceField_test and
// Vega's force-model tester): the assembled and the matrix-free ∂f/∂x and ∂f/∂v against central
// differences of the force, and the force against central differences of the energy.

#include <Eigen/Core>

#include "msfem/massspring/force_model.hpp"

namespace msfem::massspring::testing {

struct JacobianErrors {
  double dfdx_matrix = 0.0;   ///< |J_fd - J| / |J_fd| (Frobenius), assembled ∂f/∂x
  double dfdx_product = 0.0;  ///< same for the matrix-free product on a random direction
  double dfdv_matrix = 0.0;
  double dfdv_product = 0.0;
  double energy_gradient = 0.0;  ///< |f(x, 0) + ∇U_fd| / |f(x, 0)|
};

/// x plus a uniform random perturbation in [-amplitude, amplitude] per entry (seeded: repeatable).
Eigen::VectorXd perturbed(const Eigen::VectorXd& x, double amplitude, unsigned seed);

/// `step` is the finite-difference step in metres (or m/s for ∂f/∂v).
JacobianErrors check_force_jacobians(const ForceModel& model, const Eigen::VectorXd& x,
                                     const Eigen::VectorXd& v, double step);

/// The calls a solver makes of a ForceField beyond ForceModel's, each against the whole call it
/// stands for (relative errors): parts summed over 1, 2 and 3 parts against add_force and
/// add_dfdx_product (definite), the diagonal blocks against the assembled Jacobians' 3x3 diagonal
/// blocks, and the kept tangent (set in parts, then its products, pair products, blocks and, where
/// it gives one, force) against the same; and forces or products outside nodes() (must be zero).
struct FieldCallErrors {
  double force_parts = 0.0;
  double product_parts = 0.0;
  double diagonal_blocks = 0.0;
  double tangent_product = 0.0;
  double tangent_pair_product = 0.0;
  double tangent_blocks = 0.0;
  double tangent_force = 0.0;
  double tangent_rows = 0.0;   ///< where the tangent plans rows (ForceField::Tangent::plan_rows)
  double tangent_start = 0.0;  ///< where the tangent takes a step's start in one call (start_part)
  double tangent_start_rows = 0.0;  ///< where it takes it by rows (starts_by_rows, start_rows)
  double outside_nodes = 0.0;       ///< |force and product off the field's nodes| / |force|
  double worst() const;
};
FieldCallErrors check_field_calls(const ForceField& field, const Eigen::VectorXd& x,
                                  const Eigen::VectorXd& v);

}  // namespace msfem::massspring::testing
