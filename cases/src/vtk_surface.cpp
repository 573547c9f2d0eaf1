#include "msfem/cases/vtk_surface.hpp"

#include <cmath>

#include "network_vtu.hpp"
#include "surface_io_detail.hpp"

namespace msfem::cases {

namespace {

constexpr long long vtk_triangle = 5;

// One array as rows × components, every value finite.
Eigen::MatrixXd matrix_of(const std::filesystem::path& file, const detail::VtkArray& a,
                          const char* where) {
  if (!a.strings.empty() || a.type == detail::ValueType::string)
    detail::fail(file, std::string(where) + " array '" + a.name + "' holds strings, not numbers");
  const auto components = static_cast<Eigen::Index>(a.components);
  const auto rows = static_cast<Eigen::Index>(a.size() / std::size_t(a.components));
  Eigen::MatrixXd m(rows, components);
  for (Eigen::Index r = 0; r < rows; ++r)
    for (Eigen::Index c = 0; c < components; ++c) {
      m(r, c) = a.value(std::size_t(r * components + c));
      if (!std::isfinite(m(r, c)))
        detail::fail(file, std::string(where) + " array '" + a.name + "', tuple " +
                               std::to_string(r) + ": a value that is not finite");
    }
  return m;
}

}  // namespace

VtkSurface read_vtk_surface(const std::filesystem::path& file) {
  if (file.extension() != ".vtu")
    detail::fail(file, "a deformed surface is read as a VTK XML unstructured grid (.vtu)");
  const std::string bytes = detail::read_whole_file(file);
  detail::VtuDocument doc;
  detail::parse_vtu(file, bytes, doc);
  const detail::VtkGrid& g = doc.grid;
  VtkSurface s;
  const auto n = static_cast<Eigen::Index>(g.points.size() / 3);
  s.points.resize(n, 3);
  for (Eigen::Index p = 0; p < n; ++p)
    for (int c = 0; c < 3; ++c) {
      s.points(p, c) = g.points[std::size_t(3 * p + c)];
      if (!std::isfinite(s.points(p, c)))
        detail::fail(file, "point " + std::to_string(p) + ": a coordinate that is not finite");
    }
  s.triangles.resize(static_cast<Eigen::Index>(g.cell_types.size()), 3);
  for (std::size_t c = 0; c < g.cell_types.size(); ++c) {
    const long long begin = g.cell_begin[c], end = g.cell_begin[c + 1];
    if (g.cell_types[c] != vtk_triangle || end - begin != 3)
      detail::fail(file, "cell " + std::to_string(c) + ": VTK cell type " +
                             std::to_string(g.cell_types[c]) +
                             " where a surface has triangles (5) only");
    for (int k = 0; k < 3; ++k) {
      const long long id = g.connectivity[std::size_t(begin + k)];
      if (id < 0 || id >= n)
        detail::fail(file, "cell " + std::to_string(c) + ": point " + std::to_string(id) +
                               " out of range (" + std::to_string(n) + " points)");
      s.triangles(Eigen::Index(c), k) = static_cast<int>(id);
    }
  }
  for (const detail::VtkArray& a : g.point_data) {
    Eigen::MatrixXd m = matrix_of(file, a, "point data");
    if (m.rows() != n)
      detail::fail(file, "point data array '" + a.name + "' has " + std::to_string(m.rows()) +
                             " tuples for " + std::to_string(n) + " points");
    s.point_data[a.name] = std::move(m);
  }
  for (const detail::VtkArray& a : g.field_data)
    s.field_data[a.name] = matrix_of(file, a, "field data");
  if (!g.cell_data.empty())
    detail::fail(file, "cell data array '" + g.cell_data.front().name +
                           "': a deformed surface carries point and field data only");
  return s;
}

}  // namespace msfem::cases
