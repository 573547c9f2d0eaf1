#pragma once
// One problem stated once: geometry, material, supports and loads as geometry, the mass-spring
// variants and the FEM reference to run on it, and what to time and write. Read from a deal.II
// ParameterHandler file (`cases/*.prm`) by read_case(); plain structs so that users of a case need
// no deal.II header.

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "msfem/cases/units.hpp"
#include "msfem/massspring/integrators.hpp"
#include "msfem/massspring/topology_builders.hpp"

namespace msfem::cases {

/// The mass-spring models msfem builds (their names: setting_names.hpp, as every enumerated
/// setting).
enum class Variant { three_tier, single_layer, tet_edges, skeleton };
/// The FEM reference's linear solver.
enum class FemSolver { cg_gamg, cg_boomeramg, mumps };
/// The spring model `msfem calibrate` solves per load.
enum class CalibrationModel {
  nonlinear,  ///< static equilibrium by Newton, as msfem run
  linear      ///< linearised at rest: one Cholesky factorisation per load and evaluation
};

struct GeometryParameters {
  /// A surface file (relative paths are relative to the case file) or a generator spec such as
  /// "icosphere:3:0.05" (see generate_surface()).
  std::string source = "icosphere:3:0.05";
  LengthUnit unit = LengthUnit::metre;  ///< unit of the file's coordinates
  int simplify_to_vertices = 0;         ///< 0 keeps the surface as read
  int smoothing_iterations = 0;         ///< Taubin iterations after simplification
};

struct MaterialParameters {
  double youngs_modulus_pa = 3000.0;
  double poisson_ratio = 0.45;
  double density_kg_per_m3 = 1040.0;
  /// A CT in Hounsfield units (NIfTI; relative to the case file) whose voxels give E through
  /// `hu_to_youngs` (see modulus_image.hpp): both models then see that field and
  /// youngs_modulus_pa is only the scale the analytic spring rules start from. Empty: E is
  /// youngs_modulus_pa everywhere.
  std::string youngs_modulus_image;
  std::string hu_to_youngs;  ///< "HU:E; ..." (Pa), checked by parse_hu_to_youngs
};

/// The fixed region, stated as geometry; each model fixes the nodes it contains.
struct SupportParameters {
  enum class Kind { inner_core, half_space, sphere };
  Kind kind = Kind::inner_core;
  /// inner core: nodes inside the surface scaled by 1/scale about its vertex centroid.
  double inner_core_scale = 2.0;
  /// half-space: nodes x with (x - point)·outward_normal >= 0 are fixed.
  Eigen::Vector3d half_space_point = Eigen::Vector3d::Zero();
  Eigen::Vector3d half_space_normal = -Eigen::Vector3d::UnitZ();
  /// sphere: nodes within radius of center are fixed.
  Eigen::Vector3d sphere_center = Eigen::Vector3d::Zero();
  double sphere_radius_m = 0.0;
};

/// A rigid sphere pushed along the inward normal at a surface point. The point is the surface
/// vertex that lies farthest from the vertex centroid along `direction`.
struct ToolParameters {
  bool enabled = true;
  /// prescribed: the bonded patch (case value `bonded` or `prescribed`); contact: frictionless.
  enum class Mode { prescribed, contact };
  Mode mode = Mode::prescribed;
  std::vector<Eigen::Vector3d> directions = {Eigen::Vector3d::UnitZ()};
  double radius_m = 0.005;
  double depth_m = 0.005;
  /// Depths of the force-depth curve (empty: depth/4, depth/2, 3 depth/4, depth).
  std::vector<double> curve_depths_m;
  /// Largest depth increment of the spring variants' loading path (0: the curve depths only).
  double path_step_m = 0.0;
};

/// A total force spread over the surface vertices within radius of the point farthest along
/// `direction` (the pancreas paper's user drag).
struct PatchForceParameters {
  bool enabled = false;
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();
  double radius_m = 0.01;
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
};

struct LoadParameters {
  ToolParameters tool;
  Eigen::Vector3d gravity_m_per_s2 = Eigen::Vector3d::Zero();
  PatchForceParameters patch_force;
};

/// Knobs of the mass-spring variants. Stiffness starts from the analytic value (Lloyd et al. 2007
/// or van Gelder 1998) times a per-group factor; each spring gets the axial damper
/// d = 2 r sqrt(k m_a m_b / (m_a + m_b)), r = `damping_ratio`, which damps the two-body oscillator
/// of that spring and its end masses at r of critical (`msfem calibrate` chooses r for a target
/// modal damping ratio, docs/calibration.md).
struct MassSpringParameters {
  std::vector<Variant> variants = {Variant::three_tier, Variant::single_layer, Variant::tet_edges,
                                   Variant::skeleton};
  /// tet_edges' spring stiffness rule (Lloyd et al. 2007 or van Gelder 1998).
  massspring::TetStiffnessRule stiffness_model = massspring::TetStiffnessRule::lloyd;
  double damping_ratio = 0.5;  ///< spring dampers as a fraction of critical
  std::vector<std::pair<std::string, double>> group_scales;  ///< "group:factor" overrides
  /// three_tier's prisms and tet_edges' tetrahedra resist volume change (group "volume").
  bool volume_preservation = false;
  double middle_tier_scale = 1.2;
  double inner_tier_scale = 2.0;
  /// scaled about the centroid (the seed), offset along the inward normal, or along the distance
  /// field's ascent (InnerTierMethod::distance_field: never folds)
  massspring::InnerTierMethod inner_tiers = massspring::InnerTierMethod::scaling;
  bool inner_diagonals = false;        ///< tier 2 to tier 3 crossing diagonals (not the seed's)
  int skeleton_control_points = 0;     ///< 0: a tenth of the surface vertices, at least 20
  double skeleton_draw_factor = 0.45;  ///< control points drawn toward the centroid by this factor
  /// A local point distribution at the tool, after the layered brain paper's: the case's surface
  /// is refined around each tool before any model is built, so every variant (and the FEM, which
  /// keeps the refined surface's vertices) follows it. Off by default: docs/harness.md says what
  /// it does to each variant.
  struct ContactRefinement {
    bool enabled = false;
    double radius_m = 0.0;  ///< around each tool's contact point; 0: 2 × the tool radius
    double edge_m = 0.0;    ///< longest edge there; 0: the tool radius / 3
  };
  ContactRefinement contact_refinement;
  /// A user's own networks (`mass spring/networks = NAME=FILE; ...`, paths relative to the case
  /// file), each compared as a variant named NAME beside the built-in ones (docs/networks.md).
  struct Network {
    std::string name;
    std::filesystem::path file;
  };
  std::vector<Network> networks;
  /// An outside simulator's answers (`mass spring/results = NAME=FILE[,FILE...]; ...`): one
  /// deformed surface per load of the case, in load order, compared as a variant named NAME
  /// (docs/external.md).
  struct Result {
    std::string name;
    std::vector<std::filesystem::path> files;
  };
  std::vector<Result> results;
};

struct FemParameters {
  int degree = 2;
  double cell_size_m = 0.0;  ///< 0: from the surface's mean edge length
  FemSolver solver = FemSolver::cg_gamg;
  double relative_tolerance = 1e-10;
  /// Refine the FEM's surface (and volume) within 2 r of each tool, so the reference resolves the
  /// contact patch however coarse the case's surface is.
  bool refine_at_tool = true;
  double tool_cell_size_m = 0.0;  ///< edge length there; 0: the tool radius / 3
  /// How the reference's own discretisation error is estimated (docs/harness.md).
  enum class ErrorEstimate { automatic, refine, degree, lower_degree, none };
  ErrorEstimate error_estimate = ErrorEstimate::automatic;
};

struct TimingParameters {
  massspring::IntegratorKind integrator = massspring::IntegratorKind::symplectic_euler;
  double dt_s = 0.0;              ///< 0: half the estimated stable step
  int steps = 2000;               ///< dynamic steps timed for steps/s
  bool single_precision = false;  ///< timing/precision = float: the fast steppers in float
};

/// A tool load of a calibration: the case's tool pressed `depth_m` deep where `direction` points
/// (written DX,DY,DZ@DEPTH in case files and on the command line).
struct ToolLoad {
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();  ///< unit
  double depth_m = 0.0;
  /// "DX,DY,DZ@DEPTH" with the direction as given (normalised) and the depth in metres.
  std::string label() const;
  /// Same direction (to 1e-9) and depth (to 1e-12 m).
  bool same_as(const ToolLoad& other) const;
};

/// Defaults of `msfem calibrate` (each has a command-line option that overrides it).
struct CalibrationParameters {
  /// A built-in variant's name or a network's NAME (mass spring/networks); none: the first of
  /// mass spring/variants, else the first network.
  std::optional<std::string> variant;
  std::vector<std::string> groups;  ///< spring groups to fit (empty: all of the variant's)
  std::vector<ToolLoad> train, test;
  double force_weight = 1.0;          ///< J = mean over loads of e_disp² + w e_force²
  int max_evaluations = 400;          ///< objective evaluations (each: one static solve per load)
  double tolerance = 1e-5;            ///< stop when a step changes every log coefficient by less
  double bound_factor = 100.0;        ///< each factor stays within [1/b, b] of its start
  double target_damping_ratio = 0.5;  ///< of the tool-response mode, for the damping fit
  CalibrationModel model = CalibrationModel::nonlinear;
};

/// Parses "DX,DY,DZ@DEPTH; ..." (depth in metres); throws InputError naming `key` and the entry.
std::vector<ToolLoad> parse_tool_loads(const std::string& text, const std::string& key);

struct OutputParameters {
  std::string directory = "results/runs";
};

struct CaseParameters {
  std::string name;            ///< case file name without extension
  std::filesystem::path file;  ///< where it was read from
  GeometryParameters geometry;
  MaterialParameters material;
  SupportParameters support;
  LoadParameters loads;
  MassSpringParameters mass_spring;
  FemParameters fem;
  TimingParameters timing;
  OutputParameters output;
  CalibrationParameters calibration;
};

/// Reads a case file, then applies `overrides` ("section/key=value", or "section/sub/key=value").
/// Every key is typed, ranged and documented; an unknown key, a typo, a value outside its range or
/// a bad override throws InputError with one line naming the file and line (or the override).
CaseParameters read_case(const std::filesystem::path& file,
                         const std::vector<std::string>& overrides = {});

/// The case file with `overrides` applied, printed back as a complete parameter file (every key,
/// in declaration order): how `msfem calibrate` writes calibrated.prm. Throws like read_case().
std::string case_file_text(const std::filesystem::path& file,
                           const std::vector<std::string>& overrides = {});

/// The whole input language (every section, key, default, pattern and documentation).
std::string describe_case_parameters();

}  // namespace msfem::cases
