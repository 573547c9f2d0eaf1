#include "msfem/fem_reference/surface_mesher.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

#include "msfem/cases/surface.hpp"
#include "msfem/cases/surface_io.hpp"
#include "msfem/fem_reference/shape_mesher.hpp"
#include "test_surfaces.hpp"

namespace msfem::fem_reference {
namespace {

double enclosed_volume(const testing::TestSurface& s) {
  double v = 0.0;
  for (Eigen::Index t = 0; t < s.triangles.rows(); ++t) {
    const Eigen::Vector3d a = s.vertices.row(s.triangles(t, 0)),
                          b = s.vertices.row(s.triangles(t, 1)),
                          c = s.vertices.row(s.triangles(t, 2));
    v += a.dot(b.cross(c)) / 6.0;
  }
  return v;
}

TEST(SurfaceMesher, KeepsEverySurfaceVertexAsMeshVertex) {
  const testing::TestSurface sphere = testing::icosphere(3, 0.05);
  const VolumeMesh mesh = mesh_closed_surface(sphere.vertices, sphere.triangles);
  ASSERT_EQ(mesh.num_surface_vertices, sphere.vertices.rows());
  EXPECT_GT(mesh.num_vertices(), sphere.vertices.rows());
  // Surface vertex i is mesh vertex i, bit for bit: the node-to-node map is the identity.
  EXPECT_EQ(mesh.vertices.topRows(sphere.vertices.rows()), sphere.vertices);
  // The boundary faces are the surface triangles: the polyhedral volume is the surface's.
  EXPECT_NEAR(volume(mesh), enclosed_volume(sphere), 1e-12 * enclosed_volume(sphere));
  // Every surface vertex is used by a tetrahedron, and no interior vertex lies on the surface.
  std::set<int> used(mesh.tetrahedra.data(), mesh.tetrahedra.data() + mesh.tetrahedra.size());
  for (int i = 0; i < sphere.vertices.rows(); ++i)
    EXPECT_TRUE(used.count(i)) << i;
  for (Eigen::Index i = sphere.vertices.rows(); i < mesh.num_vertices(); ++i)
    EXPECT_LT(mesh.vertices.row(i).norm(), 0.05 * (1 - 1e-6));
  EXPECT_NO_THROW(check_volume_mesh(mesh));
  const Eigen::VectorXd masses = lumped_vertex_masses(mesh, 1040.0);
  EXPECT_NEAR(masses.sum(), 1040.0 * volume(mesh), 1e-12 * masses.sum());
  EXPECT_GT(masses.minCoeff(), 0.0);
}

TEST(VolumeMesh, PartitionsCellsIntoEqualSlabs) {
  const testing::TestSurface sphere = testing::icosphere(3, 0.05);
  const VolumeMesh mesh = mesh_closed_surface(sphere.vertices, sphere.triangles);
  const auto n = std::size_t(mesh.num_tetrahedra());
  for (unsigned int parts : {1u, 2u, 3u, 5u}) {
    const std::vector<unsigned int> part = partition_cells(mesh, parts);
    ASSERT_EQ(part.size(), n);
    std::vector<std::size_t> size(parts, 0);
    for (unsigned int p : part) {
      ASSERT_LT(p, parts);
      ++size[p];
    }
    const auto [smallest, largest] = std::minmax_element(size.begin(), size.end());
    EXPECT_LE(*largest - *smallest, parts) << parts << " parts";
    EXPECT_EQ(partition_cells(mesh, parts), part) << "not deterministic";
  }
  // Two parts: one cut plane, normal to an axis, separates the centroids.
  const std::vector<unsigned int> half = partition_cells(mesh, 2);
  std::vector<Eigen::Vector3d> centroids(n);
  for (std::size_t e = 0; e < n; ++e) {
    centroids[e].setZero();
    for (int k = 0; k < 4; ++k)
      centroids[e] += 0.25 * mesh.vertices.row(mesh.tetrahedra(Eigen::Index(e), k)).transpose();
  }
  bool separated_on_some_axis = false;
  for (int axis = 0; axis < 3; ++axis) {
    double max0 = -1e300, min1 = 1e300;
    for (std::size_t e = 0; e < n; ++e)
      (half[e] == 0 ? max0 : min1) =
          half[e] == 0 ? std::max(max0, centroids[e][axis]) : std::min(min1, centroids[e][axis]);
    separated_on_some_axis |= max0 <= min1;
  }
  EXPECT_TRUE(separated_on_some_axis);
}

TEST(SurfaceMesher, RefinesNearTheTool) {
  const testing::TestSurface sphere = testing::icosphere(2, 0.05);
  MeshOptions options;
  options.cell_size = 0.01;
  const VolumeMesh coarse = mesh_closed_surface(sphere.vertices, sphere.triangles, options);
  options.refinements = {LocalRefinement{Eigen::Vector3d(0, 0, 0.04), 0.01, 0.01, 0.003}};
  const VolumeMesh refined = mesh_closed_surface(sphere.vertices, sphere.triangles, options);
  auto count_near = [](const VolumeMesh& m) {
    int n = 0;
    for (Eigen::Index i = 0; i < m.num_vertices(); ++i)
      n += (m.vertices.row(i) - Eigen::RowVector3d(0, 0, 0.04)).norm() < 0.015;
    return n;
  };
  EXPECT_GT(count_near(refined), 2 * count_near(coarse));
  EXPECT_EQ(refined.vertices.topRows(sphere.vertices.rows()), sphere.vertices);
}

TEST(VolumeMesh, CellQualityOfKnownTetrahedra) {
  VolumeMesh mesh;
  const double h = std::sqrt(2.0 / 3.0), eps = 1e-4;
  mesh.vertices.resize(12, 3);
  mesh.vertices << 1, 0, -1 / std::sqrt(2.0), -1, 0, -1 / std::sqrt(2.0), 0, 1, 1 / std::sqrt(2.0),
      0, -1, 1 / std::sqrt(2.0),                     // regular
      0, 0, 0, 3, 0, 0, 0, 3, 0, 0, 0, 3,            // corner of a cube, scaled by 3
      0, 0, 0, 1, 0, 0, 0.5, h, 0, 0.5, h / 3, eps;  // a sliver of height eps
  mesh.tetrahedra.resize(3, 4);
  mesh.tetrahedra << 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11;
  const Eigen::VectorXd q = cell_quality(mesh);
  ASSERT_EQ(q.size(), 3);
  EXPECT_NEAR(q[0], 1.0, 1e-12);
  // Corner: inradius 3V / A = 3 * 4.5 / (13.5 + 4.5 sqrt 3), longest edge 3 sqrt 2.
  EXPECT_NEAR(q[1], 2.0 * std::sqrt(3.0) / (3.0 + std::sqrt(3.0)), 1e-12);
  EXPECT_GT(q[2], 0.0);
  EXPECT_LT(q[2], 10 * eps);
}

// Tetrahedra between the brain's large surface triangles and a finer interior are flat; Gmsh's
// relocation pass must raise the worst of them (0.0020 -> 0.0028 at 3 mm, 0.0010 -> 0.0040 at 1.9
// mm, where CG then needs half the iterations) without touching the surface or the cell count.
TEST(SurfaceMesher, RelocationRaisesTheWorstCellOfTheFoldedBrain) {
  cases::Surface brain =
      cases::read_surface(std::string(MSFEM_CASES_DIR) + "/data/brain_icbm152_lh_9177_mm.obj",
                          cases::LengthUnit::millimetre);
  if (cases::signed_volume(brain) < 0.0) brain.triangles.col(1).swap(brain.triangles.col(2));
  MeshOptions options;
  options.cell_size = 0.003;
  options.relocate_below_quality = 0.0;
  const VolumeMesh plain = mesh_closed_surface(brain.vertices, brain.triangles, options);
  options.relocate_below_quality = 1.0;  // always
  const VolumeMesh relocated = mesh_closed_surface(brain.vertices, brain.triangles, options);
  EXPECT_EQ(relocated.num_tetrahedra(), plain.num_tetrahedra());
  EXPECT_EQ(relocated.vertices.topRows(brain.vertices.rows()), brain.vertices);
  const double worst_plain = cell_quality(plain).minCoeff();
  const double worst_relocated = cell_quality(relocated).minCoeff();
  EXPECT_GT(worst_relocated, 1.2 * worst_plain);
  EXPECT_NEAR(volume(relocated), volume(plain), 1e-12 * volume(plain));
}

TEST(SurfaceMesher, RejectsOpenOrInconsistentSurfaces) {
  testing::TestSurface sphere = testing::icosphere(1, 1.0);
  testing::TestSurface open = sphere;
  open.triangles.conservativeResize(open.triangles.rows() - 1, 3);
  EXPECT_THROW(mesh_closed_surface(open.vertices, open.triangles), std::invalid_argument);
  testing::TestSurface flipped = sphere;
  std::swap(flipped.triangles(0, 1), flipped.triangles(0, 2));
  EXPECT_THROW(mesh_closed_surface(flipped.vertices, flipped.triangles), std::invalid_argument);
  testing::TestSurface out_of_range = sphere;
  out_of_range.triangles(3, 2) = 1000;
  EXPECT_THROW(check_closed_surface(out_of_range.vertices, out_of_range.triangles),
               std::invalid_argument);
  try {
    check_closed_surface(open.vertices, open.triangles);
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("not closed"), std::string::npos) << e.what();
  }
}

TEST(ShapeMesher, MeshesExactShapesAndRefines) {
  const VolumeMesh box = mesh_box(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0.1, 0.2), 0.05);
  EXPECT_NEAR(volume(box), 0.02, 1e-12);
  const double octant = M_PI / 6 * (1 - 0.125);
  const VolumeMesh coarse = mesh_hollow_sphere(0.5, 1.0, 0.2, true);
  const VolumeMesh fine = mesh_hollow_sphere(0.5, 1.0, 0.1, true);
  EXPECT_GT(fine.num_tetrahedra(), 3 * coarse.num_tetrahedra());
  EXPECT_NEAR(volume(fine), octant, 0.01 * octant);
  EXPECT_LT(std::abs(volume(fine) - octant), std::abs(volume(coarse) - octant));
  for (Eigen::Index i = 0; i < fine.num_vertices(); ++i) {
    EXPECT_GE(fine.vertices.row(i).minCoeff(), -1e-12);
    EXPECT_LE(fine.vertices.row(i).norm(), 1.0 + 1e-9);
    EXPECT_GE(fine.vertices.row(i).norm(), 0.5 - 1e-9);
  }
  EXPECT_THROW(mesh_hollow_sphere(1.0, 0.5, 0.1, false), std::invalid_argument);
}

}  // namespace
}  // namespace msfem::fem_reference
