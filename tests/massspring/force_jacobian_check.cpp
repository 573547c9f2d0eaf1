#include "force_jacobian_check.hpp"

#include <random>

namespace msfem::massspring::testing {
namespace {

double relative(const Eigen::MatrixXd& reference, const Eigen::MatrixXd& value) {
  const double scale = reference.norm();
  return scale > 0.0 ? (reference - value).norm() / scale : value.norm();
}

Eigen::VectorXd random_direction(Eigen::Index n, unsigned seed) {
  std::mt19937 generator(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Eigen::VectorXd d(n);
  for (Eigen::Index k = 0; k < n; ++k)
    d[k] = uniform(generator);
  return d;
}

}  // namespace

Eigen::VectorXd perturbed(const Eigen::VectorXd& x, double amplitude, unsigned seed) {
  return x + amplitude * random_direction(x.size(), seed);
}

JacobianErrors check_force_jacobians(const ForceModel& model, const Eigen::VectorXd& x,
                                     const Eigen::VectorXd& v, double step) {
  const Eigen::Index n = model.num_dofs();
  Eigen::MatrixXd fd_dfdx(n, n), fd_dfdv(n, n);
  Eigen::VectorXd fd_gradient(n);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    Eigen::VectorXd plus = x, minus = x;
    plus[k] += step;
    minus[k] -= step;
    fd_dfdx.col(k) = (model.force(plus, v) - model.force(minus, v)) / (2.0 * step);
    fd_gradient[k] = (model.potential_energy(plus) - model.potential_energy(minus)) / (2.0 * step);
    Eigen::VectorXd v_plus = v, v_minus = v;
    v_plus[k] += step;
    v_minus[k] -= step;
    fd_dfdv.col(k) = (model.force(x, v_plus) - model.force(x, v_minus)) / (2.0 * step);
  }

  JacobianErrors errors;
  errors.dfdx_matrix = relative(fd_dfdx, Eigen::MatrixXd(model.dfdx(x, v)));
  errors.dfdv_matrix = relative(fd_dfdv, Eigen::MatrixXd(model.dfdv(x)));

  const Eigen::VectorXd direction = random_direction(n, 7);
  Eigen::VectorXd product = Eigen::VectorXd::Zero(n);
  model.add_dfdx_product(x, v, direction, product);
  errors.dfdx_product = relative(fd_dfdx * direction, product);
  product.setZero();
  model.add_dfdv_product(x, direction, product);
  errors.dfdv_product = relative(fd_dfdv * direction, product);

  errors.energy_gradient = relative(model.force(x, zero), -fd_gradient);
  return errors;
}

}  // namespace msfem::massspring::testing
