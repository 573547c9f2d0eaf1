#include <gtest/gtest.h>

#include "msfem/cases/case_parameters.hpp"
#include "msfem/cases/setting_names.hpp"
#include "msfem/compare/pipeline/case_run.hpp"
#include "msfem/compare/pipeline/variant_run.hpp"
#include "msfem/massspring/mass_spring_model.hpp"
#include "msfem/massspring/topology_builders.hpp"

namespace msfem::compare {
namespace {

TEST(LoadingPath, WithoutAStepItIsTheSortedDistinctDepths) {
  EXPECT_EQ(loading_path({0.004, 0.002}, 0.004, 0.0), (std::vector<double>{0.002, 0.004}));
  EXPECT_EQ(loading_path({0.002}, 0.003, 0.0), (std::vector<double>{0.002, 0.003}));
}

TEST(LoadingPath, StepsAreEqualWithinEachIntervalNoLongerThanAskedAndKeepTheRecordedDepths) {
  const std::vector<double> path = loading_path({0.002, 0.004}, 0.004, 0.0007);
  // 0..2 mm in 3 steps (0.667 mm), 2..4 mm in 3 steps.
  ASSERT_EQ(path.size(), 6u);
  EXPECT_EQ(path[2], 0.002);
  EXPECT_EQ(path[5], 0.004);
  double last = 0.0;
  for (double d : path) {
    EXPECT_GT(d - last, 0.0);
    EXPECT_LE(d - last, 0.0007 + 1e-15);
    last = d;
  }
  EXPECT_NEAR(path[0], 0.002 / 3, 1e-15);
  EXPECT_NEAR(path[3] - path[2], 0.002 / 3, 1e-15);
  // A step that divides an interval exactly adds no sliver step.
  EXPECT_EQ(loading_path({0.002, 0.004}, 0.004, 0.0005).size(), 8u);
  // A step longer than every interval changes nothing.
  EXPECT_EQ(loading_path({0.002, 0.004}, 0.004, 0.01), (std::vector<double>{0.002, 0.004}));
}

// A frictionless sphere moves at most a quarter of its radius per static step, whatever the path
// step; a bonded patch keeps the case's path step.
TEST(LoadingPath, AFrictionlessToolStepsAtMostAQuarterOfItsRadius) {
  cases::ToolParameters tool;
  tool.radius_m = 0.004;
  tool.mode = cases::ToolParameters::Mode::contact;
  EXPECT_EQ(path_step_of(tool), 0.001);
  tool.path_step_m = 0.0005;
  EXPECT_EQ(path_step_of(tool), 0.0005);
  tool.path_step_m = 0.003;
  EXPECT_EQ(path_step_of(tool), 0.001);
  // A single curve depth at the case's depth: four equal steps, not one jump from rest.
  EXPECT_EQ(loading_path({0.004}, 0.004, path_step_of(tool)),
            (std::vector<double>{0.001, 0.002, 0.003, 0.004}));
  tool.mode = cases::ToolParameters::Mode::prescribed;
  EXPECT_EQ(path_step_of(tool), 0.003);
  tool.path_step_m = 0;
  EXPECT_EQ(path_step_of(tool), 0.0);
}

// run, sweep and calibrate press every load along one rule: the case's curve depths, scaled to the
// load's depth (quarters of it by default), in steps no longer than the path step.
TEST(LoadingPath, EveryLoadFollowsTheCasesCurveScaledToItsDepth) {
  cases::ToolParameters tool;
  tool.mode = cases::ToolParameters::Mode::prescribed;
  tool.depth_m = 0.004;
  // The case's own depth: the default quarters, as the force-depth curve records them.
  EXPECT_EQ(loading_path(tool, 0.004), loading_path(curve_depths(tool), 0.004, 0.0));
  EXPECT_EQ(loading_path(tool, 0.002), (std::vector<double>{0.0005, 0.001, 0.0015, 0.002}));
  tool.curve_depths_m = {0.002, 0.006};
  EXPECT_EQ(loading_path(tool, 0.004), (std::vector<double>{0.002, 0.004, 0.006}));
  const std::vector<double> half = loading_path(tool, 0.002);
  ASSERT_EQ(half.size(), 3u);
  EXPECT_DOUBLE_EQ(half[0], 0.001);
  EXPECT_EQ(half[1], 0.002);  // the load's own depth exactly, where its equilibrium is read
  EXPECT_DOUBLE_EQ(half[2], 0.003);
  // The case's depth lands on the load's exactly (0.004 · 0.0045/0.004 is not 0.0045 in doubles).
  tool.curve_depths_m = {0.002, 0.004};
  const std::vector<double> deeper = loading_path(tool, 0.0045);
  ASSERT_EQ(deeper.size(), 2u);
  EXPECT_EQ(deeper[1], 0.0045);
  // A frictionless tool of radius 2 mm: no step over half a millimetre.
  tool.mode = cases::ToolParameters::Mode::contact;
  tool.radius_m = 0.002;
  double last = 0.0;
  for (double d : loading_path(tool, 0.002)) {
    EXPECT_LE(d - last, 0.0005 + 1e-15);
    last = d;
  }
  EXPECT_EQ(last, 0.002);
}

BuiltVariant one_tetrahedron() {
  Eigen::MatrixX3d v(4, 3);
  v << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  Eigen::MatrixX4i t(1, 4);
  t << 0, 1, 2, 3;
  BuiltVariant b;
  b.name = "tet_edges";
  b.model = std::make_unique<massspring::MassSpringModel>(massspring::build_tet_edges(v, t));
  b.tetrahedra = t;
  return b;
}

// A tool pressing along -z (outward normal +z): the axial force is f_z, the lateral |(f_x, f_y)|.
TEST(BucklingOnset, TheFirstDepthWhereTheForceStopsGrowingOrTurnsSideways) {
  ToolPlacement tool;
  tool.outward_normal = Eigen::Vector3d::UnitZ();
  tool.depth = 0.005;
  auto at = [](double depth, double fx, double fz) {
    return ForceDepthPoint{depth, Eigen::Vector3d(fx, 0, fz), {}, {}};
  };
  // Hertz-like and straight: neither.
  const BucklingOnset straight = buckling_onset(
      {at(0.001, 0.0, 0.01), at(0.002, 0.001, 0.03), at(0.003, 0.002, 0.05)}, tool, 0.5);
  EXPECT_FALSE(straight.force_falls_at_m);
  EXPECT_FALSE(straight.turns_sideways_at_m);
  // Given unsorted: turns sideways at 3 mm (0.04 / 0.05 = 0.8 > 0.5), falls at 4 mm.
  const BucklingOnset buckled = buckling_onset(
      {at(0.004, 0.06, 0.045), at(0.001, 0.0, 0.01), at(0.003, 0.04, 0.05), at(0.002, 0.0, 0.03)},
      tool, 0.5);
  ASSERT_TRUE(buckled.force_falls_at_m);
  EXPECT_DOUBLE_EQ(*buckled.force_falls_at_m, 0.004);
  ASSERT_TRUE(buckled.turns_sideways_at_m);
  EXPECT_DOUBLE_EQ(*buckled.turns_sideways_at_m, 0.003);
  EXPECT_NEAR(buckled.lateral_fraction, 0.8, 1e-12);
  // Equal forces at two depths: the force stopped growing there.
  EXPECT_DOUBLE_EQ(
      *buckling_onset({at(0.001, 0, 0.02), at(0.002, 0, 0.02)}, tool, 0.5).force_falls_at_m, 0.002);
}

TEST(InvertedTetrahedra, CountsAnElementTurnedInsideOutNotOneMerelySquashedOrMoved) {
  const BuiltVariant b = one_tetrahedron();
  Eigen::VectorXd x(12);
  x << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  EXPECT_EQ(inverted_tetrahedra(b, x), 0);
  x[11] = 0.05;  // flattened but the same way up
  EXPECT_EQ(inverted_tetrahedra(b, x), 0);
  x[11] = -1.0;  // the apex through its base: every spring keeps its length
  EXPECT_EQ(inverted_tetrahedra(b, x), 1);
  EXPECT_NEAR(b.model->potential_energy(x), 0.0, 1e-12)
      << "a mirrored tetrahedron costs edge springs nothing";
  x.array() += 3.0;  // a rigid translation changes nothing
  EXPECT_EQ(inverted_tetrahedra(b, x), 1);
}

TEST(InvertedTetrahedra, NoneForAVariantWithoutVolumeElements) {
  BuiltVariant b = one_tetrahedron();
  b.tetrahedra.resize(0, 4);
  EXPECT_FALSE(inverted_tetrahedra(b, Eigen::VectorXd::Zero(12)).has_value());
}

}  // namespace
}  // namespace msfem::compare

namespace msfem::compare {
namespace {

// The case checks group scales against spring_groups_of before anything is built: the list must
// be exactly what each builder makes, with three_tier's inner diagonals on and off.
TEST(SpringGroups, TheListedGroupsAreWhatEachVariantBuilds) {
  auto parameters = cases::read_case(std::string(MSFEM_TEST_DATA_DIR) + "/small_sphere.prm");
  for (const bool inner_diagonals : {false, true}) {
    parameters.mass_spring.inner_diagonals = inner_diagonals;
    const Problem problem = make_problem(parameters);
    const auto mesh = mesh_problem(problem);
    for (const cases::Variant kind : cases::all_values<cases::Variant>()) {
      const BuiltVariant built = build_variant(kind, problem, mesh, problem.tools.front());
      EXPECT_EQ(built.model->network().spring_group_names, spring_groups_of(kind, parameters))
          << built.name;
    }
  }
}

}  // namespace
}  // namespace msfem::compare
