// Integrators against closed forms: oscillator frequency, damped decay, bounded energy; stable time
// step by power iteration and by bisection; blow-up detection.

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <random>

#include "icosphere.hpp"
#include "msfem/massspring/errors.hpp"
#include "msfem/massspring/integrators.hpp"
#include "msfem/massspring/mass_spring_model.hpp"
#include "msfem/massspring/stability.hpp"
#include "msfem/massspring/topology_builders.hpp"

namespace msfem::massspring {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Node 0 fixed at the origin, node 1 of mass m on a spring of stiffness k and rest length 0.1 m.
MassSpringModel single_oscillator(double k, double m, double spring_damping, double node_damping) {
  SpringNetwork net;
  net.rest_positions.resize(2, 3);
  net.rest_positions << 0, 0, 0, 0.1, 0, 0;
  net.masses = Eigen::Vector2d(1.0, m);
  net.node_damping = Eigen::Vector2d(0.0, node_damping);
  net.node_group = Eigen::VectorXi::Zero(2);
  net.node_group_names = {"all"};
  add_springs(net, {{0, 1}}, "spring");
  net.stiffness.setConstant(k);
  net.damping.setConstant(spring_damping);
  net.fixed_nodes = {0};
  return MassSpringModel(net);
}

struct Oscillation {
  double period = 0.0;      // mean time between upward zero crossings
  double decay_rate = 0.0;  // γ/2 from the envelope: ln(first peak / last peak) / time between
};

// Releases node 1 from 1 mm of stretch and records its displacement.
Oscillation measure(const MassSpringModel& model, IntegratorKind kind, double dt, int steps) {
  Integrator integrator(kind);
  State state = initial_state(model);
  state.x[3] += 0.001;
  std::vector<double> crossings, peak_times, peaks;
  double previous = 0.001, before_previous = 0.001;
  for (int n = 1; n <= steps; ++n) {
    integrator.step(model, state, dt);
    const double u = state.x[3] - 0.1;
    if (previous < 0.0 && u >= 0.0) crossings.push_back(state.time - dt * u / (u - previous));
    if (n >= 2 && previous > before_previous && previous >= u && previous > 0.0) {
      // Parabola through the last three samples locates the peak between them.
      const double curvature = before_previous - 2.0 * previous + u;
      const double offset = 0.5 * (before_previous - u) / curvature;
      peaks.push_back(previous - 0.25 * (before_previous - u) * offset);
      peak_times.push_back(state.time - dt + offset * dt);
    }
    before_previous = previous;
    previous = u;
  }
  Oscillation result;
  if (crossings.size() >= 2)
    result.period = (crossings.back() - crossings.front()) / (crossings.size() - 1);
  if (peaks.size() >= 2)
    result.decay_rate =
        std::log(peaks.front() / peaks.back()) / (peak_times.back() - peak_times.front());
  return result;
}

TEST(Integrators, UndampedOscillatorFrequencyIsSqrtKOverM) {
  const double k = 40.0, m = 0.01;
  const double omega = std::sqrt(k / m);
  const double period = 2.0 * kPi / omega;
  const MassSpringModel model = single_oscillator(k, m, 0.0, 0.0);
  for (IntegratorKind kind :
       {IntegratorKind::explicit_euler, IntegratorKind::symplectic_euler,
        IntegratorKind::central_difference, IntegratorKind::rk4, IntegratorKind::implicit_euler}) {
    const Oscillation result = measure(model, kind, period / 1000.0, 5500);
    EXPECT_NEAR(result.period / period, 1.0, 0.005) << to_string(kind);
  }
}

TEST(Integrators, DampedDecayRateMatchesClosedForm) {
  const double k = 40.0, m = 0.01;
  const double omega = std::sqrt(k / m);
  // Spring damper and node damper both act on the single moving mass: x'' + (c/m) x' + ω² x = 0,
  // envelope e^{-γt/2} with γ = c/m, damped frequency √(ω² - γ²/4).
  for (const auto& [spring_damping, node_damping] : {std::pair{0.02, 0.0}, std::pair{0.0, 0.02}}) {
    const MassSpringModel model = single_oscillator(k, m, spring_damping, node_damping);
    const double gamma = (spring_damping + node_damping) / m;
    const double damped_omega = std::sqrt(omega * omega - 0.25 * gamma * gamma);
    const double period = 2.0 * kPi / damped_omega;
    for (IntegratorKind kind : {IntegratorKind::central_difference, IntegratorKind::rk4}) {
      const Oscillation result = measure(model, kind, period / 2000.0, 2000 * 6);
      EXPECT_NEAR(result.decay_rate / (0.5 * gamma), 1.0, 0.005) << to_string(kind);
      EXPECT_NEAR(result.period / period, 1.0, 0.005) << to_string(kind);
    }
  }
}

MassSpringModel small_three_tier(double node_damping = 0.0) {
  const auto mesh = testing::icosphere(0, 0.05);
  ThreeTierOptions options;
  options.material.node_damping = node_damping;
  return MassSpringModel(build_three_tier(mesh.vertices, mesh.triangles, options));
}

State perturbed_start(const MassSpringModel& model, double amplitude) {
  State state = initial_state(model);
  std::mt19937 generator(99);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (Eigen::Index k = 0; k < state.x.size(); ++k)
    state.x[k] += amplitude * uniform(generator);
  model.enforce_constraints(state.x, state.v);
  return state;
}

// Symplectic methods conserve a shadow energy: the energy oscillates but does not drift.
TEST(Integrators, SymplecticEnergyStaysBoundedOver100kSteps) {
  // The Kuhn cube as tet_edges: small enough for 10⁵ steps of each method under sanitizers.
  Eigen::MatrixX3d cube;
  Eigen::MatrixX4i tets;
  testing::kuhn_cube(cube, tets);
  const MassSpringModel model(build_tet_edges(0.01 * cube, tets));
  const double dt =
      0.3 * predicted_stable_dt(model, IntegratorKind::central_difference, model.initial_state());
  for (IntegratorKind kind :
       {IntegratorKind::symplectic_euler, IntegratorKind::central_difference}) {
    Integrator integrator(kind);
    State state = perturbed_start(model, 5e-4);
    const double initial = model.total_energy(state.x, state.v);
    // Mean energy over the first and the last 10k steps (sampled every 4th step): the time
    // average of the oscillating energy drifts if the method gains or loses energy.
    double first_window = 0.0, last_window = 0.0, highest = 0.0;
    for (int n = 0; n < 100000; ++n) {
      integrator.step(model, state, dt);
      if (n % 4 != 0) continue;
      const double energy = model.total_energy(state.x, state.v);
      highest = std::max(highest, energy);
      if (n < 10000) first_window += energy;
      if (n >= 90000) last_window += energy;
    }
    EXPECT_LT(highest / initial, 2.0) << to_string(kind);
    EXPECT_NEAR(last_window / first_window, 1.0, 0.02) << to_string(kind);
  }
}

TEST(Stability, PowerIterationMatchesDenseEigenvalue) {
  const MassSpringModel model = small_three_tier();
  const Eigen::VectorXd x = model.initial_state();
  // Dense M^-½ K M^-½ on the free dofs.
  Eigen::MatrixXd k =
      -Eigen::MatrixXd(model.dfdx(x, Eigen::VectorXd::Zero(x.size()), Linearisation::definite));
  const Eigen::VectorXd inv_sqrt_m = model.mass_per_dof().cwiseSqrt().cwiseInverse();
  k = inv_sqrt_m.asDiagonal() * k * inv_sqrt_m.asDiagonal();
  std::vector<int> free;
  for (int i = 0; i < model.num_nodes(); ++i)
    if (!model.is_constrained(i))
      for (int c = 0; c < 3; ++c)
        free.push_back(3 * i + c);
  Eigen::MatrixXd k_free(free.size(), free.size());
  for (std::size_t r = 0; r < free.size(); ++r)
    for (std::size_t c = 0; c < free.size(); ++c)
      k_free(r, c) = k(free[r], free[c]);
  const double exact =
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(k_free).eigenvalues().maxCoeff();
  const SpectralEstimate estimate = estimate_max_eigenvalue(model, x, 2000, 1e-10);
  EXPECT_NEAR(estimate.max_eigenvalue / exact, 1.0, 1e-3);
}

TEST(Stability, BisectionAgreesWithPrediction) {
  const MassSpringModel model = small_three_tier();
  const double predicted =
      predicted_stable_dt(model, IntegratorKind::central_difference, model.initial_state());
  const double measured = measure_stable_dt(model, IntegratorKind::central_difference,
                                            0.1 * predicted, 5.0 * predicted, 2000, 0.005);
  EXPECT_NEAR(measured / predicted, 1.0, 0.03);
  // Strong spring dampers shorten the central-difference step: h²ω² + 2hγ < 4.
  const auto mesh = testing::icosphere(0, 0.05);
  ThreeTierOptions damped_options;
  damped_options.material.spring_damping = 0.5;
  const MassSpringModel spring_damped(
      build_three_tier(mesh.vertices, mesh.triangles, damped_options));
  const double damped_predicted = predicted_stable_dt(
      spring_damped, IntegratorKind::central_difference, spring_damped.initial_state());
  EXPECT_LT(damped_predicted, 0.9 * predicted);
  const double damped_measured =
      measure_stable_dt(spring_damped, IntegratorKind::central_difference, 0.1 * damped_predicted,
                        5.0 * damped_predicted, 2000, 0.005);
  // The prediction may be conservative here (the top stiffness mode is not exactly the top
  // damped mode) but never optimistic.
  EXPECT_GT(damped_measured / damped_predicted, 0.97);
  EXPECT_LT(damped_measured / damped_predicted, 1.6);
  // Explicit Euler with node damping: h < γ/ω².
  const MassSpringModel damped = small_three_tier(0.5);
  const double euler_predicted =
      predicted_stable_dt(damped, IntegratorKind::explicit_euler, damped.initial_state());
  const double euler_measured =
      measure_stable_dt(damped, IntegratorKind::explicit_euler, 0.05 * euler_predicted,
                        5.0 * euler_predicted, 2000, 0.005);
  EXPECT_NEAR(euler_measured / euler_predicted, 1.0, 0.1);
}

TEST(Stability, BlowUpIsDetectedAndReportsTheStableStep) {
  const MassSpringModel model = small_three_tier();
  const double stable =
      predicted_stable_dt(model, IntegratorKind::central_difference, model.initial_state());
  Integrator integrator(IntegratorKind::central_difference);
  State state = perturbed_start(model, 1e-5);
  try {
    run_dynamics(model, integrator, state, 3.0 * stable, 1000);
    FAIL() << "no divergence detected";
  } catch (const DivergenceError& error) {
    EXPECT_NEAR(error.stable_dt() / stable, 1.0, 1e-6);
    EXPECT_NE(std::string(error.what()).find("stable dt"), std::string::npos);
    EXPECT_LT(state.time / (3.0 * stable), 30.0);  // caught within a few steps of growth
  }
  // The same run at half the stable step is fine, and implicit Euler is fine at 20x.
  State calm = perturbed_start(model, 1e-5);
  Integrator verlet(IntegratorKind::central_difference);
  EXPECT_NO_THROW(run_dynamics(model, verlet, calm, 0.5 * stable, 1000));
  State implicit_state = perturbed_start(model, 1e-5);
  Integrator implicit(IntegratorKind::implicit_euler);
  const double start_energy = model.total_energy(implicit_state.x, implicit_state.v);
  EXPECT_NO_THROW(run_dynamics(model, implicit, implicit_state, 20.0 * stable, 200));
  EXPECT_LT(model.total_energy(implicit_state.x, implicit_state.v), start_energy);
}

TEST(Stability, RejectsBadTimeSteps) {
  const MassSpringModel model = small_three_tier();
  Integrator integrator(IntegratorKind::rk4);
  State state = initial_state(model);
  for (double dt : {0.0, -1e-3, std::nan("")}) {
    try {
      integrator.step(model, state, dt);
      FAIL() << "dt " << dt << " accepted";
    } catch (const ModelError& error) {
      EXPECT_NE(std::string(error.what()).find("time step dt"), std::string::npos);
    }
  }
}

}  // namespace
}  // namespace msfem::massspring
