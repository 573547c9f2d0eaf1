// ElasticityProblem::output_hdf5 read back with the HDF5 C library: the datasets are there, every
// node is a mesh vertex carrying the solution there, and the XDMF names them. Runs serially and
// under mpirun -np 2 (one file from both ranks).

// OpenMPI's hdf5.h includes <mpi.h>.
#include <hdf5.h>

#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "msfem/fem_reference/elasticity_problem.hpp"
#include "msfem/fem_reference/supports_and_loads.hpp"
#include "msfem/fem_reference/surface_mesher.hpp"
#include "test_surfaces.hpp"

namespace msfem::fem_reference {
namespace {

namespace fs = std::filesystem;

struct Dataset {
  std::vector<hsize_t> dims;
  std::vector<double> values;  ///< row-major, converted to double by HDF5
};

/// The whole dataset `name` of `file` as doubles, or no dims if it is missing.
Dataset read_dataset(const fs::path& file, const std::string& name) {
  Dataset result;
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) return result;
  if (H5Lexists(f, name.c_str(), H5P_DEFAULT) > 0) {
    const hid_t d = H5Dopen2(f, name.c_str(), H5P_DEFAULT);
    const hid_t space = H5Dget_space(d);
    const int rank = H5Sget_simple_extent_ndims(space);
    result.dims.resize(std::size_t(std::max(rank, 0)));
    H5Sget_simple_extent_dims(space, result.dims.data(), nullptr);
    hsize_t count = 1;
    for (hsize_t n : result.dims)
      count *= n;
    result.values.resize(count);
    if (H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, result.values.data()) < 0)
      result.dims.clear();
    H5Sclose(space);
    H5Dclose(d);
  }
  H5Fclose(f);
  return result;
}

/// True when every element of `xml` is closed in order (a parser's first check); the declaration
/// and comments are skipped.
bool tags_balance(const std::string& xml) {
  std::vector<std::string> open;
  for (std::size_t at = xml.find('<'); at != std::string::npos; at = xml.find('<', at + 1)) {
    const std::size_t end = xml.find('>', at);
    if (end == std::string::npos) return false;
    const std::string tag = xml.substr(at + 1, end - at - 1);
    if (tag.empty() || tag[0] == '?' || tag[0] == '!') continue;
    const std::string name =
        tag.substr(tag[0] == '/', tag.find_first_of(" \t\n/", 1) - (tag[0] == '/'));
    if (tag[0] == '/') {
      if (open.empty() || open.back() != name) return false;
      open.pop_back();
    } else if (tag.back() != '/') {
      open.push_back(name);
    }
  }
  return open.empty();
}

int mpi_ranks() {
  int size = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  return size;
}

class Hdf5Output : public ::testing::TestWithParam<unsigned int> {};

TEST_P(Hdf5Output, NodesAreMeshVerticesWithTheSolution) {
  const unsigned int degree = GetParam();
  const testing::TestSurface surface = testing::icosphere(2, 0.05);
  const VolumeMesh mesh = mesh_closed_surface(surface.vertices, surface.triangles);
  ElasticityModel model;
  model.degree = degree;
  model.material = {3e3, {}, 0.45, 1040, Eigen::Vector3d(0, 0, -9.81)};
  model.supports.push_back(
      fixed_support("core", inner_core(surface.vertices, surface.triangles, 2.0)));
  ToolIndentation tool;
  tool.contact_point = Eigen::Vector3d(0, 0, 0.05);
  tool.outward_normal = Eigen::Vector3d::UnitZ();
  tool.radius = 0.01;
  tool.depth = 0.005;
  model.supports.push_back(tool_support(tool));
  ElasticityProblem problem(mesh, model);
  problem.run();
  const Eigen::MatrixX3d u = problem.vertex_displacements();

  // A folder per rank count and degree: the serial and the mpirun=2 runs may overlap.
  const int ranks = mpi_ranks();
  const fs::path directory =
      fs::temp_directory_path() / ("msfem_hdf5_output_test_np" + std::to_string(ranks));
  const std::string basename = "ball_p" + std::to_string(degree);
  const fs::path xdmf_path = problem.output_hdf5(directory, basename);
  EXPECT_EQ(xdmf_path, directory / (basename + ".xdmf"));
  const fs::path h5_path = directory / (basename + ".h5");
  ASSERT_TRUE(fs::exists(h5_path));
  for (const auto& entry : fs::directory_iterator(directory))
    EXPECT_EQ(entry.path().string().find(".tmp."), std::string::npos)
        << "temporary left behind: " << entry.path();

  const Dataset nodes = read_dataset(h5_path, "nodes");
  const Dataset cells = read_dataset(h5_path, "cells");
  const Dataset displacement = read_dataset(h5_path, "displacement");
  ASSERT_EQ(nodes.dims.size(), 2u) << "no 2-d dataset 'nodes'";
  ASSERT_EQ(cells.dims.size(), 2u) << "no 2-d dataset 'cells'";
  ASSERT_EQ(displacement.dims.size(), 2u) << "no 2-d dataset 'displacement'";
  const std::size_t n_nodes = nodes.dims[0];
  EXPECT_EQ(nodes.dims[1], 3u);
  EXPECT_EQ(cells.dims[0], std::size_t(mesh.num_tetrahedra()));
  EXPECT_EQ(cells.dims[1], 4u);
  EXPECT_EQ(displacement.dims[0], n_nodes);
  EXPECT_EQ(displacement.dims[1], 3u);
  // One node per vertex and rank owning a cell around it: exactly the vertices on one rank.
  if (ranks == 1)
    EXPECT_EQ(n_nodes, std::size_t(mesh.num_vertices()));
  else
    EXPECT_GT(n_nodes, std::size_t(mesh.num_vertices()));
  EXPECT_LT(n_nodes, std::size_t(ranks * mesh.num_vertices()) + 1);
  for (double c : cells.values) {
    EXPECT_GE(c, 0.0);
    EXPECT_LT(c, double(n_nodes));
  }

  // Each node is a mesh vertex and carries the solution there; every vertex appears. deal.II 9.4
  // keeps patch data in single precision, so "to round-off" means float's: coordinates within
  // 1e-8 m (the mesh spacing is ~5 mm) and each value within 2^-23 of itself.
  std::vector<bool> seen(std::size_t(mesh.num_vertices()), false);
  const double scale = u.cwiseAbs().maxCoeff();
  ASSERT_GT(scale, 1e-3);  // the tool's 5 mm
  double worst = 0.0;      // |h5 - u| / (2^-23 |u| + 1e-15 max|u|): at most 1 for a float copy of u
  for (std::size_t n = 0; n < n_nodes; ++n) {
    const Eigen::RowVector3d x(nodes.values[3 * n], nodes.values[3 * n + 1],
                               nodes.values[3 * n + 2]);
    Eigen::Index v = 0;
    const double distance =
        std::sqrt((mesh.vertices.rowwise() - x).rowwise().squaredNorm().minCoeff(&v));
    ASSERT_LT(distance, 1e-8) << "node " << n << " is no mesh vertex";
    seen[std::size_t(v)] = true;
    for (int c = 0; c < 3; ++c) {
      const double value = displacement.values[3 * n + std::size_t(c)];
      ASSERT_TRUE(std::isfinite(value)) << "node " << n;
      worst = std::max(
          worst, std::abs(value - u(v, c)) / (std::ldexp(std::abs(u(v, c)), -23) + 1e-15 * scale));
    }
  }
  EXPECT_LE(worst, 1.0);
  EXPECT_EQ(std::count(seen.begin(), seen.end(), true), mesh.num_vertices());

  // The XDMF: well-formed, a tetrahedral grid of these sizes whose data live in the .h5 beside it.
  std::ifstream in(xdmf_path);
  std::stringstream text;
  text << in.rdbuf();
  const std::string xdmf = text.str();
  EXPECT_TRUE(tags_balance(xdmf)) << xdmf;
  EXPECT_NE(xdmf.find("<Xdmf"), std::string::npos) << xdmf;
  EXPECT_NE(xdmf.find("Tetrahedron"), std::string::npos) << xdmf;
  EXPECT_NE(xdmf.find("NumberOfElements=\"" + std::to_string(mesh.num_tetrahedra()) + "\""),
            std::string::npos)
      << xdmf;
  for (const char* dataset : {":/nodes", ":/cells", ":/displacement"})
    EXPECT_NE(xdmf.find(basename + ".h5" + dataset), std::string::npos) << dataset << "\n" << xdmf;
  EXPECT_NE(xdmf.find(std::to_string(n_nodes) + " 3"), std::string::npos) << xdmf;
}

INSTANTIATE_TEST_SUITE_P(Degrees, Hdf5Output, ::testing::Values(1u, 2u),
                         [](const auto& info) { return "P" + std::to_string(info.param); });

TEST(Hdf5VertexField, StoredVertexDisplacementRoundTrips) {
  // What `msfem run` writes from a cached result: the given values at the vertices, one process.
  const testing::TestSurface surface = testing::icosphere(1, 0.05);
  const VolumeMesh mesh = mesh_closed_surface(surface.vertices, surface.triangles);
  Eigen::MatrixX3d u(mesh.num_vertices(), 3);
  for (Eigen::Index v = 0; v < mesh.num_vertices(); ++v)
    u.row(v) = Eigen::RowVector3d(std::sin(100 * mesh.vertices(v, 0)), mesh.vertices(v, 1) * 0.1,
                                  -0.01 * mesh.vertices.row(v).squaredNorm());
  // Each rank writes its own files (MPI may not be initialised yet: the launcher's rank number).
  const char* rank = std::getenv("OMPI_COMM_WORLD_RANK");
  const fs::path directory = fs::temp_directory_path() / ("msfem_hdf5_output_test_stored_rank" +
                                                          std::string(rank ? rank : "0"));
  write_vertex_displacement_hdf5(mesh, u, directory, "stored");
  const Dataset nodes = read_dataset(directory / "stored.h5", "nodes");
  const Dataset displacement = read_dataset(directory / "stored.h5", "displacement");
  ASSERT_EQ(nodes.dims.size(), 2u);
  ASSERT_EQ(nodes.dims[0], std::size_t(mesh.num_vertices()));
  ASSERT_EQ(displacement.values.size(), nodes.values.size());
  double worst = 0.0;  // in units of float round-off, as above
  for (std::size_t n = 0; n < nodes.dims[0]; ++n) {
    Eigen::Index v = 0;
    const Eigen::RowVector3d x(nodes.values[3 * n], nodes.values[3 * n + 1],
                               nodes.values[3 * n + 2]);
    ASSERT_LT(std::sqrt((mesh.vertices.rowwise() - x).rowwise().squaredNorm().minCoeff(&v)), 1e-8);
    for (int c = 0; c < 3; ++c)
      worst = std::max(worst, std::abs(displacement.values[3 * n + std::size_t(c)] - u(v, c)) /
                                  (std::ldexp(std::abs(u(v, c)), -23) + 1e-300));
  }
  EXPECT_LE(worst, 1.0);
  EXPECT_THROW(write_vertex_displacement_hdf5(mesh, u.topRows(3), directory, "short"),
               std::invalid_argument);
  EXPECT_FALSE(fs::exists(directory / "short.h5"));
}

}  // namespace
}  // namespace msfem::fem_reference
