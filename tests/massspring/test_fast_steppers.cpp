// The fast structure-of-arrays steppers and the naive loop reproduce the reference integrators.

#include <gtest/gtest.h>

#include "icosphere.hpp"
#include "msfem/massspring/errors.hpp"
#include "msfem/massspring/fast_implicit_stepper.hpp"
#include "msfem/massspring/fast_stepper.hpp"
#include "msfem/massspring/mass_spring_model.hpp"
#include "msfem/massspring/stability.hpp"
#include "msfem/massspring/topology_builders.hpp"
#include "msfem/massspring_bench/benchmark_cases.hpp"
#include "msfem/massspring_bench/stepping_benchmark.hpp"

namespace msfem::massspring {
namespace {

MassSpringModel loaded_three_tier() {
  const auto mesh = testing::icosphere(2, 0.05);
  ThreeTierOptions options;
  options.material.spring_damping = 0.01;
  options.material.node_damping = 0.002;
  MassSpringModel model(build_three_tier(mesh.vertices, mesh.triangles, options));
  model.set_gravity({0.0, -9.81, 0.0});
  model.set_external_force(5, {0.0, 0.0, 0.01});
  return model;
}

double relative_difference(const State& a, const State& b, const Eigen::VectorXd& rest) {
  return (a.x - b.x).norm() / (b.x - rest).norm();
}

State reference_run(const MassSpringModel& model, IntegratorKind kind, double dt, int steps) {
  Integrator integrator(kind, ImplicitOptions{1e-12, 1000});
  State state = initial_state(model);
  for (int n = 0; n < steps; ++n)
    integrator.step(model, state, dt);
  return state;
}

TEST(FastExplicitStepper, MatchesSymplecticEulerInDoubleAndFloat) {
  const MassSpringModel model = loaded_three_tier();
  const double dt =
      0.5 * predicted_stable_dt(model, IntegratorKind::central_difference, model.initial_state());
  const State reference = reference_run(model, IntegratorKind::symplectic_euler, dt, 300);
  for (int threads : {1, 2}) {
    FastExplicitStepper fast(model, FastStepperOptions{threads, false, true});
    fast.step(dt, 100);
    fast.step(dt, 200);
    EXPECT_LE(relative_difference(fast.state(), reference, model.rest_state()), 1e-9) << threads;
    EXPECT_NEAR(fast.state().time, reference.time, 1e-12);
  }
  // Double's 1/√ from AVX-512VL's refined estimate (where the CPU has it) and the exact one of the
  // AVX2 lanes: a few ulp a spring, so the trajectories part by round-off only.
  FastStepperOptions exact_root{2, false, true};
  exact_root.allow_avx512 = false;
  FastExplicitStepper estimated(model, FastStepperOptions{2, false, true}),
      exact(model, exact_root);
  estimated.step(dt, 300);
  exact.step(dt, 300);
  EXPECT_LE(relative_difference(estimated.state(), exact.state(), model.rest_state()), 1e-12);
  EXPECT_LE(relative_difference(exact.state(), reference, model.rest_state()), 1e-9);
  FastExplicitStepper single(model, FastStepperOptions{2, true, true});
  single.step(dt, 300);
  EXPECT_LE(relative_difference(single.state(), reference, model.rest_state()), 2e-6);

  NaiveAosStepper naive(model);
  MassSpringModel unloaded = model;  // the naive loop has no external nodal forces
  unloaded.clear_external_forces();
  NaiveAosStepper naive_unloaded(unloaded);
  for (int n = 0; n < 300; ++n)
    naive_unloaded.step(dt);
  const State unloaded_reference =
      reference_run(unloaded, IntegratorKind::symplectic_euler, dt, 300);
  EXPECT_LE(relative_difference(naive_unloaded.state(), unloaded_reference, model.rest_state()),
            1e-9);
}

TEST(FastExplicitStepper, MatchesExplicitEulerOnTheSameKernels) {
  // Explicit Euler grows an undamped oscillation, so a short run at a tenth of the stable step.
  const MassSpringModel model = loaded_three_tier();
  const double dt =
      0.1 * predicted_stable_dt(model, IntegratorKind::central_difference, model.initial_state());
  const State reference = reference_run(model, IntegratorKind::explicit_euler, dt, 100);
  const State symplectic = reference_run(model, IntegratorKind::symplectic_euler, dt, 100);
  for (int threads : {1, 2}) {
    FastStepperOptions options;
    options.threads = threads;
    options.integrator = IntegratorKind::explicit_euler;
    FastExplicitStepper fast(model, options);
    fast.step(dt, 40);
    fast.step(dt, 60);
    EXPECT_LE(relative_difference(fast.state(), reference, model.rest_state()), 1e-9) << threads;
  }
  // Not the symplectic step under another name.
  EXPECT_GT(relative_difference(symplectic, reference, model.rest_state()), 1e-4);
}

TEST(FastExplicitStepper, AdaptiveThreadsProbeBothCountsAndChangeNoResult) {
  const MassSpringModel model = loaded_three_tier();
  const double dt =
      0.5 * predicted_stable_dt(model, IntegratorKind::central_difference, model.initial_state());
  for (bool single_precision : {false, true}) {
    FastStepperOptions fixed;
    fixed.threads = 2;
    fixed.single_precision = single_precision;
    fixed.adaptive_threads = false;
    FastStepperOptions adaptive = fixed;
    adaptive.adaptive_threads = true;
    FastStepperOptions one = fixed;
    one.threads = 1;
    FastExplicitStepper a(model, fixed), b(model, adaptive), c(model, one);
    int seen[3] = {0, 0, 0};
    for (int call = 0; call < 300; ++call) {
      a.step(dt, 2);
      b.step(dt, 2);
      c.step(dt, 2);
      ++seen[b.last_step_threads()];
    }
    EXPECT_GE(seen[1], 8) << single_precision;  // the probes at least
    EXPECT_GE(seen[2], 8) << single_precision;
    EXPECT_EQ(a.last_step_threads(), 2);
    EXPECT_EQ((a.state().x - b.state().x).cwiseAbs().maxCoeff(), 0.0) << single_precision;
    EXPECT_EQ((a.state().v - b.state().v).cwiseAbs().maxCoeff(), 0.0) << single_precision;
    EXPECT_EQ((a.state().x - c.state().x).cwiseAbs().maxCoeff(), 0.0) << single_precision;
  }
}

// Each member takes its own range of blocks first, then what is left of the others' (a counter
// per range): with three and four members on a model of about 18 blocks the ranges are uneven
// and members steal, across the four passes of an RK4 step and several steps a call. A block
// taken by no one would leave its nodes a step behind, and every team size would part from one
// thread.
TEST(FastExplicitStepper, EveryTeamSizeTakesEveryBlockOnce) {
  const MassSpringModel model = loaded_three_tier();
  const double dt =
      0.5 * predicted_stable_dt(model, IntegratorKind::central_difference, model.initial_state());
  for (const IntegratorKind kind : {IntegratorKind::symplectic_euler, IntegratorKind::rk4}) {
    FastStepperOptions one;
    one.threads = 1;
    one.integrator = kind;
    FastExplicitStepper reference(model, one);
    reference.step(dt, 150);
    for (const int threads : {2, 3, 4}) {
      FastStepperOptions team = one;
      team.threads = threads;
      team.adaptive_threads = false;
      FastExplicitStepper stepper(model, team);
      for (int call = 0; call < 50; ++call)
        stepper.step(dt, 3);
      EXPECT_EQ(stepper.last_step_threads(), threads);
      EXPECT_EQ((stepper.state().x - reference.state().x).cwiseAbs().maxCoeff(), 0.0)
          << to_string(kind) << ", " << threads << " threads";
      EXPECT_EQ((stepper.state().v - reference.state().v).cwiseAbs().maxCoeff(), 0.0)
          << to_string(kind) << ", " << threads << " threads";
    }
  }
}

// Damping that differs between springs takes the per-spring path of the kernels (a uniform
// damping, as in loaded_three_tier, takes another).
TEST(FastExplicitStepper, MatchesSymplecticEulerWithPerSpringDamping) {
  MassSpringModel model = loaded_three_tier();
  Eigen::VectorXd damping(model.network().num_springs());
  for (Eigen::Index s = 0; s < damping.size(); ++s)
    damping[s] = 0.005 * (1 + s % 3);
  model.set_damping(damping);
  const double dt =
      0.5 * predicted_stable_dt(model, IntegratorKind::central_difference, model.initial_state());
  const State reference = reference_run(model, IntegratorKind::symplectic_euler, dt, 200);
  for (const bool single_precision : {false, true}) {
    FastExplicitStepper fast(model, FastStepperOptions{2, single_precision, true});
    fast.step(dt, 200);
    EXPECT_LE(relative_difference(fast.state(), reference, model.rest_state()),
              single_precision ? 2e-6 : 1e-9);
  }
}

TEST(FastExplicitStepper, AnchorsAndRunTimeStiffnessChanges) {
  const auto mesh = testing::icosphere(2, 0.05);
  MassSpringModel model(build_single_layer(mesh.vertices, mesh.triangles));
  model.set_gravity({0.0, 0.0, -9.81});
  const double dt =
      0.5 * predicted_stable_dt(model, IntegratorKind::central_difference, model.initial_state());
  FastExplicitStepper fast(model);
  fast.step(dt, 100);
  Integrator integrator(IntegratorKind::symplectic_euler);
  State reference = initial_state(model);
  for (int n = 0; n < 100; ++n)
    integrator.step(model, reference, dt);
  EXPECT_LE(relative_difference(fast.state(), reference, model.rest_state()), 1e-9);

  // Change a group's stiffness between steps: both follow without rebuilding.
  model.scale_group_stiffness("surface_edges", 0.5);
  fast.update_parameters(model);
  fast.step(dt, 100);
  for (int n = 0; n < 100; ++n)
    integrator.step(model, reference, dt);
  EXPECT_LE(relative_difference(fast.state(), reference, model.rest_state()), 1e-9);
}

// Scanner coordinates put an organ a metre or so from the origin, where a float coordinate is
// good to 1e-7 m. The float stepper's records hold displacements from a rest frame, so a sag of a
// few millimetres keeps float's relative precision: 2e-6 (three tiers) and 2e-5 (the anchored
// single layer) of the largest displacement, against 3e-5 and 1e-3 with absolute float positions.
TEST(FastExplicitStepper, FloatKeepsASagFarFromTheOrigin) {
  auto mesh = testing::icosphere(2, 0.05);
  mesh.vertices.rowwise() += Eigen::RowVector3d(0.9, -0.7, 1.1);
  ThreeTierOptions tiers;
  tiers.material.spring_damping = 0.05;
  const std::vector<SpringNetwork> networks = {
      build_three_tier(mesh.vertices, mesh.triangles, tiers),
      build_single_layer(mesh.vertices, mesh.triangles)};
  for (const SpringNetwork& network : networks) {
    MassSpringModel model(network);
    model.set_gravity({0.0, 0.0, -9.81});
    const double dt =
        0.5 * predicted_stable_dt(model, IntegratorKind::central_difference, model.initial_state());
    FastExplicitStepper exact(model, FastStepperOptions{2, false, true});
    FastExplicitStepper single(model, FastStepperOptions{2, true, true});
    double worst = 0.0, largest = 0.0;
    for (int checkpoint = 0; checkpoint < 10; ++checkpoint) {
      exact.step(dt, 100);
      single.step(dt, 100);
      const Eigen::VectorXd x = exact.state().x;
      worst = std::max(worst, (single.state().x - x).cwiseAbs().maxCoeff());
      largest = std::max(largest, (x - model.rest_state()).cwiseAbs().maxCoeff());
    }
    EXPECT_GT(largest, 1e-5) << network.num_anchors();  // a sag, not rest
    EXPECT_LT(largest, 2e-2) << network.num_anchors();
    EXPECT_LT(worst, 1e-4 * largest) << network.num_anchors() << " anchors";
  }
}

TEST(FastExplicitStepper, DivergenceStopsWithTheStableStep) {
  const MassSpringModel model = loaded_three_tier();
  const double stable =
      predicted_stable_dt(model, IntegratorKind::central_difference, model.initial_state());
  FastExplicitStepper fast(model);
  try {
    for (int call = 0; call < 100; ++call)
      fast.step(4.0 * stable, 50);
    FAIL() << "no divergence detected";
  } catch (const DivergenceError& error) {
    EXPECT_NEAR(error.stable_dt() / stable, 1.0, 1e-9);
    EXPECT_NE(std::string(error.what()).find("stable dt"), std::string::npos);
  }
}

TEST(FastImplicitStepper, MatchesBackwardEuler) {
  const MassSpringModel model = loaded_three_tier();
  const double dt = 1e-3;
  const State reference = reference_run(model, IntegratorKind::implicit_euler, dt, 30);
  for (int threads : {1, 2}) {
    FastImplicitStepper fast(model, FastImplicitOptions{threads, true, 1e-12, 1000});
    EXPECT_FALSE(fast.single_precision_terms());  // a tight solve keeps them double
    for (int n = 0; n < 30; ++n)
      fast.step(dt);
    EXPECT_LE(relative_difference(fast.state(), reference, model.rest_state()), 1e-8) << threads;
    // Again after set_state: the warm start (the last step's Δv) must not bias the solve.
    fast.set_state(initial_state(model));
    for (int n = 0; n < 30; ++n)
      fast.step(dt);
    EXPECT_LE(relative_difference(fast.state(), reference, model.rest_state()), 1e-8) << threads;
  }
  // Haptic settings: loose tolerance, few iterations, still close.
  FastImplicitStepper haptic(model, FastImplicitOptions{2, true, 1e-3, 50});
  for (int n = 0; n < 30; ++n)
    haptic.step(dt);
  EXPECT_LE(relative_difference(haptic.state(), reference, model.rest_state()), 1e-2);
  EXPECT_LE(haptic.last_cg_iterations(), 50);
}

// The float implicit stepper's records hold displacements, as the explicit one's do: a sphere a
// metre and a half from the origin sags under gravity (float positions there are good to 1e-7 m,
// a tenth of a millimetre spring's length per thousand), and float follows double to 1e-6 of the
// sag (measured 1.8e-7; with absolute float positions 2.2e-5).
TEST(FastImplicitStepper, FloatKeepsASagFarFromTheOrigin) {
  auto mesh = testing::icosphere(2, 0.05);
  mesh.vertices.rowwise() += Eigen::RowVector3d(0.9, -0.7, 1.1);
  ThreeTierOptions tiers;
  tiers.material.spring_damping = 0.05;
  MassSpringModel model(build_three_tier(mesh.vertices, mesh.triangles, tiers));
  model.set_gravity({0.0, 0.0, -9.81});
  FastImplicitOptions in_double;
  in_double.cg_tolerance = 1e-5;
  in_double.cg_max_iterations = 200;
  FastImplicitOptions in_float = in_double;
  in_float.single_precision = true;
  FastImplicitStepper exact(model, in_double), single(model, in_float);
  double worst = 0.0, largest = 0.0;
  for (int checkpoint = 0; checkpoint < 10; ++checkpoint) {
    exact.step(1e-3, 20);
    single.step(1e-3, 20);
    const Eigen::VectorXd x = exact.state().x;
    worst = std::max(worst, (single.state().x - x).cwiseAbs().maxCoeff());
    largest = std::max(largest, (x - model.rest_state()).cwiseAbs().maxCoeff());
  }
  EXPECT_GT(largest, 1e-4);  // a sag, not rest
  EXPECT_LT(largest, 2e-2);
  EXPECT_LT(worst, 1e-6 * largest);
}

// A loose double solve keeps the springs' coefficients in float: the operator is the double one
// rounded per coefficient (6e-8), so its solves to 1e-6 stay as close to the tight solve as the
// all-double ones (measured: both 1.9e-8 of the displacement after 30 steps) and part from them by
// rounding only (1.1e-11), but part (the float path is the one taken).
TEST(FastImplicitStepper, LooseSolvesStreamFloatCoefficientsAndKeepTheDoubleSolution) {
  const MassSpringModel model = loaded_three_tier();
  const double dt = 1e-3;
  const State reference = reference_run(model, IntegratorKind::implicit_euler, dt, 30);
  for (int threads : {1, 2}) {
    FastImplicitOptions loose{threads, true, kSingleTermsTolerance, 1000};
    FastImplicitStepper single(model, loose);
    loose.single_precision_terms = false;
    FastImplicitStepper all_double(model, loose);
    ASSERT_TRUE(single.single_precision_terms());
    ASSERT_FALSE(all_double.single_precision_terms());
    single.step(dt, 30);
    all_double.step(dt, 30);
    const double single_error = relative_difference(single.state(), reference, model.rest_state());
    const double double_error =
        relative_difference(all_double.state(), reference, model.rest_state());
    EXPECT_LE(single_error, 1e-6) << threads;
    EXPECT_LE(double_error, 1e-6) << threads;
    const double apart =
        relative_difference(single.state(), all_double.state(), model.rest_state());
    EXPECT_LE(apart, 1e-9) << threads;
    EXPECT_GT(apart, 0.0) << threads;
  }
}

// The haptic default (relative residual 1e-2, warm start) against a tight solve of the same
// backward-Euler steps: over 100 steps of 1 ms the positions stay within 2e-3 of the displacement
// (measured: 8e-4 at most, in double and float alike), and no step reaches the iteration cap.
TEST(FastImplicitStepper, HapticToleranceStaysCloseToTheTightSolve) {
  const MassSpringModel model = loaded_three_tier();
  FastImplicitStepper tight(model, FastImplicitOptions{2, true, 1e-12, 2000});
  for (const bool single_precision : {false, true}) {
    FastImplicitOptions haptic;
    haptic.single_precision = single_precision;
    FastImplicitStepper fast(model, haptic);
    tight.set_state(initial_state(model));
    for (int n = 0; n < 100; ++n) {
      tight.step(1e-3);
      fast.step(1e-3);
      ASSERT_LT(fast.last_cg_iterations(), haptic.cg_max_iterations) << n;
    }
    EXPECT_LE(relative_difference(fast.state(), tight.state(), model.rest_state()), 2e-3)
        << single_precision;
  }
}

// Near rest a step's right-hand side is its springs' rounding: in float each spring force carries
// about 6e-8 of k l0, and the CG stops once its residual is down to that (in double the bound is
// 1e-9 of it). msfem bench's seed sphere rings down from its perturbed start; 2,000 steps on,
// float steps take half an iteration each (double 1.2), where chasing the rounding took 3, and
// float stays within 9.3e-4 of the start's perturbation from double (1.6e-4 chasing it).
TEST(FastImplicitStepper, FloatStopsAtItsSpringsRoundingNearRest) {
  const auto cases = benchmark_cases(std::nullopt, std::nullopt, false);
  ASSERT_EQ(cases.front().name, "seed_sphere");
  const MassSpringModel model(cases.front().network);
  const State start = perturbed_start(model);
  FastImplicitOptions in_float;
  in_float.single_precision = true;
  FastImplicitStepper single(model, in_float), exact(model, FastImplicitOptions{});
  single.set_state(start);
  exact.set_state(start);
  // While the start rings, b is far above its rounding, and float iterates as double does.
  int early[2] = {0, 0};
  for (int n = 0; n < 20; ++n) {
    single.step(1e-3);
    exact.step(1e-3);
    early[0] += single.last_cg_iterations();
    early[1] += exact.last_cg_iterations();
  }
  EXPECT_EQ(early[0], early[1]);
  single.step(1e-3, 1980);
  exact.step(1e-3, 1980);
  int iterations = 0;
  for (int n = 0; n < 100; ++n) {
    single.step(1e-3);
    iterations += single.last_cg_iterations();
  }
  exact.step(1e-3, 100);
  const double perturbation = (start.x - model.rest_state()).norm();
  EXPECT_LE(iterations, 100);
  EXPECT_LE((single.state().x - exact.state().x).norm(), 3e-3 * perturbation);
}

// The reductions are summed per block of nodes in a fixed order, so the number of threads, and
// adaptive_threads switching between one and two mid-run, leave every step bit for bit the same
// (its probes run 4 steps on the other count after 32 to 256 steps).
TEST(FastImplicitStepper, StepsDoNotDependOnTheThreadCount) {
  const MassSpringModel model = loaded_three_tier();
  for (const bool single_precision : {false, true}) {
    FastImplicitOptions one;
    one.threads = 1;
    one.single_precision = single_precision;
    FastImplicitOptions two = one, adaptive = one;
    two.threads = adaptive.threads = 2;
    two.adaptive_threads = false;
    FastImplicitStepper a(model, one), b(model, two), c(model, adaptive);
    int adaptive_threads_seen[3] = {0, 0, 0};
    for (int n = 0; n < 410; ++n) {
      a.step(1e-3);
      b.step(1e-3);
      c.step(1e-3);
      ASSERT_EQ(a.last_cg_iterations(), b.last_cg_iterations()) << n;
      EXPECT_EQ(b.last_step_threads(), 2);
      ++adaptive_threads_seen[c.last_step_threads()];
    }
    EXPECT_EQ((a.state().x - b.state().x).cwiseAbs().maxCoeff(), 0.0) << single_precision;
    EXPECT_EQ((a.state().v - b.state().v).cwiseAbs().maxCoeff(), 0.0) << single_precision;
    EXPECT_EQ((a.state().x - c.state().x).cwiseAbs().maxCoeff(), 0.0) << single_precision;
    EXPECT_EQ(adaptive_threads_seen[0], 0);
    EXPECT_GE(adaptive_threads_seen[1], 8);  // the probes at least
    EXPECT_GE(adaptive_threads_seen[2], 8);
  }
}

TEST(SteppingBenchmark, ReportsRatesForASmallModel) {
  const MassSpringModel model = loaded_three_tier();
  SteppingBenchmarkOptions options;
  options.seconds_per_sample = 0.01;
  options.samples = 3;
  const SteppingBenchmarkResult result = run_stepping_benchmark(model, options);
  EXPECT_EQ(result.nodes, 486);
  EXPECT_EQ(result.springs, 4 * 480 + 2 * 162);
  EXPECT_GT(result.explicit_steps_per_second, 0.0);
  EXPECT_GT(result.naive_steps_per_second, 0.0);
  EXPECT_GT(result.implicit_steps_per_second, 0.0);
  for (const RateSpread* s :
       {&result.explicit_spread, &result.naive_spread, &result.implicit_spread,
        &result.explicit_euler_spread, &result.rk4_spread, &result.implicit_float_spread}) {
    EXPECT_GT(s->min, 0.0);
    EXPECT_LE(s->min, s->median);
    EXPECT_LE(s->median, s->max);
  }
  EXPECT_EQ(result.explicit_spread.median, result.explicit_steps_per_second);
  ASSERT_TRUE(result.float_vs_double);
  EXPECT_EQ(result.float_vs_double->steps, 1000);
  EXPECT_EQ(result.implicit_float_spread.median, result.implicit_float_steps_per_second);
  EXPECT_GT(result.implicit_float_mean_cg_iterations, 0.0);
  ASSERT_TRUE(result.implicit_float_vs_double);
  EXPECT_EQ(result.implicit_float_vs_double->steps, 100);
  // At least the records read and written (8 doubles a node) and k, k l0 of both ends of every
  // spring; padding makes it more, but not twice more.
  const std::size_t least = 2 * 8 * sizeof(double) * 486 + 2 * 2 * sizeof(double) * result.springs;
  EXPECT_GE(result.explicit_bytes_per_step, least);
  EXPECT_LT(result.explicit_bytes_per_step, 3 * least);
}

// In float the bench's implicit figures are float's, and the comparison with double still runs:
// the implicit_float fields never read as zero beside a float implicit figure.
TEST(SteppingBenchmark, InFloatTheFloatImplicitFiguresAreTheImplicitOnes) {
  const MassSpringModel model = loaded_three_tier();
  SteppingBenchmarkOptions options;
  options.seconds_per_sample = 0.01;
  options.samples = 3;
  options.single_precision = true;
  options.run_naive = options.compare_precision = options.run_other_integrators = false;
  const SteppingBenchmarkResult result = run_stepping_benchmark(model, options);
  EXPECT_GT(result.implicit_steps_per_second, 0.0);
  EXPECT_EQ(result.implicit_float_steps_per_second, result.implicit_steps_per_second);
  EXPECT_EQ(result.implicit_float_spread.min, result.implicit_spread.min);
  EXPECT_EQ(result.implicit_float_mean_cg_iterations, result.implicit_mean_cg_iterations);
  ASSERT_TRUE(result.implicit_float_vs_double);
  EXPECT_EQ(result.implicit_float_vs_double->steps, 100);
  EXPECT_GT(result.implicit_float_vs_double->max_displacement_m, 0.0);
  EXPECT_LT(result.implicit_float_vs_double->relative(), 1e-4);
}

TEST(SteppingBenchmark, TimesEachIntegratorAtTheStepACaseGives) {
  const MassSpringModel model = loaded_three_tier();
  SteppingBenchmarkOptions options;
  options.seconds_per_sample = 0.01;
  options.samples = 1;
  options.run_naive = options.run_implicit = options.compare_precision = false;
  const SteppingBenchmarkResult own = run_stepping_benchmark(model, options);
  const double rule =
      0.5 * predicted_stable_dt(model, IntegratorKind::central_difference, model.initial_state());
  EXPECT_EQ(own.explicit_dt, rule);
  EXPECT_EQ(own.explicit_euler_dt, 0.01 * rule);
  EXPECT_EQ(own.rk4_dt, 0.01 * rule);

  BenchmarkCase given{"given", "loaded three tiers", model.network()};
  given.model = std::make_shared<MassSpringModel>(model);
  given.timed_dt = {0.3 * rule, 0.02 * rule, 0.7 * rule};
  const SteppingBenchmarkResult chosen = run_benchmark_case(given, options);
  EXPECT_EQ(chosen.explicit_dt, 0.3 * rule);
  EXPECT_EQ(chosen.explicit_euler_dt, 0.02 * rule);
  EXPECT_EQ(chosen.rk4_dt, 0.7 * rule);
  EXPECT_EQ(chosen.precision_dt, rule);  // float against double keeps the bench's own step
  EXPECT_GT(chosen.rk4_spread.median, 0.0);
}

// The implicit stepper in float against double, both at the haptic tolerance, over 100 steps of
// 1 ms from the dilated sphere: within 1e-5 of the largest displacement (measured 2.2e-7), far
// below what the tolerance itself moves either from the tight solve (2e-3,
// HapticToleranceStaysCloseToTheTightSolve).
TEST(SteppingBenchmark, FloatImplicitFollowsDoubleOnALoadedRun) {
  const MassSpringModel model = loaded_three_tier();
  const PrecisionComparison c = compare_implicit_precision(model, FastImplicitOptions{}, 1e-3, 100);
  EXPECT_EQ(c.steps, 100);
  EXPECT_GT(c.max_displacement_m, 1e-4);
  EXPECT_GT(c.max_node_error_m, 0.0);  // two precisions, not one stepper twice
  EXPECT_LT(c.relative(), 1e-5);
}

TEST(SteppingBenchmark, StreamTriadMeasuresABandwidth) {
  // Any machine that runs the tests streams more than 100 MB/s; a loop the compiler dropped, or
  // a wrong byte count, would not give a finite positive figure in this range.
  const double bandwidth = stream_triad_bandwidth(2, 1);
  EXPECT_GT(bandwidth, 1e8);
  EXPECT_LT(bandwidth, 1e13);
}

TEST(SteppingBenchmark, FloatFollowsDoubleOnALoadedRun) {
  // The level-2 sphere dilated 2 %: a few tenths of a millimetre of displacement, 1,000 steps at
  // half the stable dt. Float keeps within 1e-4 of the largest displacement (its records hold
  // displacements, which keep float's relative precision).
  const MassSpringModel model = loaded_three_tier();
  const double dt =
      0.5 * predicted_stable_dt(model, IntegratorKind::central_difference, model.initial_state());
  const PrecisionComparison c = compare_precision(model, dt, 1000, 2);
  EXPECT_GT(c.max_displacement_m, 1e-4);
  EXPECT_GT(c.max_node_error_m, 0.0);  // two precisions, not one stepper twice
  EXPECT_LT(c.relative(), 1e-4);
}

}  // namespace
}  // namespace msfem::massspring
