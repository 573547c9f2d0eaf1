#pragma once
// Meshes with their fields for ParaView: surface_<variant>.vtu, fem.vtu and .pvd collections of
// them. All lengths are metres; every writer writes through write_file_atomically, so a failure
// leaves no half-written file behind.

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace msfem::compare {

/// A field given at every point of a mesh: n x 1 (scalar) or n x 3 (vector), SI units.
struct PointField {
  std::string name;
  Eigen::MatrixXd values;
};

/// A triangle surface as a VTK XML UnstructuredGrid (ASCII, every double to 17 significant digits,
/// cell type 5), with the fields as point data. Indices are 0-based rows of `points`. Throws
/// std::invalid_argument for an index out of range, a field with the wrong number of rows or
/// columns, or a value that is not finite (an ASCII .vtu cannot hold one that ParaView reads).
void write_surface_vtu(const std::filesystem::path& path, const Eigen::MatrixX3d& points,
                       const Eigen::MatrixX3i& triangles,
                       const std::vector<PointField>& point_data);

/// The same for a tetrahedral mesh (cell type 10), e.g. the FEM volume mesh with its displacement.
void write_volume_vtu(const std::filesystem::path& path, const Eigen::MatrixX3d& points,
                      const Eigen::MatrixX4i& tetrahedra,
                      const std::vector<PointField>& point_data);

/// A ParaView collection (.pvd) that opens several files at once: `datasets` holds (file, name)
/// pairs, the file relative to the .pvd's folder; each becomes part i at timestep 0. Throws
/// std::invalid_argument for an empty or absolute file name (the folder must stay movable).
void write_pvd(const std::filesystem::path& path,
               const std::vector<std::pair<std::string, std::string>>& datasets);

}  // namespace msfem::compare
