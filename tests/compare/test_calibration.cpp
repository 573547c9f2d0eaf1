// Calibration against data whose answer is known: a mass-spring model with chosen coefficients
// stands in for the FEM, and the fit, started 2-3x off, has to find the coefficients again.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>

#include "../massspring/grasper.hpp"

#include "msfem/cases/errors.hpp"
#include "msfem/compare/calibration/calibration.hpp"
#include "msfem/massspring/integrators.hpp"
#include "msfem/massspring/mass_spring_model.hpp"

namespace msfem::compare {
namespace {

cases::CaseParameters sphere_case() {
  cases::CaseParameters p;
  p.name = "recovery";
  p.file = "recovery.prm";
  p.geometry.source = "icosphere:2:0.05";
  p.support.kind = cases::SupportParameters::Kind::inner_core;
  p.support.inner_core_scale = 2.0;
  p.loads.tool.radius_m = 0.008;
  p.loads.tool.depth_m = 0.004;
  p.loads.tool.directions = {Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX(),
                             Eigen::Vector3d(0, -1, 0.5).normalized()};
  p.mass_spring.variants = {cases::Variant::three_tier};
  return p;
}

// "FEM" data: the three-tier model with the given group scales (and whatever `dress` adds to it),
// solved on each tool at its depth.
std::vector<CalibrationLoad> synthetic_references(
    const Problem& truth, std::vector<double> depths = {0.004, 0.003, 0.0035},
    const std::function<void(BuiltVariant&)>& dress = {}) {
  std::vector<CalibrationLoad> refs;
  const fem_reference::VolumeMesh no_mesh;
  for (std::size_t i = 0; i < truth.tools.size(); ++i) {
    CalibrationLoad r;
    r.load = {truth.parameters.loads.tool.directions[i], depths[i]};
    r.tool = at_depth(truth.tools[i], depths[i]);
    BuiltVariant v = build_variant(cases::Variant::three_tier, truth, no_mesh, r.tool);
    if (dress) dress(v);
    const StaticSolution s = solve_variant_static(v);
    r.fem.surface_displacement = s.surface_displacement;
    r.fem.tool_force = s.tool_force;
    for (Eigen::Index vertex = 0; vertex < truth.surface.num_vertices(); ++vertex)
      if (std::find(v.tool_patch.begin(), v.tool_patch.end(), vertex) == v.tool_patch.end() &&
          !truth.fixed_region(truth.surface.vertices.row(vertex).transpose()))
        r.compared_vertices.push_back(static_cast<int>(vertex));
    refs.push_back(r);
  }
  return refs;
}

// Data from `p` with the groups scaled by `truth`, two loads to train on and one held out; the fit
// of the same case with the analytic coefficients starts at truth × `start_off` and must find every
// truth again to 1 % and reproduce the data.
CalibrationFit expect_recovers(const cases::CaseParameters& p,
                               const std::vector<std::string>& groups,
                               const std::vector<double>& truth,
                               const std::vector<double>& start_off) {
  cases::CaseParameters with_truth = p;
  for (std::size_t g = 0; g < groups.size(); ++g)
    with_truth.mass_spring.group_scales.emplace_back(groups[g], truth[g]);
  const std::vector<CalibrationLoad> refs = synthetic_references(make_problem(with_truth));
  CalibrationOptions options;
  options.groups = groups;
  options.tolerance = 1e-7;
  options.max_evaluations = 2000;
  for (std::size_t g = 0; g < groups.size(); ++g)
    options.start_factors.push_back(truth[g] * start_off[g]);
  const std::vector<CalibrationLoad> train(refs.begin(), refs.begin() + 2);
  const std::vector<CalibrationLoad> test(refs.begin() + 2, refs.end());
  const CalibrationFit fit =
      calibrate(make_problem(p), {}, cases::Variant::three_tier, train, test, options);
  EXPECT_EQ(fit.groups.size(), groups.size());
  for (std::size_t g = 0; g < groups.size() && g < fit.groups.size(); ++g) {
    // case_factor: fitted stiffness over the analytic one (the case has no group scales).
    EXPECT_NEAR(fit.groups[g].case_factor / truth[g], 1.0, 0.01) << groups[g];
    EXPECT_NEAR(fit.groups[g].factor * options.start_factors[g] / truth[g], 1.0, 0.01) << groups[g];
  }
  EXPECT_GT(fit.before.train[0].displacement.all.rel_l2_error, 0.05);
  EXPECT_LT(fit.after.train[0].displacement.all.rel_l2_error, 1e-3);
  EXPECT_LT(fit.after.test[0].displacement.all.rel_l2_error,
            1e-3);  // the held-out load: the truth generalises
  EXPECT_LT(fit.after.test[0].reaction_force_rel_error, 1e-3);
  EXPECT_LT(fit.objective_after, 1e-4 * fit.objective_before);
  EXPECT_EQ(fit.history.size(), static_cast<std::size_t>(fit.evaluations));
  return fit;
}

TEST(Calibration, RecoversKnownCoefficientsFromAStartTwoToThreeTimesOff) {
  expect_recovers(
      sphere_case(),
      {"tier1_edges", "tier2_edges", "tier12_diagonals", "tier12_radial", "tier23_radial"},
      {1.3, 0.8, 1.1, 0.9, 1.6}, {2.5, 0.4, 2.0, 1.0 / 3.0, 2.2});
}

TEST(Calibration, RecoversTheVolumeModulusWithTheSprings) {
  // ν = 0.45: volume preservation adds κ = λ(E, 0.45) − λ(E, 1/4) ≈ 2.7 E to every shell prism.
  cases::CaseParameters p = sphere_case();
  p.material.poisson_ratio = 0.45;
  p.mass_spring.volume_preservation = true;
  const CalibrationFit fit = expect_recovers(p, {"tier1_edges", "tier12_radial", "volume"},
                                             {1.3, 0.9, 0.6}, {2.5, 1.0 / 3.0, 2.0});
  ASSERT_EQ(fit.groups.size(), 3u);
  EXPECT_EQ(fit.groups[2].unit, "Pa");
  EXPECT_EQ(fit.groups[2].springs, 2 * make_problem(p).surface.triangles.rows());  // two shells
  const double kappa = 3000.0 * (0.45 / (1.45 * 0.1) - 0.25 / (1.25 * 0.5));
  EXPECT_NEAR(fit.groups[2].fitted_stiffness_n_per_m / (0.6 * kappa), 1.0, 0.01);
}

// A field a simulator adds to a built variant is fitted by its coefficient group as the model's
// own are: data made with a grasper (massspring's test field, written outside it) pulling the
// -z pole 3 mm down at k = 40 N/m, fitted from k = 16 N/m.
TEST(Calibration, FitsTheCoefficientGroupOfAFieldWrittenOutsideMassspring) {
  const Problem problem = make_problem(sphere_case());
  const auto add_grasper = [](double k, double pull) {
    return [k, pull](BuiltVariant& v) {
      const Eigen::MatrixX3d& rest = v.model->network().rest_positions;
      std::vector<int> surface = v.model->network().surface_nodes;
      std::sort(surface.begin(), surface.end(),
                [&](int a, int b) { return rest(a, 2) < rest(b, 2); });
      const std::vector<int> held(surface.begin(), surface.begin() + 5);
      Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
      for (int i : held)
        centroid += rest.row(i).transpose() / 5.0;
      v.model->add_field(std::make_shared<massspring::testing::Grasper>(
          v.model->num_nodes(), held, centroid - Eigen::Vector3d(0, 0, pull), k, 0.0));
    };
  };
  const auto refs = synthetic_references(problem, {0.004, 0.003, 0.0035}, add_grasper(40.0, 0.003));
  BuiltVariant base = build_variant(cases::Variant::three_tier, problem, {}, refs.front().tool);
  add_grasper(16.0, 0.003)(base);
  CalibrationOptions options;
  options.groups = {"grasp"};
  options.tolerance = 1e-7;
  const std::vector<CalibrationLoad> train(refs.begin(), refs.begin() + 2);
  const std::vector<CalibrationLoad> test(refs.begin() + 2, refs.end());
  const CalibrationFit fit = calibrate(problem, base, train, test, options);
  ASSERT_EQ(fit.groups.size(), 1u);
  EXPECT_FALSE(fit.groups[0].spring_group);
  EXPECT_EQ(fit.groups[0].unit, "N/m");
  EXPECT_EQ(fit.groups[0].springs, 1);
  EXPECT_NEAR(fit.groups[0].factor / 2.5, 1.0, 0.01);
  EXPECT_NEAR(fit.groups[0].fitted_stiffness_n_per_m / 40.0, 1.0, 0.01);
  EXPECT_GT(fit.before.train[0].displacement.all.rel_l2_error, 0.02);
  EXPECT_LT(fit.after.test[0].displacement.all.rel_l2_error, 1e-3);
  // The linearised fit weighs the field as one part, and finds the same k where the loads are
  // small enough for the model linearised at rest.
  const auto small = synthetic_references(problem, {5e-5, 5e-5, 5e-5}, add_grasper(40.0, 3e-5));
  BuiltVariant small_base =
      build_variant(cases::Variant::three_tier, problem, {}, small.front().tool);
  add_grasper(16.0, 3e-5)(small_base);
  options.linear = true;
  const CalibrationFit linear =
      calibrate(problem, small_base, {small[0], small[1]}, {small[2]}, options);
  ASSERT_EQ(linear.groups.size(), 1u);
  EXPECT_NEAR(linear.groups[0].fitted_stiffness_n_per_m / 40.0, 1.0, 0.01);
}

// A group two of the model's fields name is refused before any solve: a fit could not tell which
// to scale.
TEST(Calibration, RefusesAGroupTwoFieldsName) {
  const Problem problem = make_problem(sphere_case());
  const auto refs = synthetic_references(problem);
  BuiltVariant base = build_variant(cases::Variant::three_tier, problem, {}, refs.front().tool);
  for (int copy = 0; copy < 2; ++copy)
    base.model->add_field(std::make_shared<massspring::testing::Grasper>(
        base.model->num_nodes(), std::vector<int>{0}, Eigen::Vector3d::Zero(), 1.0, 0.0));
  CalibrationOptions options;
  options.groups = {"grasp"};
  try {
    calibrate(problem, base, refs, {}, options);
    FAIL() << "a group two fields name was accepted";
  } catch (const cases::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'grasp' 2 times"), std::string::npos) << e.what();
  }
}

TEST(Calibration, TheVolumeGroupNeedsVolumePreservation) {
  const Problem problem = make_problem(sphere_case());
  const auto refs = synthetic_references(problem);
  CalibrationOptions options;
  options.groups = {"volume"};
  try {
    calibrate(problem, {}, cases::Variant::three_tier, refs, {}, options);
    FAIL() << "the volume group was accepted without volume preservation";
  } catch (const cases::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("volume preservation = true"), std::string::npos)
        << e.what();
  }
}

TEST(Calibration, RejectsUnknownGroupsAndAnEmptyTrainingSet) {
  const Problem problem = make_problem(sphere_case());
  const auto refs = synthetic_references(problem);
  CalibrationOptions options;
  options.groups = {"tier1_edges", "no_such_group"};
  try {
    calibrate(problem, {}, cases::Variant::three_tier, refs, {}, options);
    FAIL() << "an unknown group was accepted";
  } catch (const cases::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_group"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("tier12_radial"), std::string::npos) << e.what();
  }
  options.groups = {};
  EXPECT_THROW(calibrate(problem, {}, cases::Variant::three_tier, {}, refs, options),
               cases::InputError);
}

TEST(Calibration, StopsAtTheEvaluationLimitAndKeepsTheBestPoint) {
  cases::CaseParameters p = sphere_case();
  p.mass_spring.group_scales = {{"tier1_edges", 2.0}};
  const auto refs = synthetic_references(make_problem(p));
  CalibrationOptions options;
  options.groups = {"tier1_edges", "tier2_edges"};
  options.max_evaluations = 4;
  const CalibrationFit fit =
      calibrate(make_problem(sphere_case()), {}, cases::Variant::three_tier, refs, {}, options);
  EXPECT_FALSE(fit.converged);
  EXPECT_NE(fit.stop_reason.find("evaluation limit"), std::string::npos) << fit.stop_reason;
  EXPECT_EQ(fit.evaluations, 4);
  // The point kept is the best one evaluated, never worse than the start.
  const double best = *std::min_element(fit.history.begin(), fit.history.end());
  EXPECT_LE(fit.objective_after, std::min(best, fit.objective_before) * (1 + 1e-9));
}

// The linearised fast path is the same model for small displacements. Data from a three-tier model
// with `truth` scales pressed 0.05 mm on a base-fixed sphere (as the brain's: tier 1 is held, so
// the rest stiffness has no mechanism); the linearised model's errors must agree with the nonlinear
// solve's at the start, and fitting it must recover the truth.
void expect_linear_agrees_and_recovers(cases::CaseParameters p,
                                       const std::vector<std::pair<std::string, double>>& truth,
                                       const std::vector<double>& tolerance) {
  p.support.kind = cases::SupportParameters::Kind::half_space;
  p.support.half_space_point = Eigen::Vector3d(0, 0, -0.02);
  p.support.half_space_normal = -Eigen::Vector3d::UnitZ();
  p.loads.tool.depth_m = 0.00005;
  p.loads.tool.directions = {Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX()};
  p.mass_spring.group_scales = truth;
  const std::vector<CalibrationLoad> refs = synthetic_references(make_problem(p), {5e-5, 5e-5});
  p.mass_spring.group_scales.clear();
  const Problem problem = make_problem(p);
  CalibrationOptions options;
  for (const auto& [group, scale] : truth)
    options.groups.push_back(group);
  options.max_evaluations = 1;
  const CalibrationFit newton =
      calibrate(problem, {}, cases::Variant::three_tier, refs, {}, options);
  options.linear = true;
  options.max_evaluations = 200;
  options.tolerance = 1e-6;
  const CalibrationFit linear =
      calibrate(problem, {}, cases::Variant::three_tier, refs, {}, options);
  for (std::size_t i = 0; i < refs.size(); ++i) {
    EXPECT_GT(newton.before.train[i].displacement.all.rel_l2_error, 0.02);
    // |e_lin − e_newton| ≤ ‖u_lin − u_newton‖ / ‖u_ref‖: the two fields agree to half a percent.
    EXPECT_NEAR(linear.before.train[i].displacement.all.rel_l2_error,
                newton.before.train[i].displacement.all.rel_l2_error, 0.005);
    EXPECT_NEAR(linear.before.train[i].reaction_force_rel_error,
                newton.before.train[i].reaction_force_rel_error, 0.005);
  }
  // Fitting the linearised model to (nearly linear) data recovers the scales to about 1 %.
  ASSERT_EQ(linear.groups.size(), truth.size());
  for (std::size_t g = 0; g < truth.size(); ++g)
    EXPECT_NEAR(linear.groups[g].case_factor, truth[g].second, tolerance[g]) << truth[g].first;
}

TEST(Calibration, LinearisedModelAgreesWithNewtonAtSmallDepth) {
  expect_linear_agrees_and_recovers(sphere_case(), {{"tier1_edges", 1.5}, {"tier12_radial", 0.6}},
                                    {0.03, 0.012});
}

TEST(Calibration, LinearisedVolumeStiffnessAgreesWithNewtonAndIsFitted) {
  cases::CaseParameters p = sphere_case();
  p.material.poisson_ratio = 0.45;
  p.mass_spring.volume_preservation = true;
  expect_linear_agrees_and_recovers(p, {{"tier1_edges", 1.5}, {"volume", 0.5}}, {0.03, 0.01});
}

}  // namespace
}  // namespace msfem::compare
