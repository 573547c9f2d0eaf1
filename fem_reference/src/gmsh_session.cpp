#include "gmsh_session.hpp"

#include <gmsh.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <functional>
#include <string>
#include <vector>

#include "msfem/fem_reference/errors.hpp"

namespace msfem::fem_reference::detail {

namespace {
std::mutex gmsh_mutex;
constexpr int gmsh_linear_tetrahedron = 4;
}  // namespace

GmshSession::GmshSession() : lock_(gmsh_mutex) {
  gmsh::initialize(0, nullptr, /*readConfigFiles=*/false);
  gmsh::option::setNumber("General.Terminal", 0);
  gmsh::option::setNumber("General.Verbosity", 0);
  // One thread: multi-threaded meshing differs from run to run; the reference must not.
  gmsh::option::setNumber("General.NumThreads", 1);
  gmsh::option::setNumber("Mesh.RandomSeed", 1);
  gmsh::model::add("msfem");
}

GmshSession::~GmshSession() {
  gmsh::finalize();
}

namespace {
void run_gmsh(const std::function<void()>& step) {
  try {
    step();
  } catch (...) {
    std::string message;
    gmsh::logger::getLastError(message);
    throw FemError("Gmsh 3D meshing failed: " + (message.empty() ? "unknown error" : message));
  }
}
}  // namespace

VolumeMesh generate_tetrahedra(std::size_t num_kept_nodes, double relocate_below_quality) {
  run_gmsh([] { gmsh::model::mesh::generate(3); });
  VolumeMesh mesh = current_tetrahedra(num_kept_nodes);
  if (relocate_below_quality <= 0.0 || cell_quality(mesh).minCoeff() >= relocate_below_quality)
    return mesh;
  run_gmsh([] { gmsh::model::mesh::optimize("Relocate3D"); });
  return current_tetrahedra(num_kept_nodes);
}

VolumeMesh current_tetrahedra(std::size_t num_kept_nodes) {
  std::vector<std::size_t> node_tags;
  std::vector<double> coordinates, parametric;
  gmsh::model::mesh::getNodes(node_tags, coordinates, parametric, -1, -1, true, false);
  std::vector<std::size_t> element_tags, element_nodes;
  gmsh::model::mesh::getElementsByType(gmsh_linear_tetrahedron, element_tags, element_nodes);
  if (element_tags.empty()) throw FemError("Gmsh produced no tetrahedra");

  std::size_t max_tag = 0;
  for (std::size_t tag : node_tags)
    max_tag = std::max(max_tag, tag);
  std::vector<int> position_of_tag(max_tag + 1, -1);
  for (std::size_t i = 0; i < node_tags.size(); ++i)
    position_of_tag[node_tags[i]] = int(i);

  // New ids: kept nodes first (tag t -> t - 1), then the used interior nodes in tag order.
  std::vector<int> new_id(max_tag + 1, -1);
  for (std::size_t tag = 1; tag <= num_kept_nodes; ++tag) {
    if (tag > max_tag || position_of_tag[tag] < 0)
      throw FemError("Gmsh lost surface vertex " + std::to_string(tag - 1));
    new_id[tag] = int(tag - 1);
  }
  std::vector<bool> used(max_tag + 1, false);
  for (std::size_t tag : element_nodes)
    used[tag] = true;
  int next_id = int(num_kept_nodes);
  for (std::size_t tag = num_kept_nodes + 1; tag <= max_tag; ++tag)
    if (used[tag]) new_id[tag] = next_id++;

  VolumeMesh mesh;
  mesh.num_surface_vertices = Eigen::Index(num_kept_nodes);
  mesh.vertices.resize(next_id, 3);
  for (std::size_t tag = 1; tag <= max_tag; ++tag) {
    if (new_id[tag] < 0) continue;
    const std::size_t p = std::size_t(position_of_tag[tag]);
    for (int d = 0; d < 3; ++d)
      mesh.vertices(new_id[tag], d) = coordinates[3 * p + d];
  }
  mesh.tetrahedra.resize(Eigen::Index(element_tags.size()), 4);
  for (std::size_t e = 0; e < element_tags.size(); ++e) {
    for (int k = 0; k < 4; ++k)
      mesh.tetrahedra(Eigen::Index(e), k) = new_id[element_nodes[4 * e + k]];
    const auto& t = mesh.tetrahedra.row(Eigen::Index(e));
    const Eigen::Vector3d a = mesh.vertices.row(t(1)) - mesh.vertices.row(t(0));
    const Eigen::Vector3d b = mesh.vertices.row(t(2)) - mesh.vertices.row(t(0));
    const Eigen::Vector3d c = mesh.vertices.row(t(3)) - mesh.vertices.row(t(0));
    if (a.cross(b).dot(c) < 0)
      std::swap(mesh.tetrahedra(Eigen::Index(e), 2), mesh.tetrahedra(Eigen::Index(e), 3));
  }
  return mesh;
}

}  // namespace msfem::fem_reference::detail
