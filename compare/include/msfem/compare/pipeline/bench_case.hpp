#pragma once
// A shipped case's variant as a case of `msfem bench massspring`: the model msfem sweep builds and
// the steps it times each integrator at, so that the two commands time one configuration.

#include <string>
#include <vector>

#include "msfem/cases/case_parameters.hpp"
#include "msfem/massspring_bench/benchmark_cases.hpp"

namespace msfem::compare {

/// `variant` of the case file `case_file` (under the shipped cases' folder, with `settings` as
/// --set gives them) at the case's resolution: its FEM mesh (tet_edges), supports, group scales and
/// tool at depth (a bonded patch, or the frictionless contact field), as msfem sweep builds it,
/// with msfem sweep's step for each explicit integrator (timed_dt: half the bisected stable step).
massspring::BenchmarkCase sweep_bench_case(const std::string& name, const std::string& case_file,
                                           cases::Variant variant,
                                           const std::vector<std::string>& settings);

}  // namespace msfem::compare
