#include "msfem/fem_reference/volume_mesh.hpp"

#include <Eigen/Geometry>
#include <stdexcept>
#include <string>

namespace msfem::fem_reference {

namespace {
double signed_tetrahedron_volume(const VolumeMesh& mesh, Eigen::Index e) {
  const auto t = mesh.tetrahedra.row(e);
  const Eigen::Vector3d a = mesh.vertices.row(t(1)) - mesh.vertices.row(t(0));
  const Eigen::Vector3d b = mesh.vertices.row(t(2)) - mesh.vertices.row(t(0));
  const Eigen::Vector3d c = mesh.vertices.row(t(3)) - mesh.vertices.row(t(0));
  return a.cross(b).dot(c) / 6.0;
}
}  // namespace

double volume(const VolumeMesh& mesh) {
  double sum = 0.0;
  for (Eigen::Index e = 0; e < mesh.num_tetrahedra(); ++e)
    sum += signed_tetrahedron_volume(mesh, e);
  return sum;
}

Eigen::VectorXd lumped_vertex_masses(const VolumeMesh& mesh, double density) {
  Eigen::VectorXd masses = Eigen::VectorXd::Zero(mesh.num_vertices());
  for (Eigen::Index e = 0; e < mesh.num_tetrahedra(); ++e) {
    const double quarter = density * signed_tetrahedron_volume(mesh, e) / 4.0;
    for (int k = 0; k < 4; ++k)
      masses[mesh.tetrahedra(e, k)] += quarter;
  }
  return masses;
}

void check_volume_mesh(const VolumeMesh& mesh) {
  if (mesh.num_tetrahedra() == 0) throw std::invalid_argument("volume mesh has no tetrahedra");
  for (Eigen::Index e = 0; e < mesh.num_tetrahedra(); ++e) {
    for (int k = 0; k < 4; ++k)
      if (mesh.tetrahedra(e, k) < 0 || mesh.tetrahedra(e, k) >= mesh.num_vertices())
        throw std::invalid_argument("tetrahedron " + std::to_string(e) +
                                    " refers to missing vertex " +
                                    std::to_string(mesh.tetrahedra(e, k)));
    if (!(signed_tetrahedron_volume(mesh, e) > 0.0))
      throw std::invalid_argument("tetrahedron " + std::to_string(e) + " has non-positive volume");
  }
}

}  // namespace msfem::fem_reference
