#pragma once

#include <array>
#include <string>
#include <vector>

#include "msfem/cases/surface.hpp"

namespace msfem::cases {

/// The kinds of defect that make a surface unusable as the boundary of a solid.
enum class DefectKind {
  invalid_index,             ///< a triangle refers to a vertex id outside [0, n)
  non_finite_vertex,         ///< NaN or infinite coordinate
  degenerate_triangle,       ///< repeated corner or (near) zero area
  boundary_edge,             ///< edge used by one triangle only: the surface is not closed
  non_manifold_edge,         ///< edge used by three or more triangles
  non_manifold_vertex,       ///< triangles around a vertex form more than one fan (a "bow tie")
  inconsistent_orientation,  ///< two triangles traverse a shared edge in the same direction
  multiple_components,       ///< more than one connected piece
  unreferenced_vertex,       ///< a vertex no triangle uses
  self_intersection,         ///< two non-adjacent triangles intersect
};

std::string to_string(DefectKind kind);

/// One class of defect with every element id it applies to (vertex, edge or triangle ids, or
/// triangle pairs for self-intersections, flattened as [a0, b0, a1, b1, ...]).
struct Defect {
  DefectKind kind;
  std::vector<int> elements;
  std::string message;  ///< one line: what, how many, and the first ids
};

struct SurfaceReport {
  Eigen::Index vertices = 0, edges = 0, triangles = 0;
  double volume = 0.0;  ///< enclosed volume (m^3), signed before any orientation fix
  double area = 0.0;
  Eigen::Matrix<double, 2, 3> bounding_box = Eigen::Matrix<double, 2, 3>::Zero();
  int components = 0;
  int genus = -1;  ///< from Euler's formula; -1 when not closed and manifold
  bool self_intersections_checked = false;
  std::vector<Defect> defects;
  std::vector<std::string>
      fixes;  ///< what orient_and_validate changed, e.g. the inward orientation

  bool ok() const { return defects.empty(); }
  const Defect* find(DefectKind kind) const;
};

/// Checks everything and changes nothing. An inward (negative-volume) but consistent closed surface
/// is reported in `fixes` as needing a flip, not as a defect; use orient_and_validate to flip it.
SurfaceReport validate(const Surface& surface, bool check_self_intersections = true);

/// validate(), then flips every triangle when a closed, consistently oriented surface encloses a
/// negative volume, and records that in `fixes`.
SurfaceReport orient_and_validate(Surface& surface, bool check_self_intersections = true);

/// Pairs of intersecting triangles that share no vertex or overlap beyond their shared edge/vertex
/// (CGAL Polygon Mesh Processing). Requires an edge-manifold, consistently oriented mesh; throws
/// std::invalid_argument otherwise.
std::vector<std::array<int, 2>> self_intersecting_pairs(const Surface& surface);

}  // namespace msfem::cases
