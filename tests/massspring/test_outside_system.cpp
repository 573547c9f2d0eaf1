// A system written outside massspring: nodes, masses, supports, a load and a list of fields (a
// spring network's SpringForceField and the grasper of grasper.hpp), with no MassSpringModel.
// Every solver takes it through MechanicalSystem alone and answers what it answers for the
// MassSpringModel holding the same network, supports, load and grasper.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "grasper.hpp"
#include "icosphere.hpp"
#include "msfem/massspring/errors.hpp"
#include "msfem/massspring/fast_implicit_stepper.hpp"
#include "msfem/massspring/fast_stepper.hpp"
#include "msfem/massspring/linearised_statics.hpp"
#include "msfem/massspring/mass_spring_model.hpp"
#include "msfem/massspring/mechanical_system.hpp"
#include "msfem/massspring/modal_damping.hpp"
#include "msfem/massspring/nodal_load_field.hpp"
#include "msfem/massspring/stability.hpp"
#include "msfem/massspring/static_solver.hpp"
#include "msfem/massspring/stepper.hpp"
#include "msfem/massspring/topology_builders.hpp"

namespace msfem::massspring {
namespace {

using testing::Grasper;
using testing::icosphere;

// A simulator's own system: its network held by value, the nodes inside `held_radius` fixed at
// rest, a uniform load per node, and its fields in the order it chose.
class SimulatorSystem : public MechanicalSystem {
 public:
  SimulatorSystem(SpringNetwork network, double held_radius, const Eigen::Vector3d& load)
      : network_(std::move(network)), forces_(network_.num_nodes(), 3) {
    for (int i = 0; i < network_.num_nodes(); ++i) {
      held_.push_back(network_.rest_positions.row(i).norm() < held_radius);
      forces_.row(i) = load.transpose();
    }
    fields_.push_back(std::make_shared<const SpringForceField>(network_));
    fields_.push_back(std::make_shared<const NodalLoadField>(network_.masses, gravity_, forces_));
  }
  SimulatorSystem(const SimulatorSystem&) = delete;  // its fields view its members

  void add(std::shared_ptr<const ForceField> field) { fields_.push_back(std::move(field)); }
  const SpringNetwork& network() const { return network_; }

  int num_nodes() const override { return network_.num_nodes(); }
  Eigen::VectorXd rest_state() const override { return flatten(network_.rest_positions); }
  const Eigen::VectorXd& masses() const override { return network_.masses; }
  bool is_constrained(int node) const override { return held_[node]; }
  Eigen::Vector3d constrained_target(int node) const override {
    return network_.rest_positions.row(node).transpose();
  }
  const FieldList& fields() const override { return fields_; }

 private:
  SpringNetwork network_;
  std::vector<bool> held_;
  Eigen::Vector3d gravity_ = Eigen::Vector3d::Zero();
  Eigen::MatrixX3d forces_;
  FieldList fields_;
};

struct Pair {
  std::unique_ptr<SimulatorSystem> outside;
  std::unique_ptr<MassSpringModel> model;
  std::shared_ptr<Grasper> grasper;  ///< shared by both
};

// A 5 cm sphere's three tiers, core held, a load on every node and a grasper on five surface
// nodes, as a SimulatorSystem and as a MassSpringModel.
Pair pair(double held_radius = 0.03) {
  const auto mesh = icosphere(1, 0.05);
  SpringNetwork network = build_three_tier(mesh.vertices, mesh.triangles, ThreeTierOptions{});
  network.damping.setConstant(0.01);
  network.fixed_nodes.clear();
  const Eigen::Vector3d load(0.0, 0.0, -2e-4);
  Pair p;
  p.outside = std::make_unique<SimulatorSystem>(network, held_radius, load);
  p.model = std::make_unique<MassSpringModel>(network);
  for (int i = 0; i < network.num_nodes(); ++i) {
    if (network.rest_positions.row(i).norm() < held_radius) p.model->fix_node(i);
    p.model->set_external_force(i, load);
  }
  const std::vector<int> held(network.surface_nodes.begin(), network.surface_nodes.begin() + 5);
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (int i : held)
    centroid += network.rest_positions.row(i).transpose() / 5.0;
  p.grasper = std::make_shared<Grasper>(network.num_nodes(), held,
                                        centroid + Eigen::Vector3d(0, 0, 0.001), 300.0, 0.02);
  p.outside->add(p.grasper);
  p.model->add_field(p.grasper);
  return p;
}

double relative(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return (a - b).norm() / std::max(b.norm(), 1e-300);
}

TEST(OutsideSystem, StaticsAndStabilityAnswerAsForTheModel) {
  const Pair p = pair();
  const StaticResult outside = solve_static(*p.outside);
  const StaticResult model = solve_static(*p.model);
  ASSERT_TRUE(outside.converged);
  ASSERT_TRUE(model.converged);
  const Eigen::VectorXd rest = p.model->rest_state();
  ASSERT_GT((model.x - rest).norm(), 1e-6);
  EXPECT_LT(relative(outside.x - rest, model.x - rest), 1e-10);

  const Eigen::VectorXd x = p.model->initial_state();
  const double lambda = estimate_max_eigenvalue(*p.model, x, 2000, 1e-10).max_eigenvalue;
  EXPECT_NEAR(estimate_max_eigenvalue(*p.outside, x, 2000, 1e-10).max_eigenvalue / lambda, 1.0,
              1e-12);
  for (const IntegratorKind kind : {IntegratorKind::symplectic_euler, IntegratorKind::rk4})
    EXPECT_NEAR(predicted_stable_dt(*p.outside, kind, x) / predicted_stable_dt(*p.model, kind, x),
                1.0, 1e-12)
        << to_string(kind);
  const double measured =
      measure_stable_dt(*p.model, IntegratorKind::symplectic_euler, 1e-6, 1e-3, 200, 1e-3);
  EXPECT_NEAR(
      measure_stable_dt(*p.outside, IntegratorKind::symplectic_euler, 1e-6, 1e-3, 200, 1e-3) /
          measured,
      1.0, 1e-12);

  const DampingFit fit_model = fit_damping(*p.model, model.x, 0.3);
  const DampingFit fit_outside = fit_damping(*p.outside, outside.x, 0.3);
  EXPECT_NEAR(fit_outside.frequency_hz / fit_model.frequency_hz, 1.0, 1e-8);
  EXPECT_NEAR(fit_outside.case_damping_ratio / fit_model.case_damping_ratio, 1.0, 1e-8);

  // Held below the surface, so that the linearised solve has no mechanism.
  const Pair shell = pair(0.049);
  LinearisedStatics a(*shell.outside, {shell.outside->network().stiffness});
  LinearisedStatics b(*shell.model, {shell.model->network().stiffness});
  ASSERT_EQ(a.num_parts(), 2);
  const auto ua = a.solve({1.0, 1.0}, {});
  const auto ub = b.solve({1.0, 1.0}, {});
  ASSERT_GT(ub.surface_displacement.norm(), 0.0);
  EXPECT_LT((ua.surface_displacement - ub.surface_displacement).norm(),
            1e-12 * ub.surface_displacement.norm());
}

TEST(OutsideSystem, GenericAndFastSteppersStepItAsTheModel) {
  const Pair p = pair();
  const State start = initial_state(*p.model);
  for (const IntegratorKind kind :
       {IntegratorKind::central_difference, IntegratorKind::rk4, IntegratorKind::implicit_euler}) {
    Integrator on_outside(kind, {1e-13, 5000}), on_model(kind, {1e-13, 5000});
    State a = start, b = start;
    for (int n = 0; n < 100; ++n) {
      on_outside.step(*p.outside, a, 2e-5);
      on_model.step(*p.model, b, 2e-5);
    }
    ASSERT_GT((b.x - start.x).norm(), 1e-7);
    EXPECT_LT(relative(a.x - start.x, b.x - start.x), 1e-12) << to_string(kind);
  }
  FastExplicitStepper explicit_outside(*p.outside), explicit_model(*p.model);
  explicit_outside.set_state(start);
  explicit_model.set_state(start);
  explicit_outside.step(2e-5, 100);
  explicit_model.step(2e-5, 100);
  const Eigen::VectorXd moved = explicit_model.state().x - start.x;
  ASSERT_GT(moved.norm(), 1e-7);
  EXPECT_LT(relative(explicit_outside.state().x - start.x, moved), 1e-12);
  FastImplicitStepper implicit_outside(*p.outside), implicit_model(*p.model);
  implicit_outside.set_state(start);
  implicit_model.set_state(start);
  for (int n = 0; n < 5; ++n) {
    implicit_outside.step(1e-3);
    implicit_model.step(1e-3);
  }
  EXPECT_LT(relative(implicit_outside.state().x - start.x, implicit_model.state().x - start.x),
            1e-12);
}

// Nodes held by nothing but one field: a system with no springs.
class GraspOnly : public MechanicalSystem {
 public:
  explicit GraspOnly(std::shared_ptr<const ForceField> field)
      : masses_(Eigen::VectorXd::Constant(field->num_dofs() / 3, 1e-3)), fields_{field} {}
  int num_nodes() const override { return static_cast<int>(masses_.size()); }
  Eigen::VectorXd rest_state() const override { return rest_; }
  const Eigen::VectorXd& masses() const override { return masses_; }
  bool is_constrained(int) const override { return false; }
  Eigen::Vector3d constrained_target(int) const override { return Eigen::Vector3d::Zero(); }
  const FieldList& fields() const override { return fields_; }
  Eigen::VectorXd rest_ = Eigen::VectorXd::Zero(6);

 private:
  Eigen::VectorXd masses_;
  FieldList fields_;
};

// A system without springs: the generic solvers step it, the solvers that need a spring network
// say so.
TEST(OutsideSystem, WithoutSpringsTheSpringSolversSaySo) {
  // Two nodes at the origin grasped toward (0, 0, 1 mm): their centroid oscillates about it.
  const GraspOnly system(
      std::make_shared<Grasper>(2, std::vector<int>{0, 1}, Eigen::Vector3d(0, 0, 1e-3), 2.0, 0.0));
  State s = initial_state(system);
  Integrator integrator(IntegratorKind::rk4);
  const double omega = std::sqrt(2.0 / (2 * 1e-3));  // ω² = k / (n m)
  const double quarter = 0.5 * M_PI / omega;
  for (int n = 0; n < 1000; ++n)
    integrator.step(system, s, quarter / 1000);
  EXPECT_NEAR(s.x[2], 1e-3, 1e-9);  // a quarter period: at the point, at full speed
  EXPECT_NEAR(s.v[2], 1e-3 * omega, 1e-9);
  EXPECT_THROW(FastExplicitStepper stepper(system), ModelError);
  EXPECT_THROW(FastImplicitStepper stepper(system), ModelError);
  EXPECT_EQ(divergence_reason(system, s, 0.5), "");
}

// make_stepper picks the fast kernels where they cover the scheme and the system, central
// difference as its leapfrog form, and the generic integrator for a system without springs; each
// steps as the stepper it stands for.
TEST(OutsideSystem, MakeStepperPicksWhatASimulatorRuns) {
  const Pair p = pair();
  const State start = initial_state(*p.model);
  // One thread each: a field's force is summed per thread, so thread counts differ in rounding.
  const auto leapfrog = make_stepper(*p.outside, IntegratorKind::central_difference, start, {1});
  EXPECT_STREQ(leapfrog->name(), "fast_explicit");
  EXPECT_EQ(leapfrog->kind(), IntegratorKind::symplectic_euler);
  EXPECT_TRUE(leapfrog->batches_steps());
  FastStepperOptions one;
  one.threads = 1;
  FastExplicitStepper symplectic(*p.outside, one);
  symplectic.set_state(start);
  leapfrog->step(2e-5, 50);
  symplectic.step(2e-5, 50);
  EXPECT_EQ(leapfrog->state().x, symplectic.state().x);

  const auto backward = make_stepper(*p.outside, IntegratorKind::implicit_euler, start, {1});
  EXPECT_STREQ(backward->name(), "fast_implicit");
  EXPECT_FALSE(backward->batches_steps());
  FastImplicitStepper fast(*p.outside, FastImplicitOptions{1});
  fast.set_state(start);
  backward->step(1e-3, 3);
  for (int n = 0; n < 3; ++n)
    fast.step(1e-3);
  EXPECT_EQ(backward->state().x, fast.state().x);

  const GraspOnly loose(
      std::make_shared<Grasper>(2, std::vector<int>{0, 1}, Eigen::Vector3d(0, 0, 1e-3), 2.0, 0.1));
  const auto generic = make_stepper(loose, IntegratorKind::rk4, initial_state(loose));
  EXPECT_STREQ(generic->name(), "generic");
  EXPECT_EQ(generic->kind(), IntegratorKind::rk4);
  Integrator rk4(IntegratorKind::rk4);
  State s = initial_state(loose);
  generic->step(1e-3, 20);
  for (int n = 0; n < 20; ++n)
    rk4.step(loose, s, 1e-3);
  ASSERT_GT(s.x.norm(), 0.0);
  EXPECT_EQ(generic->state().x, s.x);
  EXPECT_STREQ(generic->precision(), "double");
  // Single precision is the fast steppers' alone: asked of the generic integrator, refused.
  EXPECT_THROW(make_stepper(loose, IntegratorKind::rk4, initial_state(loose), {0, true}),
               ModelError);
}

// StepperChoice::single_precision steps the fast steppers in float: each steps as the float
// stepper it stands for, and says so.
TEST(OutsideSystem, MakeStepperStepsInFloatWhereAsked) {
  const Pair p = pair();
  const State start = initial_state(*p.model);
  const auto backward = make_stepper(*p.outside, IntegratorKind::implicit_euler, start, {1, true});
  const auto leapfrog =
      make_stepper(*p.outside, IntegratorKind::central_difference, start, {1, true});
  EXPECT_STREQ(backward->precision(), "float");
  EXPECT_STREQ(leapfrog->precision(), "float");
  FastImplicitOptions implicit_float{1};
  implicit_float.single_precision = true;
  FastImplicitStepper fast(*p.outside, implicit_float);
  FastImplicitStepper in_double(*p.outside, FastImplicitOptions{1});
  EXPECT_STREQ(in_double.precision(), "double");
  fast.set_state(start);
  in_double.set_state(start);
  backward->step(1e-3, 3);
  fast.step(1e-3, 3);
  in_double.step(1e-3, 3);
  EXPECT_EQ(backward->state().x, fast.state().x);
  EXPECT_NE(backward->state().x, in_double.state().x);  // float, not double rounded afterwards
  FastStepperOptions explicit_float;
  explicit_float.threads = 1;
  explicit_float.single_precision = true;
  FastExplicitStepper symplectic(*p.outside, explicit_float);
  symplectic.set_state(start);
  leapfrog->step(2e-5, 50);
  symplectic.step(2e-5, 50);
  EXPECT_EQ(leapfrog->state().x, symplectic.state().x);
}

}  // namespace
}  // namespace msfem::massspring
