#pragma once
// A variant stepped by the code a simulator would run for it: the case's integrator on the fast
// kernels. msfem run and sweep time it (variant_timing.cpp); msfem haptic replays with it.

#include <memory>

#include "msfem/massspring/integrators.hpp"
#include "msfem/massspring/mass_spring_model.hpp"

namespace msfem::massspring {
class FastExplicitStepper;
class FastImplicitStepper;
}  // namespace msfem::massspring

namespace msfem::compare {

/// FastExplicitStepper for symplectic Euler and central difference (its symplectic Euler with
/// velocities read at half steps is the leapfrog form of central difference: one force evaluation
/// per step, the same stable step), explicit Euler and RK4, and FastImplicitStepper for implicit
/// Euler (with the haptic CG settings msfem bench times), each with the model's force fields (the
/// tool's contact, volume preservation). `threads` (> 0) caps the steppers' own default. The model
/// must outlive the stepper.
class VariantStepper {
 public:
  VariantStepper(const massspring::MassSpringModel& model, massspring::IntegratorKind kind,
                 const massspring::State& start, int threads = 0);
  ~VariantStepper();
  VariantStepper(const VariantStepper&) = delete;
  VariantStepper& operator=(const VariantStepper&) = delete;

  void advance(double dt, int count);
  massspring::State state() const;
  /// Re-reads the model's coefficients (a run-time change of stiffness, damping or mass).
  void update_parameters(const massspring::MassSpringModel& model);
  /// fast_explicit or fast_implicit.
  const char* name() const;
  /// True on the fast explicit stepper, which takes many steps per call at one thread start.
  bool explicit_steps() const;

 private:
  std::unique_ptr<massspring::FastExplicitStepper> explicit_;
  std::unique_ptr<massspring::FastImplicitStepper> implicit_;
};

}  // namespace msfem::compare
