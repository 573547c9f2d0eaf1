#pragma once
// One interface for everything that advances a system in time, and the factory that picks what a
// simulator would run for an integrator: the fast kernels where they cover it, the generic
// integrator elsewhere.

#include <memory>

#include "msfem/massspring/integrators.hpp"
#include "msfem/massspring/mechanical_system.hpp"

namespace msfem::massspring {

/// A system's state advanced step by step. The system must outlive the stepper.
class Stepper {
 public:
  virtual ~Stepper() = default;

  /// The scheme the steps follow (central difference runs as its leapfrog form, symplectic Euler).
  virtual IntegratorKind kind() const = 0;
  /// What runs the steps: "fast_explicit", "fast_implicit" or "generic".
  virtual const char* name() const = 0;
  /// The arithmetic of the steps: "double" or "float" (the fast steppers' single precision).
  virtual const char* precision() const { return "double"; }
  virtual void set_state(const State& state) = 0;
  virtual State state() const = 0;
  /// Advances `count` steps of size dt. Throws ModelError for a bad dt.
  virtual void step(double dt, int count = 1) = 0;
  /// Re-reads the system's coefficients (stiffness, damping, masses, loads, support targets) after
  /// a run-time change; the topology and the set of supported nodes must be the same.
  virtual void update_parameters(const MechanicalSystem& system) = 0;
  /// True where one step(dt, count) call runs its steps at one start of the threads, so that a
  /// caller timing it should ask for many at once (the fast explicit stepper).
  virtual bool batches_steps() const { return false; }
};

/// How make_stepper sets up what it picks; the fast implicit stepper keeps its haptic CG settings
/// (FastImplicitOptions), the generic implicit Euler ImplicitOptions'.
struct StepperChoice {
  int threads = 0;                ///< > 0 caps the fast steppers' default thread count
  bool single_precision = false;  ///< the fast steppers in float (none other has it)
};

/// The stepper a simulator runs for `kind` on `system`, started at `start`: FastExplicitStepper
/// for symplectic Euler, central difference (as symplectic Euler with velocities read at half
/// steps: one force pass a step, the same stable step), explicit Euler and RK4;
/// FastImplicitStepper for implicit Euler; the generic Integrator where the system has no springs
/// for the kernels (no SpringForceField). Throws ModelError where single precision is asked of
/// the generic integrator.
std::unique_ptr<Stepper> make_stepper(const MechanicalSystem& system, IntegratorKind kind,
                                      const State& start, const StepperChoice& choice = {});

/// The generic Integrator behind the Stepper interface: any scheme, any system.
class GenericStepper : public Stepper {
 public:
  GenericStepper(const MechanicalSystem& system, IntegratorKind kind, ImplicitOptions implicit = {})
      : system_(&system), integrator_(kind, implicit), state_(initial_state(system)) {}
  IntegratorKind kind() const override { return integrator_.kind(); }
  const char* name() const override { return "generic"; }
  void set_state(const State& state) override { state_ = state; }
  State state() const override { return state_; }
  void step(double dt, int count = 1) override;
  void update_parameters(const MechanicalSystem& system) override { system_ = &system; }
  int last_cg_iterations() const { return integrator_.last_cg_iterations(); }

 private:
  const MechanicalSystem* system_;
  Integrator integrator_;
  State state_;
};

}  // namespace msfem::massspring
