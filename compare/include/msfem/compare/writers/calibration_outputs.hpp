#pragma once
// What `msfem calibrate` writes and prints of a case's calibration.

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "msfem/compare/calibration/calibration_case.hpp"

namespace msfem::compare {

/// `before` and `after` (each with `train` and `test` lists of the three errors), `coefficients`,
/// and the rest of what the report shows.
nlohmann::json calibration_json(const CaseCalibration& c);

/// Writes calibration.json, report.md, convergence.png (or .svg) and calibrated.prm into `dir`, and
/// for a network calibrated_NAME.vtu (or the Xsp file's extension).
void write_calibration_outputs(const CaseCalibration& c, const std::filesystem::path& dir);

/// The before/after table printed by the command.
std::string calibration_table(const CaseCalibration& c);

}  // namespace msfem::compare
