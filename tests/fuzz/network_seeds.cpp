// Seeds for the network readers' fuzz targets: one small network (four points, six springs in two
// groups, masses, fixed flags) as .xs3, with a surface triangle, a tetrahedron and anchors as .vtu,
// both by msfem's own writer, and a hand-written legacy .vtk.
//   network_seeds DIR
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "msfem/cases/network_file.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: network_seeds DIR\n");
    return 2;
  }
  const std::filesystem::path dir = argv[1];
  std::filesystem::create_directories(dir);
  msfem::cases::NetworkFile n;
  n.points.resize(4, 3);
  n.points << 0, 0, 0, 0.01, 0, 0, 0, 0.01, 0, 0, 0, 0.01;
  n.springs.resize(6, 2);
  n.springs << 0, 1, 0, 2, 0, 3, 1, 2, 1, 3, 2, 3;
  n.stiffness = Eigen::VectorXd::LinSpaced(6, 10, 60);
  n.damping = Eigen::VectorXd::Constant(6, 0.01);
  n.rest_length = Eigen::VectorXd::Constant(6, 0.01);
  n.spring_group.resize(6);
  n.spring_group << 0, 0, 0, 1, 1, 1;
  n.group_names = {"edges", "diagonals"};
  n.mass = Eigen::VectorXd::Constant(4, 0.001);
  n.fixed = std::vector<bool>{true, false, false, false};
  std::ofstream(dir / "seed_points.vtk")
      << "# vtk DataFile Version 3.0\nseed\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 4 double\n"
         "0 0 0 0.01 0 0 0 0.01 0 0 0 0.01\nCELLS 4 14\n2 0 1\n2 0 2\n2 1 2\n3 0 1 2\n"
         "CELL_TYPES 4\n3 3 3 5\nCELL_DATA 4\nSCALARS stiffness double 1\nLOOKUP_TABLE default\n"
         "10 20 30 0\nPOINT_DATA 4\nSCALARS mass double 1\nLOOKUP_TABLE default\n"
         "0.001 0.001 0.001 0.001\n";
  msfem::cases::write_network(dir / "seed.xs3", n);  // Xsp: springs, masses, fixed flags only
  n.anchor_stiffness = Eigen::VectorXd::Constant(4, 1.0);
  n.triangles.resize(1, 3);
  n.triangles << 1, 2, 3;
  n.tetrahedra.resize(1, 4);
  n.tetrahedra << 0, 1, 2, 3;
  n.bulk_modulus = Eigen::VectorXd::Constant(1, 1000.0);
  msfem::cases::write_network(dir / "seed.vtu", n);
  return 0;
}
