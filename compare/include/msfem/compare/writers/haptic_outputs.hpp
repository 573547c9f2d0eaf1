#pragma once
// msfem haptic's files: haptic.json (schema msfem-haptic), report.md and force_time.png, path.csv
// (the path replayed, in the format --path reads) and trace_<variant>.csv (every tick).

#include <filesystem>
#include <nlohmann/json.hpp>

#include "msfem/compare/pipeline/haptic.hpp"

namespace msfem::compare {

/// haptic.json: at the top the worst of the variants (the least sustained rate, the deadline
/// misses summed, the largest tick times), then each variant's own.
nlohmann::json haptic_json(const HapticRun& run);

void write_haptic_outputs(const HapticRun& run, const std::filesystem::path& directory);

}  // namespace msfem::compare
