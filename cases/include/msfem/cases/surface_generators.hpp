#pragma once

#include <Eigen/Core>
#include <string>

#include "msfem/cases/surface.hpp"

namespace msfem::cases {

/// Icosahedron subdivided `level` times (each triangle into four, new vertices pushed to the
/// sphere). Level n has 10·4ⁿ + 2 vertices, 30·4ⁿ edges and 20·4ⁿ triangles; level 3 (642 vertices)
/// is the layered brain paper's test sphere. Outward oriented. Throws std::invalid_argument for
/// level < 0, level > 9 (over 2.6 M vertices) or radius <= 0.
Surface icosphere(int level, double radius,
                  const Eigen::Vector3d& center = Eigen::Vector3d::Zero());

/// Icosphere of the given level stretched to semi-axes (a, b, c) along x, y, z.
Surface ellipsoid(int level, const Eigen::Vector3d& semi_axes,
                  const Eigen::Vector3d& center = Eigen::Vector3d::Zero());

/// A generator named in a case file or on the command line: "icosphere:LEVEL[:RADIUS_M]" (radius
/// 1 m by default) or "ellipsoid:LEVEL:A:B:C" (semi-axes in metres). Throws InputError naming the
/// spec and what is wrong with it.
Surface generate_surface(const std::string& spec);

/// Whether a case's geometry source names a generator (as opposed to a surface file).
bool is_surface_generator(const std::string& source);

}  // namespace msfem::cases
