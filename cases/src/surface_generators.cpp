#include "msfem/cases/surface_generators.hpp"

#include <charconv>
#include <sstream>

#include "msfem/cases/errors.hpp"

#include <cmath>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

namespace msfem::cases {
namespace {

struct UnitMesh {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Eigen::Vector3i> triangles;
};

UnitMesh icosahedron() {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  UnitMesh m;
  m.vertices = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  for (auto& v : m.vertices)
    v.normalize();
  m.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                 {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                 {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                 {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  return m;
}

// Splits every triangle into four; the midpoint of each edge is created once and shared by both
// triangles of the edge, which keeps the mesh closed.
void subdivide(UnitMesh& m) {
  std::unordered_map<std::uint64_t, int> midpoint_of;
  auto midpoint = [&](int a, int b) {
    const std::uint64_t key = (static_cast<std::uint64_t>(std::min(a, b)) << 32) |
                              static_cast<std::uint32_t>(std::max(a, b));
    auto [it, inserted] = midpoint_of.try_emplace(key, static_cast<int>(m.vertices.size()));
    if (inserted) m.vertices.push_back((m.vertices[a] + m.vertices[b]).normalized());
    return it->second;
  };
  std::vector<Eigen::Vector3i> finer;
  finer.reserve(4 * m.triangles.size());
  for (const auto& tri : m.triangles) {
    const int ab = midpoint(tri[0], tri[1]);
    const int bc = midpoint(tri[1], tri[2]);
    const int ca = midpoint(tri[2], tri[0]);
    finer.emplace_back(tri[0], ab, ca);
    finer.emplace_back(tri[1], bc, ab);
    finer.emplace_back(tri[2], ca, bc);
    finer.emplace_back(ab, bc, ca);
  }
  m.triangles = std::move(finer);
}

Surface to_surface(const UnitMesh& m, const Eigen::Vector3d& semi_axes,
                   const Eigen::Vector3d& center) {
  Surface s;
  s.vertices.resize(static_cast<Eigen::Index>(m.vertices.size()), 3);
  s.triangles.resize(static_cast<Eigen::Index>(m.triangles.size()), 3);
  for (std::size_t i = 0; i < m.vertices.size(); ++i)
    s.vertices.row(static_cast<Eigen::Index>(i)) =
        (m.vertices[i].cwiseProduct(semi_axes) + center).transpose();
  for (std::size_t i = 0; i < m.triangles.size(); ++i)
    s.triangles.row(static_cast<Eigen::Index>(i)) = m.triangles[i].transpose();
  return s;
}

void check_level(int level) {
  if (level < 0 || level > 9)
    throw std::invalid_argument("icosphere level " + std::to_string(level) +
                                " out of range [0, 9]");
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> parts;
  std::stringstream in(s);
  for (std::string p; std::getline(in, p, sep);)
    parts.push_back(p);
  return parts;
}

double parse_number(const std::string& spec, const std::string& text) {
  double value = 0.0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size() || !std::isfinite(value))
    throw InputError("surface generator '" + spec + "': '" + text + "' is not a finite number");
  return value;
}

int parse_level(const std::string& spec, const std::string& text) {
  int value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size() || value < 0 || value > 9)
    throw InputError("surface generator '" + spec + "': level '" + text +
                     "' is not an integer in [0, 9]");
  return value;
}

}  // namespace

bool is_surface_generator(const std::string& source) {
  return source.rfind("icosphere:", 0) == 0 || source.rfind("ellipsoid:", 0) == 0;
}

Surface generate_surface(const std::string& spec) {
  const auto parts = split(spec, ':');
  if (!parts.empty() && parts[0] == "icosphere" && (parts.size() == 2 || parts.size() == 3)) {
    const double radius = parts.size() == 3 ? parse_number(spec, parts[2]) : 1.0;
    if (!(radius > 0)) throw InputError("surface generator '" + spec + "': radius must be > 0");
    return icosphere(parse_level(spec, parts[1]), radius);
  }
  if (!parts.empty() && parts[0] == "ellipsoid" && parts.size() == 5) {
    const Eigen::Vector3d axes(parse_number(spec, parts[2]), parse_number(spec, parts[3]),
                               parse_number(spec, parts[4]));
    if (!(axes.array() > 0).all())
      throw InputError("surface generator '" + spec + "': semi-axes must be > 0");
    return ellipsoid(parse_level(spec, parts[1]), axes);
  }
  throw InputError("unknown surface generator '" + spec +
                   "' (expected icosphere:LEVEL[:RADIUS_M] or ellipsoid:LEVEL:A:B:C)");
}

Surface icosphere(int level, double radius, const Eigen::Vector3d& center) {
  if (!(radius > 0.0) || !std::isfinite(radius))
    throw std::invalid_argument("icosphere radius must be positive and finite, got " +
                                std::to_string(radius));
  return ellipsoid(level, Eigen::Vector3d::Constant(radius), center);
}

Surface ellipsoid(int level, const Eigen::Vector3d& semi_axes, const Eigen::Vector3d& center) {
  check_level(level);
  if (!(semi_axes.array() > 0.0).all() || !semi_axes.allFinite())
    throw std::invalid_argument("ellipsoid semi-axes must be positive and finite");
  if (!center.allFinite()) throw std::invalid_argument("ellipsoid center must be finite");
  UnitMesh m = icosahedron();
  for (int l = 0; l < level; ++l)
    subdivide(m);
  return to_surface(m, semi_axes, center);
}

}  // namespace msfem::cases
