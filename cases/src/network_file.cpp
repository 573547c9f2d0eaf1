// A user's mass-spring network as a file: format dispatch, the checks every format shares, and
// putting what the writers produce on disk. The formats live in network_vtu*.cpp,
// network_vtk_legacy.cpp and network_xsp.cpp.

#include "msfem/cases/network_file.hpp"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <system_error>

#include "network_detail.hpp"
#include "surface_io_detail.hpp"

namespace msfem::cases {

namespace detail {

namespace {

std::string index_text(Eigen::Index i) {
  return std::to_string(static_cast<long long>(i));
}

/// A cell or line label: "cell 12 (spring 7)", "line 40 (spring 7)", "spring 7".
std::string element_label(const NetworkOrigin& origin, const std::vector<long long>& where,
                          const char* kind, Eigen::Index i) {
  const std::string own = std::string(kind) + " " + index_text(origin.by_line ? i + 1 : i);
  if (static_cast<std::size_t>(i) >= where.size()) return own;
  return (origin.by_line ? "line " : "cell ") + std::to_string(where[static_cast<std::size_t>(i)]) +
         " (" + own + ")";
}

/// A point as the file numbers it: an Xsp mass counts from 1.
std::string point_name(const NetworkOrigin& origin, long long id) {
  return origin.by_line ? "mass " + std::to_string(id + 1) : "point " + std::to_string(id);
}

std::string position_text(const Eigen::MatrixX3d& points, Eigen::Index p) {
  return "(" + number_text(points(p, 0)) + ", " + number_text(points(p, 1)) + ", " +
         number_text(points(p, 2)) + ")";
}

}  // namespace

std::string spring_label(const NetworkOrigin& origin, Eigen::Index spring) {
  return element_label(origin, origin.spring, "spring", spring);
}

std::string triangle_label(const NetworkOrigin& origin, Eigen::Index triangle) {
  return element_label(origin, origin.triangle, "triangle", triangle);
}

std::string wedge_label(const NetworkOrigin& origin, Eigen::Index wedge) {
  return element_label(origin, origin.wedge, "wedge", wedge);
}

std::string tetrahedron_label(const NetworkOrigin& origin, Eigen::Index tetrahedron) {
  return element_label(origin, origin.tetrahedron, "tetrahedron", tetrahedron);
}

std::string point_label(const NetworkOrigin& origin, Eigen::Index point) {
  if (origin.by_line && static_cast<std::size_t>(point) < origin.point.size())
    return "line " + std::to_string(origin.point[static_cast<std::size_t>(point)]) + " (mass " +
           index_text(point + 1) + ")";
  return "point " + index_text(point);
}

void validate_network(const fs::path& file, const NetworkFile& net, const NetworkOrigin& origin) {
  const Eigen::Index n = net.points.rows(), m = net.springs.rows();
  const auto sized = [&](Eigen::Index size, Eigen::Index expected, const char* what,
                         const char* per) {
    if (size != expected)
      fail(file, std::to_string(size) + " " + what + " values for " + std::to_string(expected) +
                     " " + per);
  };
  sized(net.stiffness.size(), m, "stiffness", "springs");
  if (net.damping) sized(net.damping->size(), m, "damping", "springs");
  if (net.rest_length) sized(net.rest_length->size(), m, "rest_length", "springs");
  sized(net.spring_group.size(), m, "group", "springs");
  sized(net.bulk_modulus.size(), net.tetrahedra.rows(), "bulk_modulus", "tetrahedra");
  sized(net.wedge_bulk_modulus.size(), net.wedges.rows(), "bulk_modulus", "wedges");
  if (net.anchor_stiffness) sized(net.anchor_stiffness->size(), n, "anchor_stiffness", "points");
  if (net.anchor_damping) sized(net.anchor_damping->size(), n, "anchor_damping", "points");
  if (net.mass) sized(net.mass->size(), n, "mass", "points");
  if (net.fixed) sized(static_cast<Eigen::Index>(net.fixed->size()), n, "fixed", "points");
  if (m == 0) fail(file, "no springs");

  for (Eigen::Index p = 0; p < n; ++p)
    if (!net.points.row(p).allFinite())
      fail(file, point_label(origin, p) + ": coordinate " + position_text(net.points, p) +
                     " is not finite");
  const auto check_ids = [&](const auto& cells, auto label) {
    for (Eigen::Index c = 0; c < cells.rows(); ++c)
      for (Eigen::Index k = 0; k < cells.cols(); ++k)
        if (cells(c, k) < 0 || cells(c, k) >= n)
          fail(file, label(origin, c) + ": point id " + std::to_string(cells(c, k)) +
                         " out of range (the network has " + index_text(n) + " points)");
  };
  check_ids(net.springs, spring_label);
  check_ids(net.triangles, triangle_label);
  check_ids(net.tetrahedra, tetrahedron_label);
  check_ids(net.wedges, wedge_label);

  const auto positive = [&](const std::string& label, const char* name, double value,
                            const char* unit, bool zero_allowed) {
    if (!std::isfinite(value) || value < 0 || (value == 0 && !zero_allowed))
      fail(file, label + ": " + name + " " + number_text(value) + " " + unit +
                     " must be finite and " + (zero_allowed ? ">= 0" : "> 0"));
  };
  std::vector<bool> on_spring(static_cast<std::size_t>(n), false);
  for (Eigen::Index s = 0; s < m; ++s) {
    const std::string label = spring_label(origin, s);
    const int a = net.springs(s, 0), b = net.springs(s, 1);
    if (a == b) fail(file, label + ": zero-length spring: both ends are " + point_name(origin, a));
    if (net.points.row(a) == net.points.row(b))
      fail(file, label + ": zero-length spring: " + point_name(origin, a) + " and " +
                     point_name(origin, b) + " are both at " + position_text(net.points, a));
    on_spring[static_cast<std::size_t>(a)] = on_spring[static_cast<std::size_t>(b)] = true;
    positive(label, "stiffness", net.stiffness(s), "N/m", false);
    if (net.damping) positive(label, "damping", (*net.damping)(s), "N s/m", true);
    if (net.rest_length) positive(label, "rest_length", (*net.rest_length)(s), "m", false);
    const int group = net.spring_group(s);
    if (group < 0 || static_cast<std::size_t>(group) >= net.group_names.size())
      fail(file, label + ": group " + std::to_string(group) + " out of range (" +
                     std::to_string(net.group_names.size()) + " group names)");
  }
  if (net.mass)
    for (Eigen::Index p = 0; p < n; ++p)
      positive(point_label(origin, p), "mass", (*net.mass)(p), "kg", false);
  for (Eigen::Index t = 0; t < net.tetrahedra.rows(); ++t)
    positive(tetrahedron_label(origin, t), "bulk_modulus", net.bulk_modulus(t), "Pa", false);
  for (Eigen::Index w = 0; w < net.wedges.rows(); ++w)
    positive(wedge_label(origin, w), "bulk_modulus", net.wedge_bulk_modulus(w), "Pa", false);
  for (Eigen::Index p = 0; p < n; ++p) {
    if (net.anchor_stiffness)
      positive(point_label(origin, p), "anchor_stiffness", (*net.anchor_stiffness)(p), "N/m", true);
    if (net.anchor_damping)
      positive(point_label(origin, p), "anchor_damping", (*net.anchor_damping)(p), "N s/m", true);
  }
  for (Eigen::Index t = 0; t < net.triangles.rows(); ++t)
    for (int k = 0; k < 3; ++k)
      if (!on_spring[static_cast<std::size_t>(net.triangles(t, k))])
        fail(file, triangle_label(origin, t) + ": vertex " +
                       point_name(origin, net.triangles(t, k)) + " is in no spring");
}

}  // namespace detail

namespace {

namespace fs = std::filesystem;

NetworkFile::Format format_for(const fs::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (extension == ".vtu") return NetworkFile::Format::vtu;
  if (extension == ".vtk") return NetworkFile::Format::vtk;
  if (extension == ".xs3" || extension == ".xs4" || extension == ".xsp")
    return NetworkFile::Format::xsp;
  const std::string shown = extension.empty() ? "no extension" : "'" + extension + "'";
  detail::fail(path,
               "unknown network format " + shown + " (expected .vtu, .vtk, .xs3, .xs4, .xsp)");
}

detail::ReadNetwork read_checked(const fs::path& file, std::string_view bytes) {
  const NetworkFile::Format format = format_for(file);
  if (bytes.empty()) detail::fail(file, "empty file");
  detail::ReadNetwork read;
  switch (format) {
    case NetworkFile::Format::vtu:
      read = detail::read_vtu(file, bytes);
      break;
    case NetworkFile::Format::vtk:
      read = detail::read_vtk_legacy(file, bytes);
      break;
    case NetworkFile::Format::xsp:
      read = detail::read_xsp(file, bytes);
      break;
  }
  read.network.file = file;
  read.network.format = format;
  detail::validate_network(file, read.network, read.origin);
  return read;
}

/// Writes all bytes beside `file` and renames them onto it, so that a failed write never leaves
/// a partial file where the user's was.
void put_on_disk(const fs::path& file, const std::string& bytes) {
  fs::path temporary = file;
  temporary += ".tmp" + std::to_string(::getpid());
  detail::put_on_disk(file, temporary, bytes);
}

}  // namespace

bool is_network_source(const std::string& source) {
  return source.rfind("network:", 0) == 0;
}

fs::path network_source_file(const std::string& source) {
  return source.substr(std::string("network:").size());
}

Surface network_surface(const fs::path& file) {
  const NetworkFile n = read_network(file);
  if (n.triangles.rows() == 0)
    detail::fail(file,
                 "geometry/source = network: takes the file's surface triangles, and it has "
                 "none (Xsp carries none: give the case a surface and the network in mass "
                 "spring/networks)");
  std::vector<int> vertex_of(static_cast<std::size_t>(n.points.rows()), -1);
  for (Eigen::Index t = 0; t < n.triangles.rows(); ++t)
    for (int c = 0; c < 3; ++c)
      vertex_of[static_cast<std::size_t>(n.triangles(t, c))] = 0;
  int count = 0;
  for (int& v : vertex_of)
    if (v == 0) v = count++;
  Surface s;
  s.vertices.resize(count, 3);
  for (Eigen::Index p = 0; p < n.points.rows(); ++p)
    if (vertex_of[static_cast<std::size_t>(p)] >= 0)
      s.vertices.row(vertex_of[static_cast<std::size_t>(p)]) = n.points.row(p);
  s.triangles.resize(n.triangles.rows(), 3);
  for (Eigen::Index t = 0; t < n.triangles.rows(); ++t)
    for (int c = 0; c < 3; ++c)
      s.triangles(t, c) = vertex_of[static_cast<std::size_t>(n.triangles(t, c))];
  return s;
}

NetworkFile read_network(const fs::path& file) {
  format_for(file);
  return read_checked(file, detail::read_whole_file(file)).network;
}

NetworkFile read_network_bytes(const std::string& name, const std::string& bytes) {
  return read_checked(name, bytes).network;
}

void write_network(const fs::path& file, const NetworkFile& network) {
  const NetworkFile::Format format = format_for(file);
  NetworkFile net = network;
  if (net.spring_group.size() == 0 && net.group_names.empty()) {
    net.spring_group = Eigen::VectorXi::Zero(net.springs.rows());
    net.group_names = {"springs"};
  }
  detail::validate_network(file, net, {});
  std::string bytes;
  switch (format) {
    case NetworkFile::Format::vtu:
      for (const std::string& name : net.group_names)
        if (name.find('\0') != std::string::npos)
          detail::fail(file, "group name " + detail::quoted(name) + " holds a NUL character");
      detail::write_vtu(bytes, net);
      break;
    case NetworkFile::Format::xsp: {
      std::string extension = file.extension().string();
      std::transform(extension.begin(), extension.end(), extension.begin(),
                     [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
      if (extension == ".xs4")
        detail::fail(file, "msfem writes Xsp 3.0 (.xs3 or .xsp), not 4.0's vector springs");
      detail::write_xsp(file, bytes, net);
      break;
    }
    case NetworkFile::Format::vtk:
      detail::fail(file, "msfem writes networks as .vtu or .xs3; it reads legacy .vtk only");
  }
  put_on_disk(file, bytes);
}

void write_network_with_coefficients(const fs::path& original, const fs::path& out,
                                     const Eigen::VectorXd& stiffness,
                                     const std::optional<Eigen::VectorXd>& damping) {
  const NetworkFile::Format format = format_for(original);
  if (format_for(out) != format)
    detail::fail(out, "must have the format of " + original.string() + " (the same extension)");
  const std::string bytes = detail::read_whole_file(original);
  const detail::ReadNetwork read = read_checked(original, bytes);
  const Eigen::Index m = read.network.springs.rows();
  const auto check = [&](const Eigen::VectorXd& values, const char* name, const char* unit,
                         bool zero_allowed) {
    if (values.size() != m)
      detail::fail(original, std::to_string(values.size()) + " new " + name + " values for " +
                                 std::to_string(m) + " springs");
    for (Eigen::Index s = 0; s < m; ++s)
      if (!std::isfinite(values(s)) || values(s) < 0 || (values(s) == 0 && !zero_allowed))
        detail::fail(original, detail::spring_label(read.origin, s) + ": new " + name + " " +
                                   detail::number_text(values(s)) + " " + unit +
                                   " must be finite and " + (zero_allowed ? ">= 0" : "> 0"));
  };
  check(stiffness, "stiffness", "N/m", false);
  if (damping) check(*damping, "damping", "N s/m", true);
  std::string result;
  switch (format) {
    case NetworkFile::Format::vtu:
      result = detail::vtu_with_coefficients(original, bytes, stiffness, damping);
      break;
    case NetworkFile::Format::vtk:
      result = detail::vtk_legacy_with_coefficients(original, bytes, stiffness, damping);
      break;
    case NetworkFile::Format::xsp:
      result = detail::xsp_with_coefficients(original, bytes, stiffness, damping);
      break;
  }
  // What the simulator will load must still read: a Float32 array can round a coefficient to 0.
  read_checked(out, result);
  put_on_disk(out, result);
}

}  // namespace msfem::cases
