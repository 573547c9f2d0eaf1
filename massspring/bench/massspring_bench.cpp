// Steps per second of the mass-spring steppers on the seed sphere, the brain and 10 x the brain:
// FastExplicitStepper (SoA, 2 threads, double and float), the naive scalar AoS loop, and
// FastImplicitStepper at the haptic step of 1 ms; one force evaluation of the springs and of the
// volume preservation. `--benchmark_filter=brain_scale` etc.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <map>
#include <memory>
#include <stdexcept>

#include "msfem/massspring/fast_implicit_stepper.hpp"
#include "msfem/massspring/fast_stepper.hpp"
#include "msfem/massspring/mass_spring_model.hpp"
#include "msfem/massspring/stability.hpp"
#include "msfem/massspring/volume_force_field.hpp"
#include "msfem/massspring_bench/benchmark_cases.hpp"
#include "msfem/massspring_bench/stepping_benchmark.hpp"
#include "obj_surface.hpp"

namespace {

using namespace msfem::massspring;

const std::vector<BenchmarkCase>& all_cases() {
  static const std::vector<BenchmarkCase> cases = [] {
    std::optional<Eigen::MatrixX3d> brain_vertices;
    std::optional<Eigen::MatrixX3i> brain_triangles;
    if (auto brain = bench::read_obj(MSFEM_BRAIN_OBJ, 1e-3)) {
      brain_vertices = brain->vertices;
      brain_triangles = brain->triangles;
    }
    return benchmark_cases(brain_vertices, brain_triangles);
  }();
  return cases;
}

// Models are built once per case (and once more with volume preservation where asked) and kept
// for all benchmarks of the run; the volume model is msfem bench's *_volume case of that network.
const MassSpringModel& model_for(const std::string& name, bool volume = false) {
  static std::map<std::pair<std::string, bool>, std::unique_ptr<MassSpringModel>> models;
  auto& model = models[{name, volume}];
  if (!model) {
    const auto& cases = all_cases();
    const auto named = std::find_if(cases.begin(), cases.end(),
                                    [&](const BenchmarkCase& c) { return c.name == name; });
    if (named == cases.end()) throw std::out_of_range("no benchmark case named " + name);
    BenchmarkCase c = *named;
    c.volume_preservation = c.volume_preservation || volume;
    model = benchmark_model(c);
  }
  return *model;
}

void annotate(benchmark::State& state, const MassSpringModel& model, int steps_per_iteration) {
  state.SetItemsProcessed(state.iterations() * steps_per_iteration);  // items/s = steps/s
  state.counters["nodes"] = model.num_nodes();
  state.counters["springs"] = model.network().num_springs();
}

void explicit_step(benchmark::State& state, const std::string& name, bool single_precision,
                   int threads, bool allow_avx512) {
  const MassSpringModel& model = model_for(name);
  const double dt =
      0.5 * predicted_stable_dt(model, IntegratorKind::central_difference, model.initial_state());
  FastExplicitStepper stepper(model,
                              FastStepperOptions{threads, single_precision, true, allow_avx512});
  stepper.set_state(perturbed_start(model));
  constexpr int kSteps = 10;
  for (auto _ : state)
    stepper.step(dt, kSteps);
  annotate(state, model, kSteps);
}

void naive_step(benchmark::State& state, const std::string& name) {
  const MassSpringModel& model = model_for(name);
  const double dt =
      0.5 * predicted_stable_dt(model, IntegratorKind::central_difference, model.initial_state());
  NaiveAosStepper stepper(model, perturbed_start(model));
  for (auto _ : state)
    stepper.step(dt);
  annotate(state, model, 1);
}

// threads 2 with adaptive_threads (the default) may step on one thread while that is faster;
// the counter `threads` is the mean number the steps ran on.
void implicit_step(benchmark::State& state, const std::string& name, bool single_precision,
                   double tolerance, int threads, bool adaptive_threads, bool volume) {
  const MassSpringModel& model = model_for(name, volume);
  FastImplicitOptions options{threads, true, tolerance, 50, single_precision, adaptive_threads};
  FastImplicitStepper stepper(model, options);
  stepper.set_state(perturbed_start(model));
  long iterations = 0, thread_steps = 0;
  for (auto _ : state) {
    stepper.step(1e-3);
    iterations += stepper.last_cg_iterations();
    thread_steps += stepper.last_step_threads();
  }
  annotate(state, model, 1);
  const double steps = static_cast<double>(std::max<long>(state.iterations(), 1));
  state.counters["cg_iterations"] = static_cast<double>(iterations) / steps;
  state.counters["threads"] = static_cast<double>(thread_steps) / steps;
}

// One force evaluation of the three tiers' springs (the generic SpringForceField, which Newton and
// the generic integrators call), and of the volume preservation on their shell prisms: the ratio
// of the two is what the volume term adds to a step that evaluates both.
void forces(benchmark::State& state, const std::string& name, bool volume) {
  const MassSpringModel& model = model_for(name);
  const int nv = static_cast<int>(model.network().surface_nodes.size());
  const VolumeForceField prisms(model.num_nodes(),
                                tier_prisms(model.network().rest_positions,
                                            model.network().surface_triangles, nv, 3, 8000.0));
  const Eigen::VectorXd x = perturbed_start(model).x;
  const Eigen::VectorXd v = Eigen::VectorXd::Zero(x.size());
  Eigen::VectorXd f(x.size());
  for (auto _ : state) {
    f.setZero();
    if (volume)
      prisms.add_force(x, v, f);
    else
      model.springs().add_force(x, v, f);
    benchmark::DoNotOptimize(f.data());
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["elements"] =
      volume ? prisms.elements().num_elements() : model.network().num_springs();
}

void register_all() {
  for (const std::string name : {"seed_sphere", "brain_scale"}) {
    benchmark::RegisterBenchmark(("forces_springs/" + name).c_str(), forces, name, false)
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("forces_volume_prisms/" + name).c_str(), forces, name, true)
        ->Unit(benchmark::kMicrosecond);
  }
  for (const std::string name : {"seed_sphere", "brain_scale"})
    benchmark::RegisterBenchmark(("implicit_double_2threads_tol1e-2_volume/" + name).c_str(),
                                 implicit_step, name, false, 1e-2, 2, true, true)
        ->UseRealTime()
        ->Unit(benchmark::kMicrosecond);
  for (const std::string name : {"seed_sphere", "brain_scale", "brain_10x"}) {
    benchmark::RegisterBenchmark(("explicit_soa_double_2threads/" + name).c_str(), explicit_step,
                                 name, false, 2, true)
        ->UseRealTime()
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("explicit_soa_double_1thread/" + name).c_str(), explicit_step,
                                 name, false, 1, true)
        ->UseRealTime()
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("explicit_soa_float_2threads/" + name).c_str(), explicit_step,
                                 name, true, 2, true)
        ->UseRealTime()
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("explicit_soa_float_1thread/" + name).c_str(), explicit_step,
                                 name, true, 1, true)
        ->UseRealTime()
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("explicit_soa_float_avx2_2threads/" + name).c_str(),
                                 explicit_step, name, true, 2, false)
        ->UseRealTime()
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("naive_aos/" + name).c_str(), naive_step, name)
        ->UseRealTime()
        ->Unit(benchmark::kMicrosecond);
    for (const double tolerance : {1e-3, 1e-2}) {
      const std::string tag = tolerance == 1e-3 ? "tol1e-3" : "tol1e-2";
      benchmark::RegisterBenchmark(("implicit_double_2threads_" + tag + "/" + name).c_str(),
                                   implicit_step, name, false, tolerance, 2, true, false)
          ->UseRealTime()
          ->Unit(benchmark::kMicrosecond);
      benchmark::RegisterBenchmark(("implicit_float_2threads_" + tag + "/" + name).c_str(),
                                   implicit_step, name, true, tolerance, 2, true, false)
          ->UseRealTime()
          ->Unit(benchmark::kMicrosecond);
    }
    // The haptic float step pinned to two threads and on one, beside the adaptive one above.
    benchmark::RegisterBenchmark(("implicit_float_2threads_fixed_tol1e-2/" + name).c_str(),
                                 implicit_step, name, true, 1e-2, 2, false, false)
        ->UseRealTime()
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("implicit_float_1thread_tol1e-2/" + name).c_str(), implicit_step,
                                 name, true, 1e-2, 1, false, false)
        ->UseRealTime()
        ->Unit(benchmark::kMicrosecond);
  }
}

}  // namespace

int main(int argc, char** argv) {
  register_all();
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
