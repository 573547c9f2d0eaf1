#include "msfem/massspring/stability.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <sstream>

#include "msfem/massspring/errors.hpp"
#include "msfem/massspring/nodal_load_field.hpp"
#include "msfem/massspring/spring_force_field.hpp"
#include "msfem/massspring/tool_contact.hpp"

namespace msfem::massspring {
namespace {

// The system without its loads and its tool's contact: stability is a property of M, K and the
// damping, not of the loads.
class UnloadedSystem : public MechanicalSystem {
 public:
  explicit UnloadedSystem(const MechanicalSystem& system)
      : system_(system), springs_(system.find_field<SpringForceField>()) {
    const ForceField* loads = system.find_field<NodalLoadField>();
    for (const auto& field : system.fields())
      if (field.get() != loads && !dynamic_cast<const ToolContact*>(field.get()))
        fields_.push_back(field);
  }
  int num_nodes() const override { return system_.num_nodes(); }
  Eigen::VectorXd rest_state() const override { return system_.rest_state(); }
  const Eigen::VectorXd& masses() const override { return system_.masses(); }
  bool is_constrained(int node) const override { return system_.is_constrained(node); }
  Eigen::Vector3d constrained_target(int node) const override {
    return system_.constrained_target(node);
  }
  const FieldList& fields() const override { return fields_; }

  // The springs' energy where there are springs (the energy a run away oscillation feeds), the
  // fields' otherwise.
  double elastic_energy(const Eigen::VectorXd& x) const {
    return springs_ ? springs_->potential_energy(x) : potential_energy(x);
  }
  // The springs' mean rest length, or the rest state's extent over the cube root of its nodes.
  double length_scale() const {
    if (springs_ && springs_->network().num_springs() > 0)
      return springs_->network().rest_length.mean();
    const Eigen::MatrixX3d rest = unflatten(rest_state());
    const double extent = (rest.colwise().maxCoeff() - rest.colwise().minCoeff()).norm();
    return extent / std::cbrt(std::max(num_nodes(), 1));
  }

 private:
  const MechanicalSystem& system_;
  const SpringForceField* springs_;
  FieldList fields_;
};

}  // namespace

SpectralEstimate estimate_max_eigenvalue(const MechanicalSystem& model, const Eigen::VectorXd& x,
                                         int max_iterations, double tolerance) {
  const Eigen::Index n = x.size();
  const Eigen::VectorXd inv_sqrt_mass = model.mass_per_dof().cwiseSqrt().cwiseInverse();
  const Eigen::VectorXd v = Eigen::VectorXd::Zero(n);
  std::mt19937 generator(12345);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Eigen::VectorXd z(n);
  for (Eigen::Index k = 0; k < n; ++k)
    z[k] = uniform(generator);
  model.zero_constrained(z);
  SpectralEstimate estimate;
  if (z.norm() == 0.0) return estimate;  // everything constrained
  z.normalize();
  double previous = 0.0;
  for (int it = 1; it <= max_iterations; ++it) {
    Eigen::VectorXd y = Eigen::VectorXd::Zero(n);
    model.add_dfdx_product(x, v, inv_sqrt_mass.cwiseProduct(z), y, Linearisation::definite);
    y = -inv_sqrt_mass.cwiseProduct(y);  // M^-½ K M^-½ z with K = -∂f/∂x
    model.zero_constrained(y);
    const double rayleigh = z.dot(y);
    estimate.max_eigenvalue = rayleigh;
    estimate.iterations = it;
    const double norm = y.norm();
    if (!(norm > 0.0)) break;
    z = y / norm;
    if (it > 5 && std::abs(rayleigh - previous) <= tolerance * std::abs(rayleigh)) break;
    previous = rayleigh;
  }
  // Damping seen by the mode y = M^-½ z (Rayleigh quotient of C against M).
  const Eigen::VectorXd mode = inv_sqrt_mass.cwiseProduct(z);
  Eigen::VectorXd damping_force = Eigen::VectorXd::Zero(n);
  model.add_dfdv_product(x, mode, damping_force);
  model.zero_constrained(damping_force);
  estimate.mode_damping_rate = -mode.dot(damping_force) / z.squaredNorm();
  return estimate;
}

double predicted_stable_dt(const MechanicalSystem& model, IntegratorKind kind,
                           const Eigen::VectorXd& x) {
  if (kind == IntegratorKind::implicit_euler) return std::numeric_limits<double>::infinity();
  const SpectralEstimate spectrum = estimate_max_eigenvalue(model, x);
  const double lambda = spectrum.max_eigenvalue;
  if (!(lambda > 0.0)) return std::numeric_limits<double>::infinity();
  const double omega = std::sqrt(lambda);
  switch (kind) {
    case IntegratorKind::symplectic_euler:
    case IntegratorKind::central_difference: {
      // x'' + γx' + ω²x = 0 stepped with explicit damping is stable for h²ω² + 2hγ < 4:
      // h < (√(γ² + 4ω²) - γ) / ω², i.e. 2/ω undamped. Dampers on light nodes matter here.
      const double gamma = std::max(spectrum.mode_damping_rate, 0.0);
      return (std::sqrt(gamma * gamma + 4.0 * lambda) - gamma) / lambda;
    }
    case IntegratorKind::rk4:
      return 2.0 * std::sqrt(2.0) / omega;
    case IntegratorKind::explicit_euler: {
      // |1 + hλ| <= 1  <=>  h <= -2 Re λ / |λ|², for both roots of λ² + γλ + ω² = 0.
      const double gamma = std::max(spectrum.mode_damping_rate, 0.0);
      const double discriminant = 0.25 * gamma * gamma - lambda;
      if (discriminant < 0.0) return gamma / lambda;
      const double fastest = 0.5 * gamma + std::sqrt(discriminant);
      return 2.0 / fastest;
    }
    case IntegratorKind::implicit_euler:
      break;
  }
  return std::numeric_limits<double>::infinity();
}

std::string divergence_reason(const MechanicalSystem& model, const State& state,
                              double max_strain) {
  if (!state.x.allFinite()) return "non-finite position";
  if (!state.v.allFinite()) return "non-finite velocity";
  const auto* springs = model.find_field<SpringForceField>();
  if (!springs) return "";
  const SpringNetwork& net = springs->network();
  const double stretch_limit = 1.0 + max_strain;
  for (int s = 0; s < net.num_springs(); ++s) {
    const double length =
        (state.x.segment<3>(3 * net.springs(s, 1)) - state.x.segment<3>(3 * net.springs(s, 0)))
            .norm();
    const double ratio = length / net.rest_length[s];
    if (ratio > stretch_limit || ratio * stretch_limit < 1.0) {
      std::ostringstream out;
      out << "spring " << s << " at " << ratio << " x its rest length";
      return out.str();
    }
  }
  return "";
}

void run_dynamics(const MechanicalSystem& model, Integrator& integrator, State& state, double dt,
                  int steps, const RunOptions& options) {
  check_time_step(dt);
  const int every = std::max(options.check_every, 1);
  for (int step = 1; step <= steps; ++step) {
    integrator.step(model, state, dt);
    if (step % every != 0 && step != steps) continue;
    const std::string reason = divergence_reason(model, state, options.max_strain);
    if (reason.empty()) continue;
    const double stable = predicted_stable_dt(model, integrator.kind(), model.initial_state());
    std::ostringstream out;
    out << to_string(integrator.kind()) << " diverged at step " << step << " (t = " << state.time
        << " s) with dt = " << dt << " s: " << reason << "; predicted stable dt = " << stable
        << " s (largest eigenvalue of M^-1 K), use a smaller dt or implicit_euler";
    throw DivergenceError(out.str(), dt, stable);
  }
}

double measure_stable_dt(const MechanicalSystem& model, IntegratorKind kind, double dt_low,
                         double dt_high, int steps, double relative_tolerance) {
  check_time_step(dt_low);
  check_time_step(dt_high);
  if (!(dt_high > dt_low))
    throw ModelError("stable dt bisection: dt_high " + std::to_string(dt_high) +
                     " must exceed dt_low " + std::to_string(dt_low));
  const UnloadedSystem probe(model);
  State start = initial_state(probe);
  const double scale = 1e-4 * probe.length_scale();
  std::mt19937 generator(4242);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (Eigen::Index k = 0; k < start.x.size(); ++k)
    start.x[k] += scale * uniform(generator);
  probe.enforce_constraints(start.x, start.v);
  auto energy = [&](const State& s) {
    return probe.kinetic_energy(s.v) + probe.elastic_energy(s.x);
  };
  const double initial_energy = energy(start);
  auto bounded = [&](double dt) {
    Integrator integrator(kind);
    State state = start;
    for (int step = 0; step < steps; ++step) {
      integrator.step(probe, state, dt);
      if (!state.x.allFinite() || !state.v.allFinite()) return false;
    }
    return energy(state) <= 10.0 * initial_energy;
  };
  if (!bounded(dt_low)) return dt_low;
  if (bounded(dt_high)) return dt_high;
  double low = dt_low, high = dt_high;
  while (high - low > relative_tolerance * low) {
    const double middle = 0.5 * (low + high);
    (bounded(middle) ? low : high) = middle;
  }
  return low;
}

}  // namespace msfem::massspring
