#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "msfem/massspring/mechanical_system.hpp"
#include "msfem/massspring/name_table.hpp"

namespace msfem::massspring {

/// Positions and velocities of all nodes (node-major, 3n each) and the time.
struct State {
  Eigen::VectorXd x;
  Eigen::VectorXd v;
  double time = 0.0;
};

/// The model's initial state: rest positions, constrained nodes at their targets, at rest.
State initial_state(const MechanicalSystem& model);

enum class IntegratorKind {
  explicit_euler,      ///< x' = x + h v,  v' = v + h a(x, v)
  symplectic_euler,    ///< v' = v + h a(x, v),  x' = x + h v'
  central_difference,  ///< velocity Verlet (kick-drift-kick), the pancreas paper's central
                       ///< differences; damping uses the half-step velocity
  rk4,                 ///< classical fourth-order Runge-Kutta
  implicit_euler       ///< backward Euler, one Newton step per time step with the definite
                       ///< linearisation, solved by Jacobi-preconditioned CG (Baraff & Witkin 1998)
};

/// The integrators' names: the one list case files, `msfem sweep --integrators` and
/// parse_integrator accept.
inline constexpr NameTable<IntegratorKind, 5> integrator_table{{{
    {IntegratorKind::explicit_euler, "explicit_euler"},
    {IntegratorKind::symplectic_euler, "symplectic_euler"},
    {IntegratorKind::central_difference, "central_difference"},
    {IntegratorKind::rk4, "rk4"},
    {IntegratorKind::implicit_euler, "implicit_euler"},
}}};

/// The kind's name in integrator_table.
std::string to_string(IntegratorKind kind);
/// Every integrator, in integrator_table's order.
const std::vector<IntegratorKind>& all_integrators();
/// Their names joined by `separator` ("|" gives a deal.II Selection pattern).
std::string integrator_names(const std::string& separator);
/// Inverse of to_string; throws ModelError naming the value.
IntegratorKind parse_integrator(const std::string& name);

struct ImplicitOptions {
  double cg_tolerance = 1e-8;  ///< relative residual of (M - h D - h² K) Δv = b
  int cg_max_iterations = 500;
};

/// Advances a state by one step of size dt. Constrained nodes are held at their targets; with tool
/// contact active, nodes that end inside the tool are projected onto it (frictionless).
class Integrator {
 public:
  explicit Integrator(IntegratorKind kind, ImplicitOptions implicit = {})
      : kind_(kind), implicit_(implicit) {}

  /// Throws ModelError if dt is not finite and > 0.
  void step(const MechanicalSystem& model, State& state, double dt);

  IntegratorKind kind() const { return kind_; }
  /// CG iterations used by the last implicit step (0 for explicit integrators).
  int last_cg_iterations() const { return last_cg_iterations_; }

 private:
  void implicit_euler_step(const MechanicalSystem& model, State& state, double dt);

  IntegratorKind kind_;
  ImplicitOptions implicit_;
  int last_cg_iterations_ = 0;
  Eigen::VectorXd previous_dv_;  // warm start for CG
};

/// Throws ModelError naming dt unless it is finite and > 0.
void check_time_step(double dt);

}  // namespace msfem::massspring
