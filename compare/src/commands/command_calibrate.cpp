// msfem calibrate CASE.prm: fit a variant's spring groups to the FEM on training loads, check on
// held-out ones, and write calibrated.prm.
#include <ctime>
#include <iostream>
#include <sstream>

#include "msfem/cases/case_parameters.hpp"
#include "msfem/cases/errors.hpp"
#include "msfem/cases/setting_names.hpp"
#include "msfem/compare/calibration/calibration_case.hpp"
#include "msfem/compare/commands/commands.hpp"
#include "msfem/compare/commands/options.hpp"
#include "msfem/compare/pipeline/atomic_file.hpp"
#include "msfem/compare/pipeline/ranks.hpp"
#include "msfem/compare/writers/calibration_outputs.hpp"

namespace msfem::compare {
namespace {

std::vector<std::string> split_groups(const std::string& text) {
  std::vector<std::string> groups;
  std::stringstream in(text);
  for (std::string g; std::getline(in, g, ',');) {
    g.erase(0, g.find_first_not_of(" \t"));
    g.erase(g.find_last_not_of(" \t") + 1);
    if (g.empty()) throw std::invalid_argument("option --fit: empty group name in '" + text + "'");
    groups.push_back(g);
  }
  if (groups.empty()) throw std::invalid_argument("option --fit: no group given");
  return groups;
}

}  // namespace

int calibrate_command(const Arguments& args) {
  const Options opt(args, {"quiet", "json", "strict", "no-cache", "no-compare"},
                    {"variant", "fit", "train", "test", "out", "set", "max-evaluations"});
  if (opt.positional().size() != 1)
    throw std::invalid_argument(
        "usage: msfem calibrate CASE.prm [--variant NAME] [--fit GROUP[,GROUP...]] "
        "[--train LOADS] [--test LOADS] [--out DIR] [--strict] [--json]");
  std::vector<std::string> overrides = opt.values("set");
  if (opt.value("max-evaluations"))
    overrides.push_back("calibration/max evaluations=" +
                        std::to_string(opt.integer("max-evaluations", 0)));
  const cases::CaseParameters parameters = cases::read_case(opt.positional()[0], overrides);

  CalibrationRequest request;
  if (const auto variant = opt.value("variant")) request.variant = *variant;
  if (opt.value("fit")) request.groups = split_groups(*opt.value("fit"));
  if (opt.value("train")) request.train = cases::parse_tool_loads(*opt.value("train"), "--train");
  if (opt.value("test")) request.test = cases::parse_tool_loads(*opt.value("test"), "--test");
  request.quiet = opt.flag("quiet");
  request.compare_variants = !opt.flag("no-compare");
  request.overrides = overrides;
  const std::filesystem::path final_dir =
      opt.value("out") ? std::filesystem::path(*opt.value("out"))
                       : std::filesystem::path(parameters.output.directory) /
                             (parameters.name + "-calibrate-" + run_timestamp());
  if (!opt.flag("no-cache")) request.fem_cache_directory = fem_cache_beside(final_dir);
  std::ostringstream printed;
  bool converged = true;
  // Under mpirun every rank calibrates: the FEM solves on all of them, each evaluation's loads are
  // shared out (calibration/shared_loads.hpp), and rank 0 writes.
  const bool writes = ranks::is_root();
  ranks::agree([&] {
    if (writes) check_output_folder(final_dir);
  });
  if (!writes) {
    const CaseCalibration c = calibrate_case(parameters, request);
    return !c.fit.converged && opt.flag("strict") ? 1 : 0;
  }
  fill_directory_atomically(final_dir, [&](const std::filesystem::path& work_dir) {
    const CaseCalibration c = calibrate_case(parameters, request);
    converged = c.fit.converged;
    write_calibration_outputs(c, work_dir);
    if (opt.flag("json")) {
      printed << calibration_json(c).dump(2) << '\n';
    } else {
      printed << "calibrate " << parameters.name << ", variant " << c.variant.name << ":\n"
              << calibration_table(c) << "results in " << final_dir.string() << "\n";
    }
  });
  std::cout << printed.str();
  if (!converged) {
    std::cerr << "msfem calibrate: the optimiser did not converge; the best point found is kept"
              << (opt.flag("strict") ? " (exit 1: --strict)" : "") << "\n";
    if (opt.flag("strict")) return 1;
  }
  return 0;
}

}  // namespace msfem::compare
