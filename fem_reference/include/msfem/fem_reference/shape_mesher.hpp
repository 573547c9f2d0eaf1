#pragma once

#include <Eigen/Core>

#include "msfem/fem_reference/volume_mesh.hpp"

namespace msfem::fem_reference {

// Exact analytic shapes meshed from their OpenCASCADE geometry (Gmsh), for convergence studies:
// the boundary vertices lie on the exact surfaces and a smaller `cell_size` gives a refined mesh of
// the same shape. num_surface_vertices is 0 (there is no given surface to preserve).

/// The shell a <= r <= b about the origin; with `octant_only` just its part in x, y, z >= 0 (the
/// symmetry planes x = 0, y = 0, z = 0 become boundaries).
VolumeMesh mesh_hollow_sphere(double inner_radius, double outer_radius, double cell_size,
                              bool octant_only);

/// The box [lower, upper].
VolumeMesh mesh_box(const Eigen::Vector3d& lower, const Eigen::Vector3d& upper, double cell_size);

/// The box [lower, upper] with cells of size min_cell_size + growth * |x - focus|, at most
/// max_cell_size: fine at a contact, coarse far from it.
VolumeMesh mesh_graded_box(const Eigen::Vector3d& lower, const Eigen::Vector3d& upper,
                           const Eigen::Vector3d& focus, double min_cell_size, double growth,
                           double max_cell_size);

/// The ball |x - center| <= radius.
VolumeMesh mesh_ball(const Eigen::Vector3d& center, double radius, double cell_size);

}  // namespace msfem::fem_reference
