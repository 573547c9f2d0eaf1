// A model is its springs plus a list of force fields found by their type: a field a simulator adds
// joins every ForceModel call (force, energy, both Jacobians, as products and as triplets),
// replaces a field of its type in place, scales by its coefficient groups, and is refused by name
// where a solver cannot run it.
#include <gtest/gtest.h>

#include "force_jacobian_check.hpp"
#include "icosphere.hpp"
#include "msfem/massspring/errors.hpp"
#include "msfem/massspring/fast_implicit_stepper.hpp"
#include "msfem/massspring/fast_stepper.hpp"
#include "msfem/massspring/linearised_statics.hpp"
#include "msfem/massspring/mass_spring_model.hpp"
#include "msfem/massspring/nodal_load_field.hpp"
#include "msfem/massspring/topology_builders.hpp"
#include "msfem/massspring/volume_force_field.hpp"

namespace msfem::massspring {
namespace {

using testing::check_force_jacobians;
using testing::icosphere;
using testing::perturbed;

// Every node tied to its rest position by a spring k and a dashpot c: f = -k (x - X) - c v. Its
// dashpot is what a field-blind ∂f/∂v would miss.
class RestTether : public ForceField {
 public:
  RestTether(Eigen::VectorXd rest, double k, double c)
      : rest_(std::move(rest)), k_(k), c_(c), nodes_(rest_.size() / 3) {
    for (std::size_t i = 0; i < nodes_.size(); ++i)
      nodes_[i] = static_cast<int>(i);
  }
  int num_dofs() const override { return static_cast<int>(rest_.size()); }
  void add_force(const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                 Eigen::VectorXd& f) const override {
    f -= k_ * (x - rest_) + c_ * v;
  }
  double potential_energy(const Eigen::VectorXd& x) const override {
    return 0.5 * k_ * (x - rest_).squaredNorm();
  }
  void add_dfdx_product(const Eigen::VectorXd&, const Eigen::VectorXd&, const Eigen::VectorXd& dx,
                        Eigen::VectorXd& df, Linearisation) const override {
    df -= k_ * dx;
  }
  void add_dfdv_product(const Eigen::VectorXd&, const Eigen::VectorXd& dv,
                        Eigen::VectorXd& df) const override {
    df -= c_ * dv;
  }
  void add_dfdx_triplets(const Eigen::VectorXd&, const Eigen::VectorXd&, Triplets& t,
                         Linearisation) const override {
    for (int i = 0; i < num_dofs(); ++i)
      t.emplace_back(i, i, -k_);
  }
  void add_dfdv_triplets(const Eigen::VectorXd&, Triplets& t) const override {
    for (int i = 0; i < num_dofs(); ++i)
      t.emplace_back(i, i, -c_);
  }
  const std::vector<int>& nodes() const override { return nodes_; }
  std::string name() const override { return "tether"; }
  std::vector<std::string> coefficient_groups() const override { return {"tether"}; }
  std::shared_ptr<const ForceField> scaled(const std::string& group, double factor) const override {
    if (group != "tether") return ForceField::scaled(group, factor);
    return std::make_shared<RestTether>(rest_, k_ * factor, c_);
  }

 private:
  Eigen::VectorXd rest_;
  double k_, c_;
  std::vector<int> nodes_;
};

MassSpringModel three_tier_model() {
  const auto mesh = icosphere(1, 0.05);
  MassSpringModel model(build_three_tier(mesh.vertices, mesh.triangles, ThreeTierOptions{}));
  model.set_group_damping("tier1_edges", 0.01);
  return model;
}

// The three tiers held at their core, under gravity, tied to rest by a tether with a dashpot.
MassSpringModel tethered_model() {
  MassSpringModel model = three_tier_model();
  const Eigen::VectorXd rest = model.rest_state();
  for (int node = 0; node < model.num_nodes(); ++node)
    if (rest.segment<3>(3 * node).norm() < 0.03) model.fix_node(node);
  model.set_gravity(Eigen::Vector3d(0, 0, -9.81));
  model.set_field<RestTether>(std::make_shared<RestTether>(rest, 50.0, 0.02));
  return model;
}

// Rest, with a fixed pseudo-random velocity on the free nodes.
State moving_start(const MassSpringModel& model) {
  State start = initial_state(model);
  start.v.setRandom();
  start.v *= 0.01;
  model.zero_constrained(start.v);
  return start;
}

TEST(ForceFields, AFieldJoinsEveryForceModelCall) {
  MassSpringModel model = three_tier_model();
  const Eigen::VectorXd rest = model.rest_state();
  const Eigen::VectorXd x = perturbed(rest, 0.002, 7), v = perturbed(0 * rest, 0.01, 8);
  const Eigen::VectorXd dx = perturbed(0 * rest, 1.0, 9);
  const MassSpringModel springs_only = model;
  const double k = 40.0, c = 0.3;
  model.set_field<RestTether>(std::make_shared<RestTether>(rest, k, c));
  ASSERT_EQ(model.fields().size(), 3u);
  EXPECT_EQ(model.field_names(), "springs, nodal loads, tether");

  const Eigen::VectorXd extra = model.force(x, v) - springs_only.force(x, v);
  EXPECT_LT((extra + k * (x - rest) + c * v).norm(), 1e-9 * (k * (x - rest)).norm());
  EXPECT_NEAR(model.potential_energy(x) - springs_only.potential_energy(x),
              0.5 * k * (x - rest).squaredNorm(), 1e-9);
  Eigen::VectorXd with = Eigen::VectorXd::Zero(x.size()), without = with;
  model.add_dfdv_product(x, dx, with);
  springs_only.add_dfdv_product(x, dx, without);
  EXPECT_LT((with - without + c * dx).norm(), 1e-12 * c * dx.norm());
  const Eigen::SparseMatrix<double> dv = model.dfdv(x) - springs_only.dfdv(x);
  EXPECT_LT((Eigen::MatrixXd(dv) + c * Eigen::MatrixXd::Identity(x.size(), x.size())).norm(),
            1e-12);
  // The composed model's Jacobians against finite differences.
  const auto errors = check_force_jacobians(model, x, v, 1e-7);
  EXPECT_LT(errors.dfdx_matrix, 1e-5);
  EXPECT_LT(errors.dfdv_matrix, 1e-5);
  EXPECT_LT(errors.dfdv_product, 1e-5);
  EXPECT_LT(errors.energy_gradient, 1e-5);
}

TEST(ForceFields, ReplacedInPlaceScaledByGroupAndClearedByType) {
  MassSpringModel model = three_tier_model();
  const Eigen::VectorXd rest = model.rest_state(), x = perturbed(rest, 0.002, 3);
  const Eigen::VectorXd v = Eigen::VectorXd::Zero(x.size());
  const MassSpringModel springs_only = model;
  auto tether = std::make_shared<RestTether>(rest, 10.0, 0.0);
  model.set_field<RestTether>(tether);
  const auto& nv = model.network().surface_nodes;
  model.set_volume(VolumeForceField(
      model.num_nodes(),
      tier_prisms(model.network().rest_positions, model.network().surface_triangles,
                  static_cast<int>(nv.size()), 3, 500.0)));
  model.set_field<RestTether>(tether->scaled("tether", 3.0));
  ASSERT_EQ(model.field_names(),
            "springs, nodal loads, tether, volume preservation");  // replaced where it was
  const MassSpringModel with_volume_only = [&] {
    MassSpringModel m = model;
    m.clear_fields<RestTether>();
    return m;
  }();
  const Eigen::VectorXd tether_force = model.force(x, v) - with_volume_only.force(x, v);
  EXPECT_LT((tether_force + 30.0 * (x - rest)).norm(), 1e-9 * 30.0 * (x - rest).norm());
  EXPECT_THROW(tether->scaled("volume", 2.0), ModelError);
  EXPECT_THROW(model.add_field(std::make_shared<RestTether>(rest.head(6), 1.0, 0.0)), ModelError);
  // Copies share fields but not the list: clearing one copy's leaves the other's.
  EXPECT_EQ(springs_only.fields().size(), 2u);
  EXPECT_NE(model.volume(), nullptr);
}

// The springs and the nodal loads are the model's first two fields, over the model's own network,
// masses, gravity and external forces: a copy's read the copy's parameters, and the list refuses
// to lose or replace them.
TEST(ForceFields, SpringsAndLoadsAreTheModelsOwnFields) {
  const MassSpringModel model = three_tier_model();
  const Eigen::VectorXd rest = model.rest_state();
  const Eigen::VectorXd x = perturbed(rest, 0.002, 3), v = perturbed(0 * rest, 0.01, 4);
  ASSERT_EQ(model.field_index<SpringForceField>(), 0);
  ASSERT_EQ(model.field_index<NodalLoadField>(), 1);
  EXPECT_EQ(&model.find_field<SpringForceField>()->network(), &model.network());
  const Eigen::VectorXd before = model.force(x, v);

  MassSpringModel stiffer = model;
  EXPECT_EQ(&stiffer.springs().network(), &stiffer.network());
  stiffer.scale_group_stiffness(stiffer.network().spring_group_names[0], 2.0);
  const Eigen::Vector3d g(0.0, 0.0, -9.81), push(0.01, 0.0, 0.0);
  stiffer.set_gravity(g);
  stiffer.set_external_force(3, push);
  EXPECT_EQ(model.force(x, v), before);  // the original's springs and loads are untouched
  EXPECT_GT((stiffer.force(x, v) - before).norm(), 1e-6 * before.norm());
  EXPECT_EQ(stiffer.loads().load(3), stiffer.network().masses[3] * g + push);
  EXPECT_EQ(model.loads().load(3), Eigen::Vector3d::Zero());

  MassSpringModel assigned = three_tier_model();
  assigned = stiffer;
  EXPECT_EQ(&assigned.springs().network(), &assigned.network());
  EXPECT_EQ(assigned.force(x, v), stiffer.force(x, v));
  assigned.set_gravity(Eigen::Vector3d::Zero());
  EXPECT_EQ(stiffer.loads().load(3), stiffer.network().masses[3] * g + push);
  EXPECT_EQ(assigned.loads().load(3), push);

  // The sum over the fields is the springs' force plus the loads when nothing else is added, and
  // the loads' energy is -Σ f_i·x_i.
  Eigen::VectorXd springs_and_loads = Eigen::VectorXd::Zero(rest.size());
  stiffer.springs().add_force(x, v, springs_and_loads);
  double load_energy = 0.0;
  for (int i = 0; i < stiffer.num_nodes(); ++i) {
    springs_and_loads.segment<3>(3 * i) += stiffer.loads().load(i);
    load_energy -= stiffer.loads().load(i).dot(x.segment<3>(3 * i));
  }
  EXPECT_LT((springs_and_loads - stiffer.force(x, v)).norm(), 1e-14 * before.norm());
  EXPECT_NEAR(stiffer.loads().potential_energy(x), load_energy, 1e-14 * std::abs(load_energy));

  stiffer.clear_fields<ForceField>();
  EXPECT_EQ(stiffer.fields().size(), 2u);
  for (std::size_t own : {0u, 1u})
    EXPECT_THROW(stiffer.replace_field(own, std::make_shared<RestTether>(rest, 1.0, 0.0)),
                 ModelError);
}

// The fast steppers step a model's fields as the generic integrators do (a tether with a dashpot:
// it reads x and v): symplectic Euler on the explicit kernels, backward Euler on the implicit ones
// with the tether's Jacobians. The linearised statics give each field its own weight.
TEST(ForceFields, FastSteppersStepFieldsAndLinearStaticsWeighEach) {
  MassSpringModel model = tethered_model();
  const Eigen::VectorXd rest = model.rest_state();
  const State start = moving_start(model);
  State generic = start;
  FastExplicitStepper fast(model, FastStepperOptions{2, false, true, true});
  fast.set_state(start);
  Integrator integrator(IntegratorKind::symplectic_euler);
  const double dt = 2e-5;
  for (int n = 0; n < 300; ++n)
    integrator.step(model, generic, dt);
  fast.step(dt, 300);
  const State stepped = fast.state();
  const double travel = (generic.x - rest).norm();
  ASSERT_GT(travel, 1e-6);
  EXPECT_LT((stepped.x - generic.x).norm(), 1e-9 * travel);
  EXPECT_LT((stepped.v - generic.v).norm(), 1e-9 * generic.v.norm());
  // The field matters here: without it the same steps end elsewhere.
  MassSpringModel springs_only = model;
  springs_only.clear_fields<RestTether>();
  FastExplicitStepper blind(springs_only, FastStepperOptions{2, false, true, true});
  blind.set_state(start);
  blind.step(dt, 300);
  EXPECT_GT((blind.state().x - generic.x).norm(), 1e-3 * travel);
  // Backward Euler with the tether's spring and dashpot in the fast implicit products and
  // preconditioner: the generic integrator's steps, on one and two threads.
  State backward = start;
  Integrator implicit_integrator(IntegratorKind::implicit_euler, {1e-13, 5000});
  for (int n = 0; n < 20; ++n)
    implicit_integrator.step(model, backward, 1e-3);
  const double backward_travel = (backward.x - rest).norm();
  ASSERT_GT(backward_travel, 1e-6);
  for (const int threads : {1, 2}) {
    FastImplicitStepper implicit(model, FastImplicitOptions{threads, true, 1e-13, 5000});
    implicit.set_state(start);
    for (int n = 0; n < 20; ++n)
      implicit.step(1e-3);
    EXPECT_LT((implicit.state().x - backward.x).norm(), 1e-8 * backward_travel) << threads;
    EXPECT_LT((implicit.state().v - backward.v).norm(), 1e-8 * backward.v.norm()) << threads;
  }
  FastImplicitStepper implicit_blind(springs_only, FastImplicitOptions{2, true, 1e-13, 5000});
  implicit_blind.set_state(start);
  for (int n = 0; n < 20; ++n)
    implicit_blind.step(1e-3);
  EXPECT_GT((implicit_blind.state().x - backward.x).norm(), 1e-3 * backward_travel);
  // Under gravity alone the tether's weight w scales the displacement of a free node pinned by
  // nothing else: with the springs' part weighted 0 and the tether's w, u = m g / (w k).
  LinearisedStatics statics(model, {model.network().stiffness});
  ASSERT_EQ(statics.num_parts(), 2);
  const int node = model.network().surface_nodes.front();
  const double m = model.network().masses[node];
  for (const double w : {1.0, 4.0}) {
    const auto s = statics.solve({1e-9, w}, {});
    EXPECT_NEAR(s.surface_displacement(0, 2), -m * 9.81 / (w * 50.0), 1e-6 * m * 9.81 / 50.0);
  }
}

// RK4 takes the field at each of its four stages, at that stage's x and v, as the generic RK4
// does: with a force applied once a step the states would part at first order in the step.
TEST(ForceFields, FastRk4TakesTheFieldAtEveryStage) {
  MassSpringModel model = tethered_model();
  const State start = moving_start(model);
  State generic = start;
  Integrator integrator(IntegratorKind::rk4);
  const double dt = 2e-5;
  for (int n = 0; n < 300; ++n)
    integrator.step(model, generic, dt);
  const double travel = (generic.x - start.x).norm();
  ASSERT_GT(travel, 1e-6);
  for (const bool single_precision : {false, true})
    for (const int threads : {1, 2}) {
      FastStepperOptions options{threads, single_precision};
      options.integrator = IntegratorKind::rk4;
      FastExplicitStepper fast(model, options);
      fast.set_state(start);
      fast.step(dt, 120);
      fast.step(dt, 180);
      const State stepped = fast.state();
      // Float: x near 5 cm takes steps of ~1e-7 m here, so its sums round at ~1e-4 of the travel
      // whichever the scheme (symplectic Euler's float run is as far off).
      const double tolerance = single_precision ? 1e-3 : 1e-9;
      EXPECT_LT((stepped.x - generic.x).norm(), tolerance * travel) << threads;
      EXPECT_LT((stepped.v - generic.v).norm(), tolerance * generic.v.norm()) << threads;
    }
  MassSpringModel springs_only = model;
  springs_only.clear_fields<RestTether>();
  FastStepperOptions options;
  options.integrator = IntegratorKind::rk4;
  FastExplicitStepper blind(springs_only, options);
  blind.set_state(start);
  blind.step(dt, 300);
  EXPECT_GT((blind.state().x - generic.x).norm(), 1e-3 * travel);
}

}  // namespace
}  // namespace msfem::massspring
