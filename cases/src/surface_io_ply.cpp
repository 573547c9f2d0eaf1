// Stanford PLY, ASCII and binary (either byte order). The header declares every element and typed
// property, so properties and elements other than vertex x/y/z and face vertex_indices (normals,
// colours, edges, materials) can be stepped over exactly, whatever their types.

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <string>

#include "surface_io_detail.hpp"

namespace msfem::cases::detail {

namespace {

enum class PlyType { int8, uint8, int16, uint16, int32, uint32, float32, float64 };
enum class PlyEncoding { ascii, binary_little_endian, binary_big_endian };

bool parse_type(std::string_view name, PlyType& type) {
  // Both the original names and the sized aliases later writers (VTK, Open3D) use.
  static const std::pair<std::string_view, PlyType> names[] = {
      {"char", PlyType::int8},      {"int8", PlyType::int8},       {"uchar", PlyType::uint8},
      {"uint8", PlyType::uint8},    {"short", PlyType::int16},     {"int16", PlyType::int16},
      {"ushort", PlyType::uint16},  {"uint16", PlyType::uint16},   {"int", PlyType::int32},
      {"int32", PlyType::int32},    {"uint", PlyType::uint32},     {"uint32", PlyType::uint32},
      {"float", PlyType::float32},  {"float32", PlyType::float32}, {"double", PlyType::float64},
      {"float64", PlyType::float64}};
  for (const auto& [known, known_type] : names)
    if (name == known) {
      type = known_type;
      return true;
    }
  return false;
}

std::size_t size_of(PlyType type) {
  switch (type) {
    case PlyType::int8:
    case PlyType::uint8:
      return 1;
    case PlyType::int16:
    case PlyType::uint16:
      return 2;
    case PlyType::int32:
    case PlyType::uint32:
    case PlyType::float32:
      return 4;
    case PlyType::float64:
      return 8;
  }
  return 0;
}

bool is_integer(PlyType type) {
  return type != PlyType::float32 && type != PlyType::float64;
}

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::float32;  ///< the item type for a list
  bool is_list = false;
  PlyType count_type = PlyType::uint8;
};

struct PlyElement {
  std::string name;
  long long count = 0;
  std::vector<PlyProperty> properties;
  std::size_t line = 0;  ///< where the header declares it, for errors about its properties
};

struct PlyHeader {
  PlyEncoding encoding = PlyEncoding::ascii;
  std::vector<PlyElement> elements;
  std::size_t body_offset = 0;      ///< first byte after "end_header\n"
  std::size_t body_first_line = 0;  ///< line number of that byte, for ASCII errors
};

PlyHeader read_header(const fs::path& file, std::string_view data) {
  PlyHeader header;
  LineReader lines(data);
  std::string_view line;
  if (!lines.next(line) || line != "ply") fail(file, "not a PLY file: first line is not 'ply'");
  bool have_format = false;
  while (lines.next(line)) {
    const std::size_t number = lines.line_number();
    std::string_view rest = line;
    const std::string_view keyword = next_token(rest);
    if (keyword == "format") {
      const std::string_view encoding = next_token(rest);
      if (encoding == "ascii")
        header.encoding = PlyEncoding::ascii;
      else if (encoding == "binary_little_endian")
        header.encoding = PlyEncoding::binary_little_endian;
      else if (encoding == "binary_big_endian")
        header.encoding = PlyEncoding::binary_big_endian;
      else
        fail_at_line(file, number, "unknown PLY format " + quoted(encoding));
      have_format = true;
    } else if (keyword == "element") {
      PlyElement element;
      element.name = std::string(next_token(rest));
      const std::string_view count = next_token(rest);
      if (element.name.empty() || !parse_integer(count, element.count) || element.count < 0)
        fail_at_line(file, number, "expected 'element <name> <count>'");
      element.line = number;
      header.elements.push_back(std::move(element));
    } else if (keyword == "property") {
      if (header.elements.empty()) fail_at_line(file, number, "property before any element");
      PlyProperty property;
      std::string_view type = next_token(rest);
      if (type == "list") {
        property.is_list = true;
        const std::string_view count_type = next_token(rest);
        if (!parse_type(count_type, property.count_type) || !is_integer(property.count_type))
          fail_at_line(file, number, "bad list count type " + quoted(count_type));
        type = next_token(rest);
      }
      if (!parse_type(type, property.type))
        fail_at_line(file, number, "unknown property type " + quoted(type));
      property.name = std::string(next_token(rest));
      if (property.name.empty()) fail_at_line(file, number, "property without a name");
      header.elements.back().properties.push_back(std::move(property));
    } else if (keyword == "end_header") {
      if (!have_format) fail_at_line(file, number, "no 'format' line before end_header");
      // The body starts after this line's '\r\n' or '\n'.
      std::size_t offset = static_cast<std::size_t>(line.data() - data.data()) + line.size();
      if (offset < data.size() && data[offset] == '\r') ++offset;
      header.body_offset = std::min(offset + 1, data.size());
      header.body_first_line = number + 1;
      return header;
    } else if (keyword != "comment" && keyword != "obj_info" && !keyword.empty()) {
      fail_at_line(file, number, "unknown PLY header line " + quoted(keyword));
    }
  }
  fail(file, "PLY header has no 'end_header'");
}

/// ASCII body: whitespace-separated tokens, counted by line for error messages.
class AsciiBody {
 public:
  AsciiBody(const fs::path& file, std::string_view text, std::size_t first_line)
      : file_(file), rest_(text), line_(first_line) {}

  void at(const std::string& element, long long index) {
    element_ = &element;
    index_ = index;
  }

  double read(PlyType type) {
    const std::string_view token = next();
    if (token.empty())
      error("file ends inside " + *element_ + " #" + std::to_string(index_) + " of the body");
    if (is_integer(type)) {
      long long value;
      if (!parse_integer(token, value)) error("expected an integer, got " + quoted(token));
      return static_cast<double>(value);
    }
    double value;
    if (!parse_double(token, value)) error("expected a number, got " + quoted(token));
    return value;
  }

  void skip(PlyType type, long long count) {
    for (long long k = 0; k < count; ++k)
      read(type);
  }

  [[noreturn]] void error(const std::string& what) const { fail_at_line(file_, line_, what); }

 private:
  std::string_view next() {
    std::size_t begin = 0;
    while (begin < rest_.size() && std::isspace(static_cast<unsigned char>(rest_[begin]))) {
      if (rest_[begin] == '\n') ++line_;
      ++begin;
    }
    rest_.remove_prefix(begin);
    std::string_view probe = rest_;
    const std::string_view token = next_token(probe);
    rest_.remove_prefix(token.size());
    return token;
  }

  const fs::path& file_;
  std::string_view rest_;
  std::size_t line_;
  const std::string* element_ = nullptr;
  long long index_ = 0;
};

/// Binary body in either byte order; errors name the element and its zero-based index.
class BinaryBody {
 public:
  BinaryBody(const fs::path& file, std::string_view data, bool big_endian)
      : file_(file), data_(data), big_endian_(big_endian) {}

  void at(const std::string& element, long long index) {
    element_ = &element;
    index_ = index;
  }

  double read(PlyType type) {
    const std::size_t size = size_of(type);
    if (data_.size() - pos_ < size) error("file ends inside the element (truncated PLY)");
    std::uint64_t raw = 0;
    for (std::size_t k = 0; k < size; ++k) {
      const std::size_t byte = big_endian_ ? k : size - 1 - k;
      raw = (raw << 8) | static_cast<unsigned char>(data_[pos_ + byte]);
    }
    pos_ += size;
    switch (type) {
      case PlyType::int8:
        return static_cast<std::int8_t>(raw);
      case PlyType::uint8:
        return static_cast<std::uint8_t>(raw);
      case PlyType::int16:
        return static_cast<std::int16_t>(raw);
      case PlyType::uint16:
        return static_cast<std::uint16_t>(raw);
      case PlyType::int32:
        return static_cast<std::int32_t>(raw);
      case PlyType::uint32:
        return static_cast<std::uint32_t>(raw);
      case PlyType::float32: {
        const auto bits = static_cast<std::uint32_t>(raw);
        float value;
        std::memcpy(&value, &bits, sizeof value);
        return value;
      }
      case PlyType::float64: {
        double value;
        std::memcpy(&value, &raw, sizeof value);
        return value;
      }
    }
    return 0;
  }

  void skip(PlyType type, long long count) {
    const std::size_t size = size_of(type);
    if (static_cast<std::size_t>(count) > (data_.size() - pos_) / size)
      error("file ends inside the element (truncated PLY)");
    pos_ += static_cast<std::size_t>(count) * size;
  }

  [[noreturn]] void error(const std::string& what) const {
    fail(file_, *element_ + " #" + std::to_string(index_) + ": " + what);
  }

 private:
  const fs::path& file_;
  std::string_view data_;
  std::size_t pos_ = 0;
  bool big_endian_;
  const std::string* element_ = nullptr;
  long long index_ = 0;
};

/// Position of the property called `name` (any of `names`) in `element`, or -1.
int find_property(const PlyElement& element, std::initializer_list<std::string_view> names) {
  for (std::size_t p = 0; p < element.properties.size(); ++p)
    for (std::string_view name : names)
      if (element.properties[p].name == name) return static_cast<int>(p);
  return -1;
}

/// The property roles the reader needs, checked against the header before the body is read.
struct Layout {
  int vertex_element = -1, face_element = -1;
  int xyz[3] = {-1, -1, -1};
  int indices = -1;
};

Layout find_layout(const fs::path& file, const PlyHeader& header) {
  Layout layout;
  for (std::size_t e = 0; e < header.elements.size(); ++e) {
    if (header.elements[e].name == "vertex") layout.vertex_element = static_cast<int>(e);
    if (header.elements[e].name == "face") layout.face_element = static_cast<int>(e);
  }
  if (layout.vertex_element < 0) fail(file, "PLY header declares no 'element vertex'");
  if (layout.face_element < 0) fail(file, "PLY header declares no 'element face'");
  const PlyElement& vertex = header.elements[layout.vertex_element];
  const char* axes[] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k) {
    layout.xyz[k] = find_property(vertex, {axes[k]});
    if (layout.xyz[k] < 0 || vertex.properties[layout.xyz[k]].is_list)
      fail_at_line(file, vertex.line,
                   std::string("element vertex has no scalar property '") + axes[k] + "'");
  }
  const PlyElement& face = header.elements[layout.face_element];
  layout.indices = find_property(face, {"vertex_indices", "vertex_index"});
  if (layout.indices < 0 || !face.properties[layout.indices].is_list ||
      !is_integer(face.properties[layout.indices].type))
    fail_at_line(file, face.line,
                 "element face has no integer list property 'vertex_indices' or 'vertex_index'");
  return layout;
}

template <class Body>
Surface read_body(const PlyHeader& header, const Layout& layout, Body& body,
                  std::size_t body_bytes) {
  SurfaceBuilder builder;
  const long long num_vertices = header.elements[layout.vertex_element].count;
  // Reserve no more than the body could hold, so that a corrupt count cannot exhaust memory.
  builder.xyz.reserve(3 * std::min<std::size_t>(num_vertices, body_bytes));
  std::vector<int> polygon;
  for (std::size_t e = 0; e < header.elements.size(); ++e) {
    const PlyElement& element = header.elements[e];
    const bool is_vertex = static_cast<int>(e) == layout.vertex_element;
    const bool is_face = static_cast<int>(e) == layout.face_element;
    for (long long i = 0; i < element.count; ++i) {
      body.at(element.name, i);
      double xyz[3] = {0, 0, 0};
      for (std::size_t p = 0; p < element.properties.size(); ++p) {
        const PlyProperty& property = element.properties[p];
        const int role = static_cast<int>(p);
        if (!property.is_list) {
          const double value = body.read(property.type);
          for (int k = 0; k < 3; ++k)
            if (is_vertex && role == layout.xyz[k]) xyz[k] = value;
          continue;
        }
        const double count = body.read(property.count_type);
        if (count < 0) body.error("negative list length");
        if (!is_face || role != layout.indices) {
          body.skip(property.type, static_cast<long long>(count));
          continue;
        }
        if (count < 3)
          body.error("face with " + std::to_string(static_cast<long long>(count)) +
                     " vertices (needs at least 3)");
        polygon.clear();
        for (long long k = 0; k < static_cast<long long>(count); ++k) {
          const double index = body.read(property.type);
          if (index < 0 || index >= static_cast<double>(num_vertices))
            body.error("vertex index " + std::to_string(static_cast<long long>(index)) +
                       " out of range [0, " + std::to_string(num_vertices) + ")");
          polygon.push_back(static_cast<int>(index));
        }
        builder.add_polygon(polygon);
      }
      if (is_vertex) {
        if (!std::isfinite(xyz[0]) || !std::isfinite(xyz[1]) || !std::isfinite(xyz[2]))
          body.error("non-finite coordinate");
        builder.add_vertex(xyz[0], xyz[1], xyz[2]);
      }
    }
  }
  return builder.finish();
}

}  // namespace

Surface read_ply(const fs::path& file, std::string_view data) {
  const PlyHeader header = read_header(file, data);
  const Layout layout = find_layout(file, header);
  const std::string_view body_data = data.substr(header.body_offset);
  if (header.encoding == PlyEncoding::ascii) {
    AsciiBody body(file, body_data, header.body_first_line);
    return read_body(header, layout, body, body_data.size());
  }
  BinaryBody body(file, body_data, header.encoding == PlyEncoding::binary_big_endian);
  return read_body(header, layout, body, body_data.size());
}

void write_ply(std::string& out, const Surface& surface, const std::string& unit_name,
               bool binary) {
  // Doubles in both encodings, so that binary PLY round-trips exactly, like the text formats.
  out += "ply\nformat ";
  out += binary ? "binary_little_endian" : "ascii";
  out += " 1.0\ncomment msfem closed surface, coordinates in " + unit_name + "\n";
  out += "element vertex " + std::to_string(surface.num_vertices()) + "\n";
  out += "property double x\nproperty double y\nproperty double z\n";
  out += "element face " + std::to_string(surface.num_triangles()) + "\n";
  out += "property list uchar int vertex_indices\nend_header\n";
  for (Eigen::Index i = 0; i < surface.num_vertices(); ++i) {
    for (int k = 0; k < 3; ++k) {
      if (binary) {
        append_le_f64(out, surface.vertices(i, k));
        continue;
      }
      if (k > 0) out += ' ';
      append_number(out, surface.vertices(i, k));
    }
    if (!binary) out += '\n';
  }
  for (Eigen::Index t = 0; t < surface.num_triangles(); ++t) {
    out += binary ? std::string(1, '\3') : std::string("3");
    for (int k = 0; k < 3; ++k) {
      if (binary) {
        append_le_u32(out, static_cast<std::uint32_t>(surface.triangles(t, k)));
        continue;
      }
      out += ' ';
      append_number(out, static_cast<long long>(surface.triangles(t, k)));
    }
    if (!binary) out += '\n';
  }
}

}  // namespace msfem::cases::detail
