// The accelerated static solver (reused factorisation, Wolfe line search, nodal relaxation)
// against plain damped Newton, and warm starts.

#include <gtest/gtest.h>

#include <Eigen/SparseCholesky>
#include <cmath>
#include <memory>

#include "icosphere.hpp"
#include "msfem/massspring/mass_spring_model.hpp"
#include "msfem/massspring/static_solver.hpp"
#include "msfem/massspring/tool_contact.hpp"
#include "msfem/massspring/topology_builders.hpp"

namespace msfem::massspring {
namespace {

StaticOptions plain_newton() {
  StaticOptions options;
  options.reuse_factorization = false;
  options.relax_nodes = false;
  options.wolfe_line_search = false;
  return options;
}

// A 5 cm three-tier sphere pressed 5 mm at the pole by a prescribed patch (one equilibrium).
MassSpringModel indented_sphere() {
  const auto mesh = testing::icosphere(3, 0.05);
  MassSpringModel model(build_three_tier(mesh.vertices, mesh.triangles));
  ToolIndentation indent;
  indent.contact_point = {0.0, 0.0, 0.05};
  indent.inward_direction = {0.0, 0.0, -1.0};
  indent.radius = 0.01;
  indent.depth = 0.005;
  prescribe_contact_patch(model, indent);
  return model;
}

// The bent banana with normal-offset inner tiers, which fold where it is concave (the brain's
// problem in small), held below z = -1 cm and pressed off its symmetry plane, so that its
// equilibrium is unique and stable.
MassSpringModel indented_banana() {
  const auto mesh = testing::bent_banana(2, 0.05);
  ThreeTierOptions options;
  options.inner_tiers = InnerTierMethod::normal_offset;
  MassSpringModel model(build_three_tier(mesh.vertices, mesh.triangles, options));
  for (int i = 0; i < model.num_nodes(); ++i)
    if (model.network().rest_positions(i, 2) < -0.01) model.fix_node(i);
  const Eigen::Vector3d push = Eigen::Vector3d(0.3, 0.2, 1.0).normalized();
  Eigen::Index top = 0;
  (mesh.vertices * push).maxCoeff(&top);
  ToolIndentation indent;
  indent.contact_point = mesh.vertices.row(top).transpose();
  indent.inward_direction = -push;
  indent.radius = 0.01;
  indent.depth = 0.005;
  prescribe_contact_patch(model, indent);
  return model;
}

void expect_same_equilibrium_fewer_factorizations(const MassSpringModel& model) {
  const StaticResult plain = solve_static(model, plain_newton());
  const StaticResult fast = solve_static(model);
  ASSERT_TRUE(plain.converged);
  ASSERT_TRUE(fast.converged);
  const double displacement = (plain.x - model.initial_state()).norm();
  ASSERT_GT(displacement, 1e-3);
  EXPECT_LE((fast.x - plain.x).norm(), 1e-9 * displacement);
  EXPECT_EQ(fast.reference_norm, plain.reference_norm);
  // Plain Newton factorises at least once per iteration; the reused factorisation should leave
  // one or two (the first tangent is often indefinite: the patch compresses springs).
  EXPECT_GE(plain.factorizations, plain.iterations);
  EXPECT_LE(fast.factorizations, 2);
  EXPECT_LT(fast.factorizations, plain.factorizations);
  EXPECT_GT(fast.preconditioned_iterations, 0);
  EXPECT_EQ(fast.history.size(), static_cast<std::size_t>(fast.iterations));
}

// A plugged factorisation (here Eigen's SimplicialLLT, counting its calls) stands in for the
// built-in LDLT everywhere: indefinite tangents included, which it must refuse.
class CountingLlt final : public SparseSpdFactor {
 public:
  explicit CountingLlt(int& calls) : calls_(calls) {}
  void analyze(const Eigen::SparseMatrix<double>& k) override { llt_.analyzePattern(k); }
  bool factorize(const Eigen::SparseMatrix<double>& k) override {
    ++calls_;
    llt_.factorize(k);
    return llt_.info() == Eigen::Success;
  }
  Eigen::VectorXd solve(const Eigen::VectorXd& r) const override { return llt_.solve(r); }

 private:
  int& calls_;
  Eigen::SimplicialLLT<Eigen::SparseMatrix<double>> llt_;
};

TEST(StaticSolverPluggedFactorization, GivesTheBuiltInEquilibriumAndIsTheOneUsed) {
  for (const MassSpringModel& model : {indented_sphere(), indented_banana()}) {
    const StaticResult builtin = solve_static(model);
    int calls = 0;
    StaticOptions options;
    options.factorization = [&calls] { return std::make_unique<CountingLlt>(calls); };
    const StaticResult plugged = solve_static(model, options);
    ASSERT_TRUE(builtin.converged);
    ASSERT_TRUE(plugged.converged);
    EXPECT_EQ(calls, plugged.factorizations);
    EXPECT_GT(calls, 0);
    const double displacement = (builtin.x - model.initial_state()).norm();
    EXPECT_LE((plugged.x - builtin.x).norm(), 1e-9 * displacement);
  }
}

TEST(StaticSolverAcceleration, SphereMatchesPlainNewton) {
  expect_same_equilibrium_fewer_factorizations(indented_sphere());
}

TEST(StaticSolverAcceleration, FoldedBananaMatchesPlainNewton) {
  expect_same_equilibrium_fewer_factorizations(indented_banana());
}

TEST(StaticSolverAcceleration, WarmStartFromTheEquilibriumReturnsAtOnce) {
  const MassSpringModel model = indented_banana();
  const StaticResult cold = solve_static(model);
  ASSERT_TRUE(cold.converged);
  // The tolerance is relative to the problem, not to the start's residual (which is already at
  // round-off here): at most one iteration, and nothing moves.
  for (const StaticOptions& options : {StaticOptions(), plain_newton()}) {
    const StaticResult warm = solve_static(model, options, cold.x);
    EXPECT_TRUE(warm.converged);
    EXPECT_LE(warm.iterations, 1);
    EXPECT_EQ(warm.reference_norm, cold.reference_norm);
    EXPECT_LE((warm.x - cold.x).norm(), 1e-12 * (cold.x - model.initial_state()).norm());
  }
}

TEST(StaticSolverAcceleration, WarmStartAfterAStiffnessChangeMatchesColdStart) {
  // What a calibration loop does: new group stiffnesses, start from the last equilibrium.
  MassSpringModel model = indented_sphere();
  const StaticResult before = solve_static(model);
  ASSERT_TRUE(before.converged);
  model.scale_group_stiffness("tier12_diagonals", 1.3);
  model.scale_group_stiffness("tier1_edges", 0.8);
  const StaticResult cold = solve_static(model, plain_newton());
  const StaticResult warm = solve_static(model, StaticOptions(), before.x);
  ASSERT_TRUE(cold.converged);
  ASSERT_TRUE(warm.converged);
  EXPECT_GT((cold.x - before.x).norm(), 1e-6);  // the change moved the equilibrium
  EXPECT_LE((warm.x - cold.x).norm(), 1e-9 * (cold.x - model.initial_state()).norm());
  EXPECT_LE(warm.factorizations, 1);
  EXPECT_LE(warm.iterations, cold.iterations);
}

TEST(StaticSolverAcceleration, ToleranceBelowRoundOffStopsAtTheFloor) {
  // |f| cannot fall below the cancellation in the spring forces (~1e-16 × k × |x| per spring):
  // asked for less, Newton stops once its step no longer moves x or |f| is under that floor,
  // instead of running on.
  const MassSpringModel model = indented_sphere();
  const StaticResult usual = solve_static(model);
  StaticOptions strict;
  strict.tolerance = 1e-20;
  const StaticResult floor = solve_static(model, strict);
  ASSERT_TRUE(usual.converged);
  EXPECT_TRUE(floor.converged);
  EXPECT_TRUE(floor.converged_at_roundoff);
  EXPECT_LE(floor.iterations, usual.iterations + 3);
  EXPECT_LE((floor.x - usual.x).norm(), 1e-9 * (usual.x - model.initial_state()).norm());
}

}  // namespace
}  // namespace msfem::massspring
