#pragma once

#include "msfem/cases/surface.hpp"

namespace msfem::cases {

/// Reduces a closed, 2-manifold surface to exactly `target_vertices` vertices by edge collapse
/// (CGAL Surface_mesh_simplification, Lindstrom-Turk cost and placement, which preserve volume and
/// keep the mesh closed and manifold). Each collapse removes one vertex, three edges and two
/// triangles, so the target is reached exactly unless the link condition blocks further collapses;
/// then std::runtime_error says how far it got. Throws std::invalid_argument if the surface is not
/// closed and manifold or the target is not in [4, current vertex count].
Surface simplify(const Surface& surface, int target_vertices);

/// Taubin lambda|mu smoothing (Taubin 1995): alternating shrink (lambda > 0) and inflate (mu < 0)
/// steps of the uniform Laplacian, a low-pass filter that removes the staircase of marching-cubes
/// surfaces without the shrinkage of plain Laplacian smoothing. Topology is unchanged.
void smooth_taubin(Surface& surface, int iterations, double lambda = 0.5, double mu = -0.53);

}  // namespace msfem::cases
