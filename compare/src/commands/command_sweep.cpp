// msfem sweep CASE.prm: which variant, resolution and integrator gives the least error at the frame
// rate a simulator needs.
#include <cmath>
#include <ctime>
#include <iostream>
#include <optional>
#include <sstream>

#include "msfem/cases/case_parameters.hpp"
#include "msfem/cases/errors.hpp"
#include "msfem/cases/setting_names.hpp"
#include "msfem/cases/text.hpp"
#include "msfem/compare/commands/commands.hpp"
#include "msfem/compare/commands/options.hpp"
#include "msfem/compare/pipeline/ranks.hpp"
#include "msfem/compare/pipeline/sweep.hpp"
#include "msfem/compare/writers/atomic_file.hpp"
#include "msfem/compare/writers/plots.hpp"
#include "msfem/massspring/errors.hpp"
#include "msfem/massspring/integrators.hpp"

namespace msfem::compare {
namespace {

std::vector<int> integers(const std::string& option, const std::string& text) {
  std::vector<int> values;
  for (const auto& p : cases::split_list(text)) {
    std::size_t used = 0;
    int v = 0;
    try {
      v = std::stoi(p, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != p.size() || v <= 0)
      throw std::invalid_argument("option --" + option + ": '" + p + "' is not a positive integer");
    values.push_back(v);
  }
  // An empty list would run the default sweep, not the one asked for.
  if (values.empty())
    throw std::invalid_argument("option --" + option + ": '" + text + "' lists no value");
  return values;
}

double positive_number(const std::string& option, const std::string& text) {
  std::size_t used = 0;
  double v = 0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || !(v > 0) || !std::isfinite(v))
    throw std::invalid_argument("option --" + option + ": '" + text + "' is not a positive number");
  return v;
}

// Colour per variant, marker per integrator, the configurations that keep a 1 kHz loop ringed.
std::filesystem::path pareto_plot(const std::filesystem::path& file, const std::string& name,
                                  const std::vector<SweepPoint>& points) {
  std::vector<ParetoPoint> pareto_points;
  for (const auto& p : points)
    pareto_points.push_back({p.model() + " " + p.integrator + " @" + std::to_string(p.resolution),
                             p.realtime_factor, p.rel_l2_error, p.model(), p.integrator,
                             keeps_real_time(p, 1000.0)});
  return pareto(file, "Relative error against real-time factor: " + name, pareto_points);
}

// --volume-preservation off|on|both.
std::vector<bool> volume_settings(const std::string& value) {
  if (value != "off" && value != "on" && value != "both")
    throw cases::InputError("option --volume-preservation: '" + value + "' is not off, on or both");
  return value == "both" ? std::vector<bool>{false, true} : std::vector<bool>{value == "on"};
}

// --contact-refinement off|on|both with --contact-edge-lengths E1,E2 (m; each a pass, on implied):
// none for the off pass, each edge length (0: the case's) for an on pass.
std::vector<std::optional<double>> refinement_settings(const std::optional<std::string>& mode,
                                                       const std::optional<std::string>& edges) {
  if (mode && *mode != "off" && *mode != "on" && *mode != "both")
    throw cases::InputError("option --contact-refinement: '" + *mode + "' is not off, on or both");
  if (edges && mode && *mode == "off")
    throw cases::InputError(
        "option --contact-edge-lengths: contact refinement is off (--contact-refinement off)");
  std::vector<std::optional<double>> passes;
  if (!mode && !edges) return passes;
  if (mode && *mode != "on") passes.push_back(std::nullopt);
  if (mode && *mode == "off") return passes;
  if (!edges) {
    passes.push_back(0.0);
    return passes;
  }
  for (const auto& edge : cases::split_list(*edges))
    passes.push_back(positive_number("contact-edge-lengths", edge));
  return passes;
}

}  // namespace

int sweep_command(const Arguments& args) {
  const Options opt(args, {"quiet", "json"},
                    {"out", "set", "resolutions", "integrators", "max-error", "volume-preservation",
                     "contact-refinement", "contact-edge-lengths"});
  if (opt.positional().size() != 1)
    throw std::invalid_argument(
        "usage: msfem sweep CASE.prm [--resolutions 2,3,4] [--integrators a,b] [--max-error E] "
        "[--volume-preservation off|on|both] [--contact-refinement off|on|both] "
        "[--contact-edge-lengths E1,E2] [--out DIR]");
  std::optional<double> max_error;
  if (const auto e = opt.value("max-error")) max_error = positive_number("max-error", *e);
  const cases::CaseParameters parameters = cases::read_case(opt.positional()[0], opt.values("set"));
  SweepSettings settings;
  settings.quiet = opt.flag("quiet");
  if (const auto r = opt.value("resolutions")) settings.resolutions = integers("resolutions", *r);
  if (const auto v = opt.value("volume-preservation"))
    settings.volume_preservation = volume_settings(*v);
  settings.contact_refinement =
      refinement_settings(opt.value("contact-refinement"), opt.value("contact-edge-lengths"));
  if (!settings.contact_refinement.empty() && !parameters.loads.tool.enabled)
    throw cases::InputError(
        parameters.file.string() +
        ": --contact-refinement refines around the tool, but loads/tool is off");
  if (const auto i = opt.value("integrators")) {
    settings.integrators.clear();
    for (const auto& name : cases::split_list(*i))
      settings.integrators.push_back(
          cases::parse_setting<massspring::IntegratorKind>(name, "option --integrators"));
  }

  const std::filesystem::path final_dir = opt.value("out")
                                              ? std::filesystem::path(*opt.value("out"))
                                              : std::filesystem::path(parameters.output.directory) /
                                                    (parameters.name + "-sweep-" + run_timestamp());
  const std::filesystem::path cache = fem_cache_beside(final_dir);
  std::ostringstream printed;
  std::vector<std::pair<int, std::string>> failed;
  std::vector<SweepResult::FailedVariant> failed_variants;
  // Under mpirun every rank sweeps (the FEM and the timed items are shared) and rank 0 writes.
  const bool writes = ranks::is_root();
  ranks::agree([&] {
    if (writes) check_output_folder(final_dir);
  });
  if (!writes) {
    const SweepResult result = run_sweep(parameters, settings, cache);
    return result.failed_resolutions.empty() && result.failed_variants.empty() ? 0 : 1;
  }
  fill_directory_atomically(final_dir, [&](const std::filesystem::path& work) {
    const SweepResult result = run_sweep(parameters, settings, cache);
    const auto& points = result.points;
    failed = result.failed_resolutions;
    failed_variants = result.failed_variants;
    const nlohmann::json j = sweep_json(parameters, result);
    write_text_atomically(work / "sweep.json", j.dump(2) + "\n");
    std::string plot_line = "(plots skipped: gnuplot is not installed)";
    const std::vector<VariantConvergence> convergence = convergence_by_variant(points);
    if (gnuplot_available()) {
      const auto file = pareto_plot(work / "pareto.png", parameters.name, points);
      plot_line = "![Pareto plot](" + file.filename().string() + ")";
      std::vector<Series> series;
      for (const auto& v : convergence) {
        Series s{v.variant, {}, {}};
        for (const auto& [vertices, error] : v.error_at_vertices) {
          s.x.push_back(vertices);
          s.y.push_back(error);
        }
        series.push_back(std::move(s));
      }
      const auto resolution_file =
          xy_lines(work / "convergence.png", "Error against resolution: " + parameters.name,
                   "surface vertices", "relative error (rel L2)", series, true, true);
      plot_line += "\n\n![Error against resolution](" + resolution_file.filename().string() + ")";
    }
    const std::string answer = sweep_answer(points, max_error);
    std::string table = sweep_table(points);
    for (const auto& [resolution, why] : result.failed_resolutions)
      table += "\n> **resolution " + std::to_string(resolution) +
               " failed** and is left out of the table and plot: " + why + "\n";
    for (const auto& f : result.failed_variants)
      table += "\n> **" + f.model + " failed at resolution " + std::to_string(f.resolution) +
               "** and is left out of the table and plot: " + f.error + "\n";
    if (result.networks) table += "\n> " + result.networks->note + ".\n";
    write_text_atomically(work / "report.md",
                          "# msfem sweep: " + parameters.name + "\n\n" + answer +
                              convergence_section(convergence) + "## Every configuration\n\n" +
                              table +
                              "\nrel L2 against the FEM at each resolution; steps/s at half of "
                              "each integrator's measured stable step (median after warm-up); "
                              "real-time factor = stable step × steps/s. On the plot, ringed "
                              "points keep a 1 kHz loop in real time.\n\n" +
                              plot_line + "\n");
    printed << (opt.flag("json")
                    ? j.dump(2) + "\n"
                    : table + "\n" + answer + "results in " + final_dir.string() + "\n");
  });
  std::cout << printed.str();
  // The sweep's other resolutions and variants are written; a script still learns what is missing.
  for (const auto& [resolution, why] : failed)
    std::cerr << "msfem sweep: resolution " << resolution << " failed: " << why << "\n";
  for (const auto& f : failed_variants)
    std::cerr << "msfem sweep: resolution " << f.resolution << ": variant " << f.model
              << " failed: " << f.error << "\n";
  return failed.empty() && failed_variants.empty() ? 0 : 1;
}

}  // namespace msfem::compare
