#pragma once
// What `msfem run` writes: summary.json, report.md (+ plots), the surfaces and FEM for ParaView,
// and fields.h5 — all into a fresh run folder that appears only when complete.

#include <filesystem>

#include "msfem/compare/pipeline/case_run.hpp"

namespace msfem::compare {

/// Writes every output of the run into `directory` (which must exist and be empty). The FEM's own
/// VTU is written by run_case when asked.
void write_run_outputs(const CaseRun& run, const std::filesystem::path& directory);

}  // namespace msfem::compare
