// Writing .vtu: a whole network as ascii XML, and a user's file with new spring coefficients
// spliced into its stiffness (and damping) array, every other byte left as it was.

#include <algorithm>
#include <charconv>
#include <cstring>
#include <functional>

#include "msfem/cases/xml_text.hpp"
#include "network_vtu.hpp"
#include "surface_io_detail.hpp"

namespace msfem::cases::detail {

namespace {


void append_float(std::string& out, float value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  out.append(buffer, result.ptr);
}

/// Values as text, six to a line under `indent`, ended by a newline.
template <typename Get>
void append_values(std::string& out, std::size_t count, const std::string& indent, Get get) {
  for (std::size_t i = 0; i < count; ++i) {
    out += i % 6 == 0 ? (i > 0 ? "\n" + indent : indent) : " ";
    get(out, i);
  }
  out += "\n";
}

void open_array(std::string& out, const char* type, const char* name, int components = 1) {
  out += "        <DataArray type=\"";
  out += type;
  out += "\"";
  if (name) out += std::string(" Name=\"") + name + "\"";
  if (components != 1) out += " NumberOfComponents=\"" + std::to_string(components) + "\"";
  out += " format=\"ascii\">\n";
}

void close_array(std::string& out) {
  out += "        </DataArray>\n";
}

void real_array(std::string& out, const char* name, std::size_t count,
                const std::function<double(std::size_t)>& value) {
  open_array(out, "Float64", name);
  append_values(out, count, "          ",
                [&](std::string& text, std::size_t i) { append_number(text, value(i)); });
  close_array(out);
}

}  // namespace

void write_vtu(std::string& out, const NetworkFile& net) {
  const std::size_t springs = static_cast<std::size_t>(net.springs.rows());
  const std::size_t triangles = static_cast<std::size_t>(net.triangles.rows());
  const std::size_t tetrahedra = static_cast<std::size_t>(net.tetrahedra.rows());
  const std::size_t wedges = static_cast<std::size_t>(net.wedges.rows());
  const std::size_t volume_start = springs + triangles;
  const std::size_t cells = volume_start + tetrahedra + wedges;
  const std::size_t points = static_cast<std::size_t>(net.points.rows());
  // Cells in order springs, triangles, tetrahedra, wedges; a spring array is 0 on the other cells,
  // and bulk_modulus 0 on the surface and the springs: the reader takes each array on its own
  // cells only.
  const auto spring_value = [&](const Eigen::VectorXd& values) {
    return [&values, springs](std::size_t c) {
      return c < springs ? values(static_cast<Eigen::Index>(c)) : 0.0;
    };
  };

  out +=
      "<?xml version=\"1.0\"?>\n"
      "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
      "header_type=\"UInt64\">\n"
      "  <UnstructuredGrid>\n"
      "    <FieldData>\n"
      "      <DataArray type=\"String\" Name=\"group_names\" NumberOfTuples=\"" +
      std::to_string(net.group_names.size()) + "\" format=\"ascii\">\n";
  std::size_t code = 0;
  out += "        ";
  for (const std::string& name : net.group_names) {
    for (char c : name) {
      out += std::to_string(static_cast<unsigned char>(c));
      out += ++code % 16 == 0 ? "\n        " : " ";
    }
    out += "0";
    out += ++code % 16 == 0 ? "\n        " : " ";
  }
  out += "\n      </DataArray>\n    </FieldData>\n";
  out += "    <Piece NumberOfPoints=\"" + std::to_string(points) + "\" NumberOfCells=\"" +
         std::to_string(cells) + "\">\n";

  out += "      <PointData>\n";
  if (net.mass)
    real_array(out, "mass", points,
               [&](std::size_t p) { return (*net.mass)(static_cast<Eigen::Index>(p)); });
  if (net.fixed) {
    open_array(out, "UInt8", "fixed");
    append_values(out, points, "          ",
                  [&](std::string& text, std::size_t p) { text += (*net.fixed)[p] ? '1' : '0'; });
    close_array(out);
  }
  if (net.anchor_stiffness)
    real_array(out, "anchor_stiffness", points, [&](std::size_t p) {
      return (*net.anchor_stiffness)(static_cast<Eigen::Index>(p));
    });
  if (net.anchor_damping)
    real_array(out, "anchor_damping", points,
               [&](std::size_t p) { return (*net.anchor_damping)(static_cast<Eigen::Index>(p)); });
  out += "      </PointData>\n      <CellData>\n";
  real_array(out, "stiffness", cells, spring_value(net.stiffness));
  if (net.damping) real_array(out, "damping", cells, spring_value(*net.damping));
  if (net.rest_length) real_array(out, "rest_length", cells, spring_value(*net.rest_length));
  open_array(out, "Int32", "group");
  append_values(out, cells, "          ", [&](std::string& text, std::size_t c) {
    text += std::to_string(c < springs ? net.spring_group(static_cast<Eigen::Index>(c)) : 0);
  });
  close_array(out);
  if (tetrahedra + wedges > 0)
    real_array(out, "bulk_modulus", cells, [&](std::size_t c) {
      if (c < volume_start) return 0.0;
      c -= volume_start;
      return c < tetrahedra ? net.bulk_modulus(static_cast<Eigen::Index>(c))
                            : net.wedge_bulk_modulus(static_cast<Eigen::Index>(c - tetrahedra));
    });
  out += "      </CellData>\n      <Points>\n";
  open_array(out, "Float64", nullptr, 3);
  append_values(out, 3 * points, "          ", [&](std::string& text, std::size_t i) {
    append_number(text, net.points(static_cast<Eigen::Index>(i / 3), static_cast<int>(i % 3)));
  });
  close_array(out);
  out += "      </Points>\n      <Cells>\n";
  const auto corner = [&](std::size_t c, std::size_t k) -> long long {
    if (c < springs) return net.springs(static_cast<Eigen::Index>(c), static_cast<int>(k));
    c -= springs;
    if (c < triangles) return net.triangles(static_cast<Eigen::Index>(c), static_cast<int>(k));
    c -= triangles;
    if (c < tetrahedra) return net.tetrahedra(static_cast<Eigen::Index>(c), static_cast<int>(k));
    return net.wedges(static_cast<Eigen::Index>(c - tetrahedra), static_cast<int>(k));
  };
  const auto corners = [&](std::size_t c) -> std::size_t {
    return c < springs ? 2 : c < volume_start ? 3 : c < volume_start + tetrahedra ? 4 : 6;
  };
  open_array(out, "Int64", "connectivity");
  std::vector<long long> ids;
  for (std::size_t c = 0; c < cells; ++c)
    for (std::size_t k = 0; k < corners(c); ++k)
      ids.push_back(corner(c, k));
  append_values(out, ids.size(), "          ",
                [&](std::string& text, std::size_t i) { append_number(text, ids[i]); });
  close_array(out);
  open_array(out, "Int64", "offsets");
  long long end = 0;
  append_values(out, cells, "          ", [&](std::string& text, std::size_t c) {
    end += static_cast<long long>(corners(c));
    append_number(text, end);
  });
  close_array(out);
  open_array(out, "UInt8", "types");
  append_values(out, cells, "          ", [&](std::string& text, std::size_t c) {
    text += c < springs                     ? "3"
            : c < volume_start              ? "5"
            : c < volume_start + tetrahedra ? "10"
                                            : "13";
  });
  close_array(out);
  out += "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n";
}

namespace {

/// The bytes [begin, end) of a DataArray element, from '<' to the end of its end tag.
std::pair<std::size_t, std::size_t> element_range(const fs::path& file, const VtuDocument& doc,
                                                  const pugi::xml_node& node) {
  const std::string& xml = doc.xml;
  const std::ptrdiff_t name = node.offset_debug();
  if (name < 1 || static_cast<std::size_t>(name) >= doc.same_as_file ||
      xml.compare(static_cast<std::size_t>(name), 9, "DataArray") != 0 ||
      xml[static_cast<std::size_t>(name) - 1] != '<')
    fail(file, "cannot locate the DataArray to rewrite");
  const std::size_t begin = static_cast<std::size_t>(name) - 1;
  const std::size_t tag_end = end_of_tag(xml, begin);
  if (tag_end == xml.size()) fail(file, "cannot locate the DataArray to rewrite");
  std::size_t end = tag_end + 1;
  if (xml[tag_end - 1] != '/') {
    const std::size_t close = xml.find("</DataArray", tag_end);
    end = xml.find('>', close) + 1;
  }
  if (end > doc.same_as_file) fail(file, "cannot locate the DataArray to rewrite");
  return {begin, end};
}

/// The new ascii element: the original's attributes, less those of its old encoding and its now
/// stale range; an integer type becomes Float64, so that the coefficients are not rounded.
std::string ascii_element(const pugi::xml_node* original, const std::string& name, ValueType type,
                          const std::vector<double>& values, const std::string& indent) {
  if (is_integer(type)) type = ValueType::float64;
  std::string out = "<DataArray";
  bool named = false;
  if (original)
    for (const pugi::xml_attribute& attribute : original->attributes()) {
      const std::string key = attribute.name();
      if (key == "format" || key == "offset" || key == "RangeMin" || key == "RangeMax") continue;
      named = named || key == "Name";
      out += " " + key + "=\"" + xml_escaped(key == "type" ? xml_type_name(type) : attribute.value()) +
             "\"";
    }
  if (!original) out += std::string(" type=\"") + xml_type_name(type) + "\"";
  if (!named) out += " Name=\"" + xml_escaped(name) + "\"";
  out += " format=\"ascii\">\n";
  append_values(out, values.size(), indent + "  ", [&](std::string& text, std::size_t i) {
    if (type == ValueType::float32)
      append_float(text, static_cast<float>(values[i]));
    else
      append_number(text, values[i]);
  });
  out += indent + "</DataArray>";
  return out;
}

}  // namespace

std::string vtu_with_coefficients(const fs::path& file, std::string_view bytes,
                                  const Eigen::VectorXd& stiffness,
                                  const std::optional<Eigen::VectorXd>& damping) {
  VtuDocument doc;
  parse_vtu(file, bytes, doc);
  const ReadNetwork read = network_from_vtk(file, doc.grid);
  const std::vector<long long>& spring_cells = read.origin.spring;

  const auto find_node = [&](const char* name) {
    for (const pugi::xml_node& child : doc.cell_data.children("DataArray"))
      if (std::strcmp(child.attribute("Name").value(), name) == 0) return child;
    return pugi::xml_node();
  };
  const auto find_array = [&](const char* name) -> const VtkArray* {
    for (const VtkArray& array : doc.grid.cell_data)
      if (array.name == name) return &array;
    return nullptr;
  };
  const auto new_values = [&](const VtkArray* original, const Eigen::VectorXd& per_spring) {
    return with_spring_values(original, doc.grid.cell_types.size(), spring_cells, per_spring);
  };
  const auto indent_of = [&](std::size_t begin) {
    std::size_t line = begin;
    while (line > 0 && (bytes[line - 1] == ' ' || bytes[line - 1] == '\t'))
      --line;
    return std::string(bytes.substr(line, begin - line));
  };

  std::vector<Splice> splices;
  const pugi::xml_node stiffness_node = find_node("stiffness");
  const VtkArray* stiffness_array = find_array("stiffness");
  const auto [k_begin, k_end] = element_range(file, doc, stiffness_node);
  splices.push_back({k_begin, k_end,
                     ascii_element(&stiffness_node, "stiffness", stiffness_array->type,
                                   new_values(stiffness_array, stiffness), indent_of(k_begin))});
  if (damping) {
    const VtkArray* damping_array = find_array("damping");
    if (const pugi::xml_node node = find_node("damping")) {
      const auto [begin, end] = element_range(file, doc, node);
      splices.push_back({begin, end,
                         ascii_element(&node, "damping", damping_array->type,
                                       new_values(damping_array, *damping), indent_of(begin))});
    } else {
      const std::string indent = indent_of(k_begin);
      splices.push_back({k_end, k_end,
                         "\n" + indent +
                             ascii_element(nullptr, "damping", ValueType::float64,
                                           new_values(nullptr, *damping), indent)});
    }
  }
  return spliced(bytes, std::move(splices));
}

}  // namespace msfem::cases::detail
