// What a VTK unstructured grid means to msfem, for both the XML and the legacy reader: line cells
// are springs, triangles the surface, tetrahedra and wedges volume elements; a cell array has one
// slot per cell of any type, and each array is read on the cells it applies to (spring arrays on
// lines, bulk_modulus on tetrahedra and wedges), its other slots ignored.

#include <algorithm>
#include <climits>
#include <cmath>
#include <map>
#include <string>

#include "network_detail.hpp"
#include "surface_io_detail.hpp"

namespace msfem::cases::detail {

namespace {

constexpr long long vtk_line = 3, vtk_triangle = 5, vtk_tetra = 10, vtk_wedge = 13;

std::string cell_type_name(long long type) {
  static const std::pair<long long, const char*> names[] = {{1, "VTK_VERTEX"},
                                                            {2, "VTK_POLY_VERTEX"},
                                                            {3, "VTK_LINE"},
                                                            {4, "VTK_POLY_LINE"},
                                                            {5, "VTK_TRIANGLE"},
                                                            {6, "VTK_TRIANGLE_STRIP"},
                                                            {7, "VTK_POLYGON"},
                                                            {8, "VTK_PIXEL"},
                                                            {9, "VTK_QUAD"},
                                                            {10, "VTK_TETRA"},
                                                            {11, "VTK_VOXEL"},
                                                            {12, "VTK_HEXAHEDRON"},
                                                            {13, "VTK_WEDGE"},
                                                            {14, "VTK_PYRAMID"},
                                                            {21, "VTK_QUADRATIC_EDGE"},
                                                            {22, "VTK_QUADRATIC_TRIANGLE"},
                                                            {23, "VTK_QUADRATIC_QUAD"},
                                                            {24, "VTK_QUADRATIC_TETRA"},
                                                            {42, "VTK_POLYHEDRON"}};
  for (const auto& [known, name] : names)
    if (known == type) return std::string(" (") + name + ")";
  return "";
}

const VtkArray* find(const std::vector<VtkArray>& arrays, const std::string& name) {
  for (const VtkArray& array : arrays)
    if (array.name == name) return &array;
  return nullptr;
}

/// Refuses names msfem does not read, duplicates, strings where numbers belong and several
/// components, so that what follows can take each array as one number per cell or point.
void check_arrays(const fs::path& file, const std::vector<VtkArray>& arrays,
                  const std::string& where, std::initializer_list<const char*> known,
                  std::size_t tuples) {
  for (std::size_t a = 0; a < arrays.size(); ++a) {
    const VtkArray& array = arrays[a];
    if (std::find_if(known.begin(), known.end(), [&](const char* k) { return array.name == k; }) ==
        known.end())
      refuse_array(file, where, array.name);
    for (std::size_t b = 0; b < a; ++b)
      if (arrays[b].name == array.name)
        fail(file, where + " has two arrays named " + detail::quoted(array.name));
    const bool text = array.name == "group_names" || array.name == "group";
    if (array.type == ValueType::string && !text)
      fail(file,
           where + " " + detail::quoted(array.name) + " is a String array; msfem reads numbers");
    if (array.name == "group_names" && array.type != ValueType::string)
      fail(file, "field data 'group_names' must be a String array (one name per group)");
    if (array.components != 1)
      fail(file, where + " " + detail::quoted(array.name) + " has " +
                     std::to_string(array.components) + " components; msfem reads 1");
    if (tuples != SIZE_MAX && array.size() != tuples)
      fail(file, where + " " + detail::quoted(array.name) + " has " + std::to_string(array.size()) +
                     " values for " + std::to_string(tuples) + " " +
                     (where == "cell data" ? "cells" : "points"));
  }
}

long long integral(const fs::path& file, const std::string& label, const char* name, double value) {
  if (!(value == std::floor(value)) || !(std::abs(value) <= INT_MAX))
    fail(file, label + ": " + name + " " + number_text(value) + " is not an integer");
  return static_cast<long long>(value);
}

}  // namespace

std::string spliced(std::string_view bytes, std::vector<Splice> splices) {
  // From the last to the first, so that each splice's offsets still hold.
  std::sort(splices.begin(), splices.end(),
            [](const Splice& a, const Splice& b) { return a.begin > b.begin; });
  std::string out(bytes);
  for (const Splice& splice : splices)
    out.replace(splice.begin, splice.end - splice.begin, splice.text);
  return out;
}

std::vector<double> with_spring_values(const VtkArray* original, std::size_t cells,
                                       const std::vector<long long>& spring_cells,
                                       const Eigen::VectorXd& per_spring) {
  std::vector<double> values(cells, 0.0);
  if (original)
    for (std::size_t c = 0; c < cells; ++c)
      values[c] = original->value(c);
  for (std::size_t s = 0; s < spring_cells.size(); ++s)
    values[static_cast<std::size_t>(spring_cells[s])] = per_spring(static_cast<Eigen::Index>(s));
  return values;
}

std::string unread_array(const std::string& where, const std::string& name) {
  return where + " array " + detail::quoted(name) +
         " is not one msfem reads: stiffness, damping, rest_length, group, bulk_modulus (cell "
         "data); mass, fixed, anchor_stiffness, anchor_damping (point data); group_names (field "
         "data)";
}

void refuse_array(const fs::path& file, const std::string& where, const std::string& name) {
  fail(file, unread_array(where, name));
}

ReadNetwork network_from_vtk(const fs::path& file, const VtkGrid& grid) {
  ReadNetwork read;
  NetworkFile& net = read.network;
  NetworkOrigin& origin = read.origin;
  const std::size_t num_points = grid.points.size() / 3;
  const std::size_t num_cells = grid.cell_types.size();
  if (num_points > static_cast<std::size_t>(INT_MAX))
    fail(file,
         std::to_string(num_points) + " points; msfem reads at most " + std::to_string(INT_MAX));

  check_arrays(file, grid.cell_data, "cell data",
               {"stiffness", "damping", "rest_length", "group", "bulk_modulus"}, num_cells);
  check_arrays(file, grid.point_data, "point data",
               {"mass", "fixed", "anchor_stiffness", "anchor_damping"}, num_points);
  check_arrays(file, grid.field_data, "field data", {"group_names"}, SIZE_MAX);

  // Cells by kind, each checked for its point count and its ids.
  std::vector<std::size_t> lines, triangles, tetrahedra, wedges;
  for (std::size_t c = 0; c < num_cells; ++c) {
    const long long type = grid.cell_types[c];
    const long long count = grid.cell_begin[c + 1] - grid.cell_begin[c];
    long long expected = 0;
    std::string role;
    if (type == vtk_line) {
      expected = 2;
      role = " (spring " + std::to_string(lines.size()) + ")";
      lines.push_back(c);
    } else if (type == vtk_triangle) {
      expected = 3;
      role = " (triangle " + std::to_string(triangles.size()) + ")";
      triangles.push_back(c);
    } else if (type == vtk_tetra) {
      expected = 4;
      role = " (tetrahedron " + std::to_string(tetrahedra.size()) + ")";
      tetrahedra.push_back(c);
    } else if (type == vtk_wedge) {
      expected = 6;
      role = " (wedge " + std::to_string(wedges.size()) + ")";
      wedges.push_back(c);
    } else {
      fail(file, "cell " + std::to_string(c) + " has type " + std::to_string(type) +
                     cell_type_name(type) +
                     "; msfem reads VTK_LINE (3, springs), VTK_TRIANGLE (5, surface), "
                     "VTK_TETRA (10) and VTK_WEDGE (13, volume elements)");
    }
    if (count != expected)
      fail(file, "cell " + std::to_string(c) + cell_type_name(type) + " has " +
                     std::to_string(count) + " points, not " + std::to_string(expected));
    for (long long k = grid.cell_begin[c]; k < grid.cell_begin[c + 1]; ++k) {
      const long long id = grid.connectivity[static_cast<std::size_t>(k)];
      if (id < 0 || id >= static_cast<long long>(num_points))
        fail(file, "cell " + std::to_string(c) + role + ": point id " + std::to_string(id) +
                       " out of range (the file has " + std::to_string(num_points) + " points)");
    }
  }
  if (lines.empty()) fail(file, "no springs: the file has no VTK_LINE (3) cells");

  const auto cells_matrix = [&](const std::vector<std::size_t>& cells, auto& matrix, int corners,
                                std::vector<long long>& where) {
    matrix.resize(static_cast<Eigen::Index>(cells.size()), corners);
    for (std::size_t i = 0; i < cells.size(); ++i) {
      for (int k = 0; k < corners; ++k)
        matrix(static_cast<Eigen::Index>(i), k) = static_cast<int>(
            grid.connectivity[static_cast<std::size_t>(grid.cell_begin[cells[i]] + k)]);
      where.push_back(static_cast<long long>(cells[i]));
    }
  };
  cells_matrix(lines, net.springs, 2, origin.spring);
  cells_matrix(triangles, net.triangles, 3, origin.triangle);
  cells_matrix(tetrahedra, net.tetrahedra, 4, origin.tetrahedron);
  cells_matrix(wedges, net.wedges, 6, origin.wedge);

  net.points.resize(static_cast<Eigen::Index>(num_points), 3);
  for (std::size_t p = 0; p < num_points; ++p) {
    for (int k = 0; k < 3; ++k)
      net.points(static_cast<Eigen::Index>(p), k) = grid.points[3 * p + k];
    origin.point.push_back(static_cast<long long>(p));
  }

  const auto on_cells = [&](const VtkArray& array, const std::vector<std::size_t>& cells) {
    Eigen::VectorXd values(static_cast<Eigen::Index>(cells.size()));
    for (std::size_t i = 0; i < cells.size(); ++i)
      values(static_cast<Eigen::Index>(i)) = array.value(cells[i]);
    return values;
  };
  const VtkArray* stiffness = find(grid.cell_data, "stiffness");
  if (!stiffness) fail(file, "springs (VTK_LINE cells) need cell data stiffness");
  net.stiffness = on_cells(*stiffness, lines);
  if (const VtkArray* damping = find(grid.cell_data, "damping"))
    net.damping = on_cells(*damping, lines);
  if (const VtkArray* rest = find(grid.cell_data, "rest_length"))
    net.rest_length = on_cells(*rest, lines);
  if (const VtkArray* bulk = find(grid.cell_data, "bulk_modulus")) {
    net.bulk_modulus = on_cells(*bulk, tetrahedra);
    net.wedge_bulk_modulus = on_cells(*bulk, wedges);
  } else if (!tetrahedra.empty() || !wedges.empty()) {
    fail(file, std::string(tetrahedra.empty() ? "wedges" : "tetrahedra") +
                   " need cell data bulk_modulus (cell " +
                   std::to_string(tetrahedra.empty() ? wedges[0] : tetrahedra[0]) + " is a " +
                   (tetrahedra.empty() ? "wedge" : "tetrahedron") + ")");
  }

  // Groups: an integer array indexes field data group_names when present; otherwise each distinct
  // value is a group, in increasing order; a String array names its groups in order of appearance.
  const VtkArray* group = find(grid.cell_data, "group");
  const VtkArray* names = find(grid.field_data, "group_names");
  net.spring_group.resize(static_cast<Eigen::Index>(lines.size()));
  if (!group) {
    if (names) fail(file, "field data group_names names groups, but there is no cell data group");
    net.spring_group.setZero();
    net.group_names = {"springs"};
  } else if (group->type == ValueType::string) {
    if (names) fail(file, "field data group_names names integer groups; cell data group is String");
    std::map<std::string, int> index;
    for (std::size_t i = 0; i < lines.size(); ++i) {
      const std::string& name = group->strings[lines[i]];
      auto [it, added] = index.emplace(name, static_cast<int>(net.group_names.size()));
      if (added) net.group_names.push_back(name);
      net.spring_group(static_cast<Eigen::Index>(i)) = it->second;
    }
  } else {
    std::vector<long long> values(lines.size());
    for (std::size_t i = 0; i < lines.size(); ++i)
      values[i] = integral(file, spring_label(origin, static_cast<Eigen::Index>(i)), "group",
                           group->value(lines[i]));
    if (names) {
      net.group_names = names->strings;
      for (std::size_t i = 0; i < lines.size(); ++i) {
        if (values[i] < 0 || values[i] >= static_cast<long long>(names->strings.size()))
          fail(file, spring_label(origin, static_cast<Eigen::Index>(i)) + ": group " +
                         std::to_string(values[i]) + " has no name in field data group_names (" +
                         std::to_string(names->strings.size()) + " names)");
        net.spring_group(static_cast<Eigen::Index>(i)) = static_cast<int>(values[i]);
      }
    } else {
      std::vector<long long> distinct = values;
      std::sort(distinct.begin(), distinct.end());
      distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
      for (long long value : distinct)
        net.group_names.push_back("group_" + std::to_string(value));
      for (std::size_t i = 0; i < lines.size(); ++i)
        net.spring_group(static_cast<Eigen::Index>(i)) = static_cast<int>(
            std::lower_bound(distinct.begin(), distinct.end(), values[i]) - distinct.begin());
    }
  }

  if (const VtkArray* mass = find(grid.point_data, "mass")) {
    net.mass = Eigen::VectorXd(static_cast<Eigen::Index>(num_points));
    for (std::size_t p = 0; p < num_points; ++p)
      (*net.mass)(static_cast<Eigen::Index>(p)) = mass->value(p);
  }
  const auto on_points = [&](const VtkArray& array) {
    Eigen::VectorXd values(static_cast<Eigen::Index>(num_points));
    for (std::size_t p = 0; p < num_points; ++p)
      values(static_cast<Eigen::Index>(p)) = array.value(p);
    return values;
  };
  if (const VtkArray* anchor = find(grid.point_data, "anchor_stiffness"))
    net.anchor_stiffness = on_points(*anchor);
  if (const VtkArray* anchor = find(grid.point_data, "anchor_damping")) {
    if (!net.anchor_stiffness)
      fail(file, "point data anchor_damping needs anchor_stiffness beside it");
    net.anchor_damping = on_points(*anchor);
  }
  if (const VtkArray* fixed = find(grid.point_data, "fixed")) {
    net.fixed = std::vector<bool>(num_points);
    for (std::size_t p = 0; p < num_points; ++p) {
      const double value = fixed->value(p);
      if (value != 0 && value != 1)
        fail(file, point_label(origin, static_cast<Eigen::Index>(p)) + ": fixed " +
                       number_text(value) + " must be 0 or 1");
      (*net.fixed)[p] = value == 1;
    }
  }
  return read;
}

}  // namespace msfem::cases::detail
