#include "msfem/massspring_bench/stepping_benchmark.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>

#include "msfem/massspring/fast_implicit_stepper.hpp"
#include "msfem/massspring/fast_stepper.hpp"
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

namespace {

// Median over samples of steps per second; `advance(n)` runs n steps.
template <class Advance>
double median_rate(Advance advance, int steps_per_call, const SteppingBenchmarkOptions& options) {
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
    } while (elapsed < options.seconds_per_sample);
    rates.push_back(static_cast<double>(steps) / elapsed);
  }
  std::nth_element(rates.begin(), rates.begin() + rates.size() / 2, rates.end());
  return rates[rates.size() / 2];
}

}  // namespace

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

SteppingBenchmarkResult run_stepping_benchmark(const MassSpringModel& model,
                                               const SteppingBenchmarkOptions& options) {
  SteppingBenchmarkResult result;
  result.nodes = model.num_nodes();
  result.springs = model.network().num_springs();
  result.explicit_dt =
      0.5 * predicted_stable_dt(model, IntegratorKind::central_difference, model.initial_state());

  const State start = perturbed_start(model);

  FastStepperOptions fast_options;
  fast_options.threads = options.threads;
  fast_options.single_precision = options.single_precision;
  FastExplicitStepper fast(model, fast_options);
  fast.set_state(start);
  result.threads = fast.threads();
  result.explicit_steps_per_second = median_rate([&](int n) { fast.step(result.explicit_dt, n); },
                                                 options.steps_per_call, options);

  if (options.run_naive) {
    NaiveAosStepper naive(model, start);
    result.naive_steps_per_second = median_rate(
        [&](int n) {
          for (int k = 0; k < n; ++k)
            naive.step(result.explicit_dt);
        },
        1, options);
  }

  if (options.run_implicit) {
    FastImplicitOptions implicit_options;
    implicit_options.threads = options.threads;
    implicit_options.cg_tolerance = options.implicit_cg_tolerance;
    implicit_options.cg_max_iterations = options.implicit_cg_max_iterations;
    implicit_options.single_precision = options.single_precision;
    FastImplicitStepper implicit(model, implicit_options);
    implicit.set_state(start);
    long iterations = 0, steps = 0;
    result.implicit_steps_per_second = median_rate(
        [&](int n) {
          for (int k = 0; k < n; ++k) {
            implicit.step(options.implicit_dt);
            iterations += implicit.last_cg_iterations();
            ++steps;
          }
        },
        1, options);
    result.implicit_mean_cg_iterations = static_cast<double>(iterations) / std::max(steps, 1L);
  }
  return result;
}

}  // namespace msfem::massspring
