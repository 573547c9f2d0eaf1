#pragma once
// The FEM reference at every load of a command, through one cache: `msfem run` (each tool position
// of the case), `msfem sweep` (through run) and `msfem calibrate` (each training and held-out load)
// all get their references here. One mesh serves every load; each load's entry is cached on its
// own, keyed by everything the FEM depends on, so a command reuses what another one solved.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "msfem/compare/pipeline/fem_error_estimate.hpp"
#include "msfem/compare/pipeline/fem_run.hpp"
#include "msfem/compare/pipeline/progress.hpp"

namespace msfem::compare {

struct ForceDepthPoint {
  double depth_m = 0.0;
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
  std::optional<int> inverted_elements;  ///< a volumetric variant's inverted tetrahedra there
  std::optional<fem_reference::ContactReport> contact;  ///< the FEM's frictionless tool there
};

/// The FEM at one load: the tool at one placement (none: the case's gravity or patch force alone).
struct LoadReference {
  std::optional<ToolPlacement> tool;
  FemSolution fem;
  std::vector<ForceDepthPoint> force_depth;  ///< the FEM pressed to each requested curve depth
  std::vector<int> compared_vertices;        ///< surface vertices no support or tool prescribes
  LoadErrorEstimate fem_error;               ///< the reference's own error here (if estimated)
  std::string cache_key;
  bool from_cache = false;
};

/// What a command asks of the reference.
struct ReferenceRequest {
  std::vector<std::optional<ToolPlacement>> loads;  ///< each load's tool
  std::vector<ToolPlacement> refine_near;           ///< where the one mesh is refined
  /// The force-depth curve's depths, for the first load only (none: no curve).
  std::vector<double> curve_depths;
  /// Solves of the reference a full run of the command makes (the loads and the curve): the error
  /// estimate's method is chosen for that, whatever the cache already holds, so that it is the
  /// same for every run of the case.
  int planned_solves = 1;
  std::optional<std::filesystem::path> cache_directory;  ///< none: always solve
};

struct FemReferences {
  fem_reference::VolumeMesh mesh;
  std::vector<LoadReference> loads;  ///< in the request's order
  /// How the reference's own error was estimated (its per-load values are in `loads`).
  FemErrorEstimate estimate;
  /// The mesh's worst tetrahedron (fem_reference::cell_quality): CG's iterations follow it.
  std::optional<double> worst_cell_quality;
  int solved = 0, from_cache = 0;
};

/// The reference at every load of `request`, solved or read from the cache. Throws
/// cases::InputError for a problem the FEM cannot solve (rigid motion, an error-estimate method
/// that cannot run), before the first solve.
FemReferences fem_references(const Problem& problem, const ReferenceRequest& request,
                             const Progress& progress);

/// The surface vertices that neither a support nor `tool` prescribes: the ones compared.
std::vector<int> unprescribed_vertices(const Problem& problem,
                                       const std::optional<ToolPlacement>& tool);

}  // namespace msfem::compare
