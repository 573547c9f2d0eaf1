// msfem: mass-spring models of soft tissue measured against a linear-elastic FEM reference.
#include <cstdio>
#include <exception>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "msfem/cases/errors.hpp"
#include "msfem/compare/commands.hpp"

namespace {

struct CommandEntry {
  const char* name;
  int (*run)(const msfem::compare::Arguments&);
  const char* usage;
};

const std::vector<CommandEntry>& commands() {
  using namespace msfem::compare;
  static const std::vector<CommandEntry> table = {
      {"run", run_command,
       "run CASE.prm [--out DIR] [--set SECTION/KEY=VALUE]... [--quiet] [--json] [--no-curve]\n"
       "      the FEM and every mass-spring variant on the case; summary.json, report.md, VTU, "
       "HDF5"},
      {"sweep", sweep_command,
       "sweep CASE.prm [--resolutions 2,3,4] [--integrators a,b] [--out DIR] [--set K=V]...\n"
       "      variants x resolutions x integrators: sweep.json, table and Pareto plot"},
      {"regress", regress_command,
       "regress [--baselines DIR] [CASE.prm...] [--update] [--set K=V]...\n"
       "      compare runs with committed baselines; exit 1 on a worse metric or field, a missing\n"
       "      or stale baseline, or a non-finite value"},
      {"calibrate", calibrate_command,
       "calibrate CASE.prm [--variant NAME] [--fit GROUP[,GROUP...]] [--train LOADS] [--test "
       "LOADS]\n"
       "          [--out DIR] [--set K=V]... [--max-evaluations N] [--strict] [--json] "
       "[--no-compare]\n"
       "      fit spring-group stiffness to the FEM on training loads (DX,DY,DZ@DEPTH;...), check\n"
       "      on held-out loads; calibration.json, report.md, calibrated.prm"},
      {"params", params_command, "params\n      print the whole case-file language"},
      {"mesh-info", mesh_info_command,
       "mesh-info FILE [--unit m|cm|mm] [--json] [--no-self-intersections]\n"
       "            mesh-info --generate icosphere:LEVEL[:RADIUS_M] | ellipsoid:LEVEL:A:B:C\n"
       "      counts, volume, bounding box, genus and every defect; exit 1 on a defect"},
      {"simplify", simplify_command,
       "simplify IN OUT --vertices N [--unit m|cm|mm] [--smooth ITERATIONS]\n"
       "      edge-collapse to exactly N vertices (then Taubin smoothing), written in IN's unit"},
      {"bench", bench_command,
       "bench massspring [--json]\n      stepping speed of the mass-spring models"},
      {"verify", verify_command,
       "verify [--json]\n      the FEM reference against closed-form solutions"},
  };
  return table;
}

void print_usage(std::FILE* out) {
  std::fprintf(out, "usage: msfem COMMAND [ARGS]\n\ncommands:\n");
  for (const auto& c : commands())
    std::fprintf(out, "  %s\n", c.usage);
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
    print_usage(args.empty() ? stderr : stdout);
    return args.empty() ? 2 : 0;
  }
  const std::string name = args[0];
  args.erase(args.begin());
  for (const auto& c : commands()) {
    if (name != c.name) continue;
    try {
      return c.run(args);
    } catch (const msfem::cases::InputError& e) {
      std::cerr << "msfem " << name << ": error: " << e.what() << '\n';
      return 2;
    } catch (const std::invalid_argument& e) {
      std::cerr << "msfem " << name << ": error: " << e.what() << '\n';
      return 2;
    } catch (const std::exception& e) {
      std::cerr << "msfem " << name << ": failed: " << e.what() << '\n';
      return 1;
    }
  }
  std::cerr << "msfem: unknown command '" << name << "'\n";
  print_usage(stderr);
  return 2;
}
