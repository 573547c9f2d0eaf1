#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "msfem/cases/surface_generators.hpp"
#include "msfem/cases/surface_io.hpp"
#include "msfem/cases/surface_validation.hpp"
#include "surface_fixtures.hpp"

namespace msfem::cases {
namespace {

using testing::merged;
using testing::octahedron;
using testing::tetrahedron;

bool contains(const std::vector<int>& ids, std::initializer_list<int> wanted) {
  return std::all_of(wanted.begin(), wanted.end(),
                     [&](int w) { return std::find(ids.begin(), ids.end(), w) != ids.end(); });
}

TEST(Validate, OctahedronIsAClosedGenusZeroSolid) {
  const SurfaceReport r = validate(octahedron(2.0));
  EXPECT_TRUE(r.ok());
  EXPECT_EQ(r.vertices, 6);
  EXPECT_EQ(r.edges, 12);
  EXPECT_EQ(r.triangles, 8);
  EXPECT_EQ(r.genus, 0);
  EXPECT_EQ(r.components, 1);
  EXPECT_NEAR(r.volume, 4.0 / 3.0 * 8.0, 1e-12);
  EXPECT_NEAR(r.area, 8 * std::sqrt(3.0) / 4 * 8.0, 1e-12);  // 8 equilateral sides of 2√2
  EXPECT_TRUE(r.self_intersections_checked);
  EXPECT_TRUE(r.fixes.empty());
}

TEST(Validate, TorusHasGenusOne) {
  const SurfaceReport r = validate(testing::torus(24, 12));
  EXPECT_TRUE(r.ok()) << (r.defects.empty() ? "" : r.defects[0].message);
  EXPECT_EQ(r.genus, 1);
  EXPECT_EQ(r.edges, 3 * 24 * 12);
}

TEST(Validate, MissingTriangleLeavesItsThreeBoundaryEdges) {
  Surface s = octahedron();
  s.triangles.conservativeResize(7, 3);  // drops triangle (0, 3, 5)
  const SurfaceReport r = validate(s);
  const Defect* d = r.find(DefectKind::boundary_edge);
  ASSERT_NE(d, nullptr);
  ASSERT_EQ(d->elements.size(), 6u);  // three edges as vertex pairs
  EXPECT_TRUE(contains(d->elements, {0, 3, 5}));
  EXPECT_NE(d->message.find("3 boundary edges"), std::string::npos) << d->message;
  EXPECT_EQ(r.genus, -1);
}

TEST(Validate, OneFlippedTriangleIsInconsistentWithItsThreeNeighbours) {
  Surface s = octahedron();
  std::swap(s.triangles(4, 1), s.triangles(4, 2));
  const SurfaceReport r = validate(s);
  const Defect* d = r.find(DefectKind::inconsistent_orientation);
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->elements.size(), 6u);  // three triangle pairs, each naming triangle 4
  EXPECT_EQ(std::count(d->elements.begin(), d->elements.end(), 4), 3);
  EXPECT_FALSE(r.self_intersections_checked);
}

TEST(Validate, InwardSurfaceIsFlippedAndSaysSo) {
  Surface s = icosphere(2, 1.0);
  s.triangles.col(0).swap(s.triangles.col(1));
  const double inward_volume = signed_volume(s);
  ASSERT_LT(inward_volume, 0);
  EXPECT_EQ(validate(s).fixes.size(), 1u);  // validate() reports, changes nothing
  EXPECT_LT(signed_volume(s), 0);

  const SurfaceReport r = orient_and_validate(s);
  EXPECT_TRUE(r.ok());
  ASSERT_EQ(r.fixes.size(), 1u);
  EXPECT_NE(r.fixes[0].find("inward"), std::string::npos);
  EXPECT_NEAR(signed_volume(s), -inward_volume, 1e-14);
  EXPECT_NEAR(r.volume, -inward_volume, 1e-14);
}

TEST(Validate, DegenerateTrianglesAreNamed) {
  Surface s = octahedron();
  // The apex moved to the midpoint of edge 0-2: triangle (0, 2, 4) has no area left.
  s.vertices.row(4) = 0.5 * (s.vertices.row(0) + s.vertices.row(2));
  const SurfaceReport report = validate(s);
  const Defect* d = report.find(DefectKind::degenerate_triangle);
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->elements, std::vector<int>{0});

  Surface repeated = octahedron();
  repeated.triangles(3, 2) = repeated.triangles(3, 0);
  const SurfaceReport repeated_report = validate(repeated);
  const Defect* r = repeated_report.find(DefectKind::degenerate_triangle);
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(r->elements, std::vector<int>{3});
}

TEST(Validate, EdgeSharedByFourTrianglesIsNonManifold) {
  // Two tetrahedra glued along the edge 0-1 only.
  Surface s = merged(tetrahedron(), tetrahedron(Eigen::Vector3d(0, -2, -2)));
  s.vertices.row(4) = s.vertices.row(0);
  s.vertices.row(5) = s.vertices.row(1);
  for (Eigen::Index t = 4; t < 8; ++t)
    for (int c = 0; c < 3; ++c) {
      if (s.triangles(t, c) == 4) s.triangles(t, c) = 0;
      if (s.triangles(t, c) == 5) s.triangles(t, c) = 1;
    }
  const SurfaceReport r = validate(s);
  const Defect* d = r.find(DefectKind::non_manifold_edge);
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->elements, (std::vector<int>{0, 1}));
  EXPECT_NE(r.find(DefectKind::unreferenced_vertex), nullptr);  // 4 and 5 are left over
  EXPECT_EQ(r.genus, -1);
}

TEST(Validate, BowTieVertexIsNonManifold) {
  // Two tetrahedra touching at one vertex: every edge is fine, the shared vertex is not.
  Surface s = merged(tetrahedron(), tetrahedron(Eigen::Vector3d(-1, -1, -1)));
  // The second one lies in the negative octant; its corner (-1,-1,0) (id 7) is glued onto the
  // first one's origin (id 0).
  s.vertices.row(7) = s.vertices.row(0);
  for (Eigen::Index t = 4; t < 8; ++t)
    for (int c = 0; c < 3; ++c)
      if (s.triangles(t, c) == 7) s.triangles(t, c) = 0;
  const SurfaceReport r = validate(s);
  const Defect* d = r.find(DefectKind::non_manifold_vertex);
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->elements, std::vector<int>{0});
  EXPECT_EQ(r.find(DefectKind::non_manifold_edge), nullptr);
  EXPECT_EQ(r.find(DefectKind::boundary_edge), nullptr);
}

TEST(Validate, SecondPieceIsAnExtraComponent) {
  const Surface s = merged(octahedron(1.0), tetrahedron(Eigen::Vector3d(5, 0, 0)));
  const SurfaceReport r = validate(s);
  EXPECT_EQ(r.components, 2);
  const Defect* d = r.find(DefectKind::multiple_components);
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->elements, std::vector<int>{8});  // the tetrahedron's first triangle
  EXPECT_EQ(r.genus, 0);                        // each piece is a sphere: chi = 4 = 2C - 2g
}

TEST(Validate, VertexPushedThroughTheOppositeSideSelfIntersects) {
  Surface s = icosphere(2, 1.0);
  // Vertex 0 moved to the far side of the sphere: its fan now crosses the triangles there.
  s.vertices.row(0) = -1.5 * s.vertices.row(0);
  const SurfaceReport r = validate(s);
  const Defect* d = r.find(DefectKind::self_intersection);
  ASSERT_NE(d, nullptr);
  EXPECT_GE(d->elements.size(), 2u);
  EXPECT_TRUE(r.self_intersections_checked);
  EXPECT_TRUE(validate(icosphere(2, 1.0)).ok());
}

TEST(Validate, BadIndicesAndNonFiniteCoordinatesAreNamed) {
  Surface s = octahedron();
  s.triangles(5, 1) = 17;
  const SurfaceReport r = validate(s);
  ASSERT_EQ(r.defects.size(), 1u);
  EXPECT_EQ(r.defects[0].kind, DefectKind::invalid_index);
  EXPECT_EQ(r.defects[0].elements, std::vector<int>{5});

  Surface n = octahedron();
  n.vertices(3, 2) = std::nan("");
  const SurfaceReport non_finite = validate(n);
  const Defect* d = non_finite.find(DefectKind::non_finite_vertex);
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->elements, std::vector<int>{3});
}

TEST(Validate, SofaLiverHasFiveIntersectingPairsOfNonNeighbours) {
  Surface liver = read_surface(std::string(MSFEM_CASES_DIR) + "/data/liver_sofa_smooth_cm.obj",
                               LengthUnit::centimetre);
  const SurfaceReport r = orient_and_validate(liver);
  EXPECT_EQ(r.vertices, 2194);
  EXPECT_EQ(r.triangles, 4384);
  EXPECT_EQ(r.genus, 0);
  ASSERT_EQ(r.defects.size(), 1u) << r.defects[0].message;
  const Defect& d = r.defects[0];
  EXPECT_EQ(d.kind, DefectKind::self_intersection);
  // The data's documentation counts 5 intersecting pairs of triangles that share no vertex; CGAL
  // also finds 2 pairs of neighbours (sharing one vertex) folded through each other.
  std::vector<std::array<int, 2>> disjoint;
  for (std::size_t k = 0; k < d.elements.size(); k += 2) {
    const auto a = liver.triangles.row(d.elements[k]), b = liver.triangles.row(d.elements[k + 1]);
    bool share = false;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        share = share || a[i] == b[j];
    if (!share) disjoint.push_back({d.elements[k], d.elements[k + 1]});
  }
  EXPECT_EQ(disjoint.size(), 5u) << d.message;
  EXPECT_EQ(d.elements.size(), 14u) << d.message;
  EXPECT_NE(d.message.find("5 sharing no vertex"), std::string::npos) << d.message;
  EXPECT_NE(d.message.find("(811,1951)"), std::string::npos) << d.message;
}

TEST(Validate, SharedBrainAndPancreasAreClean) {
  for (const auto& [file, unit] : {std::pair{"brain_icbm152_lh_mm.obj", LengthUnit::millimetre},
                                   std::pair{"pancreas_vh_female_m.obj", LengthUnit::metre}}) {
    Surface s = read_surface(std::string(MSFEM_CASES_DIR) + "/data/" + file, unit);
    const SurfaceReport r = orient_and_validate(s);
    EXPECT_TRUE(r.ok()) << file << ": " << (r.defects.empty() ? "" : r.defects[0].message);
    EXPECT_EQ(r.genus, 0) << file;
    EXPECT_TRUE(r.fixes.empty()) << file << " is documented as outward";
  }
}

}  // namespace
}  // namespace msfem::cases
