#pragma once

#include <Eigen/Core>
#include <vector>

#include "msfem/cases/surface.hpp"

namespace msfem::cases {

/// A ball in which a surface is refined.
struct RefinementBall {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double radius = 0.0;
};

/// What refine_near did.
struct SurfaceRefinement {
  Surface surface;
  int passes = 0;          ///< bisection passes that split at least one edge
  int added_vertices = 0;  ///< = surface.num_vertices() − the input's
};

/// Conforming longest-edge bisection (Rivara) of every triangle that reaches into one of `balls`
/// until none of them has an edge longer than `max_edge`. Midpoints are appended, so vertex i of
/// the input is vertex i of the output and the surface keeps its shape exactly (flat facets split
/// in their plane); orientation is kept. Splitting the longest edge first bounds the smallest
/// angle below by half the input's. A triangle outside every ball is split only where a
/// neighbour's bisection needs it to stay conforming. Throws std::invalid_argument for
/// max_edge <= 0 or a ball with a negative radius; stops after `max_passes` passes.
SurfaceRefinement refine_near(const Surface& surface, const std::vector<RefinementBall>& balls,
                              double max_edge, int max_passes = 16);

}  // namespace msfem::cases
