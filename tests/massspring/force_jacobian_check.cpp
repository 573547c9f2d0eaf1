#include "force_jacobian_check.hpp"

#include <algorithm>
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

double FieldCallErrors::worst() const {
  return std::max({force_parts, product_parts, diagonal_blocks, tangent_product,
                   tangent_pair_product, tangent_blocks, tangent_force, tangent_rows, tangent_start,
                   tangent_start_rows, outside_nodes});
}

FieldCallErrors check_field_calls(const ForceField& field, const Eigen::VectorXd& x,
                                  const Eigen::VectorXd& v) {
  const Eigen::Index n = field.num_dofs();
  const int nodes = static_cast<int>(n / 3);
  const Linearisation definite = Linearisation::definite;
  const Eigen::VectorXd dx = random_direction(n, 11), dx2 = random_direction(n, 12);
  Eigen::VectorXd force = Eigen::VectorXd::Zero(n), product = force, product2 = force;
  field.add_force(x, v, force);
  field.add_dfdx_product(x, v, dx, product, definite);
  field.add_dfdx_product(x, v, dx2, product2, definite);
  const double cx = -2.0, cv = -0.5;
  const Eigen::MatrixXd jacobian =
      cx * Eigen::MatrixXd(field.dfdx(x, v, definite)) + cv * Eigen::MatrixXd(field.dfdv(x));
  Eigen::MatrixXd blocks_expected = Eigen::MatrixXd::Zero(n, 3);
  for (int i = 0; i < nodes; ++i)
    blocks_expected.middleRows<3>(3 * i) = jacobian.block<3, 3>(3 * i, 3 * i);
  auto stacked = [&](const std::vector<Eigen::Matrix3d>& blocks) {
    Eigen::MatrixXd s(n, 3);
    for (int i = 0; i < nodes; ++i)
      s.middleRows<3>(3 * i) = blocks[i];
    return s;
  };
  auto worse = [](double& slot, double value) { slot = std::max(slot, value); };

  // Rows, where the tangent plans them: the even nodes, the odd ones (so that an element or a
  // contact point straddles the two), all of them.
  std::vector<std::vector<int>> plans(3);
  for (int i = 0; i < nodes; ++i) {
    plans[std::size_t(i % 2)].push_back(i);
    plans[2].push_back(i);
  }

  FieldCallErrors e;
  std::vector<Eigen::Matrix3d> blocks(nodes, Eigen::Matrix3d::Zero());
  field.add_diagonal_blocks(x, v, cx, cv, blocks, definite);
  e.diagonal_blocks = relative(blocks_expected, stacked(blocks));
  for (int parts = 1; parts <= 3; ++parts) {
    Eigen::VectorXd f = Eigen::VectorXd::Zero(n), df = f, tf = f, tdf = f, tdf1 = f, tdf2 = f;
    std::vector<Eigen::Matrix3d> tangent_blocks(nodes, Eigen::Matrix3d::Zero());
    const auto tangent = field.tangent(x, v, definite);
    const bool rows = tangent->plan_rows(plans);
    bool gives_force = true;
    for (int part = 0; part < parts; ++part) {
      field.add_force_part(x, v, f, part, parts);
      field.add_dfdx_product_part(x, v, dx, df, definite, part, parts);
      tangent->set_part(part, parts);
    }
    for (int part = 0; part < parts; ++part) {
      tangent->add_product_part(dx, tdf, part, parts);
      tangent->add_product_pair_part(dx, tdf1, dx2, tdf2, part, parts);
      tangent->add_diagonal_blocks_part(cx, cv, tangent_blocks, part, parts);
      gives_force = tangent->add_force_part(tf, part, parts) && gives_force;
    }
    worse(e.force_parts, relative(force, f));
    worse(e.product_parts, relative(product, df));
    worse(e.tangent_product, relative(product, tdf));
    worse(e.tangent_pair_product, std::max(relative(product, tdf1), relative(product2, tdf2)));
    worse(e.tangent_blocks, relative(blocks_expected, stacked(tangent_blocks)));
    if (gives_force) worse(e.tangent_force, relative(force, tf));
    // A plan's rows are the product's at its nodes; the other entries keep what they held.
    const auto check_rows = [&](int plan) {
      Eigen::VectorXd expected = Eigen::VectorXd::Constant(n, 7.0), got = expected;
      for (int i : plans[std::size_t(plan)])
        expected.segment<3>(3 * i) += product.segment<3>(3 * i);
      tangent->add_product_rows(dx, got, plan);
      worse(e.tangent_rows, (got - expected).norm() / product.norm());
    };
    for (int plan = 0; rows && plan < int(plans.size()); ++plan)
      check_rows(plan);
    // The start of a step by rows: force + K dx, K dx2 and the blocks at the plan's rows, the
    // other entries kept; the products after it (which may read what it gathered) again.
    if (rows && tangent->starts_by_rows()) {
      for (int plan = 0; plan < int(plans.size()); ++plan) {
        Eigen::VectorXd f_expected = Eigen::VectorXd::Constant(n, 7.0), f_got = f_expected;
        Eigen::VectorXd df2_expected = f_expected, df2_got = f_expected;
        std::vector<Eigen::Matrix3d> blocks_got(nodes, Eigen::Matrix3d::Identity());
        Eigen::MatrixXd blocks_want = stacked(blocks_got);
        for (int i : plans[std::size_t(plan)]) {
          f_expected.segment<3>(3 * i) += force.segment<3>(3 * i) + product.segment<3>(3 * i);
          df2_expected.segment<3>(3 * i) += product2.segment<3>(3 * i);
          blocks_want.middleRows<3>(3 * i) += blocks_expected.middleRows<3>(3 * i);
        }
        tangent->start_rows(dx, f_got, dx2, df2_got, cx, blocks_got, plan);
        worse(e.tangent_start_rows,
              std::max({(f_got - f_expected).norm() / (force + product).norm(),
                        (df2_got - df2_expected).norm() / product2.norm(),
                        relative(blocks_want, stacked(blocks_got))}));
        check_rows(plan);
      }
    }
    // The start of a step in one call, on a tangent of its own (start_part sets it).
    const auto starter = field.tangent(x, v, definite);
    starter->plan_rows(plans);
    Eigen::VectorXd sf = Eigen::VectorXd::Zero(n), sdf2 = sf;
    std::vector<Eigen::Matrix3d> start_blocks(nodes, Eigen::Matrix3d::Zero());
    bool started = true;
    for (int part = 0; part < parts; ++part)
      started =
          starter->start_part(dx, sf, dx2, sdf2, cx, cv, start_blocks, part, parts) && started;
    if (started)
      worse(e.tangent_start, std::max({relative(force + product, sf), relative(product2, sdf2),
                                       relative(blocks_expected, stacked(start_blocks))}));
  }
  std::vector<char> on(nodes, 0);
  for (int i : field.nodes())
    on[i] = 1;
  double outside = 0.0;
  for (int i = 0; i < nodes; ++i)
    if (!on[i]) outside += force.segment<3>(3 * i).norm() + product.segment<3>(3 * i).norm();
  e.outside_nodes = outside / std::max(force.norm(), 1e-300);
  return e;
}

}  // namespace msfem::massspring::testing
