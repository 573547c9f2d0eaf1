// Format dispatch, unit conversion and the helpers every surface format shares. The formats
// themselves live in surface_io_{obj,stl,off,ply}.cpp.

#include "msfem/cases/surface_io.hpp"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <system_error>

#include "msfem/cases/errors.hpp"
#include "msfem/cases/x3d.hpp"
#include "surface_io_detail.hpp"

namespace msfem::cases {

namespace detail {

void fail(const fs::path& file, const std::string& what) {
  throw InputError(file.string() + ": " + what);
}

void fail_at_line(const fs::path& file, std::size_t line, const std::string& what) {
  throw InputError(file.string() + ":" + std::to_string(line) + ": " + what);
}

std::string quoted(std::string_view token) {
  constexpr std::size_t max_shown = 40;
  std::string shown;
  for (char c : token.substr(0, max_shown)) {
    const auto u = static_cast<unsigned char>(c);
    shown += (u >= 0x20 && u < 0x7f) ? c : '?';
  }
  if (token.size() > max_shown) shown += "...";
  return "'" + shown + "'";
}

std::string read_whole_file(const fs::path& file) {
  struct Closer {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  std::unique_ptr<std::FILE, Closer> in(std::fopen(file.c_str(), "rb"));
  if (!in) fail(file, std::string("cannot open: ") + std::strerror(errno));
  std::string data;
  char buffer[1 << 16];
  std::size_t got;
  while ((got = std::fread(buffer, 1, sizeof buffer, in.get())) > 0)
    data.append(buffer, got);
  // A directory opens on Linux but fails here with EISDIR.
  if (std::ferror(in.get())) fail(file, std::string("cannot read: ") + std::strerror(errno));
  return data;
}

bool LineReader::next(std::string_view& line) {
  if (pos_ >= text_.size()) return false;
  std::size_t end = text_.find('\n', pos_);
  if (end == std::string_view::npos) end = text_.size();
  line = text_.substr(pos_, end - pos_);
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  pos_ = end + 1;
  ++line_number_;
  return true;
}

namespace {
bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}
}  // namespace

std::string_view next_token(std::string_view& rest) {
  std::size_t begin = 0;
  while (begin < rest.size() && (is_space(rest[begin]) || rest[begin] == '\n'))
    ++begin;
  std::size_t end = begin;
  while (end < rest.size() && !is_space(rest[end]) && rest[end] != '\n')
    ++end;
  const std::string_view token = rest.substr(begin, end - begin);
  rest.remove_prefix(end);
  return token;
}

bool parse_double(std::string_view token, double& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  if (token.empty()) return false;
  const char* end = token.data() + token.size();
  const auto result = std::from_chars(token.data(), end, value);
  // Out-of-range magnitudes (1e999) report result_out_of_range and leave value unset; call them
  // infinite so that the caller reports a non-finite coordinate.
  if (result.ec == std::errc::result_out_of_range && result.ptr == end) {
    value = HUGE_VAL;
    return true;
  }
  return result.ec == std::errc() && result.ptr == end;
}

bool parse_integer(std::string_view token, long long& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  if (token.empty()) return false;
  const char* end = token.data() + token.size();
  const auto result = std::from_chars(token.data(), end, value);
  return result.ec == std::errc() && result.ptr == end;
}

void SurfaceBuilder::add_vertex(double x, double y, double z) {
  xyz.push_back(x);
  xyz.push_back(y);
  xyz.push_back(z);
}

void SurfaceBuilder::add_polygon(const std::vector<int>& polygon) {
  for (std::size_t k = 1; k + 1 < polygon.size(); ++k) {
    corners.push_back(polygon[0]);
    corners.push_back(polygon[k]);
    corners.push_back(polygon[k + 1]);
  }
}

Surface SurfaceBuilder::finish() const {
  Surface surface;
  const auto n = static_cast<Eigen::Index>(num_vertices());
  const auto m = static_cast<Eigen::Index>(corners.size() / 3);
  surface.vertices.resize(n, 3);
  for (Eigen::Index i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k)
      surface.vertices(i, k) = xyz[3 * i + k];
  surface.triangles.resize(m, 3);
  for (Eigen::Index t = 0; t < m; ++t)
    for (int k = 0; k < 3; ++k)
      surface.triangles(t, k) = corners[3 * t + k];
  return surface;
}

void append_number(std::string& out, double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  out.append(buffer, result.ptr);
}

void append_number(std::string& out, long long value) {
  char buffer[24];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  out.append(buffer, result.ptr);
}

void append_le_u32(std::string& out, std::uint32_t value) {
  for (int byte = 0; byte < 4; ++byte)
    out += static_cast<char>((value >> (8 * byte)) & 0xffu);
}

void append_le_f32(std::string& out, float value) {
  std::uint32_t bits;
  std::memcpy(&bits, &value, sizeof bits);
  append_le_u32(out, bits);
}

void append_le_f64(std::string& out, double value) {
  std::uint64_t bits;
  std::memcpy(&bits, &value, sizeof bits);
  for (int byte = 0; byte < 8; ++byte)
    out += static_cast<char>((bits >> (8 * byte)) & 0xffu);
}

}  // namespace detail

namespace {

namespace fs = std::filesystem;

/// File units per metre as an exact integer (1, 100, 1000). Dividing by it when reading gives the
/// correctly rounded metre value of what the file says, which multiplying by the inexact 1e-3 would
/// not.
double units_per_metre(LengthUnit unit) {
  switch (unit) {
    case LengthUnit::metre:
      return 1.0;
    case LengthUnit::centimetre:
      return 100.0;
    case LengthUnit::millimetre:
      return 1000.0;
  }
  throw std::logic_error("units_per_metre: invalid LengthUnit");
}

/// Refuses what no reader would take back: nothing to write, non-finite coordinates (also after
/// conversion to the file's unit), indices outside the vertex array.
void check_writable(const fs::path& file, const Surface& in_unit, const std::string& unit_name) {
  if (in_unit.num_triangles() == 0) detail::fail(file, "cannot write a surface with no triangles");
  for (Eigen::Index i = 0; i < in_unit.num_vertices(); ++i)
    if (!in_unit.vertices.row(i).allFinite())
      detail::fail(file, "cannot write vertex #" + std::to_string(i) +
                             ": non-finite coordinate (in " + unit_name + ")");
  const Eigen::Index n = in_unit.num_vertices();
  for (Eigen::Index t = 0; t < in_unit.num_triangles(); ++t)
    for (int k = 0; k < 3; ++k)
      if (in_unit.triangles(t, k) < 0 || in_unit.triangles(t, k) >= n)
        detail::fail(file, "cannot write triangle #" + std::to_string(t) + ": vertex index " +
                               std::to_string(in_unit.triangles(t, k)) + " out of range [0, " +
                               std::to_string(n) + ")");
}

/// Coordinates a million metres out, or a surface less than a micrometre across, are a wrong unit
/// or a corrupt file; CGAL's predicates overflow or divide by zero on them (the alpha wrap dies
/// with SIGFPE), so every reader's caller is spared them here.
void check_scale(const fs::path& file, const Surface& s) {
  constexpr double max_coordinate = 1e6, min_span = 1e-6;
  const auto point = [&](Eigen::Index v) {
    char text[96];
    std::snprintf(text, sizeof text, "(%g, %g, %g)", s.vertices(v, 0), s.vertices(v, 1),
                  s.vertices(v, 2));
    return std::string(text);
  };
  for (Eigen::Index v = 0; v < s.num_vertices(); ++v)
    if (!(s.vertices.row(v).cwiseAbs().maxCoeff() <= max_coordinate))
      detail::fail(file, "vertex " + std::to_string(v + 1) + " (of " +
                             std::to_string(s.num_vertices()) + ", in file order) is at " +
                             point(v) +
                             " m, more than 1e6 m from the origin: a wrong unit or a corrupt file");
  const auto box = bounding_box(s);
  const double span = (box.row(1) - box.row(0)).stableNorm();
  if (!(span >= min_span)) {
    char text[160];
    std::snprintf(text, sizeof text,
                  "the surface spans %g m (its bounding-box diagonal), less than 1e-6 m: a wrong "
                  "unit or a corrupt file",
                  span);
    detail::fail(file, text);
  }
}

}  // namespace

SurfaceFormat surface_format_for(const fs::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (extension == ".obj") return SurfaceFormat::obj;
  if (extension == ".stl") return SurfaceFormat::stl;
  if (extension == ".off") return SurfaceFormat::off;
  if (extension == ".ply") return SurfaceFormat::ply;
  if (extension == ".x3d") return SurfaceFormat::x3d;
  const std::string shown = extension.empty() ? "no extension" : "'" + extension + "'";
  detail::fail(path,
               "unknown surface format " + shown + " (expected .obj, .stl, .off, .ply, .x3d)");
}

Surface read_surface(const fs::path& path, LengthUnit unit) {
  const SurfaceFormat format = surface_format_for(path);
  const std::string data = detail::read_whole_file(path);
  if (data.empty()) detail::fail(path, "empty file");
  Surface surface;
  switch (format) {
    case SurfaceFormat::obj:
      surface = detail::read_obj(path, data);
      break;
    case SurfaceFormat::stl:
      surface = detail::read_stl(path, data);
      break;
    case SurfaceFormat::off:
      surface = detail::read_off(path, data);
      break;
    case SurfaceFormat::ply:
      surface = detail::read_ply(path, data);
      break;
    case SurfaceFormat::x3d:
      surface = read_x3d_surface_bytes(path, data);
      break;
  }
  if (surface.num_triangles() == 0) detail::fail(path, "no triangles");
  if (unit != LengthUnit::metre) surface.vertices /= units_per_metre(unit);
  check_scale(path, surface);
  return surface;
}

void write_surface(const fs::path& path, const Surface& surface,
                   const SurfaceWriteOptions& options) {
  const SurfaceFormat format = surface_format_for(path);
  const std::string unit_name = to_string(options.unit);
  Surface in_unit{surface.vertices * units_per_metre(options.unit), surface.triangles};
  check_writable(path, in_unit, unit_name);

  std::string bytes;
  switch (format) {
    case SurfaceFormat::obj:
      detail::write_obj(bytes, in_unit, unit_name);
      break;
    case SurfaceFormat::stl:
      detail::write_stl(path, bytes, in_unit, unit_name, options.binary);
      break;
    case SurfaceFormat::off:
      detail::write_off(bytes, in_unit, unit_name);
      break;
    case SurfaceFormat::ply:
      detail::write_ply(bytes, in_unit, unit_name, options.binary);
      break;
    case SurfaceFormat::x3d:
      bytes =
          "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<X3D profile=\"Interchange\" "
          "version=\"3.3\">\n  <head>\n    <meta name=\"unit\" content=\"" +
          unit_name + "\"/>\n  </head>\n  <Scene>\n" +
          x3d_shape("surface", in_unit.vertices, in_unit.triangles, Eigen::MatrixX3d(), "",
                    "    ") +
          "  </Scene>\n</X3D>\n";
      break;
  }
  // Same folder, so the rename is atomic; the pid keeps concurrent writers apart.
  fs::path temporary = path;
  temporary += ".tmp." + std::to_string(::getpid());
  detail::put_on_disk(path, temporary, bytes);
}

namespace detail {

void put_on_disk(const fs::path& file, const fs::path& temporary, const std::string& bytes) {
  std::FILE* out = std::fopen(temporary.c_str(), "wb");
  if (!out) detail::fail(file, std::string("cannot write: ") + std::strerror(errno));
  const bool written = std::fwrite(bytes.data(), 1, bytes.size(), out) == bytes.size();
  const int write_errno = errno;
  const bool closed = std::fclose(out) == 0;
  const int close_errno = errno;
  std::error_code ignored;
  if (!written || !closed) {
    fs::remove(temporary, ignored);
    detail::fail(
        file, std::string("cannot write: ") + std::strerror(!written ? write_errno : close_errno));
  }
  std::error_code renamed;
  fs::rename(temporary, file, renamed);
  if (renamed) {
    fs::remove(temporary, ignored);
    detail::fail(file, "cannot write: " + renamed.message());
  }
}

}  // namespace detail

}  // namespace msfem::cases
