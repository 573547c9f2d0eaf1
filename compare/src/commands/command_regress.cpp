// msfem regress: compare runs with committed baselines and fail the build on a worse deformation.
#include <algorithm>
#include <fstream>
#include <iostream>

#include "msfem/cases/case_parameters.hpp"
#include "msfem/cases/errors.hpp"
#include "msfem/compare/commands/commands.hpp"
#include "msfem/compare/commands/options.hpp"
#include "msfem/compare/pipeline/atomic_file.hpp"
#include "msfem/compare/pipeline/ranks.hpp"
#include "msfem/compare/writers/regression.hpp"

namespace msfem::compare {
namespace {

nlohmann::json read_baseline(const std::filesystem::path& file) {
  std::ifstream in(file);
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw cases::InputError(file.string() + ": not a baseline: " + e.what());
  }
}

// Every case with a committed baseline, from the baselines' own case_file entries.
std::vector<std::string> cases_with_baselines(const std::filesystem::path& dir) {
  std::vector<std::string> found;
  if (std::filesystem::is_directory(dir))
    for (const auto& entry : std::filesystem::directory_iterator(dir))
      if (entry.path().extension() == ".json")
        found.push_back(read_baseline(entry.path()).value("case_file", entry.path().string()));
  std::sort(found.begin(), found.end());
  if (found.empty())
    throw cases::InputError(dir.string() + ": no baselines (*.json) to compare with");
  return found;
}

void print_changes(const nlohmann::json& old_baseline, const nlohmann::json& fresh) {
  for (const auto& [variant, v] : fresh.at("variants").items())
    for (const auto& [metric, m] : v.at("metrics").items()) {
      const auto* before = old_baseline.is_null() ? nullptr
                           : old_baseline["variants"].contains(variant)
                               ? &old_baseline["variants"][variant]["metrics"]
                               : nullptr;
      const std::string was = before && before->contains(metric) ? (*before)[metric]["value"].dump()
                                                                 : std::string("(new)");
      std::cout << "  " << fresh.at("case").get<std::string>() << " " << variant << " " << metric
                << ": " << was << " -> " << m.at("value").dump() << "\n";
    }
}

}  // namespace

int regress_command(const Arguments& args) {
  const Options opt(args, {"update", "quiet"}, {"baselines", "set"});
  const std::filesystem::path dir = opt.value("baselines").value_or("results/baselines");
  const std::vector<std::string> case_files =
      opt.positional().empty() ? cases_with_baselines(dir) : opt.positional();

  std::vector<RegressionRow> rows;
  for (const auto& case_file : case_files) {
    const cases::CaseParameters parameters = cases::read_case(case_file, opt.values("set"));
    const std::filesystem::path baseline_file = dir / (parameters.name + ".json");
    if (!opt.flag("update") && !std::filesystem::exists(baseline_file)) {
      // SOFA's regression passed silently when a reference went missing; this one fails.
      rows.push_back({parameters.name, "-", "baseline file " + baseline_file.string(), "-", "-",
                      "-", "MISSING"});
      continue;
    }
    RunSettings settings;
    settings.quiet = opt.flag("quiet");
    settings.force_depth_curve = false;
    settings.time_dynamics = false;
    settings.fem_cache_directory =
        fem_cache_beside(std::filesystem::path(parameters.output.directory) / parameters.name);
    const CaseRun run = run_case(parameters, settings);
    if (opt.flag("update")) {
      if (!ranks::is_root()) continue;  // under mpirun rank 0 alone writes the baseline
      const nlohmann::json old =
          std::filesystem::exists(baseline_file) ? read_baseline(baseline_file) : nlohmann::json();
      const nlohmann::json fresh = write_baseline(run, dir);
      std::cout << "updated " << baseline_file.string() << ":\n";
      print_changes(old, fresh);
      continue;
    }
    const auto compared = compare_with_baseline(run, read_baseline(baseline_file), dir);
    rows.insert(rows.end(), compared.begin(), compared.end());
  }
  if (opt.flag("update")) return 0;

  std::cout << regression_table(rows);
  const auto failed =
      std::count_if(rows.begin(), rows.end(), [](const auto& r) { return r.failed(); });
  const auto improved =
      std::count_if(rows.begin(), rows.end(), [](const auto& r) { return r.status == "improved"; });
  std::cout << "regress: " << rows.size() << " checks, " << failed << " failed, " << improved
            << " improved\n";
  return failed > 0 ? 1 : 0;
}

}  // namespace msfem::compare
