#pragma once
// The beam of SOFA's MeshSpringForceField benchmark (MeshSpringForceField_beam10x10x40): a regular
// grid of nx × ny × nz nodes, each cube split into the six tetrahedra about its main diagonal, one
// stiffness on every tetrahedron edge, one mass on every node, the x = 0 end fixed. Written here
// by hand, as a simulator would, as an XML .vtu (springs as line cells in two groups, grid edges
// and diagonals, the boundary faces as triangles) and as SOFA's Xsp 3.0; the test solves the same
// springs with its own Newton.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace msfem::testing {

struct SofaBeam {
  int nx = 40, ny = 10, nz = 10;  ///< nodes along each axis (SOFA's grid n = "10 10 40")
  double spacing = 0.01;          ///< m between neighbouring nodes
  double stiffness = 3e4;         ///< N/m on every edge (about E h for the case's E)
  double density = 1000.0;        ///< kg/m³: the grid's volume's mass shared equally by the nodes
  double diagonal_scale = 1.0;    ///< diagonals' stiffness relative to the grid edges'

  Eigen::MatrixX3d points;
  std::vector<std::array<int, 2>> springs;
  std::vector<int> group;  ///< 0: grid edges (along an axis), 1: diagonals
  std::vector<std::array<int, 3>> triangles;
  std::vector<bool> fixed;

  int id(int i, int j, int k) const { return i + nx * (j + ny * k); }
  double node_mass() const {
    return density * (nx - 1) * (ny - 1) * (nz - 1) * spacing * spacing * spacing / (nx * ny * nz);
  }
  double spring_stiffness(std::size_t s) const {
    return group[s] == 0 ? stiffness : stiffness * diagonal_scale;
  }
};

/// Builds the beam's points, springs, surface and fixed end.
inline SofaBeam make_sofa_beam(SofaBeam b) {
  b.points.resize(b.nx * b.ny * b.nz, 3);
  b.fixed.assign(std::size_t(b.points.rows()), false);
  for (int k = 0; k < b.nz; ++k)
    for (int j = 0; j < b.ny; ++j)
      for (int i = 0; i < b.nx; ++i) {
        b.points.row(b.id(i, j, k)) << i * b.spacing, j * b.spacing, k * b.spacing;
        b.fixed[std::size_t(b.id(i, j, k))] = i == 0;
      }
  // Six tetrahedra per cube, each a path 000 -> +e_a -> +e_b -> +e_c = 111 (Kuhn's split: the
  // same in every cube, so neighbouring cubes share their faces' diagonals).
  const std::array<std::array<int, 3>, 6> orders = {
      {{{0, 1, 2}}, {{0, 2, 1}}, {{1, 0, 2}}, {{1, 2, 0}}, {{2, 0, 1}}, {{2, 1, 0}}}};
  std::set<std::array<int, 2>> edges;
  std::map<std::array<int, 3>, std::array<int, 4>> faces;  // sorted face -> face + opposite
  for (int k = 0; k + 1 < b.nz; ++k)
    for (int j = 0; j + 1 < b.ny; ++j)
      for (int i = 0; i + 1 < b.nx; ++i)
        for (const auto& order : orders) {
          std::array<int, 3> c = {{i, j, k}};
          std::array<int, 4> tet;
          tet[0] = b.id(c[0], c[1], c[2]);
          for (int s = 0; s < 3; ++s) {
            ++c[std::size_t(order[std::size_t(s)])];
            tet[std::size_t(s) + 1] = b.id(c[0], c[1], c[2]);
          }
          for (int p = 0; p < 4; ++p)
            for (int q = p + 1; q < 4; ++q)
              edges.insert(
                  std::array<int, 2>{{std::min(tet[p], tet[q]), std::max(tet[p], tet[q])}});
          for (int opposite = 0; opposite < 4; ++opposite) {
            std::array<int, 3> face;
            for (int v = 0, f = 0; v < 4; ++v)
              if (v != opposite) face[std::size_t(f++)] = tet[std::size_t(v)];
            std::array<int, 3> key = face;
            std::sort(key.begin(), key.end());
            if (faces.erase(key) == 0)
              faces[key] = {{face[0], face[1], face[2], tet[std::size_t(opposite)]}};
          }
        }
  for (const auto& e : edges) {
    b.springs.push_back(e);
    const Eigen::RowVector3d d = b.points.row(e[1]) - b.points.row(e[0]);
    const int along = (d.array().abs() > 0.5 * b.spacing).count();
    b.group.push_back(along == 1 ? 0 : 1);
  }
  // A face of one tetrahedron only is on the boundary; it faces away from the opposite vertex.
  for (const auto& [key, f] : faces) {
    const Eigen::Vector3d a = b.points.row(f[0]).transpose(), p = b.points.row(f[1]).transpose(),
                          q = b.points.row(f[2]).transpose(), o = b.points.row(f[3]).transpose();
    if ((p - a).cross(q - a).dot(o - a) > 0)
      b.triangles.push_back({{f[0], f[2], f[1]}});
    else
      b.triangles.push_back({{f[0], f[1], f[2]}});
  }
  return b;
}

/// The beam as ParaView or SOFA's VTKExporter writes an unstructured grid: line cells (springs)
/// then triangle cells (the surface); cell data stiffness, damping (none) and group (the
/// triangles' 0), point data mass and fixed; group names in field data.
inline void write_sofa_beam_vtu(const SofaBeam& b, const std::filesystem::path& file) {
  std::ofstream out(file);
  out.precision(17);
  const std::size_t cells = b.springs.size() + b.triangles.size();
  out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" "
         "byte_order=\"LittleEndian\">\n<UnstructuredGrid>\n<FieldData>\n"
         "<DataArray type=\"String\" Name=\"group_names\" NumberOfTuples=\"2\" format=\"ascii\">\n"
      // "grid_edges\0diagonals\0" as the bytes VTK writes for a string array
      << "103 114 105 100 95 101 100 103 101 115 0 100 105 97 103 111 110 97 108 115 0\n"
      << "</DataArray>\n</FieldData>\n<Piece NumberOfPoints=\"" << b.points.rows()
      << "\" NumberOfCells=\"" << cells << "\">\n<PointData>\n"
      << "<DataArray type=\"Float64\" Name=\"mass\" format=\"ascii\">\n";
  for (Eigen::Index p = 0; p < b.points.rows(); ++p)
    out << b.node_mass() << "\n";
  out << "</DataArray>\n<DataArray type=\"UInt8\" Name=\"fixed\" format=\"ascii\">\n";
  for (const bool f : b.fixed)
    out << (f ? 1 : 0) << "\n";
  out << "</DataArray>\n</PointData>\n<CellData>\n"
      << "<DataArray type=\"Float64\" Name=\"stiffness\" format=\"ascii\">\n";
  for (std::size_t s = 0; s < b.springs.size(); ++s)
    out << b.spring_stiffness(s) << "\n";
  for (std::size_t t = 0; t < b.triangles.size(); ++t)
    out << "0\n";
  // No dampers, as SOFA's MeshSpringForceField has by default and the Xsp file says (kd = 0).
  out << "</DataArray>\n<DataArray type=\"Float64\" Name=\"damping\" format=\"ascii\">\n";
  for (std::size_t c = 0; c < cells; ++c)
    out << "0\n";
  out << "</DataArray>\n<DataArray type=\"Int32\" Name=\"group\" format=\"ascii\">\n";
  for (std::size_t s = 0; s < b.springs.size(); ++s)
    out << b.group[s] << "\n";
  for (std::size_t t = 0; t < b.triangles.size(); ++t)
    out << "0\n";
  out << "</DataArray>\n</CellData>\n<Points>\n"
      << "<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (Eigen::Index p = 0; p < b.points.rows(); ++p)
    out << b.points(p, 0) << " " << b.points(p, 1) << " " << b.points(p, 2) << "\n";
  out << "</DataArray>\n</Points>\n<Cells>\n"
      << "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (const auto& s : b.springs)
    out << s[0] << " " << s[1] << "\n";
  for (const auto& t : b.triangles)
    out << t[0] << " " << t[1] << " " << t[2] << "\n";
  out << "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  std::size_t offset = 0;
  for (std::size_t s = 0; s < b.springs.size(); ++s)
    out << (offset += 2) << "\n";
  for (std::size_t t = 0; t < b.triangles.size(); ++t)
    out << (offset += 3) << "\n";
  out << "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  for (std::size_t s = 0; s < b.springs.size(); ++s)
    out << "3\n";
  for (std::size_t t = 0; t < b.triangles.size(); ++t)
    out << "5\n";
  out << "</DataArray>\n</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
}

/// The beam as SOFA's Xsp 3.0: fixed masses with a negative mass, springs numbered from 1 with
/// their rest length, gravity as SOFA's default scene has it.
inline void write_sofa_beam_xsp(const SofaBeam& b, const std::filesystem::path& file) {
  std::ofstream out(file);
  out.precision(17);
  out << "Xsp 3.0\nnumm " << b.points.rows() << "\nnums " << b.springs.size() << "\n";
  for (Eigen::Index p = 0; p < b.points.rows(); ++p)
    out << "mass " << p + 1 << " n " << b.points(p, 0) << " " << b.points(p, 1) << " "
        << b.points(p, 2) << " 0 0 0 " << (b.fixed[std::size_t(p)] ? -b.node_mass() : b.node_mass())
        << " 0\n";
  for (std::size_t s = 0; s < b.springs.size(); ++s)
    out << "lspg " << s + 1 << " " << b.springs[s][0] + 1 << " " << b.springs[s][1] + 1 << " "
        << b.spring_stiffness(s) << " 0 "
        << (b.points.row(b.springs[s][0]) - b.points.row(b.springs[s][1])).norm() << "\n";
  out << "grav 0 0 -9.81\n";
}

/// A case for the beam: its own surface as the geometry (E and ν from here), the fixed end as the
/// support, gravity, no tool unless asked; `networks` as mass spring/networks.
inline void write_sofa_beam_case(const std::filesystem::path& file, const std::string& geometry,
                                 const std::string& networks) {
  std::ofstream(file) << "# SOFA's MeshSpringForceField beam, sagging under gravity.\n"
                         "subsection geometry\n  set source = network:"
                      << geometry
                      << "\nend\n"
                         "subsection material\n  set youngs modulus = 3e6\n"
                         "  set poisson ratio = 0.3\n  set density = 1000\nend\n"
                         "subsection support\n  set fixed region = half space\n"
                         "  set half space point = 0.001, 0, 0\n"
                         "  set half space normal = -1, 0, 0\nend\n"
                         "subsection loads\n  set gravity = 0, 0, -9.81\n"
                         "  subsection tool\n    set enabled = false\n  end\nend\n"
                         "subsection mass spring\n  set variants =\n  set networks = "
                      << networks
                      << "\nend\nsubsection fem\n  set degree = 1\n"
                         "  set error estimate = none\nend\n";
}

}  // namespace msfem::testing
