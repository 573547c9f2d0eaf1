#include "msfem/massspring_bench/stepping_benchmark.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <thread>

#include "msfem/massspring/fast_implicit_stepper.hpp"
#include "msfem/massspring/fast_stepper.hpp"
#include "msfem/massspring/mass_spring_model.hpp"
#include "msfem/massspring/stability.hpp"

namespace msfem::massspring {

NaiveAosStepper::NaiveAosStepper(const MassSpringModel& model)
    : NaiveAosStepper(model, initial_state(model)) {}

NaiveAosStepper::NaiveAosStepper(const MassSpringModel& model, const State& start) {
  const SpringNetwork& net = model.network();
  const Eigen::VectorXd& x = start.x;
  time_ = start.time;
  nodes_.resize(net.num_nodes());
  for (int i = 0; i < net.num_nodes(); ++i) {
    Node& node = nodes_[i];
    for (int c = 0; c < 3; ++c) {
      node.x[c] = x[3 * i + c];
      node.v[c] = start.v[3 * i + c];
      node.f[c] = 0.0;
      node.load[c] = net.masses[i] * model.gravity()[c];
    }
    node.mass = net.masses[i];
    node.damping = net.node_damping[i];
    node.fixed = model.is_constrained(i);
  }
  springs_.resize(net.num_springs());
  for (int s = 0; s < net.num_springs(); ++s)
    springs_[s] = {net.springs(s, 0), net.springs(s, 1), net.stiffness[s], net.damping[s],
                   net.rest_length[s]};
}

void NaiveAosStepper::step(double dt) {
  for (Node& node : nodes_)
    for (int c = 0; c < 3; ++c)
      node.f[c] = node.load[c] - node.damping * node.v[c];
  for (const Spring& spring : springs_) {
    Node& a = nodes_[spring.a];
    Node& b = nodes_[spring.b];
    double d[3], w[3];
    for (int c = 0; c < 3; ++c) {
      d[c] = b.x[c] - a.x[c];
      w[c] = b.v[c] - a.v[c];
    }
    const double length = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    const double n_dot_w = (d[0] * w[0] + d[1] * w[1] + d[2] * w[2]) / length;
    const double magnitude =
        spring.stiffness * (length - spring.rest_length) + spring.damping * n_dot_w;
    for (int c = 0; c < 3; ++c) {
      const double f = magnitude * d[c] / length;
      a.f[c] += f;
      b.f[c] -= f;
    }
  }
  for (Node& node : nodes_) {
    if (node.fixed) continue;
    for (int c = 0; c < 3; ++c) {
      node.v[c] += dt * node.f[c] / node.mass;
      node.x[c] += dt * node.v[c];
    }
  }
  time_ += dt;
}

State NaiveAosStepper::state() const {
  State out{Eigen::VectorXd(3 * nodes_.size()), Eigen::VectorXd(3 * nodes_.size()), time_};
  for (std::size_t i = 0; i < nodes_.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      out.x[3 * i + c] = nodes_[i].x[c];
      out.v[3 * i + c] = nodes_[i].v[c];
    }
  return out;
}

RateSpread rate_spread(const std::function<void(int)>& advance, int steps_per_call,
                       const SteppingBenchmarkOptions& options) {
  using clock = std::chrono::steady_clock;
  // Warm-up: caches, page faults, thread start.
  const auto warm_start = clock::now();
  int calls = 0;
  do {
    advance(steps_per_call);
    ++calls;
  } while (std::chrono::duration<double>(clock::now() - warm_start).count() <
           0.25 * options.seconds_per_sample);
  std::vector<double> rates;
  for (int sample = 0; sample < std::max(options.samples, 1); ++sample) {
    long steps = 0;
    const auto start = clock::now();
    double elapsed = 0.0;
    do {
      advance(steps_per_call);
      steps += steps_per_call;
      elapsed = std::chrono::duration<double>(clock::now() - start).count();
    } while (elapsed < options.seconds_per_sample || steps < options.min_steps_per_sample);
    rates.push_back(static_cast<double>(steps) / elapsed);
  }
  std::sort(rates.begin(), rates.end());
  return {rates.front(), rates[rates.size() / 2], rates.back()};
}

State perturbed_start(const MassSpringModel& model) {
  State start = initial_state(model);
  std::mt19937 generator(2007);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const double amplitude = 1e-3 * model.network().rest_length.mean();
  for (Eigen::Index k = 0; k < start.x.size(); ++k)
    start.x[k] += amplitude * uniform(generator);
  model.enforce_constraints(start.x, start.v);
  return start;
}

double triad_bandwidth_at(std::size_t bytes, int threads, int repeats) {
  threads = std::max(threads, 1);
  const std::size_t n = std::max<std::size_t>(bytes / (3 * sizeof(double)), 64 * threads);
  std::vector<double> a(n, 0.0), b(n, 1.0), c(n, 2.0);
  const double pass_bytes = 3.0 * sizeof(double) * n;
  const long passes = std::max(1L, static_cast<long>(2e9 / pass_bytes));  // ~30 ms at 60 GB/s
  // Each thread's share stays in its own part of the caches, as a step's node blocks do; no
  // barrier between passes, so this is the bandwidth alone, not the step's synchronisation.
  auto sweep = [&](int part) {
    const std::size_t first = n * part / threads, last = n * (part + 1) / threads;
    for (long p = 0; p < passes; ++p) {
      const double s = 3.0 + 1e-9 * static_cast<double>(p & 1);
      for (std::size_t i = first; i < last; ++i)
        a[i] = b[i] + s * c[i];
      asm volatile("" : : "r"(a.data()) : "memory");  // every pass's stores happen
    }
  };
  double best = 0.0;
  for (int r = 0; r < std::max(repeats, 1); ++r) {
    const auto start = std::chrono::steady_clock::now();
    std::vector<std::thread> team;
    for (int t = 1; t < threads; ++t)
      team.emplace_back(sweep, t);
    sweep(0);
    for (auto& t : team)
      t.join();
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    best = std::max(best, pass_bytes * static_cast<double>(passes) / seconds);
  }
  if (!(a[n / 2] > 6.9)) return 0.0;  // keeps the passes from being optimised away
  return best;
}

double stream_triad_bandwidth(int threads, int repeats) {
  return triad_bandwidth_at(std::size_t(3) * (std::size_t(64) << 20), threads, repeats);
}

State loaded_start(const MassSpringModel& model) {
  State start = initial_state(model);
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  int free = 0;
  for (int i = 0; i < model.num_nodes(); ++i)
    if (!model.is_constrained(i)) {
      centroid += start.x.segment<3>(3 * i);
      ++free;
    }
  centroid /= std::max(free, 1);
  for (int i = 0; i < model.num_nodes(); ++i)
    if (!model.is_constrained(i))
      start.x.segment<3>(3 * i) += 0.02 * (start.x.segment<3>(3 * i) - centroid);
  model.enforce_constraints(start.x, start.v);
  return start;
}

namespace {

// The largest distance between a node's positions in two states.
double farthest(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  double largest = 0.0;
  for (Eigen::Index i = 0; i < a.size(); i += 3)
    largest = std::max(largest, (a - b).segment<3>(i).norm());
  return largest;
}

// Steps the two steppers side by side from the loaded start, `every` steps of dt between
// checkpoints.
PrecisionComparison compare_side_by_side(const MassSpringModel& model, Stepper& exact,
                                         Stepper& single, double dt, int steps, int every) {
  const State start = loaded_start(model);
  const Eigen::VectorXd rest = initial_state(model).x;
  exact.set_state(start);
  single.set_state(start);
  PrecisionComparison c;
  c.max_displacement_m = farthest(start.x, rest);
  for (c.steps = 0; c.steps < steps;) {
    const int n = std::min(every, steps - c.steps);
    exact.step(dt, n);
    single.step(dt, n);
    c.steps += n;
    const Eigen::VectorXd x = exact.state().x;
    c.max_node_error_m = std::max(c.max_node_error_m, farthest(x, single.state().x));
    c.max_displacement_m = std::max(c.max_displacement_m, farthest(x, rest));
  }
  return c;
}

}  // namespace

PrecisionComparison compare_precision(const MassSpringModel& model, double dt, int steps,
                                      int threads) {
  FastStepperOptions options;
  options.threads = threads;
  FastExplicitStepper exact(model, options);
  options.single_precision = true;
  FastExplicitStepper single(model, options);
  return compare_side_by_side(model, exact, single, dt, steps, 100);
}

PrecisionComparison compare_implicit_precision(const MassSpringModel& model,
                                               const FastImplicitOptions& options, double dt,
                                               int steps) {
  FastImplicitOptions in_double = options, in_float = options;
  in_double.single_precision = false;
  in_float.single_precision = true;
  FastImplicitStepper exact(model, in_double), single(model, in_float);
  return compare_side_by_side(model, exact, single, dt, steps, 10);
}

namespace {

// Explicit Euler and RK4 on the fast explicit kernels, as a simulator (and msfem sweep) runs them.
// The bench's own step for both is a hundredth of the symplectic one: a step's cost does not
// depend on its size on a model without contact, explicit Euler gains energy at any step (only the
// dampers hold it) and the dampers bound RK4's step below its undamped prediction, so that neither
// leaves a sample non-finite. A case with a tool in contact costs what its trajectory presses
// into the tool, so a case that names its steps (msfem sweep's) is timed at those.
void time_other_integrators(const MassSpringModel& model, const State& start,
                            FastStepperOptions fast_options,
                            const SteppingBenchmarkOptions& options, double rule_dt,
                            SteppingBenchmarkResult& result) {
  const auto chosen = [&](double given) { return given > 0 ? given : 0.01 * rule_dt; };
  result.explicit_euler_dt = chosen(options.timed_dt.explicit_euler);
  result.rk4_dt = chosen(options.timed_dt.rk4);
  for (const IntegratorKind kind : {IntegratorKind::explicit_euler, IntegratorKind::rk4}) {
    const bool rk4 = kind == IntegratorKind::rk4;
    const double dt = rk4 ? result.rk4_dt : result.explicit_euler_dt;
    fast_options.integrator = kind;
    FastExplicitStepper stepper(model, fast_options);
    stepper.set_state(start);
    (rk4 ? result.rk4_spread : result.explicit_euler_spread) =
        rate_spread([&](int n) { stepper.step(dt, n); }, options.steps_per_call, options);
  }
}

struct ImplicitTiming {
  RateSpread spread;
  double mean_cg_iterations = 0.0;
  bool single_precision_terms = false;
};

ImplicitTiming time_implicit(const MassSpringModel& model, const State& start,
                             const FastImplicitOptions& implicit_options,
                             const SteppingBenchmarkOptions& options) {
  FastImplicitStepper implicit(model, implicit_options);
  implicit.set_state(start);
  long iterations = 0, steps = 0;
  ImplicitTiming timed;
  timed.spread = rate_spread(
      [&](int n) {
        for (int k = 0; k < n; ++k) {
          implicit.step(options.implicit_dt);
          iterations += implicit.last_cg_iterations();
          ++steps;
        }
      },
      1, options);
  timed.mean_cg_iterations = static_cast<double>(iterations) / std::max(steps, 1L);
  timed.single_precision_terms = implicit.single_precision_terms();
  return timed;
}

}  // namespace

SteppingBenchmarkResult run_stepping_benchmark(const MassSpringModel& model,
                                               const SteppingBenchmarkOptions& options) {
  SteppingBenchmarkResult result;
  result.nodes = model.num_nodes();
  result.springs = model.network().num_springs();
  const double rule_dt =
      0.5 * predicted_stable_dt(model, IntegratorKind::central_difference, model.initial_state());
  result.explicit_dt =
      options.timed_dt.symplectic_euler > 0 ? options.timed_dt.symplectic_euler : rule_dt;
  result.precision_dt = rule_dt;

  const State start = perturbed_start(model);

  FastStepperOptions fast_options;
  fast_options.threads = options.threads;
  fast_options.single_precision = options.single_precision;
  FastExplicitStepper fast(model, fast_options);
  fast.set_state(start);
  result.threads = fast.threads();
  result.explicit_bytes_per_step = fast.streamed_bytes_per_step();
  result.explicit_spread = rate_spread([&](int n) { fast.step(result.explicit_dt, n); },
                                       options.steps_per_call, options);
  result.explicit_steps_per_second = result.explicit_spread.median;
  result.explicit_last_step_threads = fast.last_step_threads();
  if (options.run_other_integrators)
    time_other_integrators(model, start, fast_options, options, rule_dt, result);
  const bool fields = model.has_added_fields();
  if (fields)
    result.notes.push_back(
        "naive not run: the naive loop steps springs only; the fast steppers share the force "
        "fields among their threads");

  if (options.run_naive && !fields) {
    NaiveAosStepper naive(model, start);
    result.naive_spread = rate_spread(
        [&](int n) {
          for (int k = 0; k < n; ++k)
            naive.step(result.explicit_dt);
        },
        1, options);
    result.naive_steps_per_second = result.naive_spread.median;
  }

  if (options.run_implicit) {
    FastImplicitOptions implicit_options;
    implicit_options.threads = options.threads;
    implicit_options.cg_tolerance = options.implicit_cg_tolerance;
    implicit_options.cg_max_iterations = options.implicit_cg_max_iterations;
    implicit_options.single_precision = options.single_precision;
    const ImplicitTiming timed = time_implicit(model, start, implicit_options, options);
    result.implicit_spread = timed.spread;
    result.implicit_steps_per_second = timed.spread.median;
    result.implicit_mean_cg_iterations = timed.mean_cg_iterations;
    result.implicit_single_precision_terms = timed.single_precision_terms;
    if (options.run_implicit_float) {
      // Where the bench runs in float the timing above is float's already.
      implicit_options.single_precision = true;
      const ImplicitTiming in_float =
          options.single_precision ? timed : time_implicit(model, start, implicit_options, options);
      result.implicit_float_spread = in_float.spread;
      result.implicit_float_steps_per_second = in_float.spread.median;
      result.implicit_float_mean_cg_iterations = in_float.mean_cg_iterations;
      result.implicit_float_vs_double = compare_implicit_precision(
          model, implicit_options, options.implicit_dt, options.implicit_precision_steps);
    }
  }
  if (options.compare_precision)
    result.float_vs_double =
        compare_precision(model, result.precision_dt, options.precision_steps, options.threads);
  return result;
}

}  // namespace msfem::massspring
