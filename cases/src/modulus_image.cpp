// Young's modulus from a CT: the layered brain model's proposal that stiffness be "proportional to
// tissue density and, therefore, to the Hounsfield units", as one field both models sample.
#include "msfem/cases/modulus_image.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <sstream>

#include "msfem/cases/errors.hpp"
#include "msfem/cases/text.hpp"
#include "voxel_volume.hpp"

namespace msfem::cases {

const char* const default_hu_to_youngs = "-100:3000; 0:3000; 40:3500; 60:6000; 150:8000";

namespace {

std::string number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", value);
  return text;
}

bool parse_number(const std::string& text, double& value) {
  const std::string t = trimmed(text);
  std::size_t used = 0;
  try {
    value = std::stod(t, &used);
  } catch (const std::exception&) {
    return false;
  }
  return used == t.size() && std::isfinite(value);
}

// FNV-1a over bytes: a cache key, not a security property.
void mix(std::uint64_t& hash, const void* data, std::size_t bytes) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < bytes; ++i)
    hash = (hash ^ p[i]) * 1099511628211ull;
}

double lerp(double a, double b, double t) {
  return a + t * (b - a);
}

}  // namespace

double HuToYoungs::operator()(double hounsfield) const {
  if (hounsfield <= points.front()[0]) return points.front()[1];
  if (hounsfield >= points.back()[0]) return points.back()[1];
  const auto upper = std::upper_bound(points.begin(), points.end(), hounsfield,
                                      [](double h, const auto& p) { return h < p[0]; });
  const auto& a = *(upper - 1);
  const auto& b = *upper;
  return lerp(a[1], b[1], (hounsfield - a[0]) / (b[0] - a[0]));
}

std::string HuToYoungs::describe() const {
  std::string text;
  for (const auto& p : points)
    text += (text.empty() ? "" : "; ") + number(p[0]) + ":" + number(p[1]);
  return text;
}

HuToYoungs parse_hu_to_youngs(const std::string& text, const std::string& what) {
  HuToYoungs table;
  std::istringstream in(text);
  for (std::string point; std::getline(in, point, ';');) {
    if (trimmed(point).empty()) continue;
    const auto colon = point.find(':');
    double hu = 0, e = 0;
    if (colon == std::string::npos || !parse_number(point.substr(0, colon), hu) ||
        !parse_number(point.substr(colon + 1), e))
      throw InputError(what + ": '" + trimmed(point) + "' is not HU:E (two numbers, E in Pa)");
    if (!(e > 0))
      throw InputError(what + ": '" + trimmed(point) + "' gives E = " + number(e) +
                       " Pa; Young's modulus must be > 0");
    if (!table.points.empty() && !(hu > table.points.back()[0]))
      throw InputError(what + ": HU " + number(hu) + " does not increase on " +
                       number(table.points.back()[0]) + " (the points must be in increasing HU)");
    table.points.push_back({hu, e});
  }
  if (table.points.empty()) throw InputError(what + ": no HU:E point");
  return table;
}

YoungsModulusImage::YoungsModulusImage(const std::filesystem::path& image, HuToYoungs table)
    : file_(image), table_(std::move(table)) {
  const detail::VoxelVolume volume = detail::read_nifti(image);
  size_ = volume.grid.size;
  modulus_.resize(volume.values.size());
  std::transform(volume.values.begin(), volume.values.end(), modulus_.begin(),
                 [&](float hu) { return table_(hu); });
  world_to_voxel_ = volume.voxel_to_world.inverse();
  std::uint64_t hash = 14695981039346656037ull;
  mix(hash, volume.values.data(), volume.values.size() * sizeof(float));
  mix(hash, size_.data(), sizeof size_);
  mix(hash, volume.voxel_to_world.data(), 16 * sizeof(double));
  const std::string described = table_.describe();
  mix(hash, described.data(), described.size());
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(hash));
  fingerprint_ = text;
}

Eigen::Vector3d YoungsModulusImage::voxel_coordinates(const Eigen::Vector3d& world) const {
  return (world_to_voxel_ * world.homogeneous()).head<3>();
}

bool YoungsModulusImage::contains(const Eigen::Vector3d& world, double tolerance_voxels) const {
  const Eigen::Vector3d v = voxel_coordinates(world);
  for (int d = 0; d < 3; ++d)
    if (!(v[d] >= -0.5 - tolerance_voxels && v[d] <= size_[d] - 0.5 + tolerance_voxels))
      return false;
  return true;
}

double YoungsModulusImage::operator()(const Eigen::Vector3d& world) const {
  const Eigen::Vector3d v = voxel_coordinates(world);
  long i0[3];
  double t[3];
  for (int d = 0; d < 3; ++d) {
    const double c = std::clamp(v[d], 0.0, double(size_[d] - 1));
    i0[d] = std::min(static_cast<long>(c), size_[d] - 2);
    t[d] = c - double(i0[d]);
  }
  auto at = [&](long di, long dj, long dk) {
    return modulus_[(i0[0] + di) + size_[0] * ((i0[1] + dj) + size_[1] * (i0[2] + dk))];
  };
  auto along_i = [&](long dj, long dk) { return lerp(at(0, dj, dk), at(1, dj, dk), t[0]); };
  auto along_j = [&](long dk) { return lerp(along_i(0, dk), along_i(1, dk), t[1]); };
  return lerp(along_j(0), along_j(1), t[2]);
}

std::array<double, 2> YoungsModulusImage::voxel_range() const {
  const auto [low, high] = std::minmax_element(modulus_.begin(), modulus_.end());
  return {*low, *high};
}

}  // namespace msfem::cases
