#pragma once

// A user's mass-spring network as a file: what a simulator (SOFA, an X3D/Unity simulator) ships,
// read so that msfem can measure it against the FEM, and written so that a user can start from
// msfem's own models. Formats: VTK unstructured grids (XML .vtu: ascii, base64 binary, appended
// raw, zlib-compressed or not; legacy .vtk: ascii and binary) and SOFA's Xsp spring files (.xs3,
// .xs4; "Xsp 3.0" / "Xsp 4.0"). docs/networks.md.

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "msfem/cases/surface.hpp"

namespace msfem::cases {

struct NetworkFile {
  enum class Format { vtu, vtk, xsp };
  std::filesystem::path file;
  Format format = Format::vtu;

  Eigen::MatrixX3d points;                     ///< m
  Eigen::MatrixX2i springs;                    ///< point ids (line cells; Xsp `lspg`)
  Eigen::VectorXd stiffness;                   ///< N/m per spring, finite and > 0 (required)
  std::optional<Eigen::VectorXd> damping;      ///< N·s/m per spring, finite and >= 0
  std::optional<Eigen::VectorXd> rest_length;  ///< m per spring, > 0; absent: the file's length
  /// Group of each spring (index into group_names). A file without groups has one, "springs"; an
  /// integer `group` array names its groups "group_<n>"; a string array names them itself.
  Eigen::VectorXi spring_group;
  std::vector<std::string> group_names;

  Eigen::MatrixX3i triangles;    ///< the surface the simulator renders and touches (VTK only)
  Eigen::MatrixX4i tetrahedra;   ///< volume elements (VTK tetra cells with `bulk_modulus`)
  Eigen::VectorXd bulk_modulus;  ///< Pa per tetrahedron, finite and > 0
  /// Volume elements between two copies of a surface triangle (VTK wedge cells, 13: a b c of the
  /// outer triangle, then a' b' c' below them) with cell data `bulk_modulus`: the shell prisms of
  /// msfem's three tiers under volume preservation.
  Eigen::MatrixXi wedges;              ///< w x 6
  Eigen::VectorXd wedge_bulk_modulus;  ///< Pa per wedge, finite and > 0

  /// Point data `anchor_stiffness` (N/m, >= 0): a zero-length spring tying the point to where it
  /// lies in the file (SOFA's RestShapeSpringsForceField; msfem's single layer ties every free
  /// node so), with `anchor_damping` (N·s/m) beside it.
  std::optional<Eigen::VectorXd> anchor_stiffness;
  std::optional<Eigen::VectorXd> anchor_damping;

  std::optional<Eigen::VectorXd> mass;  ///< kg per point, finite and > 0
  std::optional<std::vector<bool>> fixed;
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();  ///< Xsp `grav` (m/s²); VTK: none
  std::optional<double> viscosity;                    ///< Xsp `visc`
};

/// Reads a network by its extension (.vtu, .vtk, .xs3, .xs4, .xsp). Every fault is a
/// cases::InputError naming the file and the point, cell or array at fault: a point id out of
/// range, a zero-length spring, a stiffness, damping, rest length, mass or bulk modulus that is
/// negative, zero (where it must be positive) or not finite, a cell type or an array msfem does
/// not use (refused by name, never ignored), a surface triangle whose vertex is in no spring, a
/// truncated file or a corrupt zlib block.
NetworkFile read_network(const std::filesystem::path& file);

/// The same from bytes already read (what the fuzz targets call); `name` names it in errors and its
/// extension picks the format.
NetworkFile read_network_bytes(const std::string& name, const std::string& bytes);

/// Writes `network` as an XML .vtu (ascii; every array msfem reads, groups as an integer `group`
/// cell array with the names in field data `group_names`), or as SOFA's Xsp 3.0 (.xs3: springs,
/// masses, fixed flags, gravity and viscosity only; Xsp has no triangles or volume elements).
/// Reading the file back gives `network` again, bit for bit. The network must pass read_network's
/// checks; Xsp also needs masses, and refuses tetrahedra (their bulk stiffness would be lost),
/// while it drops triangles and groups, and always writes the rest lengths (the current lengths
/// when `network` has none), so an .xs3 reads back with rest_length, damping and mass set.
void write_network(const std::filesystem::path& file, const NetworkFile& network);

/// `original` (a .vtu, .vtk or Xsp file) rewritten to `out` with only the springs' stiffness (and
/// damping, when given) replaced: every other array, the cell order and the format kept, so that
/// the simulator that wrote it loads the result unchanged. `out` has `original`'s extension. In a
/// .vtu the stiffness (and damping) DataArray becomes an ascii array of the same type (Float64 if
/// it was an integer type), whatever its encoding was, and a damping array is added beside it when
/// there was none; a .vtk has its values replaced in place, in its own encoding and type (a new
/// damping array goes at the end of its CELL_DATA); an Xsp file has the ks and kd of its `lspg`
/// records replaced, multiplied by the length where the record gives its rest length as -1.
void write_network_with_coefficients(const std::filesystem::path& original,
                                     const std::filesystem::path& out,
                                     const Eigen::VectorXd& stiffness,
                                     const std::optional<Eigen::VectorXd>& damping);

/// `geometry/source = network:FILE`: the case's surface is the network's own surface triangles,
/// their points kept (in increasing point id), so that the FEM is meshed on the simulator's
/// surface and compared with the network node to node.
bool is_network_source(const std::string& source);
std::filesystem::path network_source_file(const std::string& source);
/// The surface of a network file's triangles; InputError naming the file where it has none (Xsp).
Surface network_surface(const std::filesystem::path& file);

}  // namespace msfem::cases
