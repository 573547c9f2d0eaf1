#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "msfem/massspring/fast_implicit_stepper.hpp"
#include "msfem/massspring/integrators.hpp"
#include "msfem/massspring/mass_spring_model.hpp"

namespace msfem::massspring {

/// The plain scalar array-of-structures loop every speed-up is measured against: one struct per
/// node and per spring, forces zeroed, accumulated spring by spring, then symplectic Euler. Same
/// physics as FastExplicitStepper (springs, dampers, node damping, loads, supports; no anchors).
class NaiveAosStepper {
 public:
  explicit NaiveAosStepper(const MassSpringModel& model);
  NaiveAosStepper(const MassSpringModel& model, const State& start);
  void step(double dt);
  State state() const;

 private:
  struct Node {
    double x[3], v[3], f[3], load[3];
    double mass, damping;
    bool fixed;
  };
  struct Spring {
    int a, b;
    double stiffness, damping, rest_length;
  };
  std::vector<Node> nodes_;
  std::vector<Spring> springs_;
  double time_ = 0.0;
};

/// The step each explicit integrator is timed at, where a case's owner chose it (msfem's harness
/// gives its shipped cases msfem sweep's steps: half each integrator's bisected stable step);
/// 0: the bench's own rule (symplectic Euler at half the predicted stable step, explicit Euler and
/// RK4 at a hundredth of that).
struct ExplicitTimedSteps {
  double symplectic_euler = 0.0;  ///< and central difference, the same kernels at the same step
  double explicit_euler = 0.0;
  double rk4 = 0.0;
};

struct SteppingBenchmarkOptions {
  int threads = 2;
  ExplicitTimedSteps timed_dt;      ///< where 0, the bench's own rule
  bool single_precision = false;    ///< float for the explicit and the implicit fast stepper
  int steps_per_call = 10;          ///< explicit steps per FastExplicitStepper::step call
  double seconds_per_sample = 0.2;  ///< each sample runs at least this long
  long min_steps_per_sample = 0;    ///< and at least this many steps
  int samples = 5;                  ///< the median is reported
  bool run_naive = true;
  bool run_implicit = true;
  /// Also explicit Euler and RK4 on the fast explicit kernels (central difference is the
  /// symplectic Euler step with velocities read at half steps: the same figure).
  bool run_other_integrators = true;
  double implicit_dt = 1e-3;            ///< haptic rate
  double implicit_cg_tolerance = 1e-2;  ///< FastImplicitOptions' haptic default
  int implicit_cg_max_iterations = 50;
  bool compare_precision = true;  ///< run float against double (PrecisionComparison)
  int precision_steps = 1000;
  /// Where the implicit stepper runs in double, also time it in float and compare the two over
  /// implicit_precision_steps steps of implicit_dt (a haptic loop's tenth of a second).
  bool run_implicit_float = true;
  int implicit_precision_steps = 100;
};

/// Steps per second over a figure's samples: a spread as wide as the median says the machine, the
/// threads' placement or the barriers disturbed the run, which a median alone would hide.
struct RateSpread {
  double min = 0.0, median = 0.0, max = 0.0;
};

/// The single-precision explicit stepper against the double one on the same loaded run (both from
/// loaded_start, the same dt): the largest distance between a node's two positions at any of the
/// checkpoints, and the largest displacement from rest of the run, its loaded start included (a
/// damped model rings down within the first checkpoints; its error is the memory of that start).
struct PrecisionComparison {
  int steps = 0;
  double max_node_error_m = 0.0;
  double max_displacement_m = 0.0;
  double relative() const {
    return max_displacement_m > 0 ? max_node_error_m / max_displacement_m : 0;
  }
};

struct SteppingBenchmarkResult {
  int nodes = 0;
  int springs = 0;
  int threads = 0;
  double explicit_dt = 0.0;  ///< symplectic Euler's step: 0.5 × predicted stable dt, or as given
  double explicit_euler_dt = 0.0, rk4_dt = 0.0;  ///< the steps the other two were timed at
  double precision_dt = 0.0;                     ///< float_vs_double's: 0.5 × predicted stable dt
  double explicit_steps_per_second = 0.0;        ///< FastExplicitStepper, median
  double naive_steps_per_second = 0.0;           ///< NaiveAosStepper, median (0 when not run)
  double implicit_steps_per_second = 0.0;        ///< FastImplicitStepper, median (0 when not run)
  double implicit_mean_cg_iterations = 0.0;
  bool implicit_single_precision_terms = false;  ///< FastImplicitStepper::single_precision_terms
  RateSpread explicit_spread, naive_spread, implicit_spread;
  RateSpread explicit_euler_spread, rk4_spread;  ///< at explicit_euler_dt, rk4_dt
  std::size_t explicit_bytes_per_step = 0;
  int explicit_last_step_threads = 0;  ///< where adaptive threads ended (1 or threads)  ///<
                                       ///< FastExplicitStepper::streamed_bytes_per_step
  std::optional<PrecisionComparison> float_vs_double;  ///< when options.compare_precision
  /// The implicit stepper in float beside the double one (options.run_implicit_float); with
  /// options.single_precision the implicit figures above, the comparison with double still run.
  double implicit_float_steps_per_second = 0.0;
  double implicit_float_mean_cg_iterations = 0.0;
  RateSpread implicit_float_spread;
  std::optional<PrecisionComparison> implicit_float_vs_double;
  std::vector<std::string> notes;  ///< figures not taken, and why
};

/// Measures steps per second of the explicit fast stepper, the naive loop and the implicit fast
/// stepper on the model (loads and supports as set in it), in this process, after a warm-up. All
/// three start from the rest state with every free node displaced by a fixed pseudo-random 10⁻³ of
/// Steps per second of `advance(n)` (n steps, n = steps_per_call) after a warm-up of a quarter
/// sample: min, median and max over options.samples samples of options.seconds_per_sample (and
/// options.min_steps_per_sample) each. The one timing loop of msfem bench and of the harness's
/// timing (msfem run, sweep), so that their figures are taken alike.
RateSpread rate_spread(const std::function<void(int)>& advance, int steps_per_call,
                       const SteppingBenchmarkOptions& options);

/// Rest state with every node moved by a fixed pseudo-random 10⁻³ of the mean spring length: all
/// springs loaded, the motion bounded. Every speed measurement starts from it.
State perturbed_start(const MassSpringModel& model);

/// This machine's streaming memory bandwidth in bytes per second: the STREAM triad a = b + s c on
/// three 64 MiB arrays (far beyond any cache), split over `threads` threads, best of `repeats`.
double stream_triad_bandwidth(int threads, int repeats = 5);

/// The triad's bandwidth (bytes per second) at a working set of `bytes` (its three arrays
/// together), each of `threads` threads sweeping its own share again and again: what the machine
/// can feed a step that touches that many bytes. Below the last-level cache it is the cache's
/// bandwidth, not memory's (a 12 MB step fits a 32 MB L3, where the triad runs several times
/// faster than from memory). Best of `repeats` runs of about 30 ms each.
double triad_bandwidth_at(std::size_t bytes, int threads, int repeats = 5);

/// Rest state with every free node moved 2 % of its distance from the free nodes' centroid outwards
/// (a few millimetres on an organ): every spring loaded as a pressed organ's are, so that a
/// precision comparison sees the displacements a simulator renders, not round-off of a state at
/// rest.
State loaded_start(const MassSpringModel& model);

/// Float against double on the fast explicit stepper (see PrecisionComparison), checkpoints every
/// 100 steps.
PrecisionComparison compare_precision(const MassSpringModel& model, double dt, int steps,
                                      int threads);

/// Float against double on the fast implicit stepper, both with `options` otherwise (its CG
/// tolerance included, so the figure holds what a loose solve adds), checkpoints every 10 steps.
PrecisionComparison compare_implicit_precision(const MassSpringModel& model,
                                               const FastImplicitOptions& options, double dt,
                                               int steps);

SteppingBenchmarkResult run_stepping_benchmark(const MassSpringModel& model,
                                               const SteppingBenchmarkOptions& options = {});

}  // namespace msfem::massspring
