// The volume field's kept definite tangent (VolumeForceField::tangent): the gradients of one
// linearisation point, kept in the field's lane groups (volume_batches.hpp) so that every product
// of a solve is a vector pass over a group's lanes — a gather, a dot product per lane, a scatter —
// instead of one element at a time. With rows planned, a thread's product is the dot products of
// the groups at its nodes and then each of its nodes' sum over its elements: no scatter.

#include <algorithm>
#include <cmath>
#include <numeric>
#include <utility>
#include <vector>

#include "fields/volume_batches.hpp"
#include "msfem/massspring/volume_force_field.hpp"

namespace msfem::massspring {

// −(κ/|V⁰|) ∂V ∂Vᵀ per element with g = −6 ∂V, so a product is df −= κ/|V⁰| (g·dx)/36 g.
class DefiniteVolumeTangent final : public ForceField::Tangent {
 public:
  DefiniteVolumeTangent(const VolumeForceField& field, const Eigen::VectorXd& x)
      : field_(&field),
        batches_(field.batches_.get()),
        x_(&x),
        g_(3 * batches_->offset.size()),
        scale_(static_cast<std::size_t>(batches_->num_groups()) * L, 0.0),
        pressure_(scale_.size(), 0.0) {}

  // Gradients and volumes of this part's groups; the lanes a group does not fill keep scale 0.
  void set_part(int part, int parts) override {
    const auto& elements = field_->elements_;
    const auto [first, last] = batches_->group_range(part, parts);
    for (int group = first; group < last; ++group) {
      double volume[L];
      detail::group_gradient(*batches_, group, x_->data(), gradient(group), volume);
      for (int l = 0; l < L; ++l) {
        const std::size_t lane = static_cast<std::size_t>(group) * L + l;
        const int e = batches_->element[lane];
        const double rest = elements.rest_volume[e];
        scale_[lane] =
            l < batches_->group_lanes[group] ? elements.modulus[e] / std::abs(rest) : 0.0;
        pressure_[lane] = scale_[lane] * (volume[l] - rest);
      }
    }
  }

  void add_product_part(const Eigen::VectorXd& dx, Eigen::VectorXd& df, int part,
                        int parts) const override {
    for_each_group(part, parts, [&](int group) { add_group_product(group, dx, df); });
  }

  void add_product_pair_part(const Eigen::VectorXd& dx1, Eigen::VectorXd& df1,
                             const Eigen::VectorXd& dx2, Eigen::VectorXd& df2, int part,
                             int parts) const override {
    for_each_group(part, parts, [&](int group) {
      add_group_product(group, dx1, df1);
      add_group_product(group, dx2, df2);
    });
  }

  // The force −κ (V − V⁰)/|V⁰| ∂V = pressure g / 6 from the kept gradients and volumes: the
  // explicit pass's work without its second read of x.
  bool add_force_part(Eigen::VectorXd& f, int part, int parts) const override {
    for_each_group(part, parts, [&](int group) {
      double s[L];
      for (int l = 0; l < L; ++l)
        s[l] = pressure_[static_cast<std::size_t>(group) * L + l] / 6.0;
      detail::scatter_group(*batches_, group, gradient(group), s, f.data());
    });
    return true;
  }

  // Each planned row gathers the factors s of the elements at its node: the groups that touch
  // the plan's rows take their dot products (a group on the boundary between two plans in both),
  // then every row sums s g_k over its incidences in one fixed order, the same in every plan. The
  // elements are grouped anew in the plans' node order first, so that a plan's rows touch its own
  // groups and few others (in the field's order two threads' rows touched nearly every group).
  bool plan_rows(const std::vector<std::vector<int>>& plans) override {
    regroup(plans);
    plans_.assign(plans.size(), RowPlan{});
    std::vector<int> row_of(static_cast<std::size_t>(x_->size() / 3));
    for (std::size_t plan = 0; plan < plans.size(); ++plan) {
      RowPlan& p = plans_[plan];
      p.rows = plans[plan];
      std::fill(row_of.begin(), row_of.end(), -1);
      for (std::size_t r = 0; r < p.rows.size(); ++r)
        row_of[static_cast<std::size_t>(p.rows[r])] = static_cast<int>(r);
      std::vector<std::vector<std::pair<int, int>>> at_row(p.rows.size());  // (lane, g index)
      for (int group = 0; group < batches_->num_groups(); ++group) {
        bool touches = false;
        const int* offset = batches_->offset.data() + batches_->group_start[group];
        for (int k = 0; k < batches_->nodes(group); ++k)
          for (int l = 0; l < batches_->group_lanes[group]; ++l) {
            const int r = row_of[static_cast<std::size_t>(offset[k * L + l] / 3)];
            if (r < 0) continue;
            touches = true;
            at_row[static_cast<std::size_t>(r)].emplace_back(
                group * L + l, 3 * batches_->group_start[group] + 3 * k * L + l);
          }
        if (touches) p.groups.push_back(group);
      }
      p.row_start.push_back(0);
      for (const auto& incidences : at_row) {
        for (const auto& [lane, g] : incidences) {
          p.lane.push_back(lane);
          p.g_at.push_back(g);
        }
        p.row_start.push_back(static_cast<int>(p.lane.size()));
      }
      p.s.assign(scale_.size(), 0.0);
    }
    return true;
  }

  void add_product_rows(const Eigen::VectorXd& dx, Eigen::VectorXd& df, int plan) const override {
    const RowPlan& p = plans_[static_cast<std::size_t>(plan)];
    for (int group : p.groups) {
      double dot[L];
      detail::group_dot(*batches_, group, gradient(group), dx.data(), dot);
      for (int l = 0; l < L; ++l) {
        const std::size_t lane = static_cast<std::size_t>(group) * L + l;
        p.s[lane] = -scale_[lane] / 36.0 * dot[l];
      }
    }
    for (std::size_t r = 0; r < p.rows.size(); ++r) {
      double f[3] = {0.0, 0.0, 0.0};
      for (int i = p.row_start[r]; i < p.row_start[r + 1]; ++i) {
        const double s = p.s[static_cast<std::size_t>(p.lane[i])];
        const double* g = g_.data() + p.g_at[i];
        f[0] += s * g[0];
        f[1] += s * g[L];
        f[2] += s * g[2 * L];
      }
      for (int c = 0; c < 3; ++c)
        df[3 * p.rows[r] + c] += f[c];
    }
  }

  // The field has no velocity term: cv does not enter. blocks[i] −= cx κ/|V⁰| g_i g_iᵀ / 36.
  void add_diagonal_blocks_part(double cx, double, std::vector<Eigen::Matrix3d>& blocks, int part,
                                int parts) const override {
    for_each_group(part, parts, [&](int group) {
      const double* g = gradient(group);
      const int* offset = batches_->offset.data() + batches_->group_start[group];
      for (int k = 0; k < batches_->nodes(group); ++k)
        for (int l = 0; l < batches_->group_lanes[group]; ++l) {
          const double c = cx * scale_[static_cast<std::size_t>(group) * L + l] / 36.0;
          const Eigen::Vector3d gk(g[3 * k * L + l], g[(3 * k + 1) * L + l],
                                   g[(3 * k + 2) * L + l]);
          blocks[static_cast<std::size_t>(offset[k * L + l] / 3)].noalias() -=
              c * gk * gk.transpose();
        }
    });
  }

 private:
  static constexpr int L = detail::kVolumeLanes;

  // df −= κ/|V⁰| (g·dx)/36 g over the group's lanes.
  void add_group_product(int group, const Eigen::VectorXd& dx, Eigen::VectorXd& df) const {
    const double* g = gradient(group);
    double s[L];
    detail::group_dot(*batches_, group, g, dx.data(), s);
    for (int l = 0; l < L; ++l)
      s[l] *= -scale_[static_cast<std::size_t>(group) * L + l] / 36.0;
    detail::scatter_group(*batches_, group, g, s, df.data());
  }
  // The groups of part `part` of `parts`: set_part's, so that a thread reads only the gradients
  // it wrote itself.
  template <class Visit>
  void for_each_group(int part, int parts, const Visit& visit) const {
    const auto [first, last] = batches_->group_range(part, parts);
    for (int group = first; group < last; ++group)
      visit(group);
  }
  // The elements in lane groups by their first node in the plans' order (a node's place is its
  // first in plans[0], plans[1], ...; nodes in none go last).
  void regroup(const std::vector<std::vector<int>>& plans) {
    std::vector<long> place(static_cast<std::size_t>(x_->size() / 3), -1);
    long next = 0;
    for (const auto& rows : plans)
      for (int node : rows)
        if (place[static_cast<std::size_t>(node)] < 0)
          place[static_cast<std::size_t>(node)] = next++;
    for (long& p : place)
      if (p < 0) p = next;
    const auto& start = field_->element_node_start_;
    const auto& offset = field_->element_node_offset_;
    const int elements = static_cast<int>(start.size()) - 1;
    std::vector<long> first(static_cast<std::size_t>(elements), next);
    for (int e = 0; e < elements; ++e)
      for (int i = start[e]; i < start[e + 1]; ++i)
        first[e] = std::min(first[e], place[static_cast<std::size_t>(offset[i] / 3)]);
    std::vector<int> order(static_cast<std::size_t>(elements));
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return first[a] < first[b]; });
    own_batches_ =
        detail::batch_elements(start, offset, field_->local_tets_, field_->elements_.tet_start,
                               field_->elements_.tet_weight.data(), &order);
    batches_ = &own_batches_;
    g_.assign(3 * batches_->offset.size(), 0.0);
    scale_.assign(static_cast<std::size_t>(batches_->num_groups()) * L, 0.0);
    pressure_.assign(scale_.size(), 0.0);
  }
  double* gradient(int group) { return g_.data() + 3 * batches_->group_start[group]; }
  const double* gradient(int group) const { return g_.data() + 3 * batches_->group_start[group]; }

  struct RowPlan {
    std::vector<int> rows;          // the nodes
    std::vector<int> row_start;     // per row + 1: its incidences
    std::vector<int> lane;          // per incidence: its element's group lane (group·L + l)
    std::vector<int> g_at;          // per incidence: where its g_x is in g_ (g_y, g_z L and 2L on)
    std::vector<int> groups;        // the groups with an element at a row
    mutable std::vector<double> s;  // per group lane: −κ/|V⁰| (g·dx)/36 at `groups`
  };

  const VolumeForceField* field_;
  const detail::VolumeBatches* batches_;  // the field's, or own_batches_ once rows are planned
  detail::VolumeBatches own_batches_;
  const Eigen::VectorXd* x_;
  std::vector<double> g_;         // per group, g[(3k + c)·L + l] (group_gradient's layout)
  std::vector<double> scale_;     // per group lane: κ/|V⁰|, 0 on lanes the group does not fill
  std::vector<double> pressure_;  // per group lane: κ (V − V⁰)/|V⁰| at set_part
  std::vector<RowPlan> plans_;
};

std::unique_ptr<ForceField::Tangent> VolumeForceField::tangent(const Eigen::VectorXd& x,
                                                               const Eigen::VectorXd& v,
                                                               Linearisation mode) const {
  if (mode == Linearisation::exact) return ForceField::tangent(x, v, mode);
  return std::make_unique<DefiniteVolumeTangent>(*this, x);
}

}  // namespace msfem::massspring
