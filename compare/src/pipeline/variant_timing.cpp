// How fast a variant runs: the case's integrator on the code a simulator would run for it (the
// fast kernels where they cover the integrator and the model): settled from rest under the load,
// and timed as msfem bench times it.
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include "msfem/compare/pipeline/progress.hpp"
#include "msfem/compare/pipeline/variant_run.hpp"
#include "msfem/massspring/errors.hpp"
#include "msfem/massspring/integrators.hpp"
#include "msfem/massspring/mass_spring_model.hpp"
#include "msfem/massspring/stability.hpp"
#include "msfem/massspring/stepper.hpp"
#include "msfem/massspring_bench/stepping_benchmark.hpp"

namespace msfem::compare {
namespace {

namespace ms = msfem::massspring;

// The largest step the integrator keeps bounded, by bisection about the predicted one; for an
// unconditionally stable one the step a haptic loop uses (1 kHz).
void stable_step(Timing& t, const ms::MassSpringModel& model, ms::IntegratorKind kind,
                 const ms::State& start) {
  t.predicted_stable_dt_s = ms::predicted_stable_dt(model, kind, start.x);
  if (kind == ms::IntegratorKind::implicit_euler || !std::isfinite(t.predicted_stable_dt_s)) {
    t.stable_dt_s = 1e-3;
  } else {
    const double guess = t.predicted_stable_dt_s;
    t.stable_dt_s = ms::measure_stable_dt(model, kind, 0.25 * guess, 4.0 * guess, 400, 0.02);
  }
}

// Steps per second as msfem bench takes them (massspring::rate_spread: the median of five samples
// after a warm-up, explicit steps ten per call), samples of a tenth of a second and at least a
// fifth of the case's timing/steps each.
double median_rate(ms::Stepper& stepper, double dt, int steps) {
  ms::SteppingBenchmarkOptions options;
  options.seconds_per_sample = 0.1;
  options.min_steps_per_sample = std::max(1, steps / options.samples);
  return ms::rate_spread([&](int n) { stepper.step(dt, n); },
                         stepper.batches_steps() ? options.steps_per_call : 1, options)
      .median;
}

// Wall time from rest, with the load applied, to within 1 % of the static equilibrium's travel.
// The run ends unsettled at the wall limit, or sooner once it has stopped approaching: the
// largest distance over a simulated second (the envelope of a ringing approach: a swing can pass
// close early on) has not come 1 % of the travel below its best for two seconds running. A model
// can come to rest in another equilibrium: three_tier on the default sphere snaps through under a
// tool applied at once and rests six to eight times its travel away; with the wall limit alone
// it would run 20 s on every case run.
void settle(Timing& t, ms::Stepper& stepper, const BuiltVariant& variant,
            const Eigen::VectorXd& x_rest, const Eigen::VectorXd& equilibrium) {
  const double travel = (equilibrium - x_rest).norm();
  const int stride = 20;
  const double wall_limit_s = 20.0, window_s = 1.0;
  const int stale_windows = 2;
  const auto start = Clock::now();
  double window_end = stepper.state().time + window_s;
  double envelope = 0.0, best_envelope = std::numeric_limits<double>::infinity();
  int stale = 0;
  t.settle_distance = travel > 0.0 ? 1.0 : 0.0;
  t.settled = travel == 0.0;  // no load: at rest where it starts
  while (!t.settled && seconds_since(start) < wall_limit_s) {
    stepper.step(t.dt_s, stride);
    const ms::State s = stepper.state();
    if (!s.x.allFinite())
      throw ms::DivergenceError("variant " + variant.name + " diverged while settling at dt " +
                                    std::to_string(t.dt_s) + " s (stable dt " +
                                    std::to_string(t.stable_dt_s) + " s)",
                                t.dt_s, t.stable_dt_s);
    const double distance = (s.x - equilibrium).norm();
    t.settle_distance = distance / travel;
    if (distance <= 0.01 * travel) {
      t.settled = true;
      break;
    }
    envelope = std::max(envelope, distance);
    if (s.time >= window_end) {
      stale = envelope < best_envelope - 0.01 * travel ? 0 : stale + 1;
      best_envelope = std::min(best_envelope, envelope);
      envelope = 0.0;
      window_end += window_s;
      if (stale == stale_windows) break;
    }
  }
  t.settle_time_s = seconds_since(start);
}

// The step timed when the case sets none: half the stable one, a margin below the bisected limit;
// implicit Euler, stable at any step, at the 1 kHz step its real-time factor is reported for (its
// CG iterations, and so its cost, grow with the step: at half of it the factor would be the cost
// of another loop).
double default_dt(const Timing& t, ms::IntegratorKind kind) {
  return kind == ms::IntegratorKind::implicit_euler ? t.stable_dt_s : 0.5 * t.stable_dt_s;
}

}  // namespace

double timed_dt(const ms::MassSpringModel& model, const cases::TimingParameters& timing) {
  if (timing.dt_s > 0) return timing.dt_s;
  Timing t;
  stable_step(t, model, timing.integrator, ms::initial_state(model));
  return default_dt(t, timing.integrator);
}

Timing time_variant(const BuiltVariant& variant, const cases::TimingParameters& timing,
                    const Eigen::VectorXd& equilibrium, bool measure_settling, int threads) {
  const ms::MassSpringModel& model = *variant.model;
  const ms::IntegratorKind kind = timing.integrator;
  Timing t;
  t.integrator = ms::to_string(kind);
  const ms::State start = ms::initial_state(model);
  stable_step(t, model, kind, start);
  t.dt_s = timing.dt_s > 0 ? timing.dt_s : default_dt(t, kind);
  // The stable step is bisected on the generic integrator over 400 steps, which projects nodes out
  // of the tool; the fast kernels run longer and do not, and a contact or volume field can then
  // diverge at half that step. Such a step bounds the timed code's stable step: halve and retry.
  for (int attempt = 0;; ++attempt) {
    try {
      const ms::StepperChoice choice{threads, timing.single_precision};
      const auto stepper = ms::make_stepper(model, kind, start, choice);
      t.stepper = stepper->name();
      t.precision = stepper->precision();
      if (measure_settling) settle(t, *stepper, variant, start.x, equilibrium);
      // Timed from msfem bench's start (every node moved a pseudo-random thousandth of the mean
      // spring length), not from the settled state: a model at rest needs fewer CG iterations a
      // step than a moving one, and the two commands would time different work.
      const auto timed = ms::make_stepper(model, kind, ms::perturbed_start(model), choice);
      t.steps_per_second = median_rate(*timed, t.dt_s, timing.steps);
      break;
    } catch (const ms::DivergenceError&) {
      if (timing.dt_s > 0 || attempt == 5) throw;
      t.stable_dt_s = t.dt_s;
      t.dt_s *= 0.5;
    }
  }
  t.realtime_factor = t.stable_dt_s * t.steps_per_second;
  t.ms_per_60hz_frame = 1000.0 * (1.0 / 60.0) / t.dt_s / t.steps_per_second;
  return t;
}

}  // namespace msfem::compare
