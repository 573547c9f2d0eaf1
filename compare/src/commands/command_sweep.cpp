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
#include "msfem/compare/pipeline/atomic_file.hpp"
#include "msfem/compare/pipeline/ranks.hpp"
#include "msfem/compare/pipeline/sweep.hpp"
#include "msfem/compare/writers/sweep_report.hpp"
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

// --volume-preservation off|on|both.
std::vector<bool> volume_settings(const std::string& value) {
  if (value != "off" && value != "on" && value != "both")
    throw cases::InputError("option --volume-preservation: '" + value + "' is not off, on or both");
  return value == "both" ? std::vector<bool>{false, true} : std::vector<bool>{value == "on"};
}

// --precision double|float|both: the fast steppers' arithmetic, each timed.
std::vector<bool> precision_settings(const std::string& value) {
  if (value != "double" && value != "float" && value != "both")
    throw cases::InputError("option --precision: '" + value + "' is not double, float or both");
  return value == "both" ? std::vector<bool>{false, true} : std::vector<bool>{value == "float"};
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
                     "contact-refinement", "contact-edge-lengths", "precision"});
  if (opt.positional().size() != 1)
    throw std::invalid_argument(
        "usage: msfem sweep CASE.prm [--resolutions 2,3,4] [--integrators a,b] [--max-error E] "
        "[--volume-preservation off|on|both] [--contact-refinement off|on|both] "
        "[--contact-edge-lengths E1,E2] [--precision double|float|both] [--out DIR]");
  std::optional<double> max_error;
  if (const auto e = opt.value("max-error")) max_error = positive_number("max-error", *e);
  const cases::CaseParameters parameters = cases::read_case(opt.positional()[0], opt.values("set"));
  SweepSettings settings;
  settings.quiet = opt.flag("quiet");
  if (const auto r = opt.value("resolutions")) settings.resolutions = integers("resolutions", *r);
  if (const auto v = opt.value("volume-preservation"))
    settings.volume_preservation = volume_settings(*v);
  if (const auto v = opt.value("precision")) settings.single_precision = precision_settings(*v);
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
    failed = result.failed_resolutions;
    failed_variants = result.failed_variants;
    printed << write_sweep_outputs(work, parameters, result, max_error, opt.flag("json"));
    if (!opt.flag("json")) printed << "results in " << final_dir.string() << "\n";
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
