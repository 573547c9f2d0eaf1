#pragma once

// Structure-of-arrays copy of a system's springs shared by the fast steppers (internal): nodes
// renumbered (reverse Cuthill-McKee, constrained nodes last), springs sorted by their first node,
// CSR incidence of springs on free nodes, and the per-node constant terms (loads, anchors,
// damping). The steppers' node-centric layout (node_gather_layout.hpp) is built from it.
//
// Relative layouts (both fast steppers in float) hold each node's displacement from a rest frame
// instead of its position: float positions of a 0.1 m organ are good to 4e-9 m, a millimetre
// spring's length then to 4e-6 of itself, and a step's update x += h v loses its low bits to the
// coordinate's magnitude; a displacement keeps float's relative precision. The frame is the
// model's initial positions rounded to float, so that the kernels' frame differences X_j - X_i
// in float are those of the frame itself and x = X + u is exact in double.

#include <algorithm>
#include <numeric>
#include <string>
#include <vector>

#include "msfem/massspring/errors.hpp"
#include "msfem/massspring/integrators.hpp"
#include "msfem/massspring/mechanical_system.hpp"
#include "msfem/massspring/nodal_load_field.hpp"
#include "msfem/massspring/spring_force_field.hpp"
#include "node_ordering.hpp"

namespace msfem::massspring::detail {

template <class Real>
struct SoaLayout {
  int num_nodes = 0, num_springs = 0, num_free = 0;
  bool has_spring_damping = false;
  std::vector<int> order, new_id, spring_old_id;  // order[new] = old
  std::vector<int> a, b, offset, incident;
  std::vector<Real> stiffness, stiffness_rest, rest_length, damping;
  std::vector<Real> inverse_mass, mass, node_damping, anchor_stiffness;
  std::vector<Real> x[3], v[3], load[3];  // x: the displacement from `frame` when relative
  bool relative = false;
  std::vector<double> frame[3];  // relative: each node's frame position (float-representable)

  SoaLayout(const MechanicalSystem& model, bool reorder, bool relative_to_frame = false)
      : relative(relative_to_frame) {
    const SpringNetwork& net = spring_field(model, "the fast stepper").network();
    num_nodes = net.num_nodes();
    num_springs = net.num_springs();
    build_order(model, reorder);
    build_springs(net);
    build_incidence();
    for (int c = 0; c < 3; ++c) {
      x[c].assign(num_nodes, Real(0));
      v[c].assign(num_nodes, Real(0));
      load[c].assign(num_nodes, Real(0));
    }
    inverse_mass.assign(num_nodes, Real(0));
    mass.assign(num_nodes, Real(0));
    node_damping.assign(num_nodes, Real(0));
    anchor_stiffness.assign(num_nodes, Real(0));
    if (relative) build_frame(model);
    load_parameters(model);
    set_state(model, initial_state(model));
  }

  // The springs and the nodal loads (folded into each node's constant term) are the kernels' own;
  // the steppers take every other field through its ForceField calls.
  void load_parameters(const MechanicalSystem& model) {
    const SpringNetwork& net = spring_field(model, "the fast stepper").network();
    const auto* loads = model.find_field<NodalLoadField>();
    if (net.num_nodes() != num_nodes || net.num_springs() != num_springs)
      throw ModelError(
          "fast stepper: model topology changed (nodes or springs); build a new stepper");
    for (int i = 0; i < num_nodes; ++i)
      if (model.is_constrained(order[i]) != (i >= num_free))
        throw ModelError("fast stepper: supports changed at node " + std::to_string(order[i]) +
                         "; build a new stepper");
    has_spring_damping = false;
    for (int s = 0; s < num_springs; ++s) {
      const int old = spring_old_id[s];
      stiffness[s] = static_cast<Real>(net.stiffness[old]);
      stiffness_rest[s] = static_cast<Real>(net.stiffness[old] * net.rest_length[old]);
      rest_length[s] = static_cast<Real>(net.rest_length[old]);
      damping[s] = static_cast<Real>(net.damping[old]);
      has_spring_damping = has_spring_damping || net.damping[old] != 0.0;
    }
    // Anchors (-k_a (x - p) - c_a v) fold into per-node terms: k_a p joins the loads.
    Eigen::VectorXd anchor_k = Eigen::VectorXd::Zero(num_nodes);
    Eigen::VectorXd anchor_c = Eigen::VectorXd::Zero(num_nodes);
    Eigen::MatrixX3d anchor_kp = Eigen::MatrixX3d::Zero(num_nodes, 3);
    for (int k = 0; k < net.num_anchors(); ++k) {
      const int i = net.anchor_node[k];
      anchor_k[i] += net.anchor_stiffness[k];
      anchor_c[i] += net.anchor_damping[k];
      anchor_kp.row(i) += net.anchor_stiffness[k] * net.anchor_point.row(k);
    }
    for (int i = 0; i < num_nodes; ++i) {
      const int old = order[i];
      if (i >= num_free) {  // supports follow a moved target (e.g. a tool patch)
        const Eigen::Vector3d target = model.constrained_target(old);
        for (int c = 0; c < 3; ++c) {
          x[c][i] = static_cast<Real>(target[c] - frame_at(c, i));
          v[c][i] = Real(0);
        }
      }
      mass[i] = static_cast<Real>(model.masses()[old]);
      inverse_mass[i] = static_cast<Real>(1.0 / model.masses()[old]);
      node_damping[i] = static_cast<Real>(net.node_damping[old] + anchor_c[old]);
      anchor_stiffness[i] = static_cast<Real>(anchor_k[old]);
      // Relative: the anchor's -k_a (X + u - p) as the load's k_a (p - X) and -k_a u.
      const Eigen::Vector3d node_load = loads ? loads->load(old) : Eigen::Vector3d::Zero();
      for (int c = 0; c < 3; ++c)
        load[c][i] =
            static_cast<Real>(node_load[c] + anchor_kp(old, c) - anchor_k[old] * frame_at(c, i));
    }
  }

  void set_state(const MechanicalSystem& model, const State& state) {
    if (state.x.size() != 3 * num_nodes || state.v.size() != 3 * num_nodes)
      throw ModelError("fast stepper: state size " + std::to_string(state.x.size()) +
                       " does not match " + std::to_string(3 * num_nodes) + " dofs");
    State held = state;
    model.enforce_constraints(held.x, held.v);
    for (int i = 0; i < num_nodes; ++i)
      for (int c = 0; c < 3; ++c) {
        x[c][i] = static_cast<Real>(held.x[3 * order[i] + c] - frame_at(c, i));
        v[c][i] = static_cast<Real>(held.v[3 * order[i] + c]);
      }
  }

  // Node i's frame position (0 when the layout holds positions).
  double frame_at(int c, int i) const {
    return relative ? frame[c][static_cast<std::size_t>(i)] : 0.0;
  }

 private:
  void build_frame(const MechanicalSystem& model) {
    const Eigen::VectorXd rest = initial_state(model).x;
    for (int c = 0; c < 3; ++c) {
      frame[c].resize(static_cast<std::size_t>(num_nodes));
      for (int i = 0; i < num_nodes; ++i)
        frame[c][static_cast<std::size_t>(i)] =
            static_cast<double>(static_cast<float>(rest[3 * order[i] + c]));
    }
  }

  void build_order(const MechanicalSystem& model, bool reorder) {
    order.resize(num_nodes);
    std::iota(order.begin(), order.end(), 0);
    if (reorder)
      order = reverse_cuthill_mckee(num_nodes,
                                    spring_field(model, "the fast stepper").network().springs);
    std::stable_partition(order.begin(), order.end(),
                          [&](int old) { return !model.is_constrained(old); });
    new_id.assign(num_nodes, 0);
    for (int i = 0; i < num_nodes; ++i)
      new_id[order[i]] = i;
    num_free = 0;
    for (int old : order)
      num_free += model.is_constrained(old) ? 0 : 1;
  }

  void build_springs(const SpringNetwork& net) {
    spring_old_id.resize(num_springs);
    std::iota(spring_old_id.begin(), spring_old_id.end(), 0);
    auto first = [&](int s) {
      return std::min(new_id[net.springs(s, 0)], new_id[net.springs(s, 1)]);
    };
    std::stable_sort(spring_old_id.begin(), spring_old_id.end(),
                     [&](int p, int q) { return first(p) < first(q); });
    a.resize(num_springs);
    b.resize(num_springs);
    stiffness.resize(num_springs);
    stiffness_rest.resize(num_springs);
    rest_length.resize(num_springs);
    damping.resize(num_springs);
    for (int s = 0; s < num_springs; ++s) {
      a[s] = new_id[net.springs(spring_old_id[s], 0)];
      b[s] = new_id[net.springs(spring_old_id[s], 1)];
    }
  }

  void build_incidence() {
    offset.assign(num_free + 1, 0);
    for (int s = 0; s < num_springs; ++s) {
      if (a[s] < num_free) ++offset[a[s] + 1];
      if (b[s] < num_free) ++offset[b[s] + 1];
    }
    std::partial_sum(offset.begin(), offset.end(), offset.begin());
    incident.resize(offset.back());
    std::vector<int> fill(offset.begin(), offset.end() - 1);
    for (int s = 0; s < num_springs; ++s) {
      if (a[s] < num_free) incident[fill[a[s]]++] = s;
      if (b[s] < num_free) incident[fill[b[s]]++] = s;
    }
  }
};

}  // namespace msfem::massspring::detail
