#pragma once

#include <cstddef>
#include <memory>

#include "msfem/massspring/integrators.hpp"
#include "msfem/massspring/mechanical_system.hpp"
#include "msfem/massspring/stepper.hpp"

namespace msfem::massspring {

struct FastStepperOptions {
  int threads = 2;                ///< threads in all, the calling one included
  bool single_precision = false;  ///< float arithmetic (twice the SIMD width, ~1e-7 relative)
  bool reorder_nodes = true;      ///< reverse Cuthill-McKee order for memory locality
  /// float: 16 lanes where the CPU has AVX-512 and the network fits the cache (else 8, AVX2);
  /// double: 8 lanes where the CPU has AVX-512, 1/√ from its estimate refined to a few ulp (else
  /// 4 lanes of AVX2, a square root and a division)
  bool allow_avx512 = true;
  /// The scheme, as the generic Integrator of the same kind steps it: symplectic_euler,
  /// explicit_euler (x ← x + h v with the step's starting v, at the symplectic step's cost) or rk4
  /// (four force passes a step). Others throw ModelError; central_difference is symplectic_euler
  /// with velocities read at half steps.
  IntegratorKind integrator = IntegratorKind::symplectic_euler;
  /// Each step(dt, count) call on the whole team or on the calling thread alone, whichever took
  /// less time per step lately (re-checked by 4 calls on the other count after every 32 to 256):
  /// on a machine whose cores other jobs hold, a small model's barrier waits make two threads
  /// slower than one. Results do not depend on it (each node is updated by the same arithmetic on
  /// any thread).
  bool adaptive_threads = true;
};

/// The real-time explicit stepper: symplectic Euler, which with velocities read at half steps is
/// the central-difference (leapfrog) scheme of the pancreas paper,
///   v ← v + h M⁻¹ f(x, v),   x ← x + h v,
/// explicit Euler (x advances with the step's starting v) or classical RK4 (FastStepperOptions::
/// integrator), on the model's springs, dampers, node damping, gravity, external forces and
/// supports, and its force fields (the tool's contact, volume preservation): each force pass adds
/// a field's force, taken at the same state as the springs', to the field's free nodes after the
/// spring kernels, the members sharing the field's work (ForceField::add_force_part). The model
/// must outlive the stepper.
///
/// Layout: nodes renumbered by reverse Cuthill-McKee with the constrained ones last (never
/// updated); x and v of a node packed in one record. Each step is node-centric: every free node
/// gathers its own springs' forces from its neighbours' records of the previous step and writes its
/// new x and v to a second buffer (double buffering), so a step has no scatter, no force buffers to
/// sum and one barrier. RK4 is four such passes, one per stage, each reading the stage state the
/// last one wrote (two more buffers) and a barrier apart. Springs are stored per node in
/// vector-width chunks (sliced ELLPACK) with their k and k l0 (and c, unless one damping serves all
/// springs) beside the neighbour index. Each spring is evaluated twice, once per end: more
/// arithmetic for far less memory traffic. Each thread takes blocks of chunks from its own range
/// first and then from what is left of the others', so a thread the OS pre-empts delays a step by
/// one block. The kernels (gather_kernels.hpp) are compiled for baseline x86-64, AVX2+FMA (float 8
/// lanes, double 4) and AVX-512 (float 16, while the model fits in cache; double 8) and picked at
/// run time.
class FastExplicitStepper : public Stepper {
 public:
  explicit FastExplicitStepper(const MechanicalSystem& model,
                               const FastStepperOptions& options = {});
  ~FastExplicitStepper();
  FastExplicitStepper(const FastExplicitStepper&) = delete;
  FastExplicitStepper& operator=(const FastExplicitStepper&) = delete;

  /// Re-reads stiffness, damping, masses, gravity, external forces and support targets from the
  /// model (same topology and the same constrained nodes), e.g. after a change of group stiffness.
  void update_parameters(const MechanicalSystem& model) override;

  void set_state(const State& state) override;
  State state() const override;

  /// Advances `count` steps of size dt. Throws ModelError for a bad dt, DivergenceError (with the
  /// predicted stable dt) if the state became non-finite.
  void step(double dt, int count = 1) override;

  IntegratorKind kind() const override { return kind_; }
  const char* name() const override { return "fast_explicit"; }
  const char* precision() const override { return single_ ? "float" : "double"; }
  bool batches_steps() const override { return true; }

  int num_nodes() const;
  int num_springs() const;
  int threads() const;
  /// Threads the last step(dt, count) call ran on (1 while adaptive_threads found one faster).
  int last_step_threads() const;
  /// Bytes a spring step streams at the least: every slot's neighbour index, k, k l0 (and c), every
  /// lane's index and per-node coefficients, and the node records read and written once, as if
  /// every neighbour's record were a cache hit (RK4: four such passes, each also reading and
  /// writing its stage and combination records). With steps per second, the memory bandwidth a step
  /// uses (the roofline of a memory-bound kernel).
  std::size_t streamed_bytes_per_step() const;

  class Implementation;  // float and double kernels behind one interface

 private:
  std::unique_ptr<Implementation> impl_;
  IntegratorKind kind_;
  bool single_;
};

}  // namespace msfem::massspring
