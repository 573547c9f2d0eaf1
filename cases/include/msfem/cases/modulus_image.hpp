#pragma once

#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace msfem::cases {

/// Hounsfield units to Young's modulus: piecewise linear between the points (HU strictly
/// increasing, E > 0 Pa), held at the end values outside them.
struct HuToYoungs {
  std::vector<std::array<double, 2>> points;  ///< {HU, E in Pa}

  double operator()(double hounsfield) const;
  /// "HU:E; HU:E; ..." as the case file writes it.
  std::string describe() const;
};

/// The documented default table (docs/harness.md gives the sources): fat (-100 HU) 3 kPa, water
/// (0 HU) 3 kPa, pancreas (40 HU) 3.5 kPa, liver (60 HU) 6 kPa, enhanced parenchyma and vessels
/// (150 HU and above) 8 kPa.
extern const char* const default_hu_to_youngs;

/// Parses "HU:E; HU:E; ..." (at least one point). Throws InputError naming `what` and the point at
/// fault: not two numbers, HU not strictly increasing, E not finite and > 0.
HuToYoungs parse_hu_to_youngs(const std::string& text, const std::string& what);

/// Young's modulus as a field of world position, from a CT in Hounsfield units: the table turns
/// every voxel into E, and E is interpolated trilinearly between voxel centres (a point outside
/// the voxel centres takes the nearest face's values). A homogeneous image gives exactly its one E
/// everywhere (the interpolation is written as nested a + t (b - a)).
class YoungsModulusImage {
 public:
  /// Reads a 3-D NIfTI-1/2 image (its scl_slope / scl_inter give HU). Throws InputError naming the
  /// file: missing, not NIfTI, truncated, a singular transform.
  YoungsModulusImage(const std::filesystem::path& image, HuToYoungs table);

  double operator()(const Eigen::Vector3d& world) const;
  /// Whether `world` lies within the image's extent (its voxels' outer faces) to
  /// `tolerance_voxels`.
  bool contains(const Eigen::Vector3d& world, double tolerance_voxels = 0.5) const;
  /// Smallest and largest E over the voxels.
  std::array<double, 2> voxel_range() const;

  const std::filesystem::path& file() const { return file_; }
  const HuToYoungs& table() const { return table_; }
  /// Identifies the field for caches: the file's contents and the table.
  const std::string& fingerprint() const { return fingerprint_; }

 private:
  Eigen::Vector3d voxel_coordinates(const Eigen::Vector3d& world) const;

  std::filesystem::path file_;
  HuToYoungs table_;
  std::array<long, 3> size_{};
  std::vector<double> modulus_;  ///< per voxel, i fastest
  Eigen::Matrix4d world_to_voxel_ = Eigen::Matrix4d::Identity();
  std::string fingerprint_;
};

}  // namespace msfem::cases
