// msfem verify: the FEM reference against closed-form solutions (patch test, Lame hollow sphere,
// Timoshenko cantilever) and the locking table; exit 1 if any check fails.
#include <chrono>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>

#include "msfem/compare/commands/commands.hpp"
#include "msfem/compare/commands/options.hpp"
#include "msfem/fem_reference/verification.hpp"

namespace msfem::compare {
namespace {

nlohmann::json to_json(const fem_reference::VerificationReport& report, double seconds) {
  nlohmann::json checks = nlohmann::json::array();
  for (const auto& c : report.checks) {
    nlohmann::json levels = nlohmann::json::array();
    for (const auto& l : c.levels)
      levels.push_back({{"cell_size_m", l.cell_size},
                        {"dofs", l.dofs},
                        {"cells", l.cells},
                        {"rel_l2_error", l.rel_l2_error},
                        {"iterations", l.iterations},
                        {"solve_time_s", l.solve_time_s}});
    nlohmann::json contact = nlohmann::json::array();
    for (const auto& r : c.contact)
      contact.push_back({{"depth_ratio", r.depth_ratio},
                         {"force_n", r.force},
                         {"hertz_force_n", r.hertz_force},
                         {"sneddon_force_n", r.sneddon_force},
                         {"contact_radius_m", r.contact_radius},
                         {"sneddon_contact_radius_m", r.sneddon_contact_radius},
                         {"active_nodes", r.active_nodes},
                         {"active_set_iterations", r.iterations},
                         {"max_penetration_m", r.max_penetration}});
    checks.push_back({{"name", c.name},
                      {"rel_l2_error", c.rel_l2_error},
                      {"observed_order",
                       c.observed_order ? nlohmann::json(*c.observed_order) : nlohmann::json()},
                      {"required_order",
                       c.required_order ? nlohmann::json(*c.required_order) : nlohmann::json()},
                      {"tolerance", c.tolerance},
                      {"passed", c.passed},
                      {"note", c.note},
                      {"levels", levels},
                      {"contact", contact}});
  }
  nlohmann::json locking = nlohmann::json::array();
  for (const auto& row : report.locking)
    locking.push_back({{"poisson_ratio", row.poisson_ratio},
                       {"p1_rel_l2_error", row.p1_rel_l2_error},
                       {"p2_rel_l2_error", row.p2_rel_l2_error}});
  return {{"checks", checks},
          {"locking", locking},
          {"passed", report.all_passed()},
          {"wall_time_s", seconds}};
}

void print_table(const fem_reference::VerificationReport& report, double seconds) {
  std::printf("%-16s %12s %8s %10s %8s %9s %7s  %s\n", "check", "rel_error", "order", "tolerance",
              "min_ord", "dofs", "result", "note");
  for (const auto& c : report.checks) {
    std::printf("%-16s %12.3e ", c.name.c_str(), c.rel_l2_error);
    if (c.observed_order)
      std::printf("%8.2f ", *c.observed_order);
    else
      std::printf("%8s ", "-");
    std::printf("%10.1e ", c.tolerance);
    if (c.required_order)
      std::printf("%8.1f ", *c.required_order);
    else
      std::printf("%8s ", "-");
    std::printf("%9zu %7s  %s\n", c.levels.empty() ? std::size_t(0) : c.levels.back().dofs,
                c.passed ? "pass" : "FAIL", c.note.c_str());
  }
  if (!report.locking.empty()) {
    std::printf("\nvolumetric locking (Lame sphere, one mesh): relative L2 displacement error\n");
    std::printf("%8s %12s %12s\n", "nu", "P1", "P2");
    for (const auto& row : report.locking)
      std::printf("%8.3f %12.3e %12.3e\n", row.poisson_ratio, row.p1_rel_l2_error,
                  row.p2_rel_l2_error);
  }
  std::printf("\n%s in %.1f s\n", report.all_passed() ? "all checks passed" : "SOME CHECKS FAILED",
              seconds);
}

}  // namespace

int verify_command(const Arguments& args) {
  const Options options(args, {"json", "no-locking"}, {});
  if (!options.positional().empty())
    throw std::invalid_argument("verify takes no positional argument, got '" +
                                options.positional().front() + "'");
  fem_reference::VerificationSettings settings;
  settings.locking_table = !options.flag("no-locking");
  const auto start = std::chrono::steady_clock::now();
  const fem_reference::VerificationReport report = fem_reference::run_verification(settings);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (options.flag("json"))
    std::cout << to_json(report, seconds).dump(2) << '\n';
  else
    print_table(report, seconds);
  return report.all_passed() ? 0 : 1;
}

}  // namespace msfem::compare
