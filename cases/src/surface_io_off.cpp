// Object File Format (Geomview OFF): "OFF", then "vertices faces edges", then one vertex per line,
// then one face per line as "n i1 ... in". '#' starts a comment anywhere.

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "surface_io_detail.hpp"

namespace msfem::cases::detail {

namespace {

/// Lines with comments removed and blank lines skipped.
class OffLines {
 public:
  explicit OffLines(std::string_view text) : lines_(text) {}

  bool next(std::string_view& line) {
    while (lines_.next(line)) {
      line = line.substr(0, line.find('#'));
      std::string_view probe = line;
      if (!next_token(probe).empty()) return true;
    }
    return false;
  }
  std::size_t line_number() const { return lines_.line_number(); }

 private:
  LineReader lines_;
};

/// "OFF" and its variants with per-vertex extras (C colour, N normal, ST texture coordinates),
/// whose extra numbers follow x y z and are ignored. 4OFF and nOFF change the dimension: refused.
bool is_off_keyword(std::string_view keyword) {
  if (keyword.size() < 3 || keyword.substr(keyword.size() - 3) != "OFF") return false;
  return keyword.substr(0, keyword.size() - 3).find_first_not_of("STCN") == std::string_view::npos;
}

long long read_count(const fs::path& file, std::size_t line, std::string_view& rest,
                     const char* what) {
  const std::string_view token = next_token(rest);
  long long count;
  if (token.empty()) fail_at_line(file, line, std::string("missing ") + what + " count");
  if (!parse_integer(token, count) || count < 0)
    fail_at_line(file, line, std::string("bad ") + what + " count " + quoted(token));
  return count;
}

}  // namespace

Surface read_off(const fs::path& file, std::string_view text) {
  OffLines lines(text);
  std::string_view line;
  if (!lines.next(line)) fail(file, "no 'OFF' header");
  std::string_view rest = line;
  const std::string_view keyword = next_token(rest);
  if (!is_off_keyword(keyword))
    fail_at_line(file, lines.line_number(), "expected 'OFF' header, got " + quoted(keyword));
  // The counts may share the header's line ("OFF 8 12 0").
  std::string_view probe = rest;
  if (next_token(probe).empty()) {
    if (!lines.next(line)) fail_at_line(file, lines.line_number(), "missing vertex/face counts");
    rest = line;
  }
  const std::size_t counts_line = lines.line_number();
  const long long num_vertices = read_count(file, counts_line, rest, "vertex");
  const long long num_faces = read_count(file, counts_line, rest, "face");
  if (num_vertices > std::numeric_limits<int>::max())
    fail_at_line(file, counts_line, "too many vertices");

  SurfaceBuilder builder;
  // Reserve no more than the text could hold, so that a corrupt count cannot exhaust memory.
  builder.xyz.reserve(3 * std::min<std::size_t>(num_vertices, text.size() / 6));
  for (long long i = 0; i < num_vertices; ++i) {
    if (!lines.next(line))
      fail_at_line(file, lines.line_number(),
                   "file ends after " + std::to_string(i) + " of " + std::to_string(num_vertices) +
                       " vertices");
    rest = line;
    double xyz[3];
    for (double& value : xyz) {
      const std::string_view token = next_token(rest);
      if (token.empty()) fail_at_line(file, lines.line_number(), "vertex needs three coordinates");
      if (!parse_double(token, value))
        fail_at_line(file, lines.line_number(), "expected a number, got " + quoted(token));
      if (!std::isfinite(value)) fail_at_line(file, lines.line_number(), "non-finite coordinate");
    }
    builder.add_vertex(xyz[0], xyz[1], xyz[2]);
  }

  std::vector<int> polygon;
  for (long long f = 0; f < num_faces; ++f) {
    if (!lines.next(line))
      fail_at_line(
          file, lines.line_number(),
          "file ends after " + std::to_string(f) + " of " + std::to_string(num_faces) + " faces");
    const std::size_t number = lines.line_number();
    rest = line;
    const long long corners = read_count(file, number, rest, "face corner");
    if (corners < 3)
      fail_at_line(file, number,
                   "face with " + std::to_string(corners) + " vertices (needs at least 3)");
    polygon.clear();
    for (long long k = 0; k < corners; ++k) {
      const std::string_view token = next_token(rest);
      long long index;
      if (token.empty())
        fail_at_line(file, number,
                     "face lists " + std::to_string(k) + " of " + std::to_string(corners) +
                         " vertex indices");
      if (!parse_integer(token, index))
        fail_at_line(file, number, "expected a vertex index, got " + quoted(token));
      if (index < 0 || index >= num_vertices)
        fail_at_line(file, number,
                     "vertex index " + std::to_string(index) + " out of range [0, " +
                         std::to_string(num_vertices) + ")");
      polygon.push_back(static_cast<int>(index));
    }
    // Anything after the indices is a face colour: ignored.
    builder.add_polygon(polygon);
  }
  return builder.finish();
}

void write_off(std::string& out, const Surface& surface, const std::string& unit_name) {
  out += "OFF\n# msfem closed surface, coordinates in " + unit_name + "\n";
  append_number(out, static_cast<long long>(surface.num_vertices()));
  out += ' ';
  append_number(out, static_cast<long long>(surface.num_triangles()));
  out += " 0\n";
  for (Eigen::Index i = 0; i < surface.num_vertices(); ++i) {
    for (int k = 0; k < 3; ++k) {
      if (k > 0) out += ' ';
      append_number(out, surface.vertices(i, k));
    }
    out += '\n';
  }
  for (Eigen::Index t = 0; t < surface.num_triangles(); ++t) {
    out += '3';
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      append_number(out, static_cast<long long>(surface.triangles(t, k)));
    }
    out += '\n';
  }
}

}  // namespace msfem::cases::detail
