#include "msfem/massspring/stepper.hpp"

#include <algorithm>

#include "msfem/massspring/errors.hpp"
#include "msfem/massspring/fast_implicit_stepper.hpp"
#include "msfem/massspring/fast_stepper.hpp"
#include "msfem/massspring/spring_force_field.hpp"

namespace msfem::massspring {

void GenericStepper::step(double dt, int count) {
  for (int n = 0; n < count; ++n)
    integrator_.step(*system_, state_, dt);
}

std::unique_ptr<Stepper> make_stepper(const MechanicalSystem& system, IntegratorKind kind,
                                      const State& start, const StepperChoice& choice) {
  std::unique_ptr<Stepper> stepper;
  if (!system.find_field<SpringForceField>()) {
    if (choice.single_precision)
      throw ModelError(
          "single precision: only the fast steppers have it, and they need springs (the system "
          "has no SpringForceField)");
    stepper = std::make_unique<GenericStepper>(system, kind);
  } else if (kind == IntegratorKind::implicit_euler) {
    FastImplicitOptions options;
    options.single_precision = choice.single_precision;
    if (choice.threads > 0) options.threads = std::min(options.threads, choice.threads);
    stepper = std::make_unique<FastImplicitStepper>(system, options);
  } else {
    FastStepperOptions options;
    options.single_precision = choice.single_precision;
    if (choice.threads > 0) options.threads = std::min(options.threads, choice.threads);
    options.integrator =
        kind == IntegratorKind::central_difference ? IntegratorKind::symplectic_euler : kind;
    stepper = std::make_unique<FastExplicitStepper>(system, options);
  }
  stepper->set_state(start);
  return stepper;
}

}  // namespace msfem::massspring
