// msfem: mass-spring models of soft tissue measured against a linear-elastic FEM reference.
#include <cstdio>
#include <exception>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "msfem/cases/errors.hpp"
#include "msfem/compare/commands/commands.hpp"
#include "msfem/compare/pipeline/ranks.hpp"

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
       "          [--no-timing] [--no-cache]\n"
       "      the FEM and every mass-spring variant on the case; summary.json, report.md, VTU, "
       "HDF5\n"
       "      (--no-curve: no force-depth curve; --no-timing: no dynamics timed; --no-cache: "
       "solve\n"
       "      the FEM even if <output directory>/.fem-cache holds it)"},
      {"sweep", sweep_command,
       "sweep CASE.prm [--resolutions 2,3,4] [--integrators a,b] [--out DIR] [--set K=V]...\n"
       "          [--max-error E] [--volume-preservation off|on|both] [--quiet] [--json]\n"
       "          [--contact-refinement off|on|both] [--contact-edge-lengths E1,E2]\n"
       "          [--precision double|float|both]\n"
       "      variants x resolutions x integrators (x volume preservation x contact refinement\n"
       "      and its edge lengths, m, x the fast steppers' arithmetic): sweep.json, report.md\n"
       "      opening with the least-error configuration for a 60 Hz and a 1 kHz loop in real\n"
       "      time (and the cheapest within rel L2 E), table and Pareto plot"},
      {"regress", regress_command,
       "regress [--baselines DIR] [CASE.prm...] [--update] [--set K=V]... [--quiet]\n"
       "      compare runs with committed baselines; exit 1 on a worse metric or field, a missing\n"
       "      or stale baseline, or a non-finite value"},
      {"calibrate", calibrate_command,
       "calibrate CASE.prm [--variant NAME] [--fit GROUP[,GROUP...]] [--train LOADS] [--test "
       "LOADS]\n"
       "          [--out DIR] [--set K=V]... [--max-evaluations N] [--strict] [--json] "
       "[--no-compare]\n"
       "          [--no-cache] [--quiet]\n"
       "      fit spring-group stiffness to the FEM on training loads (DX,DY,DZ@DEPTH;...), check\n"
       "      on held-out loads; calibration.json, report.md, calibrated.prm"},
      {"haptic", haptic_command,
       "haptic CASE.prm [--path FILE] [--rate HZ] [--seconds S] [--set-at T:SECTION/KEY=VALUE]...\n"
       "          [--out DIR] [--set K=V]... [--json] [--no-cache] [--quiet]\n"
       "      replay a tool path (CSV t_s,x_m,y_m,z_m; default: press at the case's tool, slide\n"
       "      10 mm, release) against each variant, the force rendered at HZ (1000) on a thread\n"
       "      of its own; rate, deadline misses, tick times, the model's own rate and the force\n"
       "      error against the FEM along the path: haptic.json, report.md, traces"},
      {"export-load", export_load_command,
       "export-load CASE.prm OUTDIR [--set K=V]...\n"
       "      what an outside simulator needs to reproduce each load: surface.vtu (the case's\n"
       "      surface, vertex_id, fixed) and loads.json (tools along their paths, gravity, patch\n"
       "      forces, material); its answers come back as mass spring/results = NAME=FILE,..."},
      {"export-network", export_network_command,
       "export-network CASE.prm OUTDIR [--set K=V]...\n"
       "      every variant of the case as a network file a simulator loads: NAME.vtu (springs,\n"
       "      groups, masses, fixed nodes, anchors, volume elements) and, where Xsp holds the\n"
       "      whole model, NAME.xs3; each runs again as mass spring/networks = NAME=FILE"},
      {"params", params_command, "params\n      print the whole case-file language"},
      {"mesh-info", mesh_info_command,
       "mesh-info FILE [--unit m|cm|mm] [--json] [--no-self-intersections]\n"
       "            mesh-info --generate icosphere:LEVEL[:RADIUS_M] | ellipsoid:LEVEL:A:B:C\n"
       "      counts, volume, bounding box, genus and every defect; exit 1 on a defect"},
      {"simplify", simplify_command,
       "simplify IN OUT --vertices N [--unit m|cm|mm] [--smooth ITERATIONS] [--binary]\n"
       "      edge-collapse to exactly N vertices (then Taubin smoothing), written in IN's unit"},
      {"repair", repair_command,
       "repair IN OUT [--unit m|cm|mm] [--all-components] [--wrap] [--alpha A] [--offset D]\n"
       "          [--binary]\n"
       "      a broken mesh as a closed, manifold, outward surface that mesh-info accepts: merge,\n"
       "      drop degenerate and duplicate triangles, orient, stitch, keep the largest piece\n"
       "      (--all-components: every piece), and CGAL's alpha wrap where that is not enough\n"
       "      (--wrap: always; alpha defaults to the mean edge length within [diagonal/200,\n"
       "      diagonal/20], offset to alpha/30). Lengths and OUT are in IN's unit"},
      {"surface-from-image", surface_from_image_command,
       "surface-from-image IMAGE OUT (--label N | --threshold LO[:HI]) [--vertices N]\n"
       "          [--smooth K] [--unit m|cm|mm]\n"
       "      an organ of a NIfTI image (.nii, .nii.gz) as a closed surface in world coordinates:\n"
       "      largest component, cavities filled, CGAL Mesh_3 extraction, then simplification"},
      {"bench", bench_command,
       "bench massspring [--json] [--mesh-dir DIR] [--threads N] [--samples N] [--seconds S]\n"
       "          [--float] [--no-10x] [--cases NAME,...]\n"
       "      stepping speed of the mass-spring models (--cases: only those, by name)"},
      {"verify", verify_command,
       "verify [--json] [--no-locking]\n      the FEM reference against closed-form solutions"},
  };
  return table;
}

void print_usage(std::FILE* out) {
  std::fprintf(out, "usage: msfem COMMAND [ARGS]\n\ncommands:\n");
  for (const auto& c : commands())
    std::fprintf(out, "  %s\n", c.usage);
}

bool wants_help(const std::vector<std::string>& args) {
  for (const auto& a : args)
    if (a == "--help" || a == "-h") return true;
  return false;
}

// A result a script cannot read is not a success: a full disk or a closed pipe on standard output
// turns exit 0 into 1.
int finish(const std::string& name, int code) {
  std::cout.flush();
  if (!std::cout || std::fflush(stdout) != 0 || std::ferror(stdout)) {
    std::cerr << "msfem " << name << ": failed: cannot write to standard output\n";
    return code == 0 ? 1 : code;
  }
  return code;
}

// The command named by args[0]; a failure's line, printed, is kept in `failure`.
int dispatch(std::vector<std::string> args, std::string& failure) {
  if (args.empty() || args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
    print_usage(args.empty() ? stderr : stdout);
    return args.empty() ? 2 : 0;
  }
  const std::string name = args[0];
  args.erase(args.begin());
  for (const auto& c : commands()) {
    if (name != c.name) continue;
    if (wants_help(args)) {
      std::printf("usage: msfem %s\n", c.usage);
      return finish(name, 0);
    }
    int code = 1;
    try {
      return finish(name, c.run(args));
    } catch (const msfem::cases::InputError& e) {
      failure = "msfem " + name + ": error: " + e.what(), code = 2;
    } catch (const std::invalid_argument& e) {
      failure = "msfem " + name + ": error: " + e.what(), code = 2;
    } catch (const std::exception& e) {
      failure = "msfem " + name + ": failed: " + e.what();
    }
    std::cerr << failure << '\n';
    return code;
  }
  failure = "msfem: unknown command '" + name + "'";
  std::cerr << failure << '\n';
  print_usage(stderr);
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  msfem::compare::ranks::start_if_launched();
  std::string failure;
  const int code = dispatch(std::vector<std::string>(argv + 1, argv + argc), failure);
  return msfem::compare::ranks::finish(code, failure);
}
