#include "msfem/fem_reference/shape_mesher.hpp"

#include <gmsh.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "gmsh_session.hpp"

namespace msfem::fem_reference {

namespace {

void require_positive(double value, const char* name) {
  if (!(value > 0.0) || !std::isfinite(value))
    throw std::invalid_argument(std::string(name) + " must be positive, got " +
                                std::to_string(value));
}

/// Meshes the synchronised OCC model with a uniform target size.
VolumeMesh mesh_occ_model(double cell_size) {
  gmsh::model::occ::synchronize();
  gmsh::option::setNumber("Mesh.Algorithm3D", 1);  // Delaunay: reproducible, unlike HXT
  gmsh::option::setNumber("Mesh.MeshSizeMax", cell_size);
  gmsh::option::setNumber("Mesh.MeshSizeMin", 0.5 * cell_size);
  gmsh::option::setNumber("Mesh.MeshSizeFromCurvature", 0);
  gmsh::option::setNumber("Mesh.Optimize", 1);
  return detail::generate_tetrahedra(0);
}

}  // namespace

VolumeMesh mesh_hollow_sphere(double inner_radius, double outer_radius, double cell_size,
                              bool octant_only) {
  require_positive(inner_radius, "inner radius");
  require_positive(cell_size, "cell size");
  if (!(outer_radius > inner_radius))
    throw std::invalid_argument("outer radius must exceed the inner radius");
  detail::GmshSession session;
  // OCC's sphere is parametrised by latitude [angle1, angle2] and longitude [0, angle3]; latitude
  // [0, pi/2] and longitude [0, pi/2] is the octant x, y, z >= 0.
  const double lat0 = octant_only ? 0.0 : -M_PI / 2, lon = octant_only ? M_PI / 2 : 2 * M_PI;
  const int outer = gmsh::model::occ::addSphere(0, 0, 0, outer_radius, -1, lat0, M_PI / 2, lon);
  const int inner = gmsh::model::occ::addSphere(0, 0, 0, inner_radius, -1, lat0, M_PI / 2, lon);
  gmsh::vectorpair result;
  std::vector<gmsh::vectorpair> map;
  gmsh::model::occ::cut({{3, outer}}, {{3, inner}}, result, map);
  return mesh_occ_model(cell_size);
}

VolumeMesh mesh_box(const Eigen::Vector3d& lower, const Eigen::Vector3d& upper, double cell_size) {
  require_positive(cell_size, "cell size");
  const Eigen::Vector3d extent = upper - lower;
  if (!(extent.minCoeff() > 0.0))
    throw std::invalid_argument("box upper corner must exceed the lower");
  detail::GmshSession session;
  gmsh::model::occ::addBox(lower.x(), lower.y(), lower.z(), extent.x(), extent.y(), extent.z());
  return mesh_occ_model(cell_size);
}

VolumeMesh mesh_graded_box(const Eigen::Vector3d& lower, const Eigen::Vector3d& upper,
                           const Eigen::Vector3d& focus, double min_cell_size, double growth,
                           double max_cell_size) {
  require_positive(min_cell_size, "smallest cell size");
  require_positive(growth, "cell size growth");
  if (!(max_cell_size >= min_cell_size))
    throw std::invalid_argument("largest cell size must be at least the smallest");
  const Eigen::Vector3d extent = upper - lower;
  if (!(extent.minCoeff() > 0.0))
    throw std::invalid_argument("box upper corner must exceed the lower");
  detail::GmshSession session;
  gmsh::model::occ::addBox(lower.x(), lower.y(), lower.z(), extent.x(), extent.y(), extent.z());
  gmsh::model::occ::synchronize();
  const int field = gmsh::model::mesh::field::add("MathEval");
  char expression[256];
  std::snprintf(expression, sizeof expression,
                "Min(%.17g, %.17g + %.17g * Sqrt((x - %.17g)^2 + (y - %.17g)^2 + (z - %.17g)^2))",
                max_cell_size, min_cell_size, growth, focus.x(), focus.y(), focus.z());
  gmsh::model::mesh::field::setString(field, "F", expression);
  gmsh::model::mesh::field::setAsBackgroundMesh(field);
  gmsh::option::setNumber("Mesh.MeshSizeExtendFromBoundary", 0);
  gmsh::option::setNumber("Mesh.MeshSizeFromPoints", 0);
  gmsh::option::setNumber("Mesh.MeshSizeFromCurvature", 0);
  gmsh::option::setNumber("Mesh.Algorithm3D", 1);
  gmsh::option::setNumber("Mesh.MeshSizeMax", max_cell_size);
  gmsh::option::setNumber("Mesh.MeshSizeMin", min_cell_size);
  gmsh::option::setNumber("Mesh.Optimize", 1);
  return detail::generate_tetrahedra(0);
}

VolumeMesh mesh_ball(const Eigen::Vector3d& center, double radius, double cell_size) {
  require_positive(radius, "radius");
  require_positive(cell_size, "cell size");
  detail::GmshSession session;
  gmsh::model::occ::addSphere(center.x(), center.y(), center.z(), radius);
  return mesh_occ_model(cell_size);
}

}  // namespace msfem::fem_reference
