// STL, ASCII and binary. STL stores every triangle with its own three corner positions, so reading
// welds exactly equal positions into shared vertices; without that the surface would have no
// connectivity and neither model could be built from it.

#include <Eigen/Geometry>
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <unordered_map>

#include "surface_io_detail.hpp"

namespace msfem::cases::detail {

namespace {

constexpr std::size_t binary_header_bytes = 84;  // 80-byte free header + uint32 triangle count
constexpr std::size_t binary_triangle_bytes =
    50;  // normal, 3 corners (12 float32), uint16 attribute

/// Gives each distinct position one vertex id, in order of first appearance.
class Welder {
 public:
  explicit Welder(SurfaceBuilder& builder) : builder_(builder) {}

  int vertex_id(double x, double y, double z) {
    // + 0.0 turns -0.0 into +0.0, so the two zeros, which compare equal, weld.
    const Key key{x + 0.0, y + 0.0, z + 0.0};
    const auto [it, inserted] = ids_.try_emplace(key, static_cast<int>(builder_.num_vertices()));
    if (inserted) builder_.add_vertex(key.x, key.y, key.z);
    return it->second;
  }

 private:
  struct Key {
    double x, y, z;
    bool operator==(const Key& other) const { return x == other.x && y == other.y && z == other.z; }
  };
  struct KeyHash {
    std::size_t operator()(const Key& key) const {
      std::size_t seed = 0;
      for (double value : {key.x, key.y, key.z}) {
        std::uint64_t bits;
        std::memcpy(&bits, &value, sizeof bits);
        seed ^=
            std::hash<std::uint64_t>{}(bits) + 0x9e3779b97f4a7c15ull + (seed << 6) + (seed >> 2);
      }
      return seed;
    }
  };

  SurfaceBuilder& builder_;
  std::unordered_map<Key, int, KeyHash> ids_;
};

std::uint32_t le_u32(const char* bytes) {
  std::uint32_t value = 0;
  for (int byte = 3; byte >= 0; --byte)
    value = (value << 8) | static_cast<unsigned char>(bytes[byte]);
  return value;
}

float le_f32(const char* bytes) {
  const std::uint32_t bits = le_u32(bytes);
  float value;
  std::memcpy(&value, &bits, sizeof value);
  return value;
}

bool starts_with_solid(std::string_view data) {
  std::string_view rest = data;
  return next_token(rest) == "solid";
}

/// ASCII STL has no control characters besides whitespace; binary STL's float and count bytes
/// practically always contain some (a zero attribute word at least). Bytes >= 0x80 are allowed, for
/// UTF-8 solid names.
bool is_text(std::string_view data) {
  for (char c : data) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 && c != '\n' && c != '\r' && c != '\t' && c != '\v' && c != '\f') return false;
    if (u == 0x7f) return false;
  }
  return true;
}

Surface read_binary_stl(const fs::path& file, std::string_view data, std::uint32_t count) {
  SurfaceBuilder builder;
  Welder welder(builder);
  builder.corners.reserve(3 * std::size_t{count});
  for (std::uint32_t t = 0; t < count; ++t) {
    // Skip the stored normal: the corner order alone defines the orientation the models use.
    const char* corner = data.data() + binary_header_bytes + t * binary_triangle_bytes + 12;
    for (int k = 0; k < 3; ++k, corner += 12) {
      const double x = le_f32(corner), y = le_f32(corner + 4), z = le_f32(corner + 8);
      if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z))
        fail(file, "triangle #" + std::to_string(t) + ": non-finite coordinate");
      builder.corners.push_back(welder.vertex_id(x, y, z));
    }
  }
  return builder.finish();
}

/// solid / facet normal / outer loop / vertex x3 / endloop / endfacet / endsolid. The facet normal
/// is not checked (exporters write zeros or garbage); several solids in one file are concatenated.
Surface read_ascii_stl(const fs::path& file, std::string_view text) {
  SurfaceBuilder builder;
  Welder welder(builder);
  int corners_in_facet = -1;  // -1: outside a facet
  LineReader lines(text);
  std::string_view line;
  while (lines.next(line)) {
    const std::size_t number = lines.line_number();
    std::string_view rest = line;
    const std::string_view keyword = next_token(rest);
    if (keyword.empty() || keyword == "solid" || keyword == "endsolid" || keyword == "outer" ||
        keyword == "endloop") {
      continue;
    } else if (keyword == "facet") {
      if (corners_in_facet >= 0) fail_at_line(file, number, "'facet' inside an unfinished facet");
      corners_in_facet = 0;
    } else if (keyword == "vertex") {
      if (corners_in_facet < 0) fail_at_line(file, number, "'vertex' outside a facet");
      if (corners_in_facet == 3) fail_at_line(file, number, "facet with more than 3 vertices");
      double xyz[3];
      for (double& value : xyz) {
        const std::string_view token = next_token(rest);
        if (token.empty()) fail_at_line(file, number, "vertex needs three coordinates");
        if (!parse_double(token, value))
          fail_at_line(file, number, "expected a number, got " + quoted(token));
        if (!std::isfinite(value)) fail_at_line(file, number, "non-finite coordinate");
      }
      builder.corners.push_back(welder.vertex_id(xyz[0], xyz[1], xyz[2]));
      ++corners_in_facet;
    } else if (keyword == "endfacet") {
      if (corners_in_facet != 3)
        fail_at_line(
            file, number,
            "facet with " + std::to_string(std::max(corners_in_facet, 0)) + " vertices (needs 3)");
      corners_in_facet = -1;
    } else {
      fail_at_line(file, number, "unknown STL keyword " + quoted(keyword));
    }
  }
  if (corners_in_facet >= 0) fail_at_line(file, lines.line_number(), "unfinished facet at end");
  return builder.finish();
}

}  // namespace

Surface read_stl(const fs::path& file, std::string_view data) {
  // A "solid" header does not make a file ASCII: several exporters start binary headers with it.
  // The size, which binary STL fixes as 84 + 50 n, decides; text content breaks the rare tie.
  const bool text_header = starts_with_solid(data);
  if (data.size() >= binary_header_bytes) {
    const std::uint32_t count = le_u32(data.data() + 80);
    const std::uint64_t needed = binary_header_bytes + std::uint64_t{count} * binary_triangle_bytes;
    const bool ascii = text_header && is_text(data);
    if (needed == data.size() && !ascii) return read_binary_stl(file, data, count);
    if (!ascii) {
      const std::string sizes = "header says " + std::to_string(count) + " triangles (needs " +
                                std::to_string(needed) + " bytes) but file has " +
                                std::to_string(data.size()) + " bytes";
      fail(file, (needed > data.size() ? "truncated binary STL: " : "binary STL: ") + sizes);
    }
  } else if (!text_header || !is_text(data)) {
    fail(file, "not an STL file: too short for binary STL (" + std::to_string(data.size()) +
                   " bytes, needs at least 84) and no ASCII 'solid' header");
  }
  return read_ascii_stl(file, data);
}

namespace {

Eigen::Vector3d unit_normal(const Surface& surface, Eigen::Index t) {
  const Eigen::Vector3d a = surface.vertices.row(surface.triangles(t, 0));
  const Eigen::Vector3d b = surface.vertices.row(surface.triangles(t, 1));
  const Eigen::Vector3d c = surface.vertices.row(surface.triangles(t, 2));
  const Eigen::Vector3d n = (b - a).cross(c - a);
  const double length = n.norm();
  // A degenerate triangle gets the zero normal STL readers accept.
  return length > 0 && std::isfinite(length) ? Eigen::Vector3d(n / length)
                                             : Eigen::Vector3d::Zero();
}

void write_ascii_stl(std::string& out, const Surface& surface, const std::string& unit_name) {
  out += "solid msfem_surface_" + unit_name + "\n";
  for (Eigen::Index t = 0; t < surface.num_triangles(); ++t) {
    const Eigen::Vector3d normal = unit_normal(surface, t);
    out += "  facet normal";
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      append_number(out, normal[k]);
    }
    out += "\n    outer loop\n";
    for (int corner = 0; corner < 3; ++corner) {
      out += "      vertex";
      for (int k = 0; k < 3; ++k) {
        out += ' ';
        append_number(out, surface.vertices(surface.triangles(t, corner), k));
      }
      out += '\n';
    }
    out += "    endloop\n  endfacet\n";
  }
  out += "endsolid msfem_surface_" + unit_name + "\n";
}

void write_binary_stl(const fs::path& file, std::string& out, const Surface& surface,
                      const std::string& unit_name) {
  for (Eigen::Index i = 0; i < surface.num_vertices(); ++i)
    if ((surface.vertices.row(i).array().abs() > FLT_MAX).any())
      fail(file, "cannot write vertex #" + std::to_string(i) + ": coordinate too large for the " +
                     "float32 of binary STL (in " + unit_name + ")");
  // The header must not start with "solid", which would invite readers to take the file as ASCII.
  std::string header = "msfem closed surface, binary STL, coordinates in " + unit_name;
  header.resize(80, ' ');
  out += header;
  append_le_u32(out, static_cast<std::uint32_t>(surface.num_triangles()));
  for (Eigen::Index t = 0; t < surface.num_triangles(); ++t) {
    const Eigen::Vector3d normal = unit_normal(surface, t);
    for (int k = 0; k < 3; ++k)
      append_le_f32(out, static_cast<float>(normal[k]));
    for (int corner = 0; corner < 3; ++corner)
      for (int k = 0; k < 3; ++k)
        append_le_f32(out, static_cast<float>(surface.vertices(surface.triangles(t, corner), k)));
    out += std::string(2, '\0');  // attribute byte count, unused
  }
}

}  // namespace

void write_stl(const fs::path& file, std::string& out, const Surface& surface,
               const std::string& unit_name, bool binary) {
  if (binary)
    write_binary_stl(file, out, surface, unit_name);
  else
    write_ascii_stl(out, surface, unit_name);
}

}  // namespace msfem::cases::detail
