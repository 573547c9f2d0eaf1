// VTK XML unstructured grids (.vtu) in every encoding ParaView, meshio and SOFA's VTKExporter
// write: ascii, inline base64 ("binary") and appended (raw or base64), each zlib-compressed or not,
// with 32- or 64-bit block headers, in either byte order.
//
// pugixml reads the XML. Raw appended data is binary and not XML, so it is cut out before parsing
// and read at each array's offset; everything inside the XML stays at its own byte offset, which is
// what lets the coefficient rewriter splice one array and leave the rest of the file as it was.

#include <cstring>
#include <memory>

#include "network_vtu.hpp"
#include "surface_io_detail.hpp"

namespace msfem::cases::detail {

namespace {

struct Encoding {
  bool big_endian = false;
  std::size_t header_bytes = 4;
  bool compressed = false;
  bool has_appended = false, appended_base64 = false;
  std::string_view appended;  ///< after the '_' marker
  std::size_t max_values = 0;
};

class ByteSource {
 public:
  virtual ~ByteSource() = default;
  virtual bool read(std::size_t n, std::string& out) = 0;
  virtual std::size_t bound() const = 0;
};

class RawSource : public ByteSource {
 public:
  explicit RawSource(std::string_view data) : data_(data) {}
  bool read(std::size_t n, std::string& out) override {
    if (n > data_.size() - pos_) return false;
    out.append(data_.substr(pos_, n));
    pos_ += n;
    return true;
  }
  std::size_t bound() const override { return data_.size() - pos_; }

 private:
  std::string_view data_;
  std::size_t pos_ = 0;
};

class Base64Source : public ByteSource {
 public:
  explicit Base64Source(std::string_view text) : reader_(text) {}
  bool read(std::size_t n, std::string& out) override { return reader_.read(n, out); }
  std::size_t bound() const override { return reader_.bound(); }

 private:
  Base64Reader reader_;
};

/// One binary array's bytes: VTK's size header then the data, or the compression header (block
/// count, block size, last block size, compressed sizes) then zlib blocks. `expected` is the byte
/// count the array must have (-1: a String array, whose size the header alone tells).
std::string read_payload(const fs::path& file, const Encoding& encoding, ByteSource& source,
                         const std::string& where, long long expected) {
  const auto truncated = [&](const std::string& what) {
    fail(file, where + ": " + what + " (truncated file or bad base64)");
  };
  const auto word = [&]() {
    std::string bytes;
    if (!source.read(encoding.header_bytes, bytes)) truncated("data ends inside its header");
    std::uint64_t value = 0;
    for (std::size_t k = 0; k < encoding.header_bytes; ++k) {
      const std::size_t byte = encoding.big_endian ? k : encoding.header_bytes - 1 - k;
      value = (value << 8) | static_cast<unsigned char>(bytes[byte]);
    }
    return value;
  };
  const auto check_total = [&](std::uint64_t total) {
    if (expected >= 0 && total != static_cast<std::uint64_t>(expected))
      fail(file, where + ": holds " + std::to_string(total) + " bytes, expected " +
                     std::to_string(expected));
  };
  std::string data;
  if (!encoding.compressed) {
    const std::uint64_t size = word();
    check_total(size);
    if (size > source.bound() || !source.read(static_cast<std::size_t>(size), data))
      truncated("data ends before its " + std::to_string(size) + " bytes");
    return data;
  }
  const std::uint64_t blocks = word(), block_size = word(), last_size = word();
  if (blocks > source.bound() / encoding.header_bytes)
    truncated("compression header lists " + std::to_string(blocks) + " blocks");
  std::vector<std::uint64_t> compressed_sizes(static_cast<std::size_t>(blocks));
  std::uint64_t compressed_total = 0;
  for (auto& size : compressed_sizes) {
    size = word();
    compressed_total += std::min<std::uint64_t>(size, source.bound() + 1);
  }
  if (compressed_total > source.bound()) truncated("compressed blocks end early");
  // Each block inflates to the block size, the last to last_size (0: a full block); the count is
  // checked against the array's size before any block is inflated.
  const std::uint64_t cap = 1032 * (compressed_total + 64 * (blocks + 1));
  if (blocks > 0 && (block_size > cap || last_size > block_size))
    fail(file, where + ": corrupt compression header (block size " + std::to_string(block_size) +
                   ", last block " + std::to_string(last_size) + ")");
  const std::uint64_t last = last_size == 0 ? block_size : last_size;
  std::uint64_t total = 0;
  if (blocks > 0 && __builtin_mul_overflow(blocks - 1, block_size, &total))
    fail(file, where + ": corrupt compression header (" + std::to_string(blocks) + " blocks of " +
                   std::to_string(block_size) + " bytes)");
  check_total(blocks == 0 ? 0 : total + last);
  for (std::size_t b = 0; b < compressed_sizes.size(); ++b) {
    std::string block;
    if (!source.read(static_cast<std::size_t>(compressed_sizes[b]), block))
      truncated("compressed block " + std::to_string(b) + " ends early");
    const std::uint64_t size = b + 1 == compressed_sizes.size() ? last : block_size;
    const std::string error = inflate_exact(block, static_cast<std::size_t>(size), data);
    if (!error.empty())
      fail(file, where + ": corrupt zlib block " + std::to_string(b) + ": " + error);
  }
  return data;
}

std::string text_of(const pugi::xml_node& node) {
  std::string text;
  for (const pugi::xml_node& child : node.children())
    if (child.type() == pugi::node_pcdata || child.type() == pugi::node_cdata) {
      text += child.value();
      text += ' ';
    }
  return text;
}

long long count_attribute(const fs::path& file, const pugi::xml_node& node, const char* name,
                          const std::string& where, long long fallback, std::size_t max) {
  const pugi::xml_attribute attribute = node.attribute(name);
  if (!attribute) {
    if (fallback >= 0) return fallback;
    fail(file, where + " has no " + name);
  }
  long long value;
  if (!parse_integer(attribute.value(), value) || value < 0)
    fail(file, where + ": " + name + " " + detail::quoted(attribute.value()) +
                   " is not a non-negative integer");
  if (static_cast<unsigned long long>(value) > max)
    fail(file,
         where + ": " + name + " " + std::to_string(value) + " is more than the file can hold");
  return value;
}

/// Decodes one DataArray: `tuples` of them (-1: its NumberOfTuples attribute says, for field data).
VtkArray decode_array(const fs::path& file, const Encoding& encoding, const pugi::xml_node& node,
                      const std::string& where, long long tuples) {
  VtkArray array;
  array.name = node.attribute("Name").value();
  const std::string what = where + (array.name.empty() ? "" : " " + detail::quoted(array.name));
  const std::string type = node.attribute("type").value();
  if (!parse_xml_type(type, array.type))
    fail(file, what + ": DataArray type " + detail::quoted(type) +
                   " is not one msfem reads (Int8..Int64, UInt8..UInt64, Float32, Float64, "
                   "String)");
  array.components =
      count_attribute(file, node, "NumberOfComponents", what, 1, encoding.max_values);
  if (array.components == 0) fail(file, what + ": NumberOfComponents 0");
  if (tuples < 0)
    tuples = count_attribute(file, node, "NumberOfTuples", what,
                             array.type == ValueType::string ? 0 : -1, encoding.max_values);
  if (static_cast<unsigned long long>(array.components) >
      encoding.max_values / std::max<unsigned long long>(tuples, 1))
    fail(file, what + ": more values than the file can hold");
  const long long count = tuples * array.components;
  const bool text = array.type == ValueType::string;

  const std::string format = node.attribute("format").value();
  std::string bytes;
  if (format == "ascii") {
    std::string content = text_of(node);
    std::string_view rest = content;
    VtkArray parsed;
    parsed.type = text ? ValueType::uint8 : array.type;
    for (std::string_view token = next_token(rest); !token.empty(); token = next_token(rest)) {
      if (!text && static_cast<long long>(parsed.size()) == count)
        fail(file, what + ": more than " + std::to_string(count) + " values");
      if (!parse_value(token, parsed.type, parsed))
        fail(file, what + ": " + detail::quoted(token) + " is not a " + type + " value");
    }
    if (!text) {
      if (static_cast<long long>(parsed.size()) != count)
        fail(file, what + ": " + std::to_string(parsed.size()) + " values, expected " +
                       std::to_string(count) + " (truncated?)");
      parsed.name = array.name;
      parsed.components = array.components;
      return parsed;
    }
    for (long long c : parsed.integers)
      bytes += static_cast<char>(c);
  } else if (format == "binary" || format == "appended") {
    const long long expected = text ? -1 : count * static_cast<long long>(size_of(array.type));
    std::unique_ptr<ByteSource> source;
    const std::string content = format == "binary" ? text_of(node) : std::string();
    if (format == "binary") {
      source = std::make_unique<Base64Source>(content);
    } else {
      if (!encoding.has_appended) fail(file, what + ": format appended, but no AppendedData");
      const long long offset =
          count_attribute(file, node, "offset", what, -1, encoding.appended.size());
      const std::string_view from = encoding.appended.substr(static_cast<std::size_t>(offset));
      if (encoding.appended_base64)
        source = std::make_unique<Base64Source>(from);
      else
        source = std::make_unique<RawSource>(from);
    }
    bytes = read_payload(file, encoding, *source, what, expected);
    if (!text) {
      if (!decode_words(bytes, static_cast<std::size_t>(count), array.type, encoding.big_endian,
                        array))
        fail(file, what + ": a UInt64 value above 2^63");
      return array;
    }
  } else {
    fail(file, what + ": format " + detail::quoted(format) + " is not ascii, binary or appended");
  }
  // VTK writes strings as their characters, each string ended by a NUL.
  std::size_t begin = 0;
  while (begin < bytes.size()) {
    std::size_t end = bytes.find('\0', begin);
    if (end == std::string::npos) end = bytes.size();
    array.strings.push_back(bytes.substr(begin, end - begin));
    begin = end + 1;
  }
  return array;
}

std::vector<VtkArray> decode_arrays(const fs::path& file, const Encoding& encoding,
                                    const pugi::xml_node& parent, const std::string& where,
                                    long long tuples) {
  std::vector<VtkArray> arrays;
  for (const pugi::xml_node& child : parent.children()) {
    if (child.type() != pugi::node_element) continue;
    if (std::strcmp(child.name(), "DataArray") != 0)
      fail(file, where + ": element <" + std::string(child.name()) + "> is not a DataArray");
    arrays.push_back(decode_array(file, encoding, child, where, tuples));
  }
  return arrays;
}

std::vector<long long> integer_array(const fs::path& file, const Encoding& encoding,
                                     const pugi::xml_node& node, const std::string& where,
                                     long long count) {
  VtkArray array = decode_array(file, encoding, node, where, count);
  if (!is_integer(array.type) || array.components != 1)
    fail(file,
         where + " " + detail::quoted(array.name) + " must be an integer array with one component");
  return std::move(array.integers);
}

void read_cells(const fs::path& file, const Encoding& encoding, const pugi::xml_node& cells,
                long long num_cells, VtkGrid& grid) {
  pugi::xml_node connectivity, offsets, types;
  for (const pugi::xml_node& child : cells.children()) {
    if (child.type() != pugi::node_element) continue;
    const std::string name = child.attribute("Name").value();
    if (std::strcmp(child.name(), "DataArray") != 0 ||
        (name != "connectivity" && name != "offsets" && name != "types"))
      fail(file, "Cells: " + std::string(child.name()) + " " + detail::quoted(name) +
                     " is not one msfem reads (connectivity, offsets, types; no polyhedra)");
    (name == "connectivity" ? connectivity : name == "offsets" ? offsets : types) = child;
  }
  if (!connectivity || !offsets || !types)
    fail(file, "Cells needs DataArrays connectivity, offsets and types");
  const std::vector<long long> ends = integer_array(file, encoding, offsets, "Cells", num_cells);
  grid.cell_begin.assign(1, 0);
  for (std::size_t c = 0; c < ends.size(); ++c) {
    if (ends[c] < grid.cell_begin.back())
      fail(file, "Cells 'offsets': cell " + std::to_string(c) + " ends at " +
                     std::to_string(ends[c]) + ", before it starts");
    grid.cell_begin.push_back(ends[c]);
  }
  if (static_cast<unsigned long long>(grid.cell_begin.back()) > encoding.max_values)
    fail(file, "Cells 'offsets': " + std::to_string(grid.cell_begin.back()) +
                   " point ids are more than the file can hold");
  grid.connectivity = integer_array(file, encoding, connectivity, "Cells", grid.cell_begin.back());
  grid.cell_types = integer_array(file, encoding, types, "Cells", num_cells);
}

/// Where the appended data lies; cut out of the XML, which raw bytes would not be.
void split_appended(const fs::path& file, std::string_view bytes, VtuDocument& out,
                    Encoding& encoding) {
  const std::size_t open = bytes.find("<AppendedData");
  if (open == std::string_view::npos) {
    out.xml = std::string(bytes);
    out.same_as_file = bytes.size();
    return;
  }
  const std::size_t tag_end = end_of_tag(bytes, open);
  if (tag_end == bytes.size()) fail(file, "the file ends inside <AppendedData> (truncated?)");
  encoding.has_appended = true;
  if (bytes[tag_end - 1] == '/') {  // <AppendedData/>: no data
    out.xml = std::string(bytes);
    out.same_as_file = bytes.size();
    return;
  }
  std::size_t marker = tag_end + 1;
  while (marker < bytes.size() && std::strchr(" \t\r\n", bytes[marker]) && bytes[marker] != '\0')
    ++marker;
  if (marker == bytes.size() || bytes[marker] != '_')
    fail(file, "AppendedData does not start with the '_' marker");
  const std::size_t close = bytes.rfind("</AppendedData>");
  if (close == std::string_view::npos || close <= marker)
    fail(file, "AppendedData has no end tag (truncated file?)");
  encoding.appended = bytes.substr(marker + 1, close - marker - 1);
  out.xml = std::string(bytes.substr(0, tag_end + 1));
  out.same_as_file = out.xml.size();
  out.xml += bytes.substr(close);
}

pugi::xml_node only_child(const fs::path& file, const pugi::xml_node& parent,
                          std::initializer_list<const char*> allowed, const char* wanted) {
  pugi::xml_node found;
  for (const pugi::xml_node& child : parent.children()) {
    if (child.type() != pugi::node_element) continue;
    bool known = false;
    for (const char* name : allowed)
      known = known || std::strcmp(child.name(), name) == 0;
    if (!known)
      fail(file, "<" + std::string(parent.name()) + "> holds <" + child.name() +
                     ">, which msfem does not read");
    if (std::strcmp(child.name(), wanted) == 0) {
      if (found)
        fail(file, "<" + std::string(parent.name()) + "> has more than one <" + wanted +
                       "> (msfem reads one piece)");
      found = child;
    }
  }
  return found;
}

}  // namespace

std::size_t end_of_tag(std::string_view text, std::size_t open) {
  char quote = 0;
  for (std::size_t at = open; at < text.size(); ++at) {
    const char c = text[at];
    if (quote) {
      if (c == quote) quote = 0;
    } else if (c == '"' || c == '\'') {
      quote = c;
    } else if (c == '>') {
      return at;
    }
  }
  return text.size();
}

void parse_vtu(const fs::path& file, std::string_view bytes, VtuDocument& out) {
  Encoding encoding;
  encoding.max_values = max_values_for(bytes.size());
  split_appended(file, bytes, out, encoding);
  const pugi::xml_parse_result parsed = out.doc.load_buffer(out.xml.data(), out.xml.size());
  if (!parsed)
    fail(file, std::string("not well-formed XML at byte ") + std::to_string(parsed.offset) + ": " +
                   parsed.description() + " (truncated file?)");

  const pugi::xml_node root = out.doc.document_element();
  if (std::strcmp(root.name(), "VTKFile") != 0)
    fail(file, "not a VTK XML file: the root element is <" + std::string(root.name()) + ">");
  const std::string type = root.attribute("type").value();
  if (type != "UnstructuredGrid")
    fail(file, "VTKFile type " + detail::quoted(type) + "; msfem reads UnstructuredGrid");
  const std::string order = root.attribute("byte_order").value();
  if (order == "BigEndian")
    encoding.big_endian = true;
  else if (!order.empty() && order != "LittleEndian")
    fail(file, "byte_order " + detail::quoted(order) + " is not LittleEndian or BigEndian");
  const std::string header = root.attribute("header_type").value();
  if (header == "UInt64")
    encoding.header_bytes = 8;
  else if (!header.empty() && header != "UInt32")
    fail(file, "header_type " + detail::quoted(header) + " is not UInt32 or UInt64");
  const std::string compressor = root.attribute("compressor").value();
  if (compressor == "vtkZLibDataCompressor")
    encoding.compressed = true;
  else if (!compressor.empty())
    fail(file,
         "compressor " + detail::quoted(compressor) + "; msfem reads vtkZLibDataCompressor only");

  const pugi::xml_node appended =
      only_child(file, root, {"UnstructuredGrid", "AppendedData"}, "AppendedData");
  if (appended) {
    const std::string coding = appended.attribute("encoding").value();
    if (coding == "base64")
      encoding.appended_base64 = true;
    else if (coding != "raw")
      fail(file, "AppendedData encoding " + detail::quoted(coding) + " is not raw or base64");
  }
  const pugi::xml_node grid_node =
      only_child(file, root, {"UnstructuredGrid", "AppendedData"}, "UnstructuredGrid");
  if (!grid_node) fail(file, "no <UnstructuredGrid>");
  const pugi::xml_node piece = only_child(file, grid_node, {"FieldData", "Piece"}, "Piece");
  if (!piece) fail(file, "no <Piece>");
  if (const pugi::xml_node field = only_child(file, grid_node, {"FieldData", "Piece"}, "FieldData"))
    out.grid.field_data = decode_arrays(file, encoding, field, "field data", -1);

  const long long num_points =
      count_attribute(file, piece, "NumberOfPoints", "Piece", -1, encoding.max_values);
  const long long num_cells =
      count_attribute(file, piece, "NumberOfCells", "Piece", -1, encoding.max_values);
  const std::initializer_list<const char*> parts = {"PointData", "CellData", "Points", "Cells"};
  const pugi::xml_node points = only_child(file, piece, parts, "Points");
  const pugi::xml_node cells = only_child(file, piece, parts, "Cells");
  if (!points) fail(file, "no <Points>");
  if (!cells) fail(file, "no <Cells>");
  const pugi::xml_node coordinates = only_child(file, points, {"DataArray"}, "DataArray");
  if (!coordinates) fail(file, "<Points> has no DataArray");
  VtkArray xyz = decode_array(file, encoding, coordinates, "Points", num_points);
  if (xyz.components != 3 || xyz.type == ValueType::string)
    fail(file, "Points must be numbers with 3 components");
  out.grid.points.resize(xyz.size());
  for (std::size_t i = 0; i < xyz.size(); ++i)
    out.grid.points[i] = xyz.value(i);
  read_cells(file, encoding, cells, num_cells, out.grid);
  if (const pugi::xml_node data = only_child(file, piece, parts, "PointData"))
    out.grid.point_data = decode_arrays(file, encoding, data, "point data", num_points);
  out.cell_data = only_child(file, piece, parts, "CellData");
  if (out.cell_data)
    out.grid.cell_data = decode_arrays(file, encoding, out.cell_data, "cell data", num_cells);
}

ReadNetwork read_vtu(const fs::path& file, std::string_view bytes) {
  VtuDocument document;
  parse_vtu(file, bytes, document);
  return network_from_vtk(file, document.grid);
}

}  // namespace msfem::cases::detail
