// Wavefront OBJ: only the polygon geometry ("v" and "f"); normals, texture coordinates, groups and
// materials are read past because the models need positions and connectivity alone.

#include <cmath>
#include <limits>
#include <string>
#include <unordered_set>

#include "surface_io_detail.hpp"

namespace msfem::cases::detail {

namespace {

/// Statements that carry no polygon geometry. Anything else (free-form curves and surfaces, typos)
/// is refused rather than silently dropped, since the surface would then be incomplete.
bool is_ignored_statement(std::string_view keyword) {
  static const std::unordered_set<std::string_view> ignored = {
      "vn",       "vt",     "vp",     "g",          "o",        "s",     "usemtl",
      "mtllib",   "l",      "p",      "mg",         "lod",      "bevel", "c_interp",
      "d_interp", "usemap", "maplib", "shadow_obj", "trace_obj"};
  return ignored.count(keyword) > 0;
}

/// "v x y z [w] [r g b]": the first three numbers; the rest (weight, vertex colour) is not needed.
void read_vertex(const fs::path& file, std::size_t line, std::string_view rest,
                 SurfaceBuilder& builder) {
  double xyz[3];
  for (double& value : xyz) {
    const std::string_view token = next_token(rest);
    if (token.empty()) fail_at_line(file, line, "vertex needs three coordinates");
    if (!parse_double(token, value))
      fail_at_line(file, line, "expected a number, got " + quoted(token));
    if (!std::isfinite(value)) fail_at_line(file, line, "non-finite coordinate");
  }
  builder.add_vertex(xyz[0], xyz[1], xyz[2]);
}

/// "f v1 v2 v3 ..." where each corner may be v, v/vt, v//vn or v/vt/vn and a negative v counts back
/// from the last vertex read so far. Fills `polygon` with zero-based indices; positive ones are
/// checked against the final vertex count by the caller.
void read_face(const fs::path& file, std::size_t line, std::string_view rest,
               std::size_t vertices_so_far, std::vector<int>& polygon) {
  polygon.clear();
  for (std::string_view token = next_token(rest); !token.empty(); token = next_token(rest)) {
    const std::string_view index_text = token.substr(0, token.find('/'));
    long long index;
    if (!parse_integer(index_text, index))
      fail_at_line(file, line, "expected a vertex index, got " + quoted(token));
    if (index == 0) fail_at_line(file, line, "vertex index 0 (OBJ indices start at 1)");
    const long long resolved =
        index > 0 ? index - 1 : static_cast<long long>(vertices_so_far) + index;
    if (resolved < 0 || resolved > std::numeric_limits<int>::max())
      fail_at_line(file, line,
                   "vertex index " + std::to_string(index) + " out of range (" +
                       std::to_string(vertices_so_far) + " vertices read so far)");
    polygon.push_back(static_cast<int>(resolved));
  }
  if (polygon.size() < 3)
    fail_at_line(file, line,
                 "face with " + std::to_string(polygon.size()) + " vertices (needs at least 3)");
}

}  // namespace

Surface read_obj(const fs::path& file, std::string_view text) {
  SurfaceBuilder builder;
  // Line of each triangle's face statement, for the range check once all vertices are known
  // (positive indices may refer to vertices that come later in the file).
  std::vector<std::size_t> triangle_lines;
  std::vector<int> polygon;

  LineReader lines(text);
  std::string_view line;
  while (lines.next(line)) {
    std::string_view rest = line;
    const std::string_view keyword = next_token(rest);
    if (keyword.empty() || keyword.front() == '#') continue;
    if (keyword == "v") {
      read_vertex(file, lines.line_number(), rest, builder);
    } else if (keyword == "f") {
      read_face(file, lines.line_number(), rest, builder.num_vertices(), polygon);
      builder.add_polygon(polygon);
      triangle_lines.resize(builder.corners.size() / 3, lines.line_number());
    } else if (!is_ignored_statement(keyword)) {
      fail_at_line(file, lines.line_number(), "unknown OBJ statement " + quoted(keyword));
    }
  }

  const auto n = static_cast<long long>(builder.num_vertices());
  for (std::size_t corner = 0; corner < builder.corners.size(); ++corner)
    if (builder.corners[corner] >= n)
      fail_at_line(file, triangle_lines[corner / 3],
                   "vertex index " + std::to_string(builder.corners[corner] + 1) +
                       " out of range (file has " + std::to_string(n) + " vertices)");
  return builder.finish();
}

void write_obj(std::string& out, const Surface& surface, const std::string& unit_name) {
  out += "# msfem closed surface, coordinates in " + unit_name + "\n";
  for (Eigen::Index i = 0; i < surface.num_vertices(); ++i) {
    out += 'v';
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      append_number(out, surface.vertices(i, k));
    }
    out += '\n';
  }
  for (Eigen::Index t = 0; t < surface.num_triangles(); ++t) {
    out += 'f';
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      append_number(out, static_cast<long long>(surface.triangles(t, k)) + 1);
    }
    out += '\n';
  }
}

}  // namespace msfem::cases::detail
