#pragma once

#include <Eigen/Core>

#include "msfem/fem_reference/elasticity_problem.hpp"

namespace msfem::fem_reference {

// The case's supports and loads, stated as geometry once and mapped onto the FEM's nodes and faces.
// The mass-spring side applies the same definitions to its nodes.

/// Points on the side of the plane through `point` that `normal` points into, the plane itself
/// included up to `tolerance` (m).
Region half_space(const Eigen::Vector3d& point, const Eigen::Vector3d& normal,
                  double tolerance = 1e-9);

/// Points within `tolerance` of the plane through `point` with `normal` (symmetry planes).
Region plane(const Eigen::Vector3d& point, const Eigen::Vector3d& normal, double tolerance = 1e-9);

/// The closed ball |x - center| <= radius.
Region ball(const Eigen::Vector3d& center, double radius);

/// The "inner core" of the layered model: the closed surface scaled by 1/scale_divisor about its
/// vertex centroid c. x is inside iff c + s (x - c) is inside the surface, decided by a ray from c
/// (the surface must be star-shaped about c, as the layered model assumes). Throws
/// std::invalid_argument unless scale_divisor > 1 and the surface is closed.
Region inner_core(const Eigen::MatrixX3d& vertices, const Eigen::MatrixX3i& triangles,
                  double scale_divisor);

/// How a tool's contact patch is displaced.
enum class ToolPatchMode {
  /// Each boundary node inside the pushed sphere moves radially onto its surface (the closest point
  /// on the sphere; what frictionless contact would give for those nodes).
  project_onto_sphere,
  /// Each boundary node inside the pushed sphere moves by depth along the inward normal.
  uniform
};

/// A rigid sphere of `radius` touching the surface at `contact_point` (where the outward normal is
/// `outward_normal`) pushed `depth` along the inward normal: its centre moves from
/// contact_point + radius n to contact_point + (radius - depth) n.
struct ToolIndentation {
  Eigen::Vector3d contact_point = Eigen::Vector3d::Zero();
  Eigen::Vector3d outward_normal = Eigen::Vector3d::UnitZ();
  double radius = 0.0;
  double depth = 0.0;
  ToolPatchMode mode = ToolPatchMode::project_onto_sphere;
};

/// The tool as a Support on boundary nodes (named `name`); throws std::invalid_argument for a
/// non-positive radius, a negative depth or a zero normal.
Support tool_support(const ToolIndentation& tool, const std::string& name = "tool");

/// A clamped region.
Support fixed_support(const std::string& name, Region region, bool boundary_nodes_only = false);

/// Pressure p (Pa, positive pushes inward): t = -p n.
TractionField pressure(double p);

/// The same traction vector everywhere.
TractionField uniform_traction(const Eigen::Vector3d& traction);

}  // namespace msfem::fem_reference
