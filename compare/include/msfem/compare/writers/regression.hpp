#pragma once
// `msfem regress`: a change to a model or solver must not make the deformation silently worse.
// Baselines are versioned JSON files (results/baselines/<case>.json) holding each variant's metrics
// and surface displacement field with their tolerances; the tolerances live in the baseline, not in
// code.

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "msfem/compare/pipeline/case_run.hpp"

namespace msfem::compare {

/// The metrics compared, each "worse" when it grows (volume_change: when its magnitude grows).
const std::vector<Metric>& regression_metrics();

/// Writes a run's baseline into `directory`: `<case>.json` (header: format version, case and mesh
/// hashes, units, degree, git revision, date; per variant the metrics and the field's tolerances)
/// and
/// `<case>.fields.h5` (the run's fields.h5 layout: surface, FEM volume field, per-variant surface
/// displacement and error). Returns the JSON written.
nlohmann::json write_baseline(const CaseRun& run, const std::filesystem::path& directory);

/// 16 hex digits of the FNV-1a hash of a file's bytes / of the surface arrays.
std::string file_hash(const std::filesystem::path& file);
std::string surface_hash(const cases::Surface& surface);

struct RegressionRow {
  std::string case_name, variant, metric;
  std::string baseline, now, tolerance;
  std::string status;  ///< ok, improved, WORSE, MISSING, STALE, NON-FINITE
  bool failed() const { return status != "ok" && status != "improved"; }
};

/// Compares a run with its baseline; rows for every metric and the field of every variant, plus
/// rows for what is missing on either side or stale. `directory` holds the baseline's fields file.
std::vector<RegressionRow> compare_with_baseline(const CaseRun& run, const nlohmann::json& baseline,
                                                 const std::filesystem::path& directory);

std::string regression_table(const std::vector<RegressionRow>& rows);

}  // namespace msfem::compare
