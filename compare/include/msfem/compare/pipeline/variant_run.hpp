#pragma once
// One mass-spring variant on a problem: build it, map the shared supports and loads onto its nodes,
// solve its static equilibrium and time its dynamic stepping.

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "msfem/compare/pipeline/problem.hpp"
#include "msfem/compare/pipeline/variant_spec.hpp"
#include "msfem/compare/pipeline/warning.hpp"
#include "msfem/fem_reference/volume_mesh.hpp"
#include "msfem/massspring/mass_spring_model.hpp"
#include "msfem/massspring/modulus_field.hpp"

namespace msfem::compare {

/// The groups a variant's builder makes under the case's settings (the builder's own list, so
/// with three_tier's `tier23_diagonals` under mass spring/three tier/inner diagonals) and, under
/// mass spring/volume preservation, `volume` for the variants that have volume elements: for
/// checking a case's names before anything is built or solved.
std::vector<std::string> spring_groups_of(cases::Variant variant, const cases::CaseParameters& p);

/// Throws cases::InputError naming the case file and key for a `mass spring/group scales` group
/// that none of the case's variants has (or `volume` without volume preservation): a misspelled
/// group would otherwise leave the run unscaled.
void check_group_names(const cases::CaseParameters& parameters);

/// Throws cases::InputError naming the case file and key for a variant setting the problem's
/// surface cannot give (more skeleton control points than surface vertices).
void check_variants_fit(const Problem& problem);

/// The name under which `mass spring/group scales` and msfem calibrate scale the volume
/// preservation modulus (`mass spring/volume preservation`).
inline constexpr const char* volume_group = "volume";
/// Why a case or a fit names `volume` in vain.
inline constexpr const char* volume_hint =
    "the volume group is three_tier's and tet_edges' under mass spring/volume preservation = true";

/// Builds the variant's network with the case's material and options, and applies the shared
/// supports, gravity, patch force and (when given) the tool as prescribed displacement of the same
/// patch the FEM prescribes. `mesh` is the FEM's volume mesh (tet_edges springs its edges). Throws
/// cases::InputError naming the case key for a bad group name or a variant without supports.
struct BuiltVariant {
  VariantSpec spec;
  std::string name;  ///< spec's name
  std::unique_ptr<massspring::MassSpringModel> model;
  std::vector<int> tool_patch;  ///< nodes the tool prescribes (the bonded patch)
  /// The frictionless tool's pressure penalty (Pa/m), chosen at its first depth and kept.
  double contact_pressure_penalty = 0.0;
  /// The case's surface vertices are the first this many surface nodes (tet_edges on the FEM's
  /// mesh refined at the tool has more; only these are compared).
  Eigen::Index case_surface_vertices = 0;
  /// Nodes the local point distribution at the tools added: Problem::local_refinement's surface
  /// vertices (three_tier: in all three tiers; tet_edges: on the surface, the
  /// mesher grading the interior to them); unset without one.
  std::optional<int> refinement_added_nodes;
  /// The volume elements whose edges are the springs (tet_edges; empty for the other variants),
  /// node indices of the model: a spring network has no resistance to their inversion, so runs
  /// count the inverted ones.
  Eigen::MatrixX4i tetrahedra;
  /// The E its springs and volume elements were given (the case's E, or the image's range).
  massspring::ModulusRange youngs_modulus_range;
  std::vector<Warning> warnings;
};
BuiltVariant build_variant(const VariantSpec& spec, const Problem& problem,
                           const fem_reference::VolumeMesh& mesh,
                           const std::optional<ToolPlacement>& tool);
BuiltVariant build_variant(cases::Variant kind, const Problem& problem,
                           const fem_reference::VolumeMesh& mesh,
                           const std::optional<ToolPlacement>& tool);

/// A user's network (spec.network) as the variant's model: read from its file, its surface nodes
/// matched to the case's surface vertices, the arrays it leaves out taken from the case (masses
/// from the case's density, fixed nodes from the support region, dampers from the damping ratio),
/// the case's group scales applied (network_variant.cpp, docs/networks.md).
void build_network_variant(BuiltVariant& variant, const Problem& problem);

/// Reads every network of the case and matches its nodes to the surface, so that a bad file or a
/// network of another geometry is refused (cases::InputError) before the FEM is solved.
void check_networks_fit(const Problem& problem);

/// The coefficient groups of a network file: its spring groups, and `volume` where it has volume
/// elements.
std::vector<std::string> network_groups(const std::filesystem::path& file);

/// Scales the model's spring groups that `mass spring/group scales` names (a group the model does
/// not have belongs to another variant).
void scale_groups(massspring::MassSpringModel& model, const cases::CaseParameters& p);

/// Moves the tool of an already built variant to another depth (the force-depth curve).
void set_tool_depth(BuiltVariant& variant, const ToolPlacement& tool);

/// How many of the variant's tetrahedra the node-major positions `x` turn inside out (signed volume
/// of the other sign than at rest); none when the variant has no volume elements.
std::optional<int> inverted_tetrahedra(const BuiltVariant& variant, const Eigen::VectorXd& x);

struct StaticSolution {
  Eigen::VectorXd x;                                     ///< node-major positions at equilibrium
  Eigen::MatrixX3d surface_displacement;                 ///< rows in surface vertex order, m
  Eigen::Vector3d tool_force = Eigen::Vector3d::Zero();  ///< force the tissue exerts on the tool
  int newton_iterations = 0;
  double solve_time_s = 0.0;
};
/// Newton from `start` when it has the model's size (a nearby equilibrium: few iterations), else
/// from rest.
StaticSolution solve_variant_static(const BuiltVariant& variant,
                                    const Eigen::VectorXd& start = Eigen::VectorXd());

struct Timing {
  std::string integrator;  ///< the timed integrator's name; empty when not timed
  /// The code timed: fast_explicit (FastExplicitStepper: explicit and symplectic Euler, central
  /// difference, RK4) or fast_implicit (FastImplicitStepper: implicit Euler).
  std::string stepper;
  std::string precision;          ///< its arithmetic: double, or float (timing/precision)
  double dt_s = 0.0;              ///< step used for steps/s and settling
  double steps_per_second = 0.0;  ///< median over batches after warm-up
  double stable_dt_s = 0.0;       ///< largest bounded dt, by bisection
  double predicted_stable_dt_s = 0.0;
  double realtime_factor = 0.0;  ///< stable dt × steps/s (simulated s per wall s)
  double settle_time_s = 0.0;    ///< wall time to within 1 % of equilibrium after the load
  bool settled = false;
  /// distance from the static equilibrium where settling ended, over the load's travel (below
  /// 0.01 when settled; far above 1 for a model that came to rest in another equilibrium)
  double settle_distance = 0.0;
  double ms_per_60hz_frame = 0.0;
};
/// Times the case's integrator on the variant (with its loads), starting from rest, against the
/// given static equilibrium (for the settle time).
/// With measure_settling false the settle time is skipped (sweeps). `threads` (> 0) caps the fast
/// steppers' threads, for timings that run beside others on the same cores (0: their default).
Timing time_variant(const BuiltVariant& variant, const cases::TimingParameters& timing,
                    const Eigen::VectorXd& equilibrium, bool measure_settling = true,
                    int threads = 0);

/// The step time_variant steps the case's integrator with: timing/dt, or half the stable step
/// (implicit Euler: a 1 kHz loop's, the step its real-time factor is for).
double timed_dt(const massspring::MassSpringModel& model, const cases::TimingParameters& timing);

}  // namespace msfem::compare
