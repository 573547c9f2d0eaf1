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

}  // namespace msfem::massspring::testing
