#pragma once

#include <string>
#include <vector>

namespace msfem::compare {

/// Each `msfem` sub-command: takes the arguments after its name, prints its result on stdout
/// (diagnostics on stderr) and returns the process exit code. Bad input is reported by throwing
/// msfem::cases::InputError (or std::invalid_argument for a bad option), which main() prints as one
/// line and turns into exit code 2.
using Arguments = std::vector<std::string>;

int mesh_info_command(const Arguments& args);  // msfem mesh-info FILE [--unit mm]
int simplify_command(const Arguments& args);   // msfem simplify IN OUT --vertices N [--smooth K]
int surface_from_image_command(const Arguments& args);  // msfem surface-from-image IMAGE OUT
int repair_command(const Arguments& args);   // msfem repair IN OUT [--all-components] [--wrap]
int run_command(const Arguments& args);      // msfem run CASE.prm [--out DIR] [--set K=V]...
int params_command(const Arguments& args);   // msfem params
int sweep_command(const Arguments& args);    // msfem sweep CASE.prm [--resolutions ...]
int bench_command(const Arguments& args);    // msfem bench massspring|fem [--json]
int verify_command(const Arguments& args);   // msfem verify [--json]
int regress_command(const Arguments& args);  // msfem regress [--baselines DIR] [CASE...] [--update]
int export_network_command(const Arguments& args);  // msfem export-network CASE.prm OUTDIR
int export_load_command(const Arguments& args);     // msfem export-load CASE.prm OUTDIR
int haptic_command(const Arguments& args);  // msfem haptic CASE.prm [--path F] [--rate HZ]
int calibrate_command(const Arguments& args);  // msfem calibrate CASE.prm [--variant V] [--fit G]

}  // namespace msfem::compare
