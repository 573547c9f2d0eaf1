#include "msfem/fem_reference/volume_mesh.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

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

Eigen::VectorXd cell_quality(const VolumeMesh& mesh) {
  Eigen::VectorXd quality(mesh.num_tetrahedra());
  for (Eigen::Index e = 0; e < mesh.num_tetrahedra(); ++e) {
    std::array<Eigen::Vector3d, 4> x;
    for (int k = 0; k < 4; ++k)
      x[std::size_t(k)] = mesh.vertices.row(mesh.tetrahedra(e, k)).transpose();
    double area = 0.0, longest = 0.0;
    for (const auto& f : tetrahedron_faces)
      area += 0.5 * (x[std::size_t(f[1])] - x[std::size_t(f[0])])
                        .cross(x[std::size_t(f[2])] - x[std::size_t(f[0])])
                        .norm();
    for (std::size_t a = 0; a < 4; ++a)
      for (std::size_t b = a + 1; b < 4; ++b)
        longest = std::max(longest, (x[a] - x[b]).norm());
    const double inradius = 3.0 * std::abs(signed_tetrahedron_volume(mesh, e)) / area;
    quality[e] = area > 0.0 && longest > 0.0 ? 2.0 * std::sqrt(6.0) * inradius / longest : 0.0;
  }
  return quality;
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

VolumeMesh refine_uniformly(const VolumeMesh& mesh) {
  VolumeMesh fine;
  fine.num_surface_vertices = mesh.num_surface_vertices;
  const Eigen::Index n = mesh.num_vertices();
  std::unordered_map<std::int64_t, int> midpoint_of;
  std::vector<Eigen::Vector3d> midpoints;
  auto midpoint = [&](int a, int b) {
    const std::int64_t key = std::int64_t(std::min(a, b)) * n + std::max(a, b);
    const auto [it, added] = midpoint_of.try_emplace(key, int(n + Eigen::Index(midpoints.size())));
    if (added) midpoints.push_back(0.5 * (mesh.vertices.row(a) + mesh.vertices.row(b)).transpose());
    return it->second;
  };
  std::vector<std::array<int, 4>> children;
  children.reserve(std::size_t(8 * mesh.num_tetrahedra()));
  for (Eigen::Index e = 0; e < mesh.num_tetrahedra(); ++e) {
    const auto t = mesh.tetrahedra.row(e);
    const int m01 = midpoint(t(0), t(1)), m02 = midpoint(t(0), t(2)), m03 = midpoint(t(0), t(3)),
              m12 = midpoint(t(1), t(2)), m13 = midpoint(t(1), t(3)), m23 = midpoint(t(2), t(3));
    children.push_back({{t(0), m01, m02, m03}});
    children.push_back({{m01, t(1), m12, m13}});
    children.push_back({{m02, m12, t(2), m23}});
    children.push_back({{m03, m13, m23, t(3)}});
    // The octahedron's three diagonals, each with the cycle of the four other midpoints around it.
    const std::array<std::array<int, 6>, 3> cuts = {{{{m01, m23, m02, m03, m13, m12}},
                                                     {{m02, m13, m01, m03, m23, m12}},
                                                     {{m03, m12, m01, m02, m23, m13}}}};
    auto at = [&](int a, int b) -> Eigen::Vector3d {
      return 0.5 * (mesh.vertices.row(t(a)) + mesh.vertices.row(t(b))).transpose();
    };
    const std::array<double, 3> diagonal = {{(at(0, 1) - at(2, 3)).squaredNorm(),
                                             (at(0, 2) - at(1, 3)).squaredNorm(),
                                             (at(0, 3) - at(1, 2)).squaredNorm()}};
    const auto& cut =
        cuts[std::size_t(std::min_element(diagonal.begin(), diagonal.end()) - diagonal.begin())];
    for (int k = 0; k < 4; ++k)
      children.push_back(
          {{cut[0], cut[1], cut[std::size_t(2 + k)], cut[std::size_t(2 + (k + 1) % 4)]}});
  }
  fine.vertices.resize(n + Eigen::Index(midpoints.size()), 3);
  fine.vertices.topRows(n) = mesh.vertices;
  for (std::size_t i = 0; i < midpoints.size(); ++i)
    fine.vertices.row(n + Eigen::Index(i)) = midpoints[i].transpose();
  fine.tetrahedra.resize(Eigen::Index(children.size()), 4);
  for (std::size_t c = 0; c < children.size(); ++c) {
    for (int k = 0; k < 4; ++k)
      fine.tetrahedra(Eigen::Index(c), k) = children[c][std::size_t(k)];
    // The parents are positively oriented; the octahedron's children may come out mirrored.
    if (signed_tetrahedron_volume(fine, Eigen::Index(c)) < 0.0)
      std::swap(fine.tetrahedra(Eigen::Index(c), 2), fine.tetrahedra(Eigen::Index(c), 3));
  }
  return fine;
}

std::vector<unsigned int> partition_cells(const VolumeMesh& mesh, unsigned int parts) {
  const std::size_t n = std::size_t(mesh.num_tetrahedra());
  std::vector<Eigen::Vector3d> centroid(n);
  for (std::size_t e = 0; e < n; ++e) {
    centroid[e].setZero();
    for (int k = 0; k < 4; ++k)
      centroid[e] += 0.25 * mesh.vertices.row(mesh.tetrahedra(Eigen::Index(e), k)).transpose();
  }
  std::vector<std::size_t> cells(n);
  for (std::size_t e = 0; e < n; ++e)
    cells[e] = e;
  std::vector<unsigned int> part(n, 0);
  const std::function<void(std::size_t, std::size_t, unsigned int, unsigned int)> split =
      [&](std::size_t begin, std::size_t end, unsigned int first_part, unsigned int count) {
        if (count <= 1 || end - begin < 2) {
          for (std::size_t i = begin; i < end; ++i)
            part[cells[i]] = first_part;
          return;
        }
        Eigen::Vector3d low = centroid[cells[begin]], high = low;
        for (std::size_t i = begin; i < end; ++i) {
          low = low.cwiseMin(centroid[cells[i]]);
          high = high.cwiseMax(centroid[cells[i]]);
        }
        Eigen::Index axis = 0;
        (high - low).maxCoeff(&axis);
        const unsigned int left_parts = count / 2;
        const std::size_t middle = begin + (end - begin) * left_parts / count;
        std::nth_element(cells.begin() + std::ptrdiff_t(begin),
                         cells.begin() + std::ptrdiff_t(middle),
                         cells.begin() + std::ptrdiff_t(end), [&](std::size_t a, std::size_t b) {
                           return centroid[a][axis] < centroid[b][axis] ||
                                  (centroid[a][axis] == centroid[b][axis] && a < b);
                         });
        split(begin, middle, first_part, left_parts);
        split(middle, end, first_part + left_parts, count - left_parts);
      };
  split(0, n, 0, parts);
  return part;
}

}  // namespace msfem::fem_reference
