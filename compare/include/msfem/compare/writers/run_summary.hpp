#pragma once
// summary.json and the variant table of report.md and the terminal, with the provenance (git
// revision, machine) every result file carries.

#include <nlohmann/json.hpp>
#include <string>

#include "msfem/compare/pipeline/case_run.hpp"

namespace msfem::compare {

/// The run's summary (DESIGN's metric names): case, git revision, machine, units, fem, variants.
nlohmann::json summary_json(const CaseRun& run);

/// The variant table as printed on the terminal and in report.md.
std::string variant_table(const CaseRun& run);

/// `git describe --always --dirty` of the source tree msfem was built from, or "unknown".
std::string git_revision();

/// Host name, CPU model and core count.
std::string machine_description();

}  // namespace msfem::compare
