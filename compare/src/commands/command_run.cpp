// msfem run CASE.prm: both models on one problem, and a report a user can read, plot and open.
#include <chrono>
#include <cstdio>
#include <ctime>
#include <iostream>
#include <sstream>

#include "msfem/cases/case_parameters.hpp"
#include "msfem/cases/errors.hpp"
#include "msfem/compare/commands/commands.hpp"
#include "msfem/compare/commands/options.hpp"
#include "msfem/compare/pipeline/atomic_file.hpp"
#include "msfem/compare/pipeline/case_run.hpp"
#include "msfem/compare/pipeline/ranks.hpp"
#include "msfem/compare/writers/run_outputs.hpp"
#include "msfem/compare/writers/run_summary.hpp"

namespace msfem::compare {
int run_command(const Arguments& args) {
  const Options opt(args, {"quiet", "json", "no-curve", "no-timing", "no-cache"}, {"out", "set"});
  if (opt.positional().size() != 1)
    throw std::invalid_argument(
        "usage: msfem run CASE.prm [--out DIR] [--set SECTION/KEY=VALUE]...");
  const cases::CaseParameters parameters = cases::read_case(opt.positional()[0], opt.values("set"));

  const std::filesystem::path final_dir = opt.value("out")
                                              ? std::filesystem::path(*opt.value("out"))
                                              : std::filesystem::path(parameters.output.directory) /
                                                    (parameters.name + "-" + run_timestamp());
  const std::optional<std::filesystem::path> cache =
      opt.flag("no-cache") ? std::nullopt
                           : std::optional<std::filesystem::path>(fem_cache_beside(final_dir));
  std::ostringstream printed;  // shown once the folder is in place
  std::vector<std::pair<std::string, std::string>> failed;
  std::vector<std::string> buckled;  // "variant: warning", repeated on stderr
  // Under mpirun every rank runs the case and rank 0 alone writes; a folder it would refuse is
  // refused on every rank before any work.
  const bool writes = ranks::is_root();
  ranks::agree([&] {
    if (writes) check_output_folder(final_dir);
  });
  const auto run_and_write = [&](const std::filesystem::path* work_dir) {
    RunSettings settings;
    settings.quiet = opt.flag("quiet");
    settings.force_depth_curve = !opt.flag("no-curve");
    settings.time_dynamics = !opt.flag("no-timing");
    settings.fem_cache_directory = cache;
    const CaseRun run = run_case(parameters, settings);
    failed = run.failed_variants;
    if (!work_dir) return;
    for (const auto& v : run.variants)
      for (const Warning& w : v.warnings)
        if (w.under_tool()) buckled.push_back(v.name + ": " + w.written());
    write_run_outputs(run, *work_dir);
    if (opt.flag("json")) {
      printed << summary_json(run).dump(2) << '\n';
    } else {
      printed << "case " << parameters.name << ": " << run.problem.surface.num_vertices()
              << " surface vertices, FEM " << run.loads.front().fem.statistics.dofs << " dofs ("
              << run.loads.front().fem.statistics.cells << " cells), run took " << run.wall_time_s
              << " s\n"
              << variant_table(run) << "results in " << final_dir.string() << "\n";
    }
  };
  if (writes)
    fill_directory_atomically(final_dir,
                              [&](const std::filesystem::path& work) { run_and_write(&work); });
  else
    run_and_write(nullptr);
  std::cout << printed.str();
  for (const auto& warning : buckled)
    std::cerr << "msfem run: warning: " << warning << "\n";
  for (const auto& [name, why] : failed)
    std::cerr << "msfem run: variant " << name << " failed: " << why << "\n";
  return failed.empty() ? 0 : 1;  // the others' results are written; scripts still see it
}

int params_command(const Arguments& args) {
  const Options opt(args, {}, {});
  if (!opt.positional().empty()) throw std::invalid_argument("usage: msfem params");
  std::cout << "# The msfem case file language (deal.II ParameterHandler syntax). Lengths in m,\n"
               "# forces in N, stresses in Pa, densities in kg/m^3, times in s.\n"
            << cases::describe_case_parameters();
  return 0;
}

}  // namespace msfem::compare
