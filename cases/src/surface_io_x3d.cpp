#include <cmath>
#include <cstdio>
#include <cstring>
#include <pugixml.hpp>
#include <vector>

#include "msfem/cases/x3d.hpp"
#include "surface_io_detail.hpp"

namespace msfem::cases {
namespace {

// The first IndexedFaceSet under `node`, depth first.
pugi::xml_node first_face_set(const pugi::xml_node& node) {
  for (const pugi::xml_node& child : node.children()) {
    if (std::strcmp(child.name(), "IndexedFaceSet") == 0) return child;
    if (const pugi::xml_node found = first_face_set(child)) return found;
  }
  return {};
}

pugi::xml_node shape_named(const pugi::xml_node& node, const std::string& def) {
  for (const pugi::xml_node& child : node.children()) {
    if (std::strcmp(child.name(), "Shape") == 0 && def == child.attribute("DEF").value())
      return child;
    if (const pugi::xml_node found = shape_named(child, def)) return found;
  }
  return {};
}

// The numbers of an MFVec3f / MFInt32 field: whitespace and commas separate them.
std::vector<std::string_view> tokens(const char* text) {
  std::vector<std::string_view> out;
  std::string_view rest(text);
  std::size_t i = 0;
  while (i < rest.size()) {
    while (i < rest.size() && (std::isspace(static_cast<unsigned char>(rest[i])) || rest[i] == ','))
      ++i;
    const std::size_t begin = i;
    while (i < rest.size() && !std::isspace(static_cast<unsigned char>(rest[i])) && rest[i] != ',')
      ++i;
    if (i > begin) out.push_back(rest.substr(begin, i - begin));
  }
  return out;
}

}  // namespace

Surface read_x3d_surface_bytes(const std::filesystem::path& file, const std::string& bytes,
                               const std::string& def) {
  pugi::xml_document doc;
  const pugi::xml_parse_result parsed = doc.load_buffer(bytes.data(), bytes.size());
  if (!parsed)
    detail::fail(file, std::string("not XML: ") + parsed.description() + " at byte " +
                           std::to_string(parsed.offset));
  const pugi::xml_node x3d = doc.child("X3D");
  if (!x3d) detail::fail(file, "no <X3D> root element");
  pugi::xml_node faces;
  if (def.empty()) {
    faces = first_face_set(x3d);
    if (!faces) detail::fail(file, "no IndexedFaceSet");
  } else {
    const pugi::xml_node shape = shape_named(x3d, def);
    if (!shape) detail::fail(file, "no Shape with DEF '" + def + "'");
    faces = first_face_set(shape);
    if (!faces) detail::fail(file, "Shape '" + def + "' holds no IndexedFaceSet");
  }
  const pugi::xml_node coordinate = faces.child("Coordinate");
  if (!coordinate) detail::fail(file, "the IndexedFaceSet has no <Coordinate>");
  detail::SurfaceBuilder builder;
  const std::vector<std::string_view> xyz = tokens(coordinate.attribute("point").value());
  if (xyz.size() % 3 != 0)
    detail::fail(file, "Coordinate point: " + std::to_string(xyz.size()) +
                           " numbers, not a multiple of three");
  for (std::size_t p = 0; p < xyz.size(); p += 3) {
    double x[3];
    for (int k = 0; k < 3; ++k)
      if (!detail::parse_double(xyz[p + std::size_t(k)], x[k]) || !std::isfinite(x[k]))
        detail::fail(file, "Coordinate point " + std::to_string(p / 3) + ": " +
                               detail::quoted(xyz[p + std::size_t(k)]) + " is not a finite number");
    builder.add_vertex(x[0], x[1], x[2]);
  }
  const long long n = static_cast<long long>(builder.num_vertices());
  std::vector<int> polygon;
  std::size_t face = 0;
  const auto close_face = [&] {
    if (polygon.empty()) return;
    if (polygon.size() < 3)
      detail::fail(file, "coordIndex face " + std::to_string(face) + " has " +
                             std::to_string(polygon.size()) + " corners");
    builder.add_polygon(polygon);
    polygon.clear();
    ++face;
  };
  for (const std::string_view token : tokens(faces.attribute("coordIndex").value())) {
    long long index = 0;
    if (!detail::parse_integer(token, index))
      detail::fail(file, "coordIndex face " + std::to_string(face) + ": " + detail::quoted(token) +
                             " is not an integer");
    if (index == -1) {
      close_face();
    } else if (index < 0 || index >= n) {
      detail::fail(file, "coordIndex face " + std::to_string(face) + ": index " +
                             std::to_string(index) + " out of range (" + std::to_string(n) +
                             " points)");
    } else {
      polygon.push_back(static_cast<int>(index));
    }
  }
  close_face();  // the last face may end without -1
  return builder.finish();
}

Surface read_x3d_surface(const std::filesystem::path& file, const std::string& def) {
  return read_x3d_surface_bytes(file, detail::read_whole_file(file), def);
}

std::string xml_escaped(const std::string& text) {
  std::string out;
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string x3d_shape(const std::string& def, const Eigen::MatrixX3d& points,
                      const Eigen::MatrixX3i& triangles, const Eigen::MatrixX3d& colours,
                      const std::string& appearance, const std::string& indent,
                      const std::string& attributes) {
  std::string out = indent + "<Shape DEF=\"" + xml_escaped(def) + "\"" + attributes + ">\n";
  if (!appearance.empty()) out += indent + "  " + appearance + "\n";
  out += indent + "  <IndexedFaceSet solid=\"false\" colorPerVertex=\"true\" coordIndex=\"";
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    for (int k = 0; k < 3; ++k) {
      detail::append_number(out, static_cast<long long>(triangles(t, k)));
      out += ' ';
    }
    out += t + 1 < triangles.rows() ? "-1 " : "-1";
  }
  out += "\">\n" + indent + "    <Coordinate point=\"";
  for (Eigen::Index p = 0; p < points.rows(); ++p)
    for (int k = 0; k < 3; ++k) {
      detail::append_number(out, points(p, k));
      if (p + 1 < points.rows() || k < 2) out += ' ';
    }
  out += "\"></Coordinate>\n";
  if (colours.rows() > 0) {
    out += indent + "    <Color color=\"";
    char text[64];
    for (Eigen::Index p = 0; p < colours.rows(); ++p) {
      std::snprintf(text, sizeof text, "%.4f %.4f %.4f", colours(p, 0), colours(p, 1),
                    colours(p, 2));
      out += text;
      if (p + 1 < colours.rows()) out += ", ";
    }
    out += "\"></Color>\n";
  }
  out += indent + "  </IndexedFaceSet>\n" + indent + "</Shape>\n";
  return out;
}

}  // namespace msfem::cases
