#pragma once
// What `msfem run` writes: summary.json, report.md (+ plots), the surfaces and FEM for ParaView,
// and fields.h5 — all into a fresh run folder that appears only when complete.

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "msfem/compare/case_run.hpp"

namespace msfem::compare {

/// The run's summary (DESIGN's metric names): case, git revision, machine, units, fem, variants.
nlohmann::json summary_json(const CaseRun& run);

/// The variant table as printed on the terminal and in report.md.
std::string variant_table(const CaseRun& run);

/// `git describe --always --dirty` of the source tree msfem was built from, or "unknown".
std::string git_revision();

/// Host name, CPU model and core count.
std::string machine_description();

/// Writes every output of the run into `directory` (which must exist and be empty). The FEM's own
/// VTU is written by run_case when asked.
void write_run_outputs(const CaseRun& run, const std::filesystem::path& directory);

}  // namespace msfem::compare
