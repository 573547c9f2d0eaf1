#pragma once

// Shared by the per-format surface readers and writers (surface_io_*.cpp); not installed.
//
// Readers get the whole file in memory (the largest surfaces are a few MB) and return the surface
// in the file's own units; read_surface converts to metres afterwards. Writers append to a string
// that write_surface puts on disk in one go, so a format error never leaves a partial file.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "msfem/cases/surface.hpp"

namespace msfem::cases::detail {

namespace fs = std::filesystem;

// ---- errors: one line, "<file>: what" or "<file>:<line>: what" ----

[[noreturn]] void fail(const fs::path& file, const std::string& what);
[[noreturn]] void fail_at_line(const fs::path& file, std::size_t line, const std::string& what);

/// A token quoted for an error message, cut short and stripped of control characters so that the
/// message stays on one line.
std::string quoted(std::string_view token);

// ---- reading ----

/// The whole file as bytes; throws "<file>: cannot open: <strerror>" (or "cannot read").
std::string read_whole_file(const fs::path& file);

/// Splits text into lines, dropping the '\r' of CRLF files, and counts them from 1.
class LineReader {
 public:
  explicit LineReader(std::string_view text) : text_(text) {}
  bool next(std::string_view& line);
  std::size_t line_number() const { return line_number_; }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  std::size_t line_number_ = 0;
};

/// Removes and returns the next whitespace-separated token of `rest`; empty when none is left.
std::string_view next_token(std::string_view& rest);

/// Whole-token number parsing (std::from_chars: no locale, no allocation). A leading '+' is
/// accepted because some exporters write one. "nan" and "inf" parse, so that the caller can report
/// them as non-finite rather than as non-numeric.
bool parse_double(std::string_view token, double& value);
bool parse_integer(std::string_view token, long long& value);

/// Flat arrays filled while reading, turned into a Surface at the end.
struct SurfaceBuilder {
  std::vector<double> xyz;
  std::vector<int> corners;  ///< three per triangle

  std::size_t num_vertices() const { return xyz.size() / 3; }
  void add_vertex(double x, double y, double z);
  /// Fan-triangulates polygon (a, b, c, ...) as (a, b, c), (a, c, d), ...; keeps the winding.
  void add_polygon(const std::vector<int>& polygon);
  Surface finish() const;
};

/// The surface in the file's units; the format is that of the file's name.
Surface read_obj(const fs::path& file, std::string_view text);
Surface read_stl(const fs::path& file, std::string_view data);
Surface read_off(const fs::path& file, std::string_view text);
Surface read_ply(const fs::path& file, std::string_view data);

// ---- writing: the surface is already in the file's unit and checked finite and in range ----

/// Shortest decimal that reads back to the same double (std::to_chars), so text round trips are
/// exact, as %.17g would be, with fewer digits.
void append_number(std::string& out, double value);
void append_number(std::string& out, long long value);

/// Little-endian binary values (the STL and PLY binary writers' byte order on any host).
void append_le_u32(std::string& out, std::uint32_t value);
void append_le_f32(std::string& out, float value);
void append_le_f64(std::string& out, double value);

void write_obj(std::string& out, const Surface& surface, const std::string& unit_name);
void write_off(std::string& out, const Surface& surface, const std::string& unit_name);
void write_stl(const fs::path& file, std::string& out, const Surface& surface,
               const std::string& unit_name, bool binary);
void write_ply(std::string& out, const Surface& surface, const std::string& unit_name, bool binary);

/// Writes all bytes to `temporary` and renames it to `file` (readers see the old file or the new,
/// never half of one); on failure removes `temporary` and throws InputError naming `file`.
void put_on_disk(const fs::path& file, const fs::path& temporary, const std::string& bytes);

}  // namespace msfem::cases::detail
