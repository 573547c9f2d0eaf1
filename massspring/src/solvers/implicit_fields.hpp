// The model's force fields (tool contact, volume preservation) in the fast implicit stepper's
// backward-Euler system (fast_implicit_stepper.hpp). The spring kernels assemble
//   A_s = M - h D_s - h² K_s,   b_s = h (f_s + h K_s v)
// per lane; a field F adds A_F = -h D_F - h² K_F (definite K_F) and b_F = h (f_F + h K_F v) at its
// nodes, through its ForceField calls on full-size vectors gathered at those nodes only. So that
// no member writes a lane another member reads before a barrier, each member handles the field
// nodes whose lanes lie in its own blocks (member 0 also the constrained ones, which have no lane).
#pragma once

#include <Eigen/Core>
#include <Eigen/Dense>
#include <algorithm>
#include <memory>
#include <type_traits>
#include <vector>

#include "kernels/node_gather_layout.hpp"
#include "msfem/massspring/mechanical_system.hpp"
#include "msfem/massspring/nodal_load_field.hpp"
#include "msfem/massspring/spring_force_field.hpp"

namespace msfem::massspring::detail {

template <class Real, int W>
class ImplicitFields {
 public:
  ImplicitFields(const SoaLayout<Real>& soa, const NodeGatherLayout<Real, W>& gather, int team)
      : soa_(&soa), gather_(&gather), team_(team) {}

  bool empty() const { return fields_.empty(); }
  // Whether every field's tangent gives rows (ForceField::Tangent::plan_rows): the CG products
  // then go through rows_product and rows_apply, with no parts to sum and no barrier of their own.
  bool rows() const { return rows_; }

  // The model's fields and, per field node, its new id, lane and block (-1 when constrained).
  // Then block_work, for the caller to share the blocks, and plan.
  void take(const MechanicalSystem& model) {
    fields_.clear();
    tangents_.clear();
    std::vector<char> used(static_cast<std::size_t>(soa_->num_nodes), 0);
    const ForceField* springs = &spring_field(model, "the fast stepper");
    const ForceField* loads = model.find_field<NodalLoadField>();
    for (const auto& field : model.fields()) {
      if (field.get() == springs || field.get() == loads) continue;  // the kernels' own
      fields_.push_back(field);
      tangents_.push_back(field->tangent(x_, v_, Linearisation::definite));
      for (int node : field->nodes())
        used[static_cast<std::size_t>(node)] = 1;
    }
    std::vector<int> lane_of(static_cast<std::size_t>(soa_->num_nodes), -1);
    for (std::size_t lane = 0; lane < gather_->lane_node.size(); ++lane)
      if (gather_->lane_node[lane] != gather_->idle_record)
        lane_of[static_cast<std::size_t>(gather_->lane_node[lane])] = static_cast<int>(lane);
    nodes_.clear();
    for (int node = 0; node < soa_->num_nodes; ++node) {
      if (!used[static_cast<std::size_t>(node)]) continue;
      const int id = soa_->new_id[static_cast<std::size_t>(node)];
      const int lane = lane_of[static_cast<std::size_t>(id)];
      int block = -1;
      if (lane >= 0) {
        const auto& begin = gather_->block_begin;
        block = static_cast<int>(std::upper_bound(begin.begin(), begin.end(), lane / W) -
                                 begin.begin()) -
                1;
      }
      nodes_.push_back({node, id, lane, block});
    }
    // By block, the constrained nodes first (member 0's): a member's nodes are then one range.
    std::stable_sort(nodes_.begin(), nodes_.end(),
                     [](const Node& p, const Node& q) { return p.block < q.block; });
    node_offsets_.clear();
    for (int node = 0; node < soa_->num_nodes; ++node)
      if (used[static_cast<std::size_t>(node)]) node_offsets_.push_back(3 * node);
    const Eigen::Index dofs = 3 * static_cast<Eigen::Index>(soa_->num_nodes);
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(fields_.empty() ? 0 : dofs);
    for (auto* v : {&x_, &v_, &hv_, &dv_, &hdv_, &hu_, &u_})
      *v = zero;
    for (auto* per_member : {&b_part_, &a_part_, &product_part_})
      per_member->assign(static_cast<std::size_t>(team_), zero);
    blocks_part_.assign(static_cast<std::size_t>(team_),
                        std::vector<Eigen::Matrix3d>(
                            fields_.empty() ? 0 : static_cast<std::size_t>(soa_->num_nodes),
                            Eigen::Matrix3d::Zero()));
    member_dots_.assign(static_cast<std::size_t>(team_), 0.0);
  }

  // Per block of the layout: what the fields' products cost at its nodes' rows, in spring slots
  // (ForceField::Tangent::add_row_work).
  std::vector<double> block_work() const {
    std::vector<double> per_node(fields_.empty() ? 0 : static_cast<std::size_t>(soa_->num_nodes));
    for (const auto& tangent : tangents_)
      tangent->add_row_work(per_node);
    std::vector<double> work(gather_->block_begin.size() - 1, 0.0);
    for (const Node& n : nodes_)
      if (n.block >= 0)
        work[static_cast<std::size_t>(n.block)] += per_node[static_cast<std::size_t>(n.node)];
    return work;
  }

  // The rows of each member's blocks. `member_block`: the members' first blocks when the whole
  // team steps, then the number of blocks.
  void plan(const std::vector<int>& member_block) {
    plan_rows(member_block, 3 * static_cast<Eigen::Index>(soa_->num_nodes));
  }

  // Once u is final at block `block`'s lanes, before the reduction's barrier: u at the field
  // nodes of plan `plan` there into what every member's next rows_product reads (each member
  // writes its own nodes once): h u into a vector for the tangents that read one; for those that
  // read records, u into records of doubles where the stepper's own records are floats (in double
  // they read the stepper's records themselves).
  void share_direction(int plan, int block, const Real* u_records, double h) {
    const auto& nodes = plan_nodes_[static_cast<std::size_t>(plan)];
    const auto& start = plan_block_start_[static_cast<std::size_t>(plan)];
    const auto first = nodes.begin() + start[block], last = nodes.begin() + start[block + 1];
    if constexpr (!std::is_same_v<Real, double>)
      if (u_by_records_)
        for (auto n = first; n != last; ++n)
          for (int c = 0; c < 3; ++c)
            u_records_[kDirection * static_cast<std::size_t>(n->id) + c] =
                u_records[kDirection * n->id + c];
    if (hu_by_vector_)
      for (auto n = first; n != last; ++n)
        for (int c = 0; c < 3; ++c)
          hu_[3 * n->node + c] = h * u_records[kDirection * n->id + c];
  }

  // Before a product, by the member with plan `plan` (member_plan), once every member has shared
  // its u (share_direction) and passed the barrier: the fields' rows -A_F u / h = K_F (h u) at
  // its nodes, from `u_records` (the stepper's) or the shares.
  void rows_product(int plan, const Real* u_records, double h) {
    Eigen::VectorXd& y = plan_y_[static_cast<std::size_t>(plan)];
    for (const Node& n : plan_nodes_[static_cast<std::size_t>(plan)])
      y.template segment<3>(3 * n.node).setZero();
    const double* records;
    if constexpr (std::is_same_v<Real, double>)
      records = u_records;
    else
      records = u_records_.data();
    for (const auto& tangent : tangents_)
      if (tangent->reads_direction_records())
        tangent->add_product_rows_records(records, h, y, plan);
      else
        tangent->add_product_rows(hu_, y, plan);
  }

  // Once the spring product has written w at block `block`'s lanes: w += A_F u at the plan's
  // nodes there; returns their part of u·A_F u.
  double rows_apply(int plan, int block, const CgVectors<Real>& cg, const Real* u_records,
                    double h) const {
    const Eigen::VectorXd& y = plan_y_[static_cast<std::size_t>(plan)];
    const auto& nodes = plan_nodes_[static_cast<std::size_t>(plan)];
    const std::size_t p = static_cast<std::size_t>(plan);
    double dot = 0.0;
    for (auto n = nodes.begin() + plan_block_start_[p][block];
         n != nodes.begin() + plan_block_start_[p][block + 1]; ++n)
      for (int c = 0; c < 3; ++c) {
        const double yc = y[3 * n->node + c];
        cg.y[c][n->lane] -= static_cast<Real>(h * yc);
        dot += u_records[kDirection * n->id + c] * yc;
      }
    return -h * dot;
  }

  // The plan of member `member` of `members` (1, or the whole team).
  int member_plan(int member, int members) const { return members == 1 ? team_ : member; }

  // Before the linearising pass: x, v and the warm start Δv at this member's field nodes.
  void gather_state(int b0, int b1, const Real* records, const Real* dv_records, double h) {
    for (const Node& n : owned(b0, b1)) {
      for (int c = 0; c < 3; ++c) {
        const Eigen::Index k = 3 * n.node + c;
        x_[k] = soa_->frame_at(c, n.id) + records[kRecord * n.id + c];
        v_[k] = records[kRecord * n.id + 3 + c];
        dv_[k] = dv_records[kDirection * n.id + c];
        hv_[k] = h * v_[k];
        hdv_[k] = h * dv_[k];
      }
    }
  }

  // After the pass's barrier, this member's part of the fields' right-hand side, b_F / h =
  // f_F + K_F (h v), of -A_F Δv / h = K_F (h Δv) + D_F Δv and of the diagonal blocks of
  // -A_F = h D_F + h² K_F. The parts are zero at every field node here: start_apply clears
  // what it reads. Where every tangent starts by rows, only the tangents' own parts (set_part):
  // start_apply takes the rest by rows.
  void start_part(int member, int members, double h) {
    if (start_rows_) {
      for (const auto& tangent : tangents_)
        tangent->set_part(member, members);
      return;
    }
    Eigen::VectorXd& b = b_part_[static_cast<std::size_t>(member)];
    Eigen::VectorXd& a = a_part_[static_cast<std::size_t>(member)];
    std::vector<Eigen::Matrix3d>& blocks = blocks_part_[static_cast<std::size_t>(member)];
    for (std::size_t k = 0; k < fields_.size(); ++k) {
      ForceField::Tangent& tangent = *tangents_[k];
      if (!tangent.start_part(hv_, b, hdv_, a, h * h, h, blocks, member, members)) {
        tangent.set_part(member, members);
        if (!tangent.add_force_part(b, member, members))
          fields_[k]->add_force_part(x_, v_, b, member, members);
        tangent.add_product_pair_part(hv_, b, hdv_, a, member, members);
        tangent.add_diagonal_blocks_part(h * h, h, blocks, member, members);
      }
      if (member == 0) fields_[k]->add_dfdv_product(x_, dv_, a);
    }
  }

  // After the next barrier, at this member's field lanes: b += b_F, r += b_F - A_F Δv, the
  // preconditioner's block B += A_F (inverted), u = B⁻¹ r into cg.p and `u_records`. Where they
  // start by rows, the tangents give b_F, A_F Δv and the blocks at the rows of plan `plan`; else
  // this sums the members' parts and clears them at this member's nodes, so that no member zeroes
  // a whole part each step.
  void start_apply(int b0, int b1, int members, int plan, const CgVectors<Real>& cg,
                   Real* u_records, double h) {
    if (start_rows_) {
      const std::size_t p = static_cast<std::size_t>(plan);
      Eigen::VectorXd& b = plan_u_[p];  // free until the products
      Eigen::VectorXd& a = plan_y_[p];
      std::vector<Eigen::Matrix3d>& blocks = plan_blocks_[p];
      for (const Node& n : plan_nodes_[p]) {
        b.template segment<3>(3 * n.node).setZero();
        a.template segment<3>(3 * n.node).setZero();
        blocks[static_cast<std::size_t>(n.node)].setZero();
      }
      for (const auto& tangent : tangents_)
        tangent->start_rows(hv_, b, hdv_, a, h * h, blocks, plan);
      for (const Node& n : plan_nodes_[p])
        apply_start(n, b.template segment<3>(3 * n.node), a.template segment<3>(3 * n.node),
                    blocks[static_cast<std::size_t>(n.node)], cg, u_records, h);
      return;
    }
    for (const Node& n : owned(b0, b1)) {
      Eigen::Vector3d b_field = Eigen::Vector3d::Zero(), a_field = Eigen::Vector3d::Zero();
      Eigen::Matrix3d field_block = Eigen::Matrix3d::Zero();
      for (int m = 0; m < members; ++m) {
        auto b_part = b_part_[static_cast<std::size_t>(m)].template segment<3>(3 * n.node);
        auto a_part = a_part_[static_cast<std::size_t>(m)].template segment<3>(3 * n.node);
        Eigen::Matrix3d& block =
            blocks_part_[static_cast<std::size_t>(m)][static_cast<std::size_t>(n.node)];
        b_field += b_part;
        a_field += a_part;
        field_block += block;
        b_part.setZero();
        a_part.setZero();
        block.setZero();
      }
      if (n.lane >= 0) apply_start(n, b_field, a_field, field_block, cg, u_records, h);
    }
  }

  // Before a product: h u at this member's field nodes (u of every node is complete in
  // `u_records` since the last reduction).
  void gather_direction(int b0, int b1, const Real* u_records, double h) {
    for (const Node& n : owned(b0, b1)) {
      for (int c = 0; c < 3; ++c) {
        u_[3 * n.node + c] = u_records[kDirection * n.id + c];
        hu_[3 * n.node + c] = h * u_[3 * n.node + c];
      }
    }
  }

  // After the product's barrier: this member's part of -A_F u / h = K_F (h u) + D_F u, and its
  // part of u·(-A_F u)/h. The part is zero at every field node here: product_apply clears it.
  void product_part(int member, int members) {
    Eigen::VectorXd& y = product_part_[static_cast<std::size_t>(member)];
    for (std::size_t k = 0; k < fields_.size(); ++k) {
      tangents_[k]->add_product_part(hu_, y, member, members);
      if (member == 0) fields_[k]->add_dfdv_product(x_, u_, y);
    }
    double dot = 0.0;
    for (int offset : node_offsets_)
      dot +=
          u_[offset] * y[offset] + u_[offset + 1] * y[offset + 1] + u_[offset + 2] * y[offset + 2];
    member_dots_[static_cast<std::size_t>(member)] = dot;
  }

  // After the next barrier: w += A_F u at this member's field lanes, the parts cleared at its
  // nodes; returns u·A_F u (every member the same sum).
  double product_apply(int b0, int b1, int members, const CgVectors<Real>& cg, double h) {
    for (const Node& n : owned(b0, b1)) {
      for (int c = 0; c < 3; ++c) {
        double sum = 0.0;
        for (int m = 0; m < members; ++m) {
          double& part = product_part_[static_cast<std::size_t>(m)][3 * n.node + c];
          sum += part;
          part = 0.0;
        }
        if (n.lane >= 0) cg.y[c][n.lane] -= static_cast<Real>(h * sum);
      }
    }
    double dot = 0.0;
    for (int m = 0; m < members; ++m)
      dot += member_dots_[static_cast<std::size_t>(m)];
    return -h * dot;
  }

 private:
  struct Node {
    int node, id, lane, block;  // original id, layout id, lane (-1: constrained), block
  };

  struct NodeRange {
    const Node *first, *last;
    const Node* begin() const { return first; }
    const Node* end() const { return last; }
  };
  // The field nodes of the member that handles blocks [b0, b1): those whose lanes lie in them,
  // and for the member of block 0 the constrained ones.
  NodeRange owned(int b0, int b1) const {
    const auto from = [&](int block) {
      return std::partition_point(nodes_.begin(), nodes_.end(),
                                  [&](const Node& n) { return n.block < block; });
    };
    const auto first = b0 == 0 ? nodes_.begin() : from(b0);
    return {nodes_.data() + (first - nodes_.begin()), nodes_.data() + (from(b1) - nodes_.begin())};
  }
  // Plan m < team for member m of the whole team, plan `team` for one member stepping alone:
  // the field nodes with lanes in the member's blocks.
  void plan_rows(const std::vector<int>& member_block, Eigen::Index dofs) {
    rows_ = !fields_.empty();
    plan_nodes_.assign(static_cast<std::size_t>(team_) + 1, {});
    std::vector<std::vector<int>> rows(static_cast<std::size_t>(team_) + 1);
    for (int plan = 0; plan <= team_; ++plan) {
      const int b0 = plan == team_ ? 0 : member_block[static_cast<std::size_t>(plan)];
      const int b1 = plan == team_ ? member_block.back() : member_block[plan + 1];
      for (const Node& n : owned(b0, b1))
        if (n.lane >= 0) {
          plan_nodes_[static_cast<std::size_t>(plan)].push_back(n);
          rows[static_cast<std::size_t>(plan)].push_back(n.node);
        }
    }
    for (const auto& tangent : tangents_)
      rows_ = tangent->plan_rows(rows) && rows_;
    start_rows_ = rows_;
    for (const auto& tangent : tangents_)
      start_rows_ = start_rows_ && tangent->starts_by_rows();
    // The tangents that read the direction as records read it in the stepper's record order.
    u_by_records_ = hu_by_vector_ = false;
    for (const auto& tangent : tangents_)
      (tangent->reads_direction_records() ? u_by_records_ : hu_by_vector_) = rows_;
    if (u_by_records_)
      for (const auto& tangent : tangents_)
        if (tangent->reads_direction_records()) tangent->set_record_order(soa_->new_id);
    u_records_.assign(u_by_records_ && !std::is_same_v<Real, double>
                          ? kDirection * static_cast<std::size_t>(soa_->num_nodes + 2)
                          : 0,
                      0.0);
    // Per plan and block: where the block's nodes start in the plan's (nodes are by block).
    plan_block_start_.assign(static_cast<std::size_t>(team_) + 1, {});
    for (int plan = 0; plan <= team_; ++plan) {
      const auto& nodes = plan_nodes_[static_cast<std::size_t>(plan)];
      auto& start = plan_block_start_[static_cast<std::size_t>(plan)];
      for (int block = 0; block <= member_block.back(); ++block)
        start.push_back(
            static_cast<int>(std::partition_point(nodes.begin(), nodes.end(),
                                                  [&](const Node& n) { return n.block < block; }) -
                             nodes.begin()));
    }
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(rows_ ? dofs : 0);
    plan_u_.assign(static_cast<std::size_t>(team_) + 1, zero);
    plan_y_.assign(static_cast<std::size_t>(team_) + 1, zero);
    plan_blocks_.assign(
        static_cast<std::size_t>(team_) + 1,
        std::vector<Eigen::Matrix3d>(start_rows_ ? static_cast<std::size_t>(dofs / 3) : 0,
                                     Eigen::Matrix3d::Zero()));
  }
  // At node n's lane, from the fields' b_F / h, -A_F Δv / h and diagonal block of -A_F.
  static void apply_start(const Node& n, const Eigen::Ref<const Eigen::Vector3d>& b_field,
                          const Eigen::Ref<const Eigen::Vector3d>& a_field,
                          const Eigen::Matrix3d& field_block, const CgVectors<Real>& cg,
                          Real* u_records, double h) {
    Eigen::Vector3d r;
    for (int c = 0; c < 3; ++c) {
      cg.b[c][n.lane] += static_cast<Real>(h * b_field[c]);
      cg.r[c][n.lane] += static_cast<Real>(h * (b_field[c] + a_field[c]));
      r[c] = cg.r[c][n.lane];
    }
    const Eigen::Matrix3d inverse = (read_block(cg.block, n.lane) - field_block).inverse();
    write_block(cg, n.lane, inverse);
    const Eigen::Vector3d u = inverse * r;
    for (int c = 0; c < 3; ++c) {
      cg.p[c][n.lane] = static_cast<Real>(u[c]);
      u_records[kDirection * n.id + c] = static_cast<Real>(u[c]);
    }
  }
  static Eigen::Matrix3d read_block(Real* const (&block)[6], int lane) {
    const auto q = [&](int e) { return static_cast<double>(block[e][lane]); };
    Eigen::Matrix3d m;
    m << q(0), q(3), q(4), q(3), q(1), q(5), q(4), q(5), q(2);
    return m;
  }
  static void write_block(const CgVectors<Real>& cg, int lane, const Eigen::Matrix3d& m) {
    const double entries[6] = {m(0, 0), m(1, 1), m(2, 2), m(0, 1), m(0, 2), m(1, 2)};
    for (int e = 0; e < 6; ++e)
      cg.inverse_block[e][lane] = static_cast<Real>(entries[e]);
  }

  const SoaLayout<Real>* soa_;
  const NodeGatherLayout<Real, W>* gather_;
  int team_;
  std::vector<std::shared_ptr<const ForceField>> fields_;
  std::vector<std::unique_ptr<ForceField::Tangent>> tangents_;  // one per field, set each step
  std::vector<Node> nodes_;                         // by block, the constrained (block -1) first
  std::vector<int> node_offsets_;                   // 3·node of the field nodes, ascending
  Eigen::VectorXd x_, v_, hv_, dv_, hdv_, hu_, u_;  // shared, written at field nodes by owners
  std::vector<Eigen::VectorXd> b_part_, a_part_, product_part_;  // per member
  // per member, per node: its part of h D_F + h² K_F
  std::vector<std::vector<Eigen::Matrix3d>> blocks_part_;
  std::vector<double> member_dots_;
  bool rows_ = false;
  bool u_by_records_ = false, hu_by_vector_ = false;  // rows: which forms of u the tangents read
  std::vector<double> u_records_;  // float steppers: u in double records, the stepper's order
  bool start_rows_ = false;        // rows, and every tangent starts a step by rows
  std::vector<std::vector<Node>> plan_nodes_;       // per plan, by block
  std::vector<std::vector<int>> plan_block_start_;  // per plan, per block + 1
  std::vector<Eigen::VectorXd> plan_u_, plan_y_;    // per plan: h u at every field node, its rows
  std::vector<std::vector<Eigen::Matrix3d>> plan_blocks_;  // per plan: the fields' blocks by row
};

}  // namespace msfem::massspring::detail
