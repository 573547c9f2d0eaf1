// Legacy VTK (.vtk) unstructured grids, ASCII and BINARY (big-endian, as VTK writes it): the
// classic CELLS layout (a count before each cell's ids) and VTK 5.1's OFFSETS/CONNECTIVITY, cell
// and point arrays as SCALARS or FIELD arrays (meshio writes the latter), dataset FIELD data.
//
// Keyword lines are read as lines and data as tokens or bytes after them, the way vtkDataReader
// does; each cell array's data range is kept so that new coefficients can be spliced in place.

#include <algorithm>
#include <cctype>
#include <cstring>

#include "network_detail.hpp"
#include "surface_io_detail.hpp"

namespace msfem::cases::detail {

namespace {

struct Range {
  bool found = false;
  std::size_t begin = 0, end = 0;
  ValueType type = ValueType::float64;
};

struct LegacyFile {
  bool binary = false;
  VtkGrid grid;
  Range stiffness, damping;
  std::size_t cell_data_end = std::string_view::npos;
};

std::string upper(std::string_view text) {
  std::string out(text);
  for (char& c : out)
    c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return out;
}

bool legacy_type(std::string_view name, bool binary, ValueType& type) {
  static const std::pair<const char*, ValueType> names[] = {
      {"unsigned_char", ValueType::uint8},   {"char", ValueType::int8},
      {"unsigned_short", ValueType::uint16}, {"short", ValueType::int16},
      {"unsigned_int", ValueType::uint32},   {"int", ValueType::int32},
      {"vtktypeint64", ValueType::int64},    {"vtktypeuint64", ValueType::uint64},
      {"float", ValueType::float32},         {"double", ValueType::float64}};
  // These have no fixed size on disk (a C long, vtkIdType): text only.
  static const std::pair<const char*, ValueType> text_only[] = {
      {"long", ValueType::int64},
      {"unsigned_long", ValueType::uint64},
      {"vtkidtype", ValueType::int64},
      {"string", ValueType::string}};
  const std::string lower = [&] {
    std::string out(name);
    for (char& c : out)
      c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return out;
  }();
  for (const auto& [known, known_type] : names)
    if (lower == known) {
      type = known_type;
      return true;
    }
  if (!binary)
    for (const auto& [known, known_type] : text_only)
      if (lower == known) {
        type = known_type;
        return true;
      }
  return false;
}

class LegacyReader {
 public:
  LegacyReader(const fs::path& file, std::string_view data) : file_(file), data_(data) {}

  void parse(LegacyFile& out);

 private:
  enum class Section { none, cell, point };

  [[noreturn]] void error(const std::string& what) const {
    fail_at_line(file_, line_of(keyword_), what);
  }
  std::size_t line_of(std::size_t pos) const {
    return 1 + static_cast<std::size_t>(
                   std::count(data_.begin(), data_.begin() + std::min(pos, data_.size()), '\n'));
  }
  void skip_blank() {
    while (pos_ < data_.size() && std::strchr(" \t\r\n\v\f", data_[pos_]) && data_[pos_] != '\0')
      ++pos_;
  }
  std::string_view line() {
    const std::size_t end = std::min(data_.find('\n', pos_), data_.size());
    std::string_view text = data_.substr(pos_, end - pos_);
    if (!text.empty() && text.back() == '\r') text.remove_suffix(1);
    pos_ = std::min(end + 1, data_.size());
    return text;
  }
  std::vector<std::string_view> line_tokens() {
    std::string_view rest = line();
    std::vector<std::string_view> tokens;
    for (std::string_view t = next_token(rest); !t.empty(); t = next_token(rest))
      tokens.push_back(t);
    return tokens;
  }
  /// The next token, without moving: in a BINARY file what follows may be data.
  std::string peek_keyword() const {
    std::size_t at = pos_;
    while (at < data_.size() && std::strchr(" \t\r\n\v\f", data_[at]) && data_[at] != '\0')
      ++at;
    std::string_view rest = data_.substr(at, 64);
    return upper(next_token(rest));
  }
  std::size_t count(std::string_view token, const char* what) {
    long long value;
    if (!parse_integer(token, value) || value < 0) error(std::string("bad ") + what + " count");
    if (static_cast<unsigned long long>(value) > data_.size())
      error(std::string(what) + " count " + std::to_string(value) +
            " is more than the file can hold");
    return static_cast<std::size_t>(value);
  }
  ValueType type_of(std::string_view name) {
    ValueType type;
    if (!legacy_type(name, binary_, type))
      error("data type " + detail::quoted(name) + " is not one msfem reads" +
            (binary_ ? " in a BINARY file" : ""));
    return type;
  }
  void values(ValueType type, std::size_t count, VtkArray& array, Range* range,
              const std::string& what);
  void strings(std::size_t count, VtkArray& array);
  void skip_metadata() {
    if (peek_keyword() != "METADATA") return;
    skip_blank();
    line();
    while (pos_ < data_.size() && !line_tokens().empty()) {
    }
  }
  void cells(const std::vector<std::string_view>& tokens);
  void field(const std::vector<std::string_view>& tokens, Section section);
  std::vector<VtkArray>& arrays(Section section) {
    return section == Section::cell    ? out_->grid.cell_data
           : section == Section::point ? out_->grid.point_data
                                       : out_->grid.field_data;
  }
  Range* range_for(Section section, const std::string& name) {
    if (section != Section::cell) return nullptr;
    if (name == "stiffness") return &out_->stiffness;
    if (name == "damping") return &out_->damping;
    return nullptr;
  }

  const fs::path& file_;
  std::string_view data_;
  std::size_t pos_ = 0, keyword_ = 0;
  bool binary_ = false;
  LegacyFile* out_ = nullptr;
  std::size_t num_cells_ = 0;
  bool have_cells_ = false, have_types_ = false;
};

void LegacyReader::values(ValueType type, std::size_t count, VtkArray& array, Range* range,
                          const std::string& what) {
  if (type == ValueType::string) error(what + ": numbers expected, not strings");
  array.type = type;
  std::size_t begin = pos_;
  if (binary_) {
    const std::size_t size = size_of(type);
    if (count > (data_.size() - pos_) / size)
      error(what + ": the file ends before its " + std::to_string(count) + " values (truncated)");
    if (!decode_words(data_.substr(pos_, count * size), count, type, true, array))
      error(what + ": a value above 2^63");
    pos_ += count * size;
  } else {
    for (std::size_t i = 0; i < count; ++i) {
      skip_blank();
      if (i == 0) begin = pos_;
      std::string_view rest = data_.substr(pos_);
      const std::string_view token = next_token(rest);
      if (token.empty())
        error(what + ": the file ends after " + std::to_string(i) + " of " + std::to_string(count) +
              " values (truncated)");
      if (!parse_value(token, type, array))
        fail_at_line(file_, line_of(pos_),
                     what + ": " + detail::quoted(token) + " is not a valid value");
      pos_ += token.size();
    }
  }
  if (range) *range = {true, begin, pos_, type};
}

void LegacyReader::strings(std::size_t count, VtkArray& array) {
  // One string a line; vtkDataWriter escapes bytes as %XX.
  array.type = ValueType::string;
  for (std::size_t i = 0; i < count; ++i) {
    if (pos_ >= data_.size()) error("the file ends inside a string array (truncated)");
    const std::string_view raw = line();
    std::string text;
    for (std::size_t k = 0; k < raw.size(); ++k) {
      if (raw[k] == '%' && k + 2 < raw.size() &&
          std::isxdigit(static_cast<unsigned char>(raw[k + 1])) &&
          std::isxdigit(static_cast<unsigned char>(raw[k + 2]))) {
        text += static_cast<char>(std::stoi(std::string(raw.substr(k + 1, 2)), nullptr, 16));
        k += 2;
      } else {
        text += raw[k];
      }
    }
    array.strings.push_back(std::move(text));
  }
}

void LegacyReader::cells(const std::vector<std::string_view>& tokens) {
  if (tokens.size() < 3) error("expected 'CELLS <count> <size>'");
  const std::size_t first = count(tokens[1], "cell"), second = count(tokens[2], "cell size");
  VtkGrid& grid = out_->grid;
  if (peek_keyword() == "OFFSETS") {
    skip_blank();
    keyword_ = pos_;
    const auto offsets_line = line_tokens();
    if (offsets_line.size() < 2) error("expected 'OFFSETS <type>'");
    VtkArray offsets, ids;
    values(type_of(offsets_line[1]), first, offsets, nullptr, "OFFSETS");
    skip_blank();
    keyword_ = pos_;
    const auto connectivity_line = line_tokens();
    if (connectivity_line.empty() || upper(connectivity_line[0]) != "CONNECTIVITY" ||
        connectivity_line.size() < 2)
      error("expected 'CONNECTIVITY <type>' after the offsets");
    values(type_of(connectivity_line[1]), second, ids, nullptr, "CONNECTIVITY");
    if (!is_integer(offsets.type) || !is_integer(ids.type)) error("cell ids must be integers");
    if (first > 0 && offsets.integers[0] != 0) error("OFFSETS must start at 0");
    for (std::size_t c = 1; c < first; ++c)
      if (offsets.integers[c] < offsets.integers[c - 1])
        error("OFFSETS: cell " + std::to_string(c - 1) + " ends before it starts");
    if (first > 0 && offsets.integers.back() != static_cast<long long>(second))
      error("OFFSETS end at " + std::to_string(offsets.integers.back()) + ", not at " +
            std::to_string(second));
    grid.cell_begin = first > 0 ? offsets.integers : std::vector<long long>{0};
    grid.connectivity = std::move(ids.integers);
    num_cells_ = first > 0 ? first - 1 : 0;
  } else {
    VtkArray raw;
    values(ValueType::int32, second, raw, nullptr, "CELLS");
    grid.cell_begin.assign(1, 0);
    std::size_t at = 0;
    for (std::size_t c = 0; c < first; ++c) {
      const long long size = at < second ? raw.integers[at] : -1;
      if (size < 0 || static_cast<std::size_t>(size) > second - at - 1)
        error("CELLS: cell " + std::to_string(c) + " runs past the " + std::to_string(second) +
              " numbers the CELLS line announces");
      for (long long k = 0; k < size; ++k)
        grid.connectivity.push_back(raw.integers[at + 1 + static_cast<std::size_t>(k)]);
      at += 1 + static_cast<std::size_t>(size);
      grid.cell_begin.push_back(static_cast<long long>(grid.connectivity.size()));
    }
    if (at != second)
      error("CELLS: the cells use " + std::to_string(at) + " numbers, the line announces " +
            std::to_string(second));
    num_cells_ = first;
  }
  if (have_types_ && grid.cell_types.size() != num_cells_)
    error("CELLS and CELL_TYPES count different cells");
  have_cells_ = true;
}

void LegacyReader::field(const std::vector<std::string_view>& tokens, Section section) {
  if (tokens.size() < 3) error("expected 'FIELD <name> <arrays>'");
  const std::size_t arrays_count = count(tokens[2], "FIELD array");
  for (std::size_t a = 0; a < arrays_count; ++a) {
    skip_metadata();
    skip_blank();
    keyword_ = pos_;
    const auto header = line_tokens();
    if (header.size() == 1 && header[0] == "NULL_ARRAY") continue;
    if (header.size() < 4) error("expected '<name> <components> <tuples> <type>'");
    VtkArray array;
    array.name = std::string(header[0]);
    const std::size_t components = count(header[1], "component");
    const std::size_t tuples = count(header[2], "tuple");
    if (components == 0 || (tuples > 0 && components > data_.size() / tuples))
      error("FIELD array " + detail::quoted(array.name) + ": bad size");
    array.components = static_cast<long long>(components);
    const ValueType type = type_of(header[3]);
    if (type == ValueType::string)
      strings(components * tuples, array);
    else
      values(type, components * tuples, array, range_for(section, array.name),
             "FIELD array " + detail::quoted(array.name));
    arrays(section).push_back(std::move(array));
  }
}

void LegacyReader::parse(LegacyFile& out) {
  out_ = &out;
  std::string_view first = line();
  if (upper(first.substr(0, 22)) != "# VTK DATAFILE VERSION")
    fail(file_, "not a legacy VTK file: the first line is not '# vtk DataFile Version x.x'");
  line();  // the title
  skip_blank();
  keyword_ = pos_;
  const auto format = line_tokens();
  const std::string encoding = format.empty() ? "" : upper(format[0]);
  if (encoding != "ASCII" && encoding != "BINARY") error("expected ASCII or BINARY");
  binary_ = out.binary = encoding == "BINARY";

  bool dataset = false, have_points = false;
  Section section = Section::none;
  std::size_t section_count = 0;
  for (skip_blank(); pos_ < data_.size(); skip_blank()) {
    keyword_ = pos_;
    const auto tokens = line_tokens();
    const std::string keyword = upper(tokens[0]);
    const auto need = [&](std::size_t n, const char* form) {
      if (tokens.size() < n) error(std::string("expected '") + form + "'");
    };
    if (keyword != "DATASET" && keyword != "FIELD" && keyword != "METADATA" && !dataset)
      error(detail::quoted(tokens[0]) + " before 'DATASET UNSTRUCTURED_GRID'");
    if (keyword == "DATASET") {
      need(2, "DATASET UNSTRUCTURED_GRID");
      if (upper(tokens[1]) != "UNSTRUCTURED_GRID")
        error("DATASET " + std::string(tokens[1]) + "; msfem reads UNSTRUCTURED_GRID");
      dataset = true;
    } else if (keyword == "POINTS") {
      need(3, "POINTS <count> <type>");
      VtkArray xyz;
      const std::size_t n = count(tokens[1], "point");
      if (n > data_.size() / 3) error("point count " + std::to_string(n) + " is too large");
      values(type_of(tokens[2]), 3 * n, xyz, nullptr, "POINTS");
      out.grid.points.resize(3 * n);
      for (std::size_t i = 0; i < 3 * n; ++i)
        out.grid.points[i] = xyz.value(i);
      have_points = true;
    } else if (keyword == "CELLS") {
      cells(tokens);
    } else if (keyword == "CELL_TYPES") {
      need(2, "CELL_TYPES <count>");
      VtkArray types;
      values(ValueType::int32, count(tokens[1], "cell type"), types, nullptr, "CELL_TYPES");
      out.grid.cell_types = std::move(types.integers);
      if (have_cells_ && out.grid.cell_types.size() != num_cells_)
        error("CELL_TYPES counts " + std::to_string(out.grid.cell_types.size()) + " cells, CELLS " +
              std::to_string(num_cells_));
      have_types_ = true;
    } else if (keyword == "CELL_DATA" || keyword == "POINT_DATA") {
      need(2, "CELL_DATA <count>");
      if (section == Section::cell) out.cell_data_end = keyword_;
      section = keyword == "CELL_DATA" ? Section::cell : Section::point;
      section_count = count(tokens[1], "data");
      const std::size_t expected =
          section == Section::cell ? num_cells_ : out.grid.points.size() / 3;
      if ((section == Section::cell && !(have_cells_ && have_types_)) ||
          (section == Section::point && !have_points))
        error(keyword + " before the points and cells");
      if (section_count != expected)
        error(keyword + " " + std::to_string(section_count) + ", but the grid has " +
              std::to_string(expected));
    } else if (keyword == "SCALARS") {
      need(3, "SCALARS <name> <type> [components]");
      if (section == Section::none) error("SCALARS outside CELL_DATA and POINT_DATA");
      VtkArray array;
      array.name = std::string(tokens[1]);
      array.components =
          tokens.size() > 3 ? static_cast<long long>(count(tokens[3], "component")) : 1;
      if (array.components < 1 || array.components > 4) error("SCALARS take 1 to 4 components");
      const ValueType type = type_of(tokens[2]);
      if (peek_keyword() == "LOOKUP_TABLE") {
        skip_blank();
        line();
      }
      values(type, section_count * static_cast<std::size_t>(array.components), array,
             range_for(section, array.name), "SCALARS " + detail::quoted(array.name));
      arrays(section).push_back(std::move(array));
    } else if (keyword == "FIELD") {
      field(tokens, section);
    } else if (keyword == "METADATA") {
      while (pos_ < data_.size() && !line_tokens().empty()) {
      }
    } else if (keyword == "VECTORS" || keyword == "NORMALS" || keyword == "TENSORS" ||
               keyword == "TEXTURE_COORDINATES" || keyword == "COLOR_SCALARS" ||
               keyword == "GLOBAL_IDS" || keyword == "PEDIGREE_IDS" || keyword == "EDGE_FLAGS" ||
               keyword == "TANGENTS" || keyword == "RATIONAL_WEIGHTS" ||
               keyword == "HIGHERORDERDEGREES") {
      const std::string name = tokens.size() > 1 ? std::string(tokens[1]) : "";
      error(unread_array(
          std::string(section == Section::point ? "point data " : "cell data ") + keyword, name));
    } else if (keyword == "LOOKUP_TABLE") {
      error("a LOOKUP_TABLE section (a colour map) is not something msfem reads");
    } else {
      error("unknown keyword " + detail::quoted(tokens[0]));
    }
  }
  if (section == Section::cell) out.cell_data_end = data_.size();
  if (!dataset) fail(file_, "no 'DATASET UNSTRUCTURED_GRID'");
  if (!have_points || !have_cells_ || !have_types_)
    fail(file_, "needs POINTS, CELLS and CELL_TYPES");
}

void append_big_endian(std::string& out, double value, ValueType type) {
  std::uint64_t bits = 0;
  if (type == ValueType::float32) {
    const float f = static_cast<float>(value);
    std::uint32_t b32;
    std::memcpy(&b32, &f, sizeof b32);
    bits = b32;
  } else {
    std::memcpy(&bits, &value, sizeof bits);
  }
  for (std::size_t k = size_of(type); k-- > 0;)
    out += static_cast<char>((bits >> (8 * k)) & 0xffu);
}

std::string data_text(const std::vector<double>& values, ValueType type, bool binary) {
  std::string out;
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (binary) {
      append_big_endian(out, values[i], type);
      continue;
    }
    if (i > 0) out += i % 9 == 0 ? "\n" : " ";
    append_number(out, type == ValueType::float32
                           ? static_cast<double>(static_cast<float>(values[i]))
                           : values[i]);
  }
  return out;
}

}  // namespace

ReadNetwork read_vtk_legacy(const fs::path& file, std::string_view bytes) {
  LegacyFile legacy;
  LegacyReader(file, bytes).parse(legacy);
  return network_from_vtk(file, legacy.grid);
}

std::string vtk_legacy_with_coefficients(const fs::path& file, std::string_view bytes,
                                         const Eigen::VectorXd& stiffness,
                                         const std::optional<Eigen::VectorXd>& damping) {
  LegacyFile legacy;
  LegacyReader(file, bytes).parse(legacy);
  const ReadNetwork read = network_from_vtk(file, legacy.grid);
  const auto original = [&](const char* name) -> const VtkArray* {
    for (const VtkArray& array : legacy.grid.cell_data)
      if (array.name == name) return &array;
    return nullptr;
  };
  const auto per_cell = [&](const VtkArray* array, const Eigen::VectorXd& per_spring) {
    return with_spring_values(array, legacy.grid.cell_types.size(), read.origin.spring, per_spring);
  };
  std::vector<Splice> splices;
  const auto replace = [&](const Range& range, const char* name, const Eigen::VectorXd& values) {
    if (!is_real(range.type))
      fail(file, std::string("cell data ") + name +
                     " is an integer array; msfem cannot write coefficients into it");
    splices.push_back({range.begin, range.end,
                       data_text(per_cell(original(name), values), range.type, legacy.binary)});
  };
  replace(legacy.stiffness, "stiffness", stiffness);
  if (damping && legacy.damping.found) {
    replace(legacy.damping, "damping", *damping);
  } else if (damping) {
    const std::size_t at = legacy.cell_data_end;
    std::string text = at > 0 && bytes[at - 1] != '\n' ? "\n" : "";
    text += "SCALARS damping double 1\nLOOKUP_TABLE default\n" +
            data_text(per_cell(nullptr, *damping), ValueType::float64, legacy.binary) + "\n";
    splices.push_back({at, at, text});
  }
  return spliced(bytes, std::move(splices));
}

}  // namespace msfem::cases::detail
