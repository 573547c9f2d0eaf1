// A haptic simulator's use of msfem's mass-spring library: build the layered brain paper's three
// tiers on the seed sphere, press a frictionless tool into it, find the static force, then run a
// 1 kHz loop with the fast implicit stepper (the tool pressed over half a second, then held), and
// stiffen the outer tier's springs at run time as the paper's menu does.
//
//   embed_simulator [--json] [--expect-force F]
//
// The model is msfem's `three_tier` variant of cases/sphere_indent.prm node for node, so its
// static force equals `msfem run`'s three_tier force: with --expect-force F (that force, N) the
// program exits 1 unless its static force is F to 1e-8, the loop settles within 1 % of it and the
// stiffer outer tier pushes back harder (CI runs it so).
#include <Eigen/Core>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "msfem/massspring/fast_implicit_stepper.hpp"
#include "msfem/massspring/mass_spring_model.hpp"
#include "msfem/massspring/modal_damping.hpp"
#include "msfem/massspring/static_solver.hpp"
#include "msfem/massspring/surface_contact.hpp"
#include "msfem/massspring/tool_contact.hpp"
#include "msfem/massspring/topology_builders.hpp"

namespace ms = msfem::massspring;

namespace {

// The icosahedron subdivided `level` times onto the sphere of `radius` (msfem's icosphere:L:R).
void icosphere(int level, double radius, Eigen::MatrixX3d& vertices, Eigen::MatrixX3i& triangles) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                                    {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                                    {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (auto& p : v)
    p.normalize();
  std::vector<Eigen::Vector3i> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                    {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                    {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                    {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int l = 0; l < level; ++l) {
    std::map<std::pair<int, int>, int> midpoint_of;
    auto midpoint = [&](int a, int b) {
      const auto [it, inserted] =
          midpoint_of.try_emplace(std::minmax(a, b), static_cast<int>(v.size()));
      if (inserted) v.push_back((v[a] + v[b]).normalized());
      return it->second;
    };
    std::vector<Eigen::Vector3i> finer;
    for (const auto& tri : f) {
      const int ab = midpoint(tri[0], tri[1]), bc = midpoint(tri[1], tri[2]),
                ca = midpoint(tri[2], tri[0]);
      finer.insert(finer.end(),
                   {{tri[0], ab, ca}, {tri[1], bc, ab}, {tri[2], ca, bc}, {ab, bc, ca}});
    }
    f = std::move(finer);
  }
  vertices.resize(Eigen::Index(v.size()), 3);
  triangles.resize(Eigen::Index(f.size()), 3);
  for (std::size_t i = 0; i < v.size(); ++i)
    vertices.row(Eigen::Index(i)) = radius * v[i].transpose();
  for (std::size_t i = 0; i < f.size(); ++i)
    triangles.row(Eigen::Index(i)) = f[i].transpose();
}

// The tool's push along its axis: what a haptic device renders.
double push(const ms::MassSpringModel& model, const Eigen::VectorXd& x,
            const ms::ToolIndentation& tool) {
  return -ms::contact_reaction_force(model, x).dot(tool.inward_direction);
}

}  // namespace

int main(int argc, char** argv) {
  bool json = false;
  std::optional<double> expected;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--json") == 0) {
      json = true;
    } else if (std::strcmp(argv[i], "--expect-force") == 0 && i + 1 < argc) {
      expected = std::strtod(argv[++i], nullptr);
    } else {
      std::fprintf(stderr, "usage: embed_simulator [--json] [--expect-force F]\n");
      return 2;
    }
  }

  // 1. The network: E = 3 kPa, 1040 kg/m^3, tiers at 1/1.2 and 1/2 of the 5 cm sphere, tier 3
  //    fixed, dampers at half the critical ratio.
  Eigen::MatrixX3d surface;
  Eigen::MatrixX3i triangles;
  icosphere(3, 0.05, surface, triangles);
  ms::ThreeTierOptions options;
  options.center = surface.colwise().mean().transpose();
  ms::MassSpringModel model(ms::build_three_tier(surface, triangles, options));
  const int v = static_cast<int>(surface.rows());
  for (int node = 2 * v; node < 3 * v; ++node)
    model.fix_node(node);
  model.set_damping(ms::damping_for_ratio(model.network(), 0.5));

  // 2. A 5 mm frictionless sphere pressed 5 mm at the pole, in four static steps (a frictionless
  //    tool moved further than a quarter of its radius at once can pass through the surface).
  Eigen::Index pole = 0;
  (surface.rowwise() - options.center->transpose()).col(2).maxCoeff(&pole);
  ms::ToolIndentation tool;
  tool.contact_point = surface.row(pole).transpose();
  tool.inward_direction = -(tool.contact_point - *options.center).normalized();
  tool.radius = 0.005;
  const double depth = 0.005;
  double penalty = 0.0;  // picked from the network's stiffness on the first activation
  Eigen::VectorXd x;
  for (int quarter = 1; quarter <= 4; ++quarter) {
    tool.depth = depth * quarter / 4;
    penalty = ms::activate_surface_contact(model, tool, penalty);
    const ms::StaticResult r = ms::solve_static(model, {}, x);
    if (!r.converged) {
      std::fprintf(stderr, "embed_simulator: Newton did not converge at %g m\n", tool.depth);
      return 1;
    }
    x = r.x;
  }
  const double static_force = push(model, x, tool);

  // 3. The haptic loop: 1 kHz backward Euler from rest, the tool pressed at 10 mm/s to its depth,
  //    then held; the force a device would render each tick.
  const double dt = 1e-3;
  ms::FastImplicitStepper stepper(model);
  stepper.set_state({model.initial_state(), Eigen::VectorXd::Zero(3 * model.num_nodes()), 0.0});
  double loop_force = 0.0;
  for (int tick = 1; tick <= 4000; ++tick) {
    const double pressed = std::min(depth, 0.01 * tick * dt);
    if (pressed != tool.depth || tick == 1) {
      tool.depth = pressed;
      ms::activate_surface_contact(model, tool, penalty);
      stepper.update_parameters(model);
    }
    stepper.step(dt);
    loop_force = push(model, stepper.state().x, tool);
  }

  // 4. The menu: the outer tier's springs twice as stiff while the loop runs; the tool feels it.
  model.scale_group_stiffness("tier1_edges", 2.0);
  stepper.update_parameters(model);
  for (int tick = 0; tick < 2000; ++tick)
    stepper.step(dt);
  const double stiffer_force = push(model, stepper.state().x, tool);

  if (json)
    std::printf(
        "{\"nodes\": %d, \"springs\": %d, \"static_force_n\": %.17g, \"loop_force_n\": %.17g, "
        "\"loop_rel_difference\": %.6g, \"stiffer_tier1_force_n\": %.17g}\n",
        model.num_nodes(), model.network().num_springs(), static_force, loop_force,
        std::abs(loop_force - static_force) / static_force, stiffer_force);
  else
    std::printf(
        "three tiers, %d nodes, %d springs\nstatic force at 5 mm: %.6g N\n1 kHz loop after 4 s: "
        "%.6g N (%.3g %% from static)\ntier1_edges x2: %.6g N\n",
        model.num_nodes(), model.network().num_springs(), static_force, loop_force,
        100 * std::abs(loop_force - static_force) / static_force, stiffer_force);
  if (!expected) return 0;
  const bool same = std::abs(static_force - *expected) <= 1e-8 * std::abs(*expected);
  const bool settles = std::abs(loop_force - static_force) <= 0.01 * static_force;
  const bool felt = stiffer_force > loop_force;
  std::fprintf(stderr,
               "embed_simulator: static force %s msfem run's %.17g N to 1e-8; the 1 kHz loop %s "
               "within 1 %%; the stiffer tier %s\n",
               same ? "equals" : "DIFFERS FROM", *expected, settles ? "settles" : "DOES NOT SETTLE",
               felt ? "is felt" : "IS NOT FELT");
  return same && settles && felt ? 0 : 1;
}
