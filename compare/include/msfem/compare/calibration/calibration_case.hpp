#pragma once
// `msfem calibrate` on a case: the FEM once per load (cached like `msfem run`'s), the fit, the
// damping and mass checks, the held-out comparison with the case's other variants, and the
// outputs (calibration.json, report.md, convergence plot, calibrated.prm).

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "msfem/compare/calibration/calibration.hpp"
#include "msfem/fem_reference/volume_mesh.hpp"

namespace msfem::compare {

/// What the command line asks for; anything left unset comes from the case's calibration section.
struct CalibrationRequest {
  std::optional<std::string> variant;  ///< a built-in variant's name or a network's NAME
  std::optional<std::vector<std::string>> groups;
  std::optional<std::vector<cases::ToolLoad>> train, test;
  bool quiet = false;
  bool compare_variants = true;  ///< also evaluate the case's other variants on the held-out loads
  std::vector<std::string> overrides;  ///< the run's --set, repeated in calibrated.prm
  std::optional<std::filesystem::path> fem_cache_directory;
};

/// A variant's mean held-out errors (the calibrated one after its fit, the others as the case has
/// them).
struct VariantOnTest {
  std::string name;
  bool calibrated = false;
  double mean_rel_l2_error = 0.0;
  double mean_reaction_force_rel_error = 0.0;
};

/// A fitted network as its simulator loads it: the user's file with the fitted groups' stiffness
/// (and, where the file carries dampers, the damping of the fitted ratio) put in.
struct NetworkHandBack {
  std::filesystem::path original;
  std::string file_name;  ///< calibrated_NAME and the original's extension
  Eigen::VectorXd stiffness;
  std::optional<Eigen::VectorXd> damping;
};

struct CaseCalibration {
  Problem problem;
  fem_reference::VolumeMesh mesh;
  VariantSpec variant;
  std::optional<NetworkHandBack> hand_back;  ///< set when the variant is a user's network
  CalibrationOptions options;
  double target_damping_ratio = 0.0;
  std::vector<CalibrationLoad> train, test;
  CalibrationFit fit;
  massspring::DampingFit damping;
  CalibrationErrors
      nonlinear_check;  ///< the calibrated case re-solved (Newton) on the first training load
  double lumped_mass_kg = 0.0, fem_mass_kg = 0.0;
  std::vector<VariantOnTest> variants;  ///< sorted, best (lowest held-out rel_l2_error) first
  int fem_solves = 0, fem_from_cache = 0;
  double fem_time_s = 0.0, total_time_s = 0.0;
  /// --set assignments that turn the case into the calibrated one (written into calibrated.prm).
  std::vector<std::string> calibrated_overrides;
  std::vector<std::string> notes;  ///< what the report should say besides the tables
};

/// Checks the request (variant of the case, non-empty and disjoint train and test sets, known
/// groups), solves or loads the FEM of every load, and fits. Throws cases::InputError naming the
/// case file or the option at fault.
CaseCalibration calibrate_case(const cases::CaseParameters& parameters,
                               const CalibrationRequest& request);

}  // namespace msfem::compare
