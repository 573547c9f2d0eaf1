#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <tuple>
#include <vector>

#include "msfem/cases/errors.hpp"
#include "msfem/cases/surface_generators.hpp"
#include "msfem/cases/surface_io.hpp"
#include "msfem/cases/surface_repair.hpp"
#include "surface_fixtures.hpp"

namespace msfem::cases {
namespace {

using testing::merged;
using testing::octahedron;

void expect_valid_single_piece(const Surface& s, const RepairReport& r) {
  const SurfaceReport check = validate(s);  // independent of the report the repair kept
  for (const auto& d : check.defects)
    ADD_FAILURE() << d.message;
  EXPECT_TRUE(r.result.ok());
  EXPECT_EQ(check.components, 1);
  EXPECT_EQ(check.genus, 0);
  EXPECT_GT(check.volume, 0.0);  // outward
}

Surface with_rows_appended(const Surface& s, const Eigen::MatrixX3i& extra) {
  Surface out = s;
  out.triangles.conservativeResize(s.num_triangles() + extra.rows(), 3);
  out.triangles.bottomRows(extra.rows()) = extra;
  return out;
}

// Five duplicated triangles, three flipped ones and a small octahedron far away: cleaning alone
// must restore the sphere exactly, without the wrap.
Surface sphere_with_duplicates_flips_and_extra_piece() {
  const Surface sphere = icosphere(3, 1.0);
  Surface soup = with_rows_appended(sphere, sphere.triangles.topRows(5));
  for (int t : {100, 400, 900})
    soup.triangles.row(t) =
        Eigen::RowVector3i(soup.triangles(t, 0), soup.triangles(t, 2), soup.triangles(t, 1));
  return merged(soup, octahedron(0.1, Eigen::Vector3d(5, 0, 0)));
}

TEST(SurfaceRepair, DuplicatesFlipsAndAnExtraPieceAreCleanedWithoutWrapping) {
  const Surface sphere = icosphere(3, 1.0);
  RepairReport r;
  const Surface s = repair_surface(sphere_with_duplicates_flips_and_extra_piece(), {}, r);
  expect_valid_single_piece(s, r);
  EXPECT_FALSE(r.wrapped);
  EXPECT_EQ(r.duplicate_triangles, 5);
  EXPECT_EQ(r.flipped_triangles, 3);
  EXPECT_EQ(r.dropped_components, 1);
  EXPECT_EQ(r.dropped_triangles, 8);
  EXPECT_EQ(s.num_triangles(), sphere.num_triangles());
  EXPECT_NEAR(r.result.volume, signed_volume(sphere), 1e-12);
}

TEST(SurfaceRepair, AllPiecesAreKeptWhenAsked) {
  RepairOptions options;
  options.keep_all_components = true;
  RepairReport r;
  const Surface s = repair_surface(sphere_with_duplicates_flips_and_extra_piece(), options, r);
  EXPECT_EQ(r.result.components, 2);
  EXPECT_EQ(r.dropped_components, 0);
  EXPECT_EQ(s.num_triangles(), 1280 + 8);
  EXPECT_EQ(r.result.defects.size(), 1u);  // the second piece, and nothing else
}

TEST(SurfaceRepair, AHoleAndEveryOtherDefectAreClosedByTheWrap) {
  Surface soup = sphere_with_duplicates_flips_and_extra_piece();
  // Two neighbouring triangles of the sphere removed: a hole no stitching can close.
  Surface holed = soup;
  holed.triangles.resize(soup.num_triangles() - 2, 3);
  holed.triangles << soup.triangles.topRows(10),
      soup.triangles.bottomRows(soup.num_triangles() - 12);
  RepairReport r;
  const Surface s = repair_surface(holed, {}, r);
  expect_valid_single_piece(s, r);
  EXPECT_TRUE(r.wrapped);
  EXPECT_NE(r.wrap_reason.find("boundary_edge"), std::string::npos) << r.wrap_reason;
  EXPECT_EQ(r.dropped_components, 1);  // the octahedron, wrapped apart and dropped
  EXPECT_FALSE(r.input_volume.has_value());
  const double sphere_volume = signed_volume(icosphere(3, 1.0));
  EXPECT_NEAR(r.result.volume / sphere_volume, 1.0, 0.04);
}

TEST(SurfaceRepair, ANonManifoldFinIsWrappedAway) {
  Surface s = icosphere(2, 1.0);
  const Eigen::Index tip = s.num_vertices();
  s.vertices.conservativeResize(tip + 1, 3);
  s.vertices.row(tip) =
      1.02 * (s.vertices.row(s.triangles(0, 0)) + s.vertices.row(s.triangles(0, 1))) / 2;
  Eigen::MatrixX3i fin(1, 3);
  fin << s.triangles(0, 0), s.triangles(0, 1), static_cast<int>(tip);
  s = with_rows_appended(s, fin);
  ASSERT_TRUE(validate(s, false).find(DefectKind::non_manifold_edge));
  RepairReport r;
  const Surface out = repair_surface(s, {}, r);
  expect_valid_single_piece(out, r);
  EXPECT_TRUE(r.wrapped);
  EXPECT_NEAR(r.result.volume / signed_volume(icosphere(2, 1.0)), 1.0, 0.05);
}

TEST(SurfaceRepair, OverlappingSpheresAreWrappedIntoTheirUnion) {
  const Surface big = icosphere(3, 1.0);
  const Surface small = [] {
    Surface s = icosphere(3, 0.8);
    s.vertices.col(0).array() += 1.2;
    return s;
  }();
  RepairReport r;
  const Surface s = repair_surface(merged(big, small), {}, r);
  expect_valid_single_piece(s, r);
  EXPECT_TRUE(r.wrapped);
  EXPECT_NE(r.wrap_reason.find("self_intersection"), std::string::npos) << r.wrap_reason;
  EXPECT_EQ(r.dropped_components, 0);
  EXPECT_GT(r.result.volume, 1.05 * signed_volume(big));
  EXPECT_LT(r.result.volume, 0.95 * (signed_volume(big) + signed_volume(small)));
}

TEST(SurfaceRepair, ShippedLiverIsValidAfterRepairWithinThreePercentOfItsVolume) {
  const Surface liver =
      read_surface(std::string(MSFEM_DEFAULT_CASES_DIR) + "/data/liver_sofa_smooth_cm.obj",
                   LengthUnit::centimetre);
  ASSERT_FALSE(validate(liver).ok());
  RepairReport r;
  const Surface s = repair_surface(liver, {}, r);
  expect_valid_single_piece(s, r);
  EXPECT_TRUE(r.wrapped);
  ASSERT_TRUE(r.input_volume.has_value());
  EXPECT_NEAR(*r.input_volume, signed_volume(liver), 1e-12);
  EXPECT_NEAR(r.result.volume / *r.input_volume, 1.0, 0.03);
}

TEST(SurfaceRepair, TheDefaultAlphaFollowsTheEdgeLengthWithinTheDiagonalBounds) {
  const Surface sphere = icosphere(3, 1.0);
  const double alpha = default_wrap_alpha(sphere);
  EXPECT_GT(alpha, 0.1);  // level 3: edges about 0.16 of the radius
  EXPECT_LT(alpha, 0.2);
  const Surface icosahedron = icosphere(0, 1.0);  // edges 1.05, over a twentieth of the diagonal
  const auto box = bounding_box(icosahedron);
  EXPECT_NEAR(default_wrap_alpha(icosahedron), (box.row(1) - box.row(0)).norm() / 20.0, 1e-12);
}

TEST(SurfaceRepair, NothingUsableIsAnInputError) {
  Surface flat;
  flat.vertices.resize(3, 3);
  flat.vertices << 0, 0, 0, 1, 0, 0, 2, 0, 0;
  flat.triangles.resize(2, 3);
  flat.triangles << 0, 1, 1, 2, 2, 0;
  RepairReport r;
  EXPECT_THROW(repair_surface(flat, {}, r), InputError);
  EXPECT_THROW(repair_surface(Surface{}, {}, r), InputError);
}

TEST(SurfaceRepair, AbsurdCoordinatesAndWrapSizesAreRefusedBeforeCgal) {
  // Each of these died with SIGFPE inside the alpha wrap or refined for hours.
  RepairReport r;
  RepairOptions wrap;
  wrap.always_wrap = true;
  const Surface far{1e200 * icosphere(1, 1.0).vertices, icosphere(1, 1.0).triangles};
  try {
    repair_surface(far, wrap, r);
    ADD_FAILURE() << "1e200 m accepted";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "vertex 0 is more than 1e6 m from the origin");
  }
  const Surface sphere = icosphere(1, 1.0);  // bounding-box diagonal 2 sqrt(3) m
  const std::vector<std::tuple<double, double, std::string>> sizes = {
      {1e300, 0.1, "the wrap's alpha 1e+300 m must be between 1/500 and 10 times"},
      {1e-300, 0.1, "the wrap's alpha 1e-300 m must be between 1/500 and 10 times"},
      {1e-3, 0.1, "the wrap's alpha 0.001 m must be between 1/500 and 10 times"},
      {0.5, 1e300, "the wrap's offset 1e+300 m must be between 1e-6 and 1 times"},
      {0.5, 1e-300, "the wrap's offset 1e-300 m must be between 1e-6 and 1 times"},
  };
  for (const auto& [alpha, offset, expected] : sizes) {
    RepairOptions options = wrap;
    options.alpha = alpha;
    options.offset = offset;
    try {
      repair_surface(sphere, options, r);
      ADD_FAILURE() << "alpha " << alpha << ", offset " << offset << " accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()), expected + " the surface's bounding-box diagonal, 3.4641 m");
    }
  }
}

}  // namespace
}  // namespace msfem::cases
