#pragma once
// A triangle surface with its point and field data from a VTK XML unstructured grid (.vtu, every
// encoding the network reader takes): what a simulator writes as its deformed surface.

#include <Eigen/Core>
#include <filesystem>
#include <map>
#include <string>

namespace msfem::cases {

struct VtkSurface {
  Eigen::MatrixX3d points;
  Eigen::MatrixX3i triangles;
  /// Each array as rows × components (point data: one row per point).
  std::map<std::string, Eigen::MatrixXd> point_data, field_data;
};

/// Reads `file` (.vtu); every fault is an InputError naming the file: a cell that is not a
/// triangle, a triangle's point out of range, a point array whose length is not the points', an
/// array of strings, a value that is not finite.
VtkSurface read_vtk_surface(const std::filesystem::path& file);

}  // namespace msfem::cases
