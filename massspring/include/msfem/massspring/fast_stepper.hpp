#pragma once

#include <memory>

#include "msfem/massspring/integrators.hpp"
#include "msfem/massspring/mass_spring_model.hpp"

namespace msfem::massspring {

struct FastStepperOptions {
  int threads = 2;                ///< threads in all, the calling one included
  bool single_precision = false;  ///< float arithmetic (twice the SIMD width, ~1e-7 relative)
  bool reorder_nodes = true;      ///< reverse Cuthill-McKee order for memory locality
};

/// The real-time explicit stepper: symplectic Euler, which with velocities read at half steps is
/// the central-difference (leapfrog) scheme of the pancreas paper,
///   v ← v + h M⁻¹ f(x, v),   x ← x + h v,
/// on the model's springs, dampers, node damping, gravity, external forces and supports (tool
/// contact is not applied here; use Integrator for that). The model must outlive the stepper.
///
/// Layout: structure of arrays, nodes renumbered by reverse Cuthill-McKee with the constrained
/// ones last (never updated), springs sorted by their first node so that neighbouring springs touch
/// neighbouring nodes. Each step is two passes split over a persistent thread team with spin
/// barriers: (1) each thread takes a contiguous share of the springs and scatters their forces
/// into its own node-force buffer (no write conflicts); (2) each thread takes a share of the free
/// nodes, sums the buffers, clears them and updates v and x. The kernels are compiled for baseline
/// x86-64 and for AVX2+FMA and picked at run time.
class FastExplicitStepper {
 public:
  explicit FastExplicitStepper(const MassSpringModel& model,
                               const FastStepperOptions& options = {});
  ~FastExplicitStepper();
  FastExplicitStepper(const FastExplicitStepper&) = delete;
  FastExplicitStepper& operator=(const FastExplicitStepper&) = delete;

  /// Re-reads stiffness, damping, masses, gravity, external forces and support targets from the
  /// model (same topology and the same constrained nodes), e.g. after a change of group stiffness.
  void update_parameters(const MassSpringModel& model);

  void set_state(const State& state);
  State state() const;

  /// Advances `count` steps of size dt. Throws ModelError for a bad dt, DivergenceError (with the
  /// predicted stable dt) if the state became non-finite.
  void step(double dt, int count = 1);

  int num_nodes() const;
  int num_springs() const;
  int threads() const;

  class Implementation;  // float and double kernels behind one interface

 private:
  std::unique_ptr<Implementation> impl_;
};

}  // namespace msfem::massspring
