// msfem haptic CASE.prm: a tool path replayed against each variant at a haptic device's rate, the
// force it renders measured against the FEM's quasi-static answer along the path.
#include <cmath>
#include <iostream>
#include <sstream>

#include "msfem/cases/case_parameters.hpp"
#include "msfem/cases/errors.hpp"
#include "msfem/compare/commands/commands.hpp"
#include "msfem/compare/commands/options.hpp"
#include "msfem/compare/pipeline/atomic_file.hpp"
#include "msfem/compare/pipeline/haptic.hpp"
#include "msfem/compare/pipeline/ranks.hpp"
#include "msfem/compare/writers/haptic_outputs.hpp"

namespace msfem::compare {
namespace {

constexpr int fem_samples = 8;
constexpr double min_rate_hz = 50.0;
constexpr double max_ticks = 1e7;  // 10 s at 1 MHz, 2.8 h at 1 kHz: a trace of 0.5 GB

double positive_option(const Options& opt, const std::string& key, double fallback, double most) {
  const auto text = opt.value(key);
  if (!text) return fallback;
  char* end = nullptr;
  const double value = std::strtod(text->c_str(), &end);
  if (text->empty() || end != text->c_str() + text->size() || !std::isfinite(value) ||
      !(value > 0) || value > most)
    throw cases::InputError("--" + key + " '" + *text + "': expected a number in (0, " +
                            std::to_string(most) + "]");
  return value;
}

// --seconds, else the path's own length, in ticks the trace can hold.
double seconds_to_replay(const Options& opt, const ToolPath& path, double rate_hz) {
  const double seconds = positive_option(opt, "seconds", path.end() - path.start(), 3600.0);
  const auto path_file = opt.value("path");
  const std::string path_name = path_file ? "--path " + *path_file : "the default tool path";
  const std::string what =
      opt.value("seconds") ? "--seconds " + *opt.value("seconds")
                           : path_name + ": the path's length " + std::to_string(seconds) + " s";
  if (!opt.value("seconds") && seconds > 3600.0)
    throw cases::InputError(what + " is over an hour (are its times in seconds?); give --seconds");
  if (seconds * rate_hz > max_ticks)
    throw cases::InputError(what + " at " + std::to_string(rate_hz) + " Hz is " +
                            std::to_string(seconds * rate_hz) + " ticks; at most " +
                            std::to_string(static_cast<long>(max_ticks)));
  if (seconds * rate_hz < 1.0)
    throw cases::InputError(what + " is shorter than one tick at " + std::to_string(rate_hz) +
                            " Hz");
  return seconds;
}

// The tool each variant is built with: the case's first (made frictionless: a replayed tool
// touches, it is not bonded), else the first sample's.
ToolPlacement contact_tool(const Problem& problem, const std::vector<PathSample>& samples) {
  ToolPlacement tool = problem.tools.empty() ? samples.front().tool : problem.tools.front();
  tool.frictionless = true;
  return tool;
}

// The variant's equilibrium at each sample, each Newton started from the last one's answer.
std::vector<std::optional<Eigen::Vector3d>> static_forces(BuiltVariant& built,
                                                          const std::vector<PathSample>& samples,
                                                          std::vector<std::string>& notes) {
  std::vector<std::optional<Eigen::Vector3d>> forces;
  Eigen::VectorXd x;
  for (const PathSample& s : samples) {
    set_tool_depth(built, s.tool);
    try {
      const StaticSolution at = solve_variant_static(built, x);
      x = at.x;
      forces.emplace_back(at.tool_force);
    } catch (const std::runtime_error& e) {
      notes.push_back(built.name + ": no equilibrium at t = " + std::to_string(s.t_s) + " s (" +
                      e.what() + ")");
      forces.emplace_back();
    }
  }
  return forces;
}

void measure_variants(HapticRun& run, const Problem& problem, const fem_reference::VolumeMesh& mesh,
                      const Progress& progress) {
  const ToolPlacement tool = contact_tool(problem, run.samples);
  for (const VariantSpec& spec : variant_specs(problem.parameters)) {
    try {
      BuiltVariant built = build_variant(spec, problem, mesh, tool);
      const auto forces = static_forces(built, run.samples, run.notes);
      set_tool_depth(built, tool);
      progress.stage("replaying " + spec.name + " for " + std::to_string(run.settings.seconds) +
                     " s");
      HapticReplay replay =
          replay_variant(built, problem.parameters, *run.path, run.settings, run.changes);
      run.variants.push_back(
          measure_along_path(std::move(replay), run.samples, run.references, forces));
    } catch (const cases::InputError&) {
      throw;
    } catch (const std::runtime_error& e) {
      run.failed.emplace_back(spec.name, e.what());
      progress.stage("variant " + spec.name + " failed: " + e.what());
    }
  }
}

std::string summary_text(const HapticRun& run, const std::filesystem::path& folder) {
  std::ostringstream s;
  s << "case " << run.case_name << ": " << run.settings.seconds << " s replayed at "
    << run.settings.rate_hz << " Hz, the FEM at " << run.samples.size() << " path points\n";
  for (const VariantAlongPath& v : run.variants) {
    const HapticReplay& r = v.replay;
    s << "  " << r.name << ": haptic " << r.rate_hz << " Hz, " << r.deadline_misses
      << " deadline misses, tick p50/p99/max " << r.tick.p50_ms << "/" << r.tick.p99_ms << "/"
      << r.tick.max_ms << " ms; model " << r.model_rate_hz << " steps/s (real-time factor "
      << r.realtime_factor << "); force error along the path rms " << v.rms_error_n << " N ("
      << v.relative_error << " of the FEM's)\n";
  }
  s << "results in " << folder.string() << "\n";
  return s.str();
}

}  // namespace

int haptic_command(const Arguments& args) {
  const Options opt(args, {"quiet", "json", "no-cache"},
                    {"out", "set", "path", "rate", "seconds", "set-at"});
  if (opt.positional().size() != 1)
    throw std::invalid_argument(
        "usage: msfem haptic CASE.prm [--path FILE] [--rate HZ] [--seconds S] [--json] "
        "[--set-at T:KEY=VALUE]...");
  const std::filesystem::path case_file = opt.positional()[0];
  const cases::CaseParameters parameters = cases::read_case(case_file, opt.values("set"));
  if (ranks::count() > 1)
    throw cases::InputError(
        "msfem haptic runs as one process: its haptic thread needs a core of "
        "its own (run it without mpirun)");
  HapticRun run;
  run.case_name = parameters.name;
  run.case_file = case_file;
  run.fem_degree = parameters.fem.degree;
  run.settings.rate_hz = positive_option(opt, "rate", 1000.0, 100000.0);
  if (run.settings.rate_hz < min_rate_hz)
    throw cases::InputError("--rate " + *opt.value("rate") + ": at least " +
                            std::to_string(static_cast<int>(min_rate_hz)) +
                            " Hz (the force is compared over 50 ms windows of ticks)");
  if (!(parameters.loads.tool.radius_m > 0))
    throw cases::InputError(case_file.string() +
                            ": loads/tool/radius: the replayed tool is a "
                            "sphere of that radius; set one");
  const Problem problem = make_problem(parameters);
  check_variants_fit(problem);
  run.path_source = opt.value("path") ? *opt.value("path") : "default";
  run.path = opt.value("path") ? read_tool_path(*opt.value("path")) : default_tool_path(problem);
  if (run.path->had_orientation())
    run.notes.push_back(
        "The path's orientation quaternions were read and checked; a spherical "
        "tool looks the same in every orientation, so they change nothing.");
  run.settings.seconds = seconds_to_replay(opt, *run.path, run.settings.rate_hz);
  const double last_tick =
      std::floor(run.settings.seconds * run.settings.rate_hz) / run.settings.rate_hz;
  run.changes =
      parse_parameter_changes(opt.values("set-at"), case_file, opt.values("set"), last_tick);
  run.samples = path_samples(problem, *run.path, run.settings.seconds, fem_samples,
                             opt.value("path") ? *opt.value("path") : case_file.string());
  if (!parameters.mass_spring.results.empty())
    run.notes.push_back(
        "Outside simulators' answers (mass spring/results) are not replayed: they "
        "are answers at the case's loads, not models to step.");

  const std::filesystem::path folder = opt.value("out")
                                           ? std::filesystem::path(*opt.value("out"))
                                           : std::filesystem::path(parameters.output.directory) /
                                                 (parameters.name + "-haptic-" + run_timestamp());
  check_output_folder(folder);
  const Progress progress(opt.flag("quiet"));
  ReferenceRequest request;
  for (const PathSample& s : run.samples) {
    request.loads.emplace_back(s.tool);
    request.refine_near.push_back(s.tool);
  }
  request.planned_solves = static_cast<int>(run.samples.size());
  if (!opt.flag("no-cache")) request.cache_directory = fem_cache_beside(folder);
  FemReferences references = fem_references(problem, request, progress);
  run.references = std::move(references.loads);
  run.fem_error = references.estimate;
  measure_variants(run, problem, references.mesh, progress);

  fill_directory_atomically(
      folder, [&](const std::filesystem::path& work) { write_haptic_outputs(run, work); });
  std::cout << (opt.flag("json") ? haptic_json(run).dump(2) + "\n" : summary_text(run, folder));
  for (const auto& [name, why] : run.failed)
    std::cerr << "msfem haptic: variant " << name << " failed: " << why << "\n";
  return run.failed.empty() ? 0 : 1;
}

}  // namespace msfem::compare
