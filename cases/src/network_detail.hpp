#pragma once

// Shared by the network readers and writers (network_*.cpp); not installed.
//
// Each format reader turns the file's bytes into a NetworkFile plus where each element came from
// (a VTK cell or point id, an Xsp line), so that network_file.cpp can check every rule once, for
// all formats, and still name the element the way the file does. Sizes read from a file are
// checked against the bytes left before anything is allocated for them: a fuzzer feeds these.

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "msfem/cases/network_file.hpp"

namespace msfem::cases::detail {

namespace fs = std::filesystem;

// ---- what was read, and where it came from ----

struct NetworkOrigin {
  /// Xsp: each element is a line of the file (springs and masses counted from 1, as the file does);
  /// VTK: a cell or a point id, from 0 as VTK does. Empty vectors (a network built in memory): the
  /// element's own index.
  bool by_line = false;
  std::vector<long long> spring, triangle, tetrahedron, wedge, point;
};

struct ReadNetwork {
  NetworkFile network;
  NetworkOrigin origin;
};

std::string spring_label(const NetworkOrigin& origin, Eigen::Index spring);
std::string point_label(const NetworkOrigin& origin, Eigen::Index point);
std::string triangle_label(const NetworkOrigin& origin, Eigen::Index triangle);
std::string tetrahedron_label(const NetworkOrigin& origin, Eigen::Index tetrahedron);
std::string wedge_label(const NetworkOrigin& origin, Eigen::Index wedge);

/// Every rule read_network promises (ids in range, no zero-length spring, positive finite
/// coefficients, triangles on springs, array sizes that match); throws the first fault found.
void validate_network(const fs::path& file, const NetworkFile& network,
                      const NetworkOrigin& origin);

/// A number as it reads back exactly: shortest round-trip decimal.
std::string number_text(double value);

// ---- VTK data arrays, shared by the XML and the legacy readers ----

enum class ValueType {
  int8,
  uint8,
  int16,
  uint16,
  int32,
  uint32,
  int64,
  uint64,
  float32,
  float64,
  string
};

std::size_t size_of(ValueType type);
bool is_integer(ValueType type);
bool is_real(ValueType type);
/// The XML name ("Float64"); the legacy names map onto the same types in network_vtk_legacy.cpp.
const char* xml_type_name(ValueType type);
bool parse_xml_type(std::string_view name, ValueType& type);

struct VtkArray {
  std::string name;
  ValueType type = ValueType::float64;
  long long components = 1;
  std::vector<double> reals;        ///< Float32 (already rounded to float) and Float64
  std::vector<long long> integers;  ///< every integer type
  std::vector<std::string> strings;

  std::size_t size() const;
  double value(std::size_t i) const {
    return is_integer(type) ? static_cast<double>(integers[i]) : reals[i];
  }
};

/// A file's bytes [begin, end) to be replaced by `text`: how a coefficient rewrite keeps every
/// other byte of the user's file.
struct Splice {
  std::size_t begin, end;
  std::string text;
};

/// `bytes` with every splice applied (they must not overlap).
std::string spliced(std::string_view bytes, std::vector<Splice> splices);

/// A cell array's values with the springs' replaced: `cells` values, those of `original` (0 where
/// it is absent), and per_spring[s] at the cell spring_cells[s]: what a coefficient rewrite writes.
std::vector<double> with_spring_values(const VtkArray* original, std::size_t cells,
                                       const std::vector<long long>& spring_cells,
                                       const Eigen::VectorXd& per_spring);

/// Appends `count` words of `type` from `bytes` (exactly count * size_of(type) of them) to
/// `array`; false when a UInt64 does not fit a signed 64-bit integer.
bool decode_words(std::string_view bytes, std::size_t count, ValueType type, bool big_endian,
                  VtkArray& array);

/// Parses one whitespace-separated token as a value of `type` into `array`; false when it is not
/// one (not a number, a fraction for an integer type, out of the type's range).
bool parse_value(std::string_view token, ValueType type, VtkArray& array);

/// An unstructured grid as VTK stores it, before msfem's reading of it.
struct VtkGrid {
  std::vector<double> points;         ///< x, y, z per point
  std::vector<long long> cell_begin;  ///< cells + 1 entries into connectivity
  std::vector<long long> connectivity;
  std::vector<long long> cell_types;
  std::vector<VtkArray> cell_data, point_data, field_data;
};

/// The network a VTK grid describes; refuses cell types and arrays msfem does not read, by name.
ReadNetwork network_from_vtk(const fs::path& file, const VtkGrid& grid);

/// The most values any encoding could hold in `file_size` bytes (zlib inflates at most 1032:1):
/// a count above it is refused before anything is allocated for it.
std::size_t max_values_for(std::size_t file_size);

// ---- base64 and zlib ----

/// Base64 as VTK writes it: whitespace anywhere, and padding at the end of any 4-character group,
/// because VTK encodes a compressed array's header and its blocks as separate base64 strings.
class Base64Reader {
 public:
  explicit Base64Reader(std::string_view text) : text_(text) {}
  /// Appends the next `n` bytes to `out`; false when the text ends first or is not base64.
  bool read(std::size_t n, std::string& out);
  /// No more than this many bytes are left.
  std::size_t bound() const { return (text_.size() - pos_) / 4 * 3 + (have_ - used_); }

 private:
  bool next_group();
  std::string_view text_;
  std::size_t pos_ = 0;
  unsigned char group_[3] = {};
  std::size_t have_ = 0, used_ = 0;  ///< bytes decoded in group_, and taken from it
};

/// Inflates one zlib stream that must give exactly `size` bytes, appended to `out`. Returns an
/// empty string on success, else what went wrong (zlib's message).
std::string inflate_exact(std::string_view compressed, std::size_t size, std::string& out);

// ---- the formats ----

ReadNetwork read_vtu(const fs::path& file, std::string_view bytes);
ReadNetwork read_vtk_legacy(const fs::path& file, std::string_view bytes);
ReadNetwork read_xsp(const fs::path& file, std::string_view bytes);

/// `network` is already validated.
void write_vtu(std::string& out, const NetworkFile& network);
void write_xsp(const fs::path& file, std::string& out, const NetworkFile& network);

/// The original file's bytes with the springs' stiffness (and damping, when given) replaced; the
/// values are per spring, in the order the reader returns them, and already checked.
std::string vtu_with_coefficients(const fs::path& file, std::string_view bytes,
                                  const Eigen::VectorXd& stiffness,
                                  const std::optional<Eigen::VectorXd>& damping);
std::string vtk_legacy_with_coefficients(const fs::path& file, std::string_view bytes,
                                         const Eigen::VectorXd& stiffness,
                                         const std::optional<Eigen::VectorXd>& damping);
std::string xsp_with_coefficients(const fs::path& file, std::string_view bytes,
                                  const Eigen::VectorXd& stiffness,
                                  const std::optional<Eigen::VectorXd>& damping);

/// What the VTK readers accept for a cell or point array: one message for both formats.
std::string unread_array(const std::string& where, const std::string& name);
[[noreturn]] void refuse_array(const fs::path& file, const std::string& where,
                               const std::string& name);

}  // namespace msfem::cases::detail
