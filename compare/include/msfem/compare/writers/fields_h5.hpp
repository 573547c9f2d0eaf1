#pragma once
// Every field of a run in one HDF5 file (fields.h5), for scripts and for `msfem regress`. All
// lengths are metres; written through write_file_atomically.

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

namespace msfem::compare {

/// One mass-spring variant's result at the surface vertices: its displacement and its error
/// (variant minus FEM), n x 3 each, metres.
struct VariantField {
  std::string name;
  Eigen::MatrixX3d surface_displacement;
  Eigen::MatrixX3d error;
};

/// The FEM reference on its own volume mesh (0-based vertex indices), displacement in metres.
struct FemField {
  Eigen::MatrixX3d vertices;
  Eigen::MatrixX4i tetrahedra;
  Eigen::MatrixX3d displacement;
};

/// fields.h5: every field of a run, row-major (dims {rows, cols}), lengths with attribute
/// units = "m", indices int32 and 0-based:
///   /surface/vertices (n x 3), /surface/triangles (m x 3),
///   /fem/vertices, /fem/tetrahedra, /fem/displacement,
///   /variants/<name>/displacement (n x 3), /variants/<name>/error (n x 3),
///   /variants/<name>/error_magnitude (n).
/// Throws std::invalid_argument for mismatched sizes, out-of-range indices or a variant name that
/// is empty, repeated or holds '/'; std::runtime_error naming the file and dataset if HDF5 fails.
void write_fields_h5(const std::filesystem::path& path, const Eigen::MatrixX3d& surface_vertices,
                     const Eigen::MatrixX3i& surface_triangles, const FemField& fem,
                     const std::vector<VariantField>& variants);

/// A numeric dataset of an HDF5 file as a matrix: rank 2 as rows x cols, rank 1 as n x 1, a
/// scalar as 1 x 1; integer datasets are converted to double. Throws std::runtime_error naming the
/// file and dataset if either is missing or unreadable.
Eigen::MatrixXd read_h5_matrix(const std::filesystem::path& path, const std::string& dataset);

/// A string attribute (fixed or variable length) of a dataset or group, e.g. a dataset's "units".
/// Throws std::runtime_error naming the file, object and attribute if it cannot be read.
std::string read_h5_string_attribute(const std::filesystem::path& path, const std::string& object,
                                     const std::string& attribute);

}  // namespace msfem::compare
