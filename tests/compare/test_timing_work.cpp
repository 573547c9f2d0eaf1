// msfem sweep (the harness's timing) and msfem bench massspring time the same step for the same
// model: the seed sphere's three tiers as cases/sphere_indent.prm builds them and as the bench
// builds them have the same nodes and springs and stream the same bytes per step on the same fast
// kernels (per-spring dampers at the case's damping ratio in both). Wall time is left to the
// benchmarks; this is what makes their figures comparable.
#include <gtest/gtest.h>

#include "msfem/cases/case_parameters.hpp"
#include "msfem/compare/pipeline/bench_case.hpp"
#include "msfem/compare/pipeline/variant_run.hpp"
#include "msfem/massspring/fast_stepper.hpp"
#include "msfem/massspring/mass_spring_model.hpp"
#include "msfem/massspring_bench/benchmark_cases.hpp"

namespace msfem::compare {
namespace {

namespace ms = msfem::massspring;

TEST(TimingWork, TheSweepAndTheBenchStepTheSameSeedSphere) {
  const cases::CaseParameters parameters =
      cases::read_case(std::string(MSFEM_CASES_DIR) + "/sphere_indent.prm",
                       {"loads/tool/enabled=false", "loads/gravity=0,0,-9.81"});
  const Problem problem = make_problem(parameters);
  const BuiltVariant harness = build_variant(cases::Variant::three_tier, problem, {}, std::nullopt);
  const auto cases = ms::benchmark_cases(std::nullopt, std::nullopt, false);
  ASSERT_EQ(cases.front().name, "seed_sphere");
  const ms::MassSpringModel bench(cases.front().network);

  EXPECT_EQ(harness.model->num_nodes(), 1926);
  EXPECT_EQ(bench.num_nodes(), harness.model->num_nodes());
  EXPECT_EQ(bench.network().num_springs(), harness.model->network().num_springs());
  for (const auto integrator : {ms::IntegratorKind::symplectic_euler, ms::IntegratorKind::rk4}) {
    ms::FastStepperOptions options;
    options.integrator = integrator;
    const ms::FastExplicitStepper timed_by_sweep(*harness.model, options);
    const ms::FastExplicitStepper timed_by_bench(bench, options);
    // The case's support (the inner core) and the bench's (the inner tier) hold a few nodes
    // differently, a few padded lanes' worth of bytes.
    const double sweep = static_cast<double>(timed_by_sweep.streamed_bytes_per_step());
    const double bench_bytes = static_cast<double>(timed_by_bench.streamed_bytes_per_step());
    EXPECT_NEAR(sweep, bench_bytes, 1e-3 * bench_bytes) << ms::to_string(integrator);
  }
}

// The pressed seed sphere of msfem bench is msfem sweep's model, timed at msfem sweep's step for
// each explicit integrator (RK4 at half its own bisected stable step, not a hundredth of
// symplectic Euler's): with the tool in contact a step costs what the trajectory has pressed into
// the tool, so at another step the two commands would time another state.
TEST(TimingWork, TheBenchTimesThePressedSphereAtTheSweepsSteps) {
  const ms::BenchmarkCase bench =
      sweep_bench_case("seed_sphere_contact", "sphere_indent.prm", cases::Variant::three_tier, {});
  const cases::CaseParameters parameters =
      cases::read_case(std::string(MSFEM_CASES_DIR) + "/sphere_indent.prm", {});
  const Problem problem = make_problem(parameters);
  const BuiltVariant swept =
      build_variant(cases::Variant::three_tier, problem, {}, problem.tools.front());
  ASSERT_TRUE(swept.model->has_added_fields());  // the contact field
  EXPECT_EQ(bench.model->num_nodes(), swept.model->num_nodes());
  EXPECT_EQ(bench.model->network().num_springs(), swept.model->network().num_springs());
  const std::pair<ms::IntegratorKind, double> steps[] = {
      {ms::IntegratorKind::symplectic_euler, bench.timed_dt.symplectic_euler},
      {ms::IntegratorKind::explicit_euler, bench.timed_dt.explicit_euler},
      {ms::IntegratorKind::rk4, bench.timed_dt.rk4}};
  for (const auto& [integrator, bench_dt] : steps) {
    cases::TimingParameters timing = parameters.timing;
    timing.integrator = integrator;
    timing.steps = 20;
    const Timing sweep = time_variant(swept, timing, Eigen::VectorXd(), false);
    EXPECT_EQ(bench_dt, sweep.dt_s) << ms::to_string(integrator);
    EXPECT_GT(sweep.dt_s, 0.0);
  }
  // The three steps are each integrator's own: RK4's is about 80 times explicit Euler's here.
  EXPECT_GT(bench.timed_dt.rk4, 10.0 * bench.timed_dt.explicit_euler);
}

// The settle time of msfem run: the seed sphere's three tiers sag under gravity to within 1 % of
// their static equilibrium; against an equilibrium no run can approach (the same, every node
// lifted 1 cm) the run ends unsettled long before its 20 s wall limit, saying how far it stayed.
TEST(TimingWork, SettlingEndsAtTheEquilibriumOrOnceTheRunStopsApproachingIt) {
  const cases::CaseParameters parameters =
      cases::read_case(std::string(MSFEM_CASES_DIR) + "/sphere_indent.prm",
                       {"loads/tool/enabled=false", "loads/gravity=0,0,-9.81"});
  const Problem problem = make_problem(parameters);
  const BuiltVariant variant =
      build_variant(cases::Variant::single_layer, problem, {}, std::nullopt);
  const StaticSolution equilibrium = solve_variant_static(variant, Eigen::VectorXd());

  const Timing reached = time_variant(variant, parameters.timing, equilibrium.x);
  EXPECT_TRUE(reached.settled);
  EXPECT_LE(reached.settle_distance, 0.01);
  EXPECT_GT(reached.settle_time_s, 0.0);

  Eigen::VectorXd unreachable = equilibrium.x;
  for (Eigen::Index i = 2; i < unreachable.size(); i += 3)
    unreachable[i] += 0.01;
  const Timing stalled = time_variant(variant, parameters.timing, unreachable);
  EXPECT_FALSE(stalled.settled);
  EXPECT_GT(stalled.settle_distance, 0.9);
  EXPECT_LT(stalled.settle_time_s, 10.0);
  EXPECT_EQ(reached.precision, "double");
}

// timing/precision = float times the fast steppers in float: implicit Euler in float settles the
// sagging sphere to the double static equilibrium, within the settle criterion's 1 %.
TEST(TimingWork, FloatStepsSettleToTheDoubleEquilibrium) {
  const cases::CaseParameters parameters = cases::read_case(
      std::string(MSFEM_CASES_DIR) + "/sphere_indent.prm",
      {"loads/tool/enabled=false", "loads/gravity=0,0,-9.81", "timing/integrator=implicit_euler",
       "timing/precision=float", "timing/steps=50"});
  ASSERT_TRUE(parameters.timing.single_precision);
  const Problem problem = make_problem(parameters);
  const BuiltVariant variant =
      build_variant(cases::Variant::single_layer, problem, {}, std::nullopt);
  const StaticSolution equilibrium = solve_variant_static(variant, Eigen::VectorXd());
  const Timing t = time_variant(variant, parameters.timing, equilibrium.x);
  EXPECT_EQ(t.stepper, "fast_implicit");
  EXPECT_EQ(t.precision, "float");
  EXPECT_TRUE(t.settled);
  EXPECT_LE(t.settle_distance, 0.01);
  EXPECT_GT(t.steps_per_second, 0.0);
}

}  // namespace
}  // namespace msfem::compare
