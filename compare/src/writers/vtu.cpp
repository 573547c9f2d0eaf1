// ParaView files of the result writers: VTK XML UnstructuredGrid (.vtu) for the surface and the FEM
// volume mesh, and the .pvd collection that opens them together. ASCII with 17 significant digits:
// the files are small (a surface of thousands of vertices) and a double read back is the double
// written, which lets tests and users compare numbers exactly.

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "msfem/cases/xml_text.hpp"
#include "msfem/compare/pipeline/atomic_file.hpp"
#include "msfem/compare/writers/vtu.hpp"

namespace msfem::compare {

namespace fs = std::filesystem;

namespace {

// VTK cell type ids (vtkCellType.h).
constexpr int kVtkTriangle = 5;
constexpr int kVtkTetra = 10;

std::string full_precision(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.17g", value);
  return buffer;
}

void require_finite(const Eigen::MatrixXd& values, const std::string& what) {
  for (Eigen::Index r = 0; r < values.rows(); ++r)
    if (!values.row(r).allFinite())
      throw std::invalid_argument(what + ": value at row " + std::to_string(r) + " is not finite");
}

void check_mesh(const Eigen::MatrixX3d& points, const Eigen::MatrixXi& cells,
                const std::vector<PointField>& point_data) {
  require_finite(points, "points");
  for (Eigen::Index c = 0; c < cells.rows(); ++c)
    for (Eigen::Index k = 0; k < cells.cols(); ++k)
      if (cells(c, k) < 0 || cells(c, k) >= points.rows())
        throw std::invalid_argument("cell " + std::to_string(c) + " refers to point " +
                                    std::to_string(cells(c, k)) + " of " +
                                    std::to_string(points.rows()));
  for (const PointField& field : point_data) {
    if (field.name.empty()) throw std::invalid_argument("a point field has no name");
    if (field.values.rows() != points.rows())
      throw std::invalid_argument("point field '" + field.name + "' has " +
                                  std::to_string(field.values.rows()) + " rows for " +
                                  std::to_string(points.rows()) + " points");
    if (field.values.cols() != 1 && field.values.cols() != 3)
      throw std::invalid_argument("point field '" + field.name + "' has " +
                                  std::to_string(field.values.cols()) +
                                  " components; 1 (scalar) or 3 (vector) expected");
    require_finite(field.values, "point field '" + field.name + "'");
  }
}

// One DataArray, a row of the matrix per line so the file stays readable in a text editor.
void write_data_array(std::ostream& out, const std::string& attributes,
                      const Eigen::MatrixXd& values) {
  out << "        <DataArray type=\"Float64\" " << attributes << " NumberOfComponents=\""
      << values.cols() << "\" format=\"ascii\">\n";
  for (Eigen::Index r = 0; r < values.rows(); ++r) {
    out << "         ";
    for (Eigen::Index c = 0; c < values.cols(); ++c)
      out << ' ' << full_precision(values(r, c));
    out << '\n';
  }
  out << "        </DataArray>\n";
}

// ParaView colours by the active scalars / vectors of the PointData tag: the first of each kind.
std::string active_attributes(const std::vector<PointField>& point_data) {
  std::string scalars, vectors;
  for (const PointField& field : point_data) {
    if (field.values.cols() == 1 && scalars.empty()) scalars = field.name;
    if (field.values.cols() == 3 && vectors.empty()) vectors = field.name;
  }
  std::string attributes;
  if (!scalars.empty()) attributes += " Scalars=\"" + cases::xml_escaped(scalars) + "\"";
  if (!vectors.empty()) attributes += " Vectors=\"" + cases::xml_escaped(vectors) + "\"";
  return attributes;
}

std::string unstructured_grid_xml(const Eigen::MatrixX3d& points, const Eigen::MatrixXi& cells,
                                  int cell_type, const std::vector<PointField>& point_data) {
  std::ostringstream out;
  out << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      << "  <UnstructuredGrid>\n"
      << "    <Piece NumberOfPoints=\"" << points.rows() << "\" NumberOfCells=\"" << cells.rows()
      << "\">\n";
  out << "      <PointData" << active_attributes(point_data) << ">\n";
  for (const PointField& field : point_data)
    write_data_array(out, "Name=\"" + cases::xml_escaped(field.name) + "\"", field.values);
  out << "      </PointData>\n";
  out << "      <Points>\n";
  write_data_array(out, "Name=\"Points\"", points);
  out << "      </Points>\n";
  out << "      <Cells>\n"
      << "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (Eigen::Index c = 0; c < cells.rows(); ++c) {
    out << "         ";
    for (Eigen::Index k = 0; k < cells.cols(); ++k)
      out << ' ' << cells(c, k);
    out << '\n';
  }
  out << "        </DataArray>\n"
      << "        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  for (Eigen::Index c = 0; c < cells.rows(); ++c)
    out << (c % 16 == 0 ? "          " : " ") << (c + 1) * cells.cols()
        << (c % 16 == 15 || c + 1 == cells.rows() ? "\n" : "");
  out << "        </DataArray>\n"
      << "        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  for (Eigen::Index c = 0; c < cells.rows(); ++c)
    out << (c % 32 == 0 ? "          " : " ") << cell_type
        << (c % 32 == 31 || c + 1 == cells.rows() ? "\n" : "");
  out << "        </DataArray>\n"
      << "      </Cells>\n"
      << "    </Piece>\n"
      << "  </UnstructuredGrid>\n"
      << "</VTKFile>\n";
  return out.str();
}

void write_unstructured_vtu(const fs::path& path, const Eigen::MatrixX3d& points,
                            const Eigen::MatrixXi& cells, int cell_type,
                            const std::vector<PointField>& point_data) {
  check_mesh(points, cells, point_data);
  write_text_atomically(path, unstructured_grid_xml(points, cells, cell_type, point_data));
}

}  // namespace

void write_surface_vtu(const fs::path& path, const Eigen::MatrixX3d& points,
                       const Eigen::MatrixX3i& triangles,
                       const std::vector<PointField>& point_data) {
  write_unstructured_vtu(path, points, triangles, kVtkTriangle, point_data);
}

void write_volume_vtu(const fs::path& path, const Eigen::MatrixX3d& points,
                      const Eigen::MatrixX4i& tetrahedra,
                      const std::vector<PointField>& point_data) {
  write_unstructured_vtu(path, points, tetrahedra, kVtkTetra, point_data);
}

void write_pvd(const fs::path& path,
               const std::vector<std::pair<std::string, std::string>>& datasets) {
  std::ostringstream out;
  out << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      << "  <Collection>\n";
  for (std::size_t i = 0; i < datasets.size(); ++i) {
    const auto& [file, name] = datasets[i];
    if (file.empty()) throw std::invalid_argument("dataset " + std::to_string(i) + " has no file");
    if (fs::path(file).is_absolute())
      throw std::invalid_argument("dataset file '" + file +
                                  "' is absolute; give it relative to the .pvd");
    out << "    <DataSet timestep=\"0\" part=\"" << i << "\" file=\"" << cases::xml_escaped(file)
        << "\" name=\"" << cases::xml_escaped(name) << "\"/>\n";
  }
  out << "  </Collection>\n"
      << "</VTKFile>\n";
  write_text_atomically(path, out.str());
}

}  // namespace msfem::compare
