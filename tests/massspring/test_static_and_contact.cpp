// Static equilibrium by Newton against long damped dynamics; tool indentation as a prescribed
// patch and as frictionless contact, with the reaction force on the tool.

#include <gtest/gtest.h>

#include <cmath>

#include "icosphere.hpp"
#include "msfem/massspring/integrators.hpp"
#include "msfem/massspring/mass_spring_model.hpp"
#include "msfem/massspring/stability.hpp"
#include "msfem/massspring/static_solver.hpp"
#include "msfem/massspring/tool_contact.hpp"
#include "msfem/massspring/topology_builders.hpp"

namespace msfem::massspring {
namespace {

MassSpringModel three_tier_model(int level, double node_damping = 0.0) {
  const auto mesh = testing::icosphere(level, 0.05);
  ThreeTierOptions options;
  options.material.node_damping = node_damping;
  return MassSpringModel(build_three_tier(mesh.vertices, mesh.triangles, options));
}

// Sum of the internal forces on the constrained nodes, i.e. minus what the supports take.
Eigen::Vector3d support_force(const MassSpringModel& model, const Eigen::VectorXd& x,
                              const std::vector<int>& skip) {
  const Eigen::VectorXd f = model.force(x, Eigen::VectorXd::Zero(x.size()));
  Eigen::Vector3d total = Eigen::Vector3d::Zero();
  for (int i : model.constrained_nodes())
    if (std::find(skip.begin(), skip.end(), i) == skip.end()) total += f.segment<3>(3 * i);
  return total;
}

TEST(StaticSolver, NewtonUnderGravityMatchesLongDampedDynamics) {
  MassSpringModel model = three_tier_model(0, 0.0);
  model.set_gravity({0.0, 0.0, -9.81});
  const StaticResult statics = solve_static(model);
  ASSERT_TRUE(statics.converged);
  EXPECT_LE(statics.iterations, 12);
  const Eigen::VectorXd rest = model.initial_state();
  const double sag = (statics.x - rest).norm();
  EXPECT_GT(sag, 1e-3);  // a visible deformation, so the check below means something

  // Same answer with CG as the linear solver.
  StaticOptions cg_options;
  cg_options.linear_solver = StaticLinearSolver::cg;
  const StaticResult statics_cg = solve_static(model, cg_options);
  ASSERT_TRUE(statics_cg.converged);
  EXPECT_LE((statics_cg.x - statics.x).norm(), 1e-9 * sag);

  // Long damped run with central differences (node damping ≈ critical for the slow modes).
  const double mean_mass = model.network().masses.mean();
  const double omega_max = std::sqrt(estimate_max_eigenvalue(model, rest).max_eigenvalue);
  model.set_node_damping(2.0 * mean_mass * omega_max / 6.0);
  const double dt = 0.5 * predicted_stable_dt(model, IntegratorKind::central_difference, rest);
  Integrator integrator(IntegratorKind::central_difference);
  State state = initial_state(model);
  for (int n = 0; n < 20000; ++n)
    integrator.step(model, state, dt);
  EXPECT_LE((state.x - statics.x).norm() / sag, 1e-6);
}

TEST(StaticSolver, LargeLoadNeedsTheLineSearchAndStillConverges) {
  MassSpringModel model = three_tier_model(1);
  model.set_gravity({0.0, 0.0, -9.81 * 20.0});  // sags by a good fraction of the radius
  const StaticResult statics = solve_static(model);
  EXPECT_TRUE(statics.converged);
  EXPECT_LE(statics.residual_norm, 1e-10 * statics.reference_norm);
}

ToolIndentation north_pole_indent(double depth) {
  ToolIndentation indent;
  indent.contact_point = {0.0, 0.0, 0.05};
  indent.inward_direction = {0.0, 0.0, -1.0};
  indent.radius = 0.01;
  indent.depth = depth;
  return indent;
}

TEST(ToolContact, PrescribedPatchReactionBalancesTheSupports) {
  MassSpringModel model = three_tier_model(2);
  const std::vector<int> patch = prescribe_contact_patch(model, north_pole_indent(0.005));
  ASSERT_GE(patch.size(), 1u);
  const StaticResult statics = solve_static(model);
  ASSERT_TRUE(statics.converged);
  const Eigen::Vector3d reaction = patch_reaction_force(model, statics.x, patch);
  EXPECT_GT(reaction.z(), 0.0);  // the tissue pushes the tool back out
  EXPECT_LE(reaction.head<2>().norm(), 1e-6 * reaction.norm());
  // Global balance: tool reaction + tier-3 support forces = 0 (no other load).
  EXPECT_LE((reaction + support_force(model, statics.x, patch)).norm(), 1e-8 * reaction.norm());

  // Scaling every spring by 2 leaves the prescribed-displacement solution and doubles the force,
  // without rebuilding anything.
  for (const auto& group : model.network().spring_group_names)
    model.scale_group_stiffness(group, 2.0);
  const StaticResult stiffer = solve_static(model);
  EXPECT_LE((stiffer.x - statics.x).norm(),
            1e-8 * (statics.x - model.initial_state()).norm() + 1e-15);
  EXPECT_NEAR(patch_reaction_force(model, stiffer.x, patch).z() / reaction.z(), 2.0, 1e-8);
}

// Level 3: with a coarser mesh a single node lies under the tool, and frictionless contact lets it
// slide off sideways (a correct but degenerate answer).
TEST(ToolContact, FrictionlessContactKeepsNodesOutsideTheTool) {
  MassSpringModel model = three_tier_model(3);
  const ToolIndentation indent = north_pole_indent(0.005);
  activate_sphere_contact(model, indent);
  const StaticResult statics = solve_static(model);
  ASSERT_TRUE(statics.converged);
  const SphereTool tool = indent.tool();
  double deepest = 0.0;
  int touching = 0;
  for (int i : model.network().surface_nodes) {
    const double gap = (statics.x.segment<3>(3 * i) - tool.center).norm() - tool.radius;
    deepest = std::max(deepest, -gap);
    if (gap < 1e-4) ++touching;
  }
  EXPECT_GE(touching, 1);
  EXPECT_LE(deepest, 1e-3 * indent.depth);  // penalty penetration
  const Eigen::Vector3d reaction = contact_reaction_force(model, statics.x);
  EXPECT_GT(reaction.z(), 0.0);
  EXPECT_LE((reaction + support_force(model, statics.x, {})).norm(), 1e-7 * reaction.norm());

  // Same order as the prescribed patch (the patch sticks, contact slides).
  MassSpringModel patch_model = three_tier_model(3);
  const auto patch = prescribe_contact_patch(patch_model, indent);
  const StaticResult patch_statics = solve_static(patch_model);
  const double ratio = reaction.z() / patch_reaction_force(patch_model, patch_statics.x, patch).z();
  EXPECT_GT(ratio, 0.8);
  EXPECT_LT(ratio, 1.25);

  // Dynamics: nodes are projected out of the tool after every step.
  model.set_node_damping(0.05);
  Integrator integrator(IntegratorKind::implicit_euler, ImplicitOptions{1e-6, 200});
  State state = initial_state(model);
  for (int n = 0; n < 5; ++n) {
    integrator.step(model, state, 1e-3);
    for (int i : model.network().surface_nodes)
      EXPECT_GE((state.x.segment<3>(3 * i) - tool.center).norm(), tool.radius - 1e-12);
  }
}

}  // namespace
}  // namespace msfem::massspring
