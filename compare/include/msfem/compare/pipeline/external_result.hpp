#pragma once
// An outside simulator's answer as a variant (mass spring/results, docs/external.md): its deformed
// surface at each load of the case (as msfem export-load described the loads), with the tool force
// when it measured one, compared with the FEM like any of msfem's own variants.

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "msfem/compare/pipeline/case_run.hpp"

namespace msfem::compare {

namespace external {
/// loads.json (msfem export-load) and FILE.force.json: their `schema` and `version`.
inline constexpr const char* loads_schema = "msfem-loads";
inline constexpr int loads_version = 1;
inline constexpr const char* force_schema = "msfem-force";
inline constexpr int force_version = 1;
}  // namespace external

/// One result file read against the case's surface.
struct ExternalAnswer {
  Eigen::MatrixX3d surface_displacement;      ///< rows in the case's surface vertex order, m
  std::optional<Eigen::Vector3d> tool_force;  ///< N, the force the tissue exerts on the tool
  std::vector<ForceDepthPoint> curve;         ///< FILE's curve.csv beside it, when there is one
};

/// Reads `file`: a .vtu of the deformed surface (point data `displacement`, or its deformed
/// points), or an .obj of deformed positions, in surface.vtu's vertex order; the force as field
/// data `tool_force` or in STEM.force.json beside it, the curve in STEM.curve.csv. Throws
/// cases::InputError naming `where`, the file and the vertex or item at fault: a vertex count,
/// order or unit that is not the case's, a value that is not finite, a force without 3 components,
/// a JSON of another schema or version.
ExternalAnswer read_external_answer(const std::filesystem::path& file, const Problem& problem,
                                    const std::string& where);

/// Reads every result file of the case against its surface and load count, so that a bad one is
/// refused before the FEM is solved.
void check_results_fit(const Problem& problem);

/// The case's results (mass spring/results) measured against the run's FEM at each load, in the
/// case's order: every metric and zone a variant gets, timing "external".
std::vector<VariantResult> external_variants(const CaseRun& run);

}  // namespace msfem::compare
