#pragma once
// A case turned into geometry both models share: the validated surface, the fixed region and the
// tool placements, each stated once and mapped by each model onto its own nodes.

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "msfem/cases/case_parameters.hpp"
#include "msfem/cases/modulus_image.hpp"
#include "msfem/cases/surface.hpp"
#include "msfem/fem_reference/elasticity_problem.hpp"

namespace msfem::compare {

/// Where a tool presses: the surface vertex farthest from the centroid along the case's direction.
struct ToolPlacement {
  int vertex = -1;
  Eigen::Vector3d contact_point = Eigen::Vector3d::Zero();
  Eigen::Vector3d outward_normal = Eigen::Vector3d::UnitZ();  ///< the vertex normal there
  double radius = 0.0;
  double depth = 0.0;
  bool frictionless = false;  ///< loads/tool/mode = contact; otherwise the bonded patch
  /// Centre of the sphere at full depth: contact + (radius − depth) n.
  Eigen::Vector3d pushed_center() const {
    return contact_point + (radius - depth) * outward_normal;
  }
};

/// The local point distribution at the tools (mass spring/contact refinement), once applied.
struct LocalRefinement {
  double radius_m = 0.0;   ///< around each tool's contact point
  double edge_m = 0.0;     ///< longest surface edge inside
  int added_vertices = 0;  ///< surface vertices added (appended after the case's own)
};

struct Problem {
  cases::CaseParameters parameters;
  cases::Surface surface;  ///< outward, closed, manifold, metres
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  std::vector<std::string> notes;  ///< what loading changed (orientation fixed, simplified, ...)
  /// The fixed region as a predicate on positions (the same for both models).
  std::function<bool(const Eigen::Vector3d&)> fixed_region;
  std::vector<ToolPlacement> tools;  ///< one per tool direction (empty when the tool is off)
  /// Set when the surface was refined around the tools; the centroid and the fixed region are
  /// those of the surface before (refinement keeps its shape, but not its vertex centroid).
  std::optional<LocalRefinement> local_refinement;
  /// E from the case's material/youngs modulus image, when it names one (null: E is constant).
  std::shared_ptr<const cases::YoungsModulusImage> youngs_modulus_image;
};

/// E(x) in Pa as both models take it: the image's field, or the case's constant E.
double youngs_modulus_at(const Problem& problem, const Eigen::Vector3d& x);

/// The case's surface as its source gives it (a generator, an image's organ, or a file), before
/// the case's simplification, smoothing and checks; `notes` gets what extraction did.
cases::Surface source_surface(const cases::CaseParameters& parameters,
                              std::vector<std::string>& notes);

/// Loads and checks the case's surface (generate or read, simplify, smooth, orient) and places its
/// supports and tools. Throws cases::InputError naming the case file for a surface with defects, a
/// fixed region or tool that catches no surface node, or a tool deeper than the model.
Problem make_problem(const cases::CaseParameters& parameters);

/// The surface vertex farthest from `centroid` along the unit `direction`: where a tool presses or
/// a patch force pulls. Of vertices as far (a flat face) the one nearest the line through the
/// centroid.
int farthest_vertex(const cases::Surface& surface, const Eigen::Vector3d& centroid,
                    const Eigen::Vector3d& direction);

/// The point of a surface nearest a position: its triangle and the point's barycentric weights
/// on that triangle's vertices.
struct SurfacePoint {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  int triangle = -1;
  Eigen::Vector3d weights = Eigen::Vector3d::Zero();
};
SurfacePoint closest_surface_point(const cases::Surface& surface, const Eigen::Vector3d& x);

/// The surface vertices a patch force pulls (empty without one): within its radius of the vertex
/// farthest along its direction.
std::vector<int> patch_vertices(const Problem& problem);

/// Mean displacement of `displacement`'s rows `vertices`.
Eigen::Vector3d mean_displacement(const Eigen::MatrixX3d& displacement,
                                  const std::vector<int>& vertices);

/// Enclosed volume of the surface moved by `displacement` (per vertex) over its rest volume, − 1.
double volume_change(const cases::Surface& surface, const Eigen::MatrixX3d& displacement);

/// The tool at a given depth (the force-depth curve uses several).
ToolPlacement at_depth(ToolPlacement tool, double depth);

/// The tool as prescribed displacement, the same for both models: every surface node inside the
/// sphere at full depth moves along the push axis onto the sphere's far side, as under a rigid
/// indenter (a radial projection would push the nodes next to the centre sideways, not down).
/// Named "tool", on boundary nodes only.
fem_reference::Support tool_patch_support(const ToolPlacement& tool);

}  // namespace msfem::compare
