#pragma once
// msfem sweep's outputs: sweep.json, report.md (the answer, the error against resolution, every
// configuration) and the Pareto and convergence plots.

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "msfem/cases/case_parameters.hpp"
#include "msfem/compare/pipeline/sweep.hpp"

namespace msfem::compare {

nlohmann::json sweep_json(const cases::CaseParameters& parameters, const SweepResult& result);
std::string sweep_table(const std::vector<SweepPoint>& points);

/// The sweep's answer, markdown: for a 60 Hz visual loop and a 1 kHz haptic loop in real time,
/// the least-error configuration that keeps it (rel L2, then force error); with `max_error`, the
/// cheapest configuration (largest real-time factor) within that rel L2.
std::string sweep_answer(const std::vector<SweepPoint>& points, std::optional<double> max_error);

/// The convergence as a markdown section, saying which variants do not converge.
std::string convergence_section(const std::vector<VariantConvergence>& convergence);

/// Writes sweep.json, report.md and the plots (when gnuplot is installed) into `directory`;
/// returns what the command prints: the JSON with `json`, else the table and the answer.
std::string write_sweep_outputs(const std::filesystem::path& directory,
                                const cases::CaseParameters& parameters, const SweepResult& result,
                                std::optional<double> max_error, bool json);

}  // namespace msfem::compare
