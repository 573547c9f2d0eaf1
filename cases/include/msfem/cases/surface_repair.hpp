#pragma once

#include <optional>

#include "msfem/cases/surface.hpp"
#include "msfem/cases/surface_validation.hpp"

namespace msfem::cases {

struct RepairOptions {
  bool keep_all_components = false;  ///< keep every piece instead of the largest (by triangles)
  bool always_wrap = false;          ///< rewrap even when cleaning alone gives a valid surface
  std::optional<double> alpha;       ///< wrap alpha in metres; default_wrap_alpha() when unset
  std::optional<double> offset;      ///< wrap offset in metres; alpha / 30 when unset
};

/// What repair_surface changed, in the order it did it.
struct RepairReport {
  Eigen::Index input_vertices = 0, input_triangles = 0;
  int merged_vertices = 0;       ///< duplicate points merged and unreferenced points removed
  int degenerate_triangles = 0;  ///< repeated corner, or zero area (collinear corners)
  int duplicate_triangles = 0;   ///< same three corners as an earlier triangle, either order
  int stitched_edges = 0;        ///< border halfedge pairs glued together
  int flipped_triangles = 0;     ///< turned to agree with their neighbours, or outward
  int dropped_components = 0;    ///< pieces other than the largest
  int dropped_triangles = 0;     ///< triangles in those pieces
  bool wrapped = false;
  std::string wrap_reason;             ///< the defects that made cleaning alone not enough
  double alpha = 0.0, offset = 0.0;    ///< the wrap's, in metres, when wrapped
  std::optional<double> input_volume;  ///< when the input is closed and consistently oriented
  SurfaceReport result;                ///< orient_and_validate of the returned surface
};

/// The alpha a wrap uses unless told otherwise: the mean edge length of the input, clamped to
/// [diagonal / 200, diagonal / 20] of its bounding box. The wrap then resolves about as finely as
/// the input, so the vertex count stays close, and a pathological input (a few huge or tiny
/// triangles) still gets a usable size.
double default_wrap_alpha(const Surface& surface);

/// Turns a broken triangle soup (metres) into a closed, 2-manifold, outward, self-intersection-free
/// surface with CGAL Polygon Mesh Processing: merge duplicate points, remove degenerate and
/// duplicate triangles, orient consistently, stitch borders, orient outward, keep the largest
/// component. Where that is not enough (a hole, a non-manifold edge, a self-intersection, pieces
/// overlapping each other) the cleaned soup is rewrapped with CGAL's alpha_wrap_3 and cleaned
/// again. The result is checked with orient_and_validate before it is returned. Throws InputError
/// when the input has no usable triangle or even the wrap leaves a defect.
Surface repair_surface(const Surface& input, const RepairOptions& options, RepairReport& report);

}  // namespace msfem::cases
