// The calibration helpers a simulator can use without msfem's harness: statics linearised at rest
// with the stiffness split into scalable parts, and spring dampers fitted for a modal damping
// ratio.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "msfem/massspring/integrators.hpp"
#include "msfem/massspring/linearised_statics.hpp"
#include "msfem/massspring/mass_spring_model.hpp"
#include "msfem/massspring/modal_damping.hpp"

namespace msfem::massspring {
namespace {

// Node 0 (mass m0) at the origin tied to six nodes (mass m) at ±length on each axis (nodes 1, 2
// on +x, -x; 3, 4 on ±y; 5, 6 on ±z), spring s joining node 0 to node s + 1 with stiffness k[s].
SpringNetwork star(const Eigen::VectorXd& k, double length, double m0 = 0.01, double m = 0.01) {
  SpringNetwork n;
  n.rest_positions = Eigen::MatrixX3d::Zero(7, 3);
  for (int a = 0; a < 3; ++a) {
    n.rest_positions(1 + 2 * a, a) = length;
    n.rest_positions(2 + 2 * a, a) = -length;
  }
  n.masses = Eigen::VectorXd::Constant(7, m);
  n.masses[0] = m0;
  n.node_damping = Eigen::VectorXd::Zero(7);
  n.node_group = Eigen::VectorXi::Zero(7);
  n.node_group_names = {"all"};
  n.springs.resize(6, 2);
  for (int s = 0; s < 6; ++s)
    n.springs.row(s) << 0, s + 1;
  n.stiffness = k;
  n.damping = Eigen::VectorXd::Zero(6);
  n.rest_length = Eigen::VectorXd::Constant(6, length);
  n.spring_group = Eigen::VectorXi::Zero(6);
  n.spring_group_names = {"s"};
  n.surface_nodes = {0, 1, 2, 3, 4, 5, 6};
  return n;
}

// The +x spring (k1, part 0) and the -x spring (k2, part 1) in series between a node moved u along
// x and a fixed one; the y and z springs (part 2) hold the free node sideways. With weights w the
// free node moves w0 k1 u / (w0 k1 + w1 k2) and the moved node feels the series spring's force
// -k1 k2 w0 w1 u / (w0 k1 + w1 k2); one factorisation per set of weights, any weights.
TEST(LinearisedStatics, TwoSpringsInSeriesUnderEveryWeighting) {
  const double k1 = 40.0, k2 = 10.0, k3 = 5.0, u = 1e-4;
  const Eigen::VectorXd k = (Eigen::VectorXd(6) << k1, k2, k3, k3, k3, k3).finished();
  MassSpringModel model(star(k, 0.01));
  for (int node = 2; node < 7; ++node)
    model.fix_node(node);
  model.prescribe_displacement(1, Eigen::Vector3d(u, 0, 0));
  std::vector<Eigen::VectorXd> parts(3, Eigen::VectorXd::Zero(6));
  parts[0][0] = k1;
  parts[1][1] = k2;
  parts[2].tail(4) = k.tail(4);
  LinearisedStatics statics(model, parts);
  ASSERT_EQ(statics.num_parts(), 3);
  for (const std::vector<double>& w :
       {std::vector<double>{1, 1, 1}, {0.5, 3.0, 1.0}, {2, 0.1, 7}}) {
    const auto s = statics.solve(w, {1});
    const double a = w[0] * k1, b = w[1] * k2;
    EXPECT_NEAR(s.surface_displacement(0, 0), a * u / (a + b), 1e-12);
    EXPECT_NEAR(s.surface_displacement.row(0).tail<2>().norm(), 0.0, 1e-15);
    EXPECT_NEAR(s.patch_force.x(), -a * b * u / (a + b), 1e-12 * a);
    EXPECT_NEAR(s.patch_force.tail<2>().norm(), 0.0, 1e-12);
  }
}

// A free node of mass m held by six equal springs to fixed nodes of mass m_a on ±x, ±y, ±z: K = 2k
// I, so every mode has ω² = 2k/m, and C = 2d I with d = 2 r √(k μ), μ = m_a m/(m_a+m), gives the
// modal ratio ζ = d/(ω m) = r √(2μ/m). The fitted r must also damp a simulated free vibration so.
TEST(ModalDamping, DampingFitMatchesTheSixSpringOscillatorAndItsFreeVibration) {
  const double k = 50.0, m = 0.2, m_a = 0.3, length = 0.01;
  MassSpringModel model(star(Eigen::VectorXd::Constant(6, k), length, m, m_a));
  for (int node = 1; node < 7; ++node)
    model.fix_node(node);

  const double target = 0.1;
  const DampingFit fit = fit_damping(model, model.initial_state(), target);
  const double omega = std::sqrt(2 * k / m), mu = m_a * m / (m_a + m);
  EXPECT_NEAR(fit.frequency_hz, omega / (2 * M_PI), 1e-8 * omega);
  // Every mode is alike here, so a given shape (the Rayleigh-quotient path) agrees.
  Eigen::VectorXd shape = Eigen::VectorXd::Zero(model.num_dofs());
  shape[0] = 1e-4;
  shape[1] = -3e-5;
  const DampingFit along = fit_damping(model, model.initial_state(), target, shape);
  EXPECT_NEAR(along.frequency_hz, fit.frequency_hz, 1e-9 * fit.frequency_hz);
  EXPECT_NEAR(along.case_damping_ratio, fit.case_damping_ratio, 1e-9);
  EXPECT_NEAR(fit.modal_ratio_per_unit_r, std::sqrt(2 * mu / m), 1e-8);
  EXPECT_NEAR(fit.case_damping_ratio, target / std::sqrt(2 * mu / m), 1e-8);
  ASSERT_TRUE(fit.reachable);

  // Free vibration with the fitted damping: the logarithmic decrement gives ζ back.
  Eigen::VectorXd d(6);
  for (int s = 0; s < 6; ++s)
    d[s] = 2 * fit.case_damping_ratio * std::sqrt(k * mu);
  model.set_damping(d);
  State state = initial_state(model);
  state.x[0] = 1e-5;  // small: the springs stay linear
  const double period = 2 * M_PI / omega, dt = period / 2000;
  Integrator rk4(IntegratorKind::rk4);
  std::vector<double> peaks;
  double previous = state.x[0], before_previous = state.x[0];
  for (int step = 0; step < 8000 && peaks.size() < 3; ++step) {
    rk4.step(model, state, dt);
    if (previous > before_previous && previous > state.x[0] && previous > 0)
      peaks.push_back(previous);
    before_previous = previous;
    previous = state.x[0];
  }
  ASSERT_EQ(peaks.size(), 3u);
  const double delta = std::log(peaks[0] / peaks[1]);
  const double zeta = delta / std::sqrt(4 * M_PI * M_PI + delta * delta);
  EXPECT_NEAR(zeta, target, 0.01 * target);
}

}  // namespace
}  // namespace msfem::massspring
