#include "msfem/massspring/integrators.hpp"
#include "msfem/massspring/tool_contact.hpp"

#include <cmath>

#include "msfem/massspring/errors.hpp"

namespace msfem::massspring {

State initial_state(const MechanicalSystem& model) {
  State state{model.rest_state(), Eigen::VectorXd::Zero(model.num_dofs()), 0.0};
  model.enforce_constraints(state.x, state.v);
  return state;
}

std::string to_string(IntegratorKind kind) {
  return integrator_table.name(kind);
}

const std::vector<IntegratorKind>& all_integrators() {
  static const std::vector<IntegratorKind> kinds = integrator_table.values();
  return kinds;
}

std::string integrator_names(const std::string& separator) {
  return integrator_table.names(separator);
}

IntegratorKind parse_integrator(const std::string& name) {
  if (const auto kind = integrator_table.find(name)) return *kind;
  throw ModelError("integrator '" + name + "': unknown (" + integrator_names(", ") + ")");
}

void check_time_step(double dt) {
  if (!(dt > 0.0) || !std::isfinite(dt))
    throw ModelError("time step dt = " + std::to_string(dt) + " s must be finite and > 0");
}

void Integrator::step(const MechanicalSystem& model, State& state, double dt) {
  check_time_step(dt);
  if (state.x.size() != model.num_dofs() || state.v.size() != model.num_dofs())
    throw ModelError("state: size " + std::to_string(state.x.size()) + " does not match " +
                     std::to_string(model.num_dofs()) + " model dofs");
  last_cg_iterations_ = 0;
  switch (kind_) {
    case IntegratorKind::explicit_euler: {
      const Eigen::VectorXd a = model.acceleration(state.x, state.v);
      state.x += dt * state.v;
      state.v += dt * a;
      break;
    }
    case IntegratorKind::symplectic_euler: {
      state.v += dt * model.acceleration(state.x, state.v);
      state.x += dt * state.v;
      break;
    }
    case IntegratorKind::central_difference: {
      state.v += 0.5 * dt * model.acceleration(state.x, state.v);
      state.x += dt * state.v;
      state.v += 0.5 * dt * model.acceleration(state.x, state.v);
      break;
    }
    case IntegratorKind::rk4: {
      const Eigen::VectorXd& x = state.x;
      const Eigen::VectorXd& v = state.v;
      const Eigen::VectorXd a1 = model.acceleration(x, v);
      const Eigen::VectorXd v2 = v + 0.5 * dt * a1;
      const Eigen::VectorXd a2 = model.acceleration(x + 0.5 * dt * v, v2);
      const Eigen::VectorXd v3 = v + 0.5 * dt * a2;
      const Eigen::VectorXd a3 = model.acceleration(x + 0.5 * dt * v2, v3);
      const Eigen::VectorXd v4 = v + dt * a3;
      const Eigen::VectorXd a4 = model.acceleration(x + dt * v3, v4);
      state.x += dt / 6.0 * (v + 2.0 * v2 + 2.0 * v3 + v4);
      state.v += dt / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4);
      break;
    }
    case IntegratorKind::implicit_euler:
      implicit_euler_step(model, state, dt);
      break;
  }
  model.enforce_constraints(state.x, state.v);
  project_out_of_tool(model, state.x, state.v);
  state.time += dt;
}

}  // namespace msfem::massspring
