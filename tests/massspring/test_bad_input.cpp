// Bad input gives one clear ModelError naming the item, never a crash or a NaN.

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>

#include "icosphere.hpp"
#include "msfem/massspring/errors.hpp"
#include "msfem/massspring/fast_stepper.hpp"
#include "msfem/massspring/mass_spring_model.hpp"
#include "msfem/massspring/topology_builders.hpp"

namespace msfem::massspring {
namespace {

// Runs `action`, expects ModelError whose message contains every fragment.
void expect_model_error(const std::function<void()>& action,
                        const std::vector<std::string>& fragments) {
  try {
    action();
    ADD_FAILURE() << "no ModelError; expected one mentioning '" << fragments.front() << "'";
  } catch (const ModelError& error) {
    const std::string message = error.what();
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    for (const auto& fragment : fragments)
      EXPECT_NE(message.find(fragment), std::string::npos)
          << "'" << fragment << "' not in: " << message;
  }
}

SpringNetwork small_network() {
  const auto mesh = testing::icosphere(1, 0.05);
  return build_three_tier(mesh.vertices, mesh.triangles);
}

TEST(BadInput, SpringParameters) {
  SpringNetwork negative = small_network();
  negative.stiffness[7] = -3.0;
  expect_model_error([&] { MassSpringModel model(negative); }, {"spring 7", "stiffness -3"});

  SpringNetwork not_a_number = small_network();
  not_a_number.stiffness[11] = std::numeric_limits<double>::quiet_NaN();
  expect_model_error([&] { MassSpringModel model(not_a_number); }, {"spring 11", "stiffness"});

  SpringNetwork bad_damping = small_network();
  bad_damping.damping[2] = -1.0;
  expect_model_error([&] { MassSpringModel model(bad_damping); }, {"spring 2", "damping"});

  MassSpringModel model(small_network());
  expect_model_error([&] { model.set_group_stiffness("tier1_edges", -1.0); },
                     {"tier1_edges", "stiffness"});
  expect_model_error([&] { model.scale_group_stiffness("no_such_group", 2.0); }, {"no_such_group"});
  Eigen::VectorXd k = model.network().stiffness;
  k[4] = std::numeric_limits<double>::infinity();
  expect_model_error([&] { model.set_stiffness(k); }, {"spring 4"});
}

TEST(BadInput, Masses) {
  SpringNetwork zero_mass = small_network();
  zero_mass.masses[5] = 0.0;
  expect_model_error([&] { MassSpringModel model(zero_mass); }, {"node 5", "mass 0"});
  MassSpringModel model(small_network());
  expect_model_error([&] { model.set_node_group_mass("tier2", -1.0); }, {"tier2", "mass"});
  Material material;
  material.density = 0.0;
  ThreeTierOptions options;
  options.material = material;
  const auto mesh = testing::icosphere(1, 0.05);
  expect_model_error([&] { build_three_tier(mesh.vertices, mesh.triangles, options); },
                     {"density"});
}

TEST(BadInput, ZeroLengthSpringAndIndices) {
  SpringNetwork collapsed = small_network();
  collapsed.rest_positions.row(collapsed.springs(3, 1)) =
      collapsed.rest_positions.row(collapsed.springs(3, 0));
  collapsed.rest_length[3] = 0.0;
  expect_model_error([&] { MassSpringModel model(collapsed); }, {"spring 3", "zero-length"});

  SpringNetwork out_of_range = small_network();
  out_of_range.springs(9, 1) = 100000;
  expect_model_error([&] { MassSpringModel model(out_of_range); },
                     {"spring 9", "100000", "out of range"});

  auto mesh = testing::icosphere(1, 0.05);
  mesh.triangles(6, 2) = 999;
  expect_model_error([&] { build_three_tier(mesh.vertices, mesh.triangles); },
                     {"triangle 6", "999"});

  Eigen::MatrixX3d cube;
  Eigen::MatrixX4i tets;
  testing::kuhn_cube(cube, tets);
  tets(2, 1) = -1;
  expect_model_error([&] { build_tet_edges(cube, tets); }, {"tetrahedron 2", "-1"});
  testing::kuhn_cube(cube, tets);
  tets.row(4) << 0, 1, 2, 3;  // the four corners of the bottom face: flat
  expect_model_error([&] { build_tet_edges(cube, tets); }, {"tetrahedron 4", "zero volume"});

  MassSpringModel model(small_network());
  expect_model_error([&] { model.fix_node(-2); }, {"-2", "out of range"});
  expect_model_error([&] { model.set_external_force(5000, Eigen::Vector3d::Zero()); }, {"5000"});
}

TEST(BadInput, TooFewControlPointsForFourLinks) {
  const auto surface = testing::icosphere(1, 0.05);
  Eigen::MatrixX3d control(3, 3);
  control << 0.01, 0, 0, 0, 0.01, 0, 0, 0, 0.01;
  Eigen::MatrixX3i control_triangles(1, 3);
  control_triangles << 0, 1, 2;
  expect_model_error(
      [&] { build_skeleton(surface.vertices, surface.triangles, control, control_triangles); },
      {"3 control points", "4 links"});
  // A control point on a surface vertex makes a zero-length link.
  const auto coarse = testing::icosphere(0, 0.05);
  SkeletonOptions same_place;
  same_place.control_scale = 1.0;
  expect_model_error(
      [&] {
        build_skeleton(surface.vertices, surface.triangles, coarse.vertices, coarse.triangles,
                       same_place);
      },
      {"zero-length"});
}

TEST(BadInput, TimeStepsAndStates) {
  MassSpringModel model(small_network());
  FastExplicitStepper fast(model);
  expect_model_error([&] { fast.step(0.0); }, {"dt"});
  expect_model_error([&] { fast.step(-1e-4); }, {"dt"});
  State wrong{Eigen::VectorXd::Zero(6), Eigen::VectorXd::Zero(6), 0.0};
  expect_model_error([&] { fast.set_state(wrong); }, {"state size"});
  Integrator integrator(IntegratorKind::central_difference);
  expect_model_error([&] { integrator.step(model, wrong, 1e-4); }, {"state"});
  expect_model_error([&] { parse_integrator("leapfrog2"); }, {"leapfrog2"});
}

}  // namespace
}  // namespace msfem::massspring
