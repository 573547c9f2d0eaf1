// msfem bench massspring: steps per second of the mass-spring steppers on the seed sphere, the
// brain and ten times the brain, against the naive scalar loop run in the same process, and on two
// shipped cases' models exactly as msfem sweep times them.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <thread>

#include "msfem/cases/case_parameters.hpp"
#include "msfem/cases/surface_io.hpp"
#include "msfem/compare/commands/commands.hpp"
#include "msfem/compare/commands/options.hpp"
#include "msfem/compare/pipeline/bench_case.hpp"
#include "msfem/massspring_bench/benchmark_cases.hpp"

namespace msfem::compare {
namespace {

constexpr const char* kBrainFile = "brain_icbm152_lh_9177_mm.obj";

const std::vector<std::string> kBuiltinCases = {"seed_sphere", "brain_scale", "brain_scale_volume",
                                                "brain_10x"};
const std::vector<std::string> kCaseFileCases = {"seed_sphere_contact",
                                                 "seed_sphere_tet_edges_volume"};

// The names --cases gives (all when it is not given), checked before anything is built.
std::vector<std::string> wanted_cases(const Options& options) {
  std::vector<std::string> known = kBuiltinCases;
  if (options.flag("no-10x")) known.pop_back();
  known.insert(known.end(), kCaseFileCases.begin(), kCaseFileCases.end());
  if (!options.value("cases")) return known;
  const std::vector<std::string> wanted = options.list("cases");
  if (wanted.empty()) throw std::invalid_argument("option --cases: '' lists no case");
  for (auto name = wanted.begin(); name != wanted.end(); ++name) {
    if (std::find(wanted.begin(), name, *name) != name)
      throw std::invalid_argument("option --cases: '" + *name + "' is named twice");
    if (std::find(known.begin(), known.end(), *name) == known.end()) {
      std::string list;
      for (const auto& k : known)
        list += (list.empty() ? "" : ", ") + k;
      throw std::invalid_argument("option --cases: no bench case '" + *name + "' (" + list + ")");
    }
  }
  return wanted;
}

// The wanted cases, built in the order named: the massspring-only models, then the shipped case
// files' (the seed sphere pressed by the frictionless tool, the default case's model; tet_edges
// with volume preservation, the one spring model whose error falls with resolution).
std::vector<massspring::BenchmarkCase> built_cases(
    const std::vector<std::string>& wanted, const std::optional<Eigen::MatrixX3d>& brain_vertices,
    const std::optional<Eigen::MatrixX3i>& brain_triangles) {
  const auto named = [&](const std::string& name) {
    return std::find(wanted.begin(), wanted.end(), name) != wanted.end();
  };
  std::vector<massspring::BenchmarkCase> all;
  if (std::any_of(kBuiltinCases.begin(), kBuiltinCases.end(), named))
    all = massspring::benchmark_cases(brain_vertices, brain_triangles, named("brain_10x"));
  if (named("seed_sphere_contact"))
    all.push_back(sweep_bench_case("seed_sphere_contact", "sphere_indent.prm",
                                   cases::Variant::three_tier, {}));
  if (named("seed_sphere_tet_edges_volume"))
    all.push_back(sweep_bench_case("seed_sphere_tet_edges_volume", "sphere_indent_bonded.prm",
                                   cases::Variant::tet_edges,
                                   {"mass spring/volume preservation=true"}));
  std::vector<massspring::BenchmarkCase> chosen;
  for (const std::string& name : wanted)
    for (auto& c : all)
      if (c.name == name) chosen.push_back(std::move(c));
  return chosen;
}

nlohmann::json spread_json(const massspring::RateSpread& s) {
  if (!(s.median > 0)) return nullptr;  // not run
  return {{"min", s.min}, {"median", s.median}, {"max", s.max}};
}

nlohmann::json precision_json(const std::optional<massspring::PrecisionComparison>& p, double dt) {
  if (!p) return nullptr;
  return {{"steps", p->steps},
          {"dt_s", dt},
          {"max_node_error_m", p->max_node_error_m},
          {"max_displacement_m", p->max_displacement_m},
          {"max_node_error_over_max_displacement", p->relative()}};
}

nlohmann::json to_json(const massspring::BenchmarkCase& c,
                       const massspring::SteppingBenchmarkResult& r,
                       const massspring::SteppingBenchmarkOptions& options, double stream,
                       double at_working_set) {
  const double explicit_bandwidth = r.explicit_bytes_per_step * r.explicit_steps_per_second;
  nlohmann::json warnings = c.network.warnings;
  for (const auto& note : r.notes)
    warnings.push_back(note);
  return {
      {"name", c.name},
      {"volume_preservation", c.volume_preservation},
      {"description", c.description},
      {"nodes", r.nodes},
      {"springs", r.springs},
      {"threads", r.threads},
      {"explicit_last_step_threads", r.explicit_last_step_threads},
      {"explicit_steps_per_second", r.explicit_steps_per_second},
      {"naive_steps_per_second", r.naive_steps_per_second},
      {"speedup_over_naive", r.naive_steps_per_second > 0.0
                                 ? r.explicit_steps_per_second / r.naive_steps_per_second
                                 : 0.0},
      {"implicit_steps_per_second", r.implicit_steps_per_second},
      {"implicit_mean_cg_iterations", r.implicit_mean_cg_iterations},
      {"implicit_single_precision_terms", r.implicit_single_precision_terms},
      {"explicit_steps_per_second_spread", spread_json(r.explicit_spread)},
      {"naive_steps_per_second_spread", spread_json(r.naive_spread)},
      {"implicit_steps_per_second_spread", spread_json(r.implicit_spread)},
      {"steps_per_second_by_integrator",
       {{"symplectic_euler", spread_json(r.explicit_spread)},
        {"central_difference", spread_json(r.explicit_spread)},
        {"explicit_euler", spread_json(r.explicit_euler_spread)},
        {"rk4", spread_json(r.rk4_spread)},
        {"implicit_euler", spread_json(r.implicit_spread)}}},
      {"float_vs_double", precision_json(r.float_vs_double, r.precision_dt)},
      {"implicit_float_steps_per_second", r.implicit_float_steps_per_second},
      {"implicit_float_steps_per_second_spread", spread_json(r.implicit_float_spread)},
      {"implicit_float_mean_cg_iterations", r.implicit_float_mean_cg_iterations},
      {"implicit_float_vs_double", precision_json(r.implicit_float_vs_double, options.implicit_dt)},
      {"explicit_bytes_per_step", r.explicit_bytes_per_step},
      {"explicit_bytes_per_second", explicit_bandwidth},
      {"explicit_fraction_of_stream_bandwidth", stream > 0 ? explicit_bandwidth / stream : 0.0},
      {"working_set_bytes", r.explicit_bytes_per_step},
      {"working_set_triad_bytes_per_second", at_working_set},
      {"fraction_of_working_set_roofline",
       at_working_set > 0 ? explicit_bandwidth / at_working_set : 0.0},
      {"explicit_dt_s", r.explicit_dt},
      {"implicit_dt_s", options.implicit_dt},
      {"dt_s_by_integrator",
       {{"symplectic_euler", r.explicit_dt},
        {"central_difference", r.explicit_dt},
        {"explicit_euler", r.explicit_euler_dt > 0 ? nlohmann::json(r.explicit_euler_dt) : nullptr},
        {"rk4", r.rk4_dt > 0 ? nlohmann::json(r.rk4_dt) : nullptr},
        {"implicit_euler",
         r.implicit_steps_per_second > 0 ? nlohmann::json(options.implicit_dt) : nullptr}}},
      {"warnings", warnings}};
}

// The brain surface the brain cases are built on, or none (a sphere of its size stands in).
std::optional<cases::Surface> brain_surface(const Options& options) {
  const std::filesystem::path mesh_dir =
      options.value("mesh-dir").value_or(std::string(MSFEM_DEFAULT_CASES_DIR) + "/data");
  const std::filesystem::path brain_path = mesh_dir / kBrainFile;
  if (std::filesystem::exists(brain_path))
    return cases::read_surface(brain_path, cases::LengthUnit::millimetre);
  std::cerr << "msfem bench: " << brain_path.string()
            << " not found; brain_scale uses a geodesic sphere of the same size\n";
  return std::nullopt;
}

// The roofline at a working set: the triad at each size, on the stepper's threads. A step whose
// bytes fit the caches is held to the caches' bandwidth, not memory's.
nlohmann::json cache_ladder(int threads, bool print) {
  nlohmann::json ladder = nlohmann::json::array();
  for (const double megabytes : {0.25, 1.0, 4.0, 12.0, 32.0, 128.0}) {
    const auto bytes = static_cast<std::size_t>(megabytes * 1e6);
    const double rate = massspring::triad_bandwidth_at(bytes, threads);
    ladder.push_back({{"bytes", bytes}, {"triad_bytes_per_second", rate}});
    if (print) std::printf("triad at %7.2f MB: %7.2f GB/s\n", megabytes, 1e-9 * rate);
  }
  return ladder;
}

int bench_massspring(const Options& options) {
  const bool json = options.flag("json");
  const std::vector<std::string> wanted = wanted_cases(options);
  std::optional<Eigen::MatrixX3d> brain_vertices;
  std::optional<Eigen::MatrixX3i> brain_triangles;
  if (const auto brain = brain_surface(options)) {
    brain_vertices = brain->vertices;
    brain_triangles = brain->triangles;
  }

  massspring::SteppingBenchmarkOptions bench_options;
  // Bounded so that a typo is an error, not a machine's worth of threads or an hour's run.
  bench_options.threads = static_cast<int>(options.integer("threads", 2, 1, 256));
  bench_options.samples = static_cast<int>(options.integer("samples", 5, 1, 1000));
  bench_options.single_precision = options.flag("float");
  bench_options.seconds_per_sample =
      options.number("seconds", bench_options.seconds_per_sample, 0.0, 600.0);

  // The roofline: a memory-bound step can go no faster than this machine streams its bytes.
  const double stream = massspring::stream_triad_bandwidth(bench_options.threads);
  if (!json) std::printf("stream triad bandwidth %.2f GB/s\n", 1e-9 * stream);
  const nlohmann::json ladder = cache_ladder(bench_options.threads, !json);
  nlohmann::json cases_json = nlohmann::json::array();
  for (const auto& c : built_cases(wanted, brain_vertices, brain_triangles)) {
    const auto result = massspring::run_benchmark_case(c, bench_options);
    const double at_working_set =
        massspring::triad_bandwidth_at(result.explicit_bytes_per_step, result.threads);
    cases_json.push_back(to_json(c, result, bench_options, stream, at_working_set));
    if (!json)
      std::printf(
          "%-18s %8d nodes %9d springs  explicit %9.0f steps/s (%.0f-%.0f)  naive %8.0f steps/s "
          "(x%.1f)  implicit %8.0f steps/s (%.1f CG it.; float %.0f)  float/double %.1e  explicit "
          "%.2f GB/s "
          "(%.0f %% of stream, %.0f %% of the triad at its %.1f MB)\n",
          c.name.c_str(), result.nodes, result.springs, result.explicit_steps_per_second,
          result.explicit_spread.min, result.explicit_spread.max, result.naive_steps_per_second,
          result.naive_steps_per_second > 0.0
              ? result.explicit_steps_per_second / result.naive_steps_per_second
              : 0.0,
          result.implicit_steps_per_second, result.implicit_mean_cg_iterations,
          result.implicit_float_steps_per_second,
          result.float_vs_double ? result.float_vs_double->relative() : 0.0,
          1e-9 * result.explicit_bytes_per_step * result.explicit_steps_per_second,
          stream > 0
              ? 100.0 * result.explicit_bytes_per_step * result.explicit_steps_per_second / stream
              : 0.0,
          at_working_set > 0 ? 100.0 * result.explicit_bytes_per_step *
                                   result.explicit_steps_per_second / at_working_set
                             : 0.0,
          1e-6 * static_cast<double>(result.explicit_bytes_per_step));
  }
  if (json) {
    const nlohmann::json report = {{"benchmark", "massspring"},
                                   {"hardware_threads", std::thread::hardware_concurrency()},
                                   {"threads", bench_options.threads},
                                   {"single_precision", bench_options.single_precision},
                                   {"seconds_per_sample", bench_options.seconds_per_sample},
                                   {"stream_triad_bytes_per_second", stream},
                                   {"cache_ladder", ladder},
                                   {"samples", bench_options.samples},
                                   {"statistic",
                                    "median steps per second after warm-up; *_spread: min, "
                                    "median, max over the samples"},
                                   {"cases", cases_json}};
    std::cout << report.dump(2) << "\n";
  }
  return 0;
}

}  // namespace

int bench_command(const Arguments& args) {
  const Options options(args, {"json", "float", "no-10x"},
                        {"mesh-dir", "threads", "samples", "seconds", "cases"});
  if (options.positional().size() != 1)
    throw std::invalid_argument(
        "usage: msfem bench massspring [--json] [--mesh-dir DIR] [--threads N] [--samples N] "
        "[--seconds S] [--float] [--no-10x] [--cases NAME,...]");
  const std::string& what = options.positional().front();
  if (what == "massspring") return bench_massspring(options);
  throw std::invalid_argument("bench '" + what + "': unknown (massspring)");
}

}  // namespace msfem::compare
