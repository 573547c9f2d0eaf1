// The volume field's kept definite tangent (VolumeForceField::tangent): the gradients of one
// linearisation point, kept in the field's lane groups (volume_batches.hpp) so that every product
// of a solve is a vector pass over a group's lanes — a gather, a dot product per lane, a scatter —
// instead of one element at a time. With rows planned, a thread's product is the dot products of
// the groups at its nodes and then each of its nodes' sum over its elements: no scatter. The start
// of a backward-Euler step goes the same way (start_rows), and gathers each row's gradients into
// row order for the step's products.

#include <algorithm>
#include <cmath>
#include <numeric>
#include <utility>
#include <vector>

#include "fields/volume_batches.hpp"
#include "fields/volume_rows.hpp"
#include "msfem/massspring/volume_force_field.hpp"

namespace msfem::massspring {

// −(κ/|V⁰|) ∂V ∂Vᵀ per element with g = −6 ∂V, so a product is df −= κ/|V⁰| (g·dx)/36 g.
class DefiniteVolumeTangent final : public ForceField::Tangent {
 public:
  DefiniteVolumeTangent(const VolumeForceField& field, const Eigen::VectorXd& x)
      : field_(&field), batches_(field.batches_.get()), x_(&x), g_(3 * batches_->offset.size()) {
    set_lane_constants();
  }

  // Gradients and volumes of this part's groups; the lanes a group does not fill keep scale 0.
  void set_part(int part, int parts) override {
    // Read only after the caller's barrier that follows every part's set_part.
    if (part == 0)
      for (RowPlan& p : plans_)
        p.rows_gathered = false;
    for_each_group(part, parts, [&](int group) { set_group(group); });
  }

  // Group by group, each group's gradients still in the cache for the rest: f += pressure g / 6
  // + K dx1 and df2 += K dx2 (one scatter each), and the group's diagonal blocks.
  bool start_part(const Eigen::VectorXd& dx1, Eigen::VectorXd& f, const Eigen::VectorXd& dx2,
                  Eigen::VectorXd& df2, double cx, double, std::vector<Eigen::Matrix3d>& blocks,
                  int part, int parts) override {
    for_each_group(part, parts, [&](int group) {
      set_group(group);
      const double* g = gradient(group);
      const std::size_t first = static_cast<std::size_t>(group) * L;
      double s1[L], s2[L];
      detail::group_dot_pair(*batches_, group, g, dx1.data(), dx2.data(), &factor_[first],
                             &force_[first], s1, s2);
      detail::scatter_group_pair(*batches_, group, g, s1, f.data(), s2, df2.data());
      add_group_blocks(group, cx, blocks);
    });
    return true;
  }

  void add_product_part(const Eigen::VectorXd& dx, Eigen::VectorXd& df, int part,
                        int parts) const override {
    for_each_group(part, parts, [&](int group) { add_group_product(group, dx, df); });
  }

  void add_product_pair_part(const Eigen::VectorXd& dx1, Eigen::VectorXd& df1,
                             const Eigen::VectorXd& dx2, Eigen::VectorXd& df2, int part,
                             int parts) const override {
    for_each_group(part, parts, [&](int group) {
      const double* g = gradient(group);
      const std::size_t first = static_cast<std::size_t>(group) * L;
      double s1[L], s2[L];
      detail::group_dot_pair(*batches_, group, g, dx1.data(), dx2.data(), &factor_[first], nullptr,
                             s1, s2);
      detail::scatter_group_pair(*batches_, group, g, s1, df1.data(), s2, df2.data());
    });
  }

  // The force −κ (V − V⁰)/|V⁰| ∂V = pressure g / 6 from the kept gradients and volumes: the
  // explicit pass's work without its second read of x.
  bool add_force_part(Eigen::VectorXd& f, int part, int parts) const override {
    for_each_group(part, parts, [&](int group) {
      detail::scatter_group(*batches_, group, gradient(group),
                            &force_[static_cast<std::size_t>(group) * L], f.data());
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
      std::vector<char> read(row_of.size(), 0);
      for (int group : p.groups) {
        const int* offset = batches_->offset.data() + batches_->group_start[group];
        for (int k = 0; k < batches_->nodes(group); ++k)
          for (int l = 0; l < batches_->group_lanes[group]; ++l)
            read[static_cast<std::size_t>(offset[k * L + l] / 3)] = 1;
      }
      for (std::size_t node = 0; node < read.size(); ++node)
        if (read[node]) p.read.push_back(static_cast<int>(node));
      p.row_start.push_back(0);
      for (const auto& incidences : at_row) {
        for (const auto& [lane, g] : incidences) {
          p.lane.push_back(lane);
          p.g_at.push_back(g);
        }
        p.row_start.push_back(static_cast<int>(p.lane.size()));
      }
      p.s.assign(scale_.size(), 0.0);
      p.s2.assign(scale_.size(), 0.0);
      p.g_rows.assign(4 * p.lane.size(), 0.0);
      p.row_out.assign(16 * p.rows.size(), 0.0);
      p.x1.assign(4 * records(), 0.0);
      p.x2.assign(4 * records(), 0.0);
    }
    return true;
  }

  // Per element at each of its nodes: its share of the element's dot product and of the row's
  // sum. A step of the pressed tet_edges sphere spends about 1.4 times as long per such incidence
  // as per spring slot (12.2 against 8.5 ns, one thread, perf).
  void add_row_work(std::vector<double>& work) const override {
    constexpr double slots_per_incidence = 1.4;
    for (int node_offset : field_->element_node_offset_)
      work[static_cast<std::size_t>(node_offset / 3)] += slots_per_incidence;
  }

  void add_product_rows(const Eigen::VectorXd& dx, Eigen::VectorXd& df, int plan) const override {
    const RowPlan& p = plans_[static_cast<std::size_t>(plan)];
    to_own_records(dx, p.read, p.x1);
    add_product_rows_records(p.x1.data(), 1.0, df, plan);
  }

  bool reads_direction_records() const override { return true; }
  void set_record_order(const std::vector<int>& record_of_node) override {
    record_of_node_ = record_of_node;
    set_records();
    for (RowPlan& p : plans_) {
      p.x1.assign(4 * records(), 0.0);
      p.x2.assign(4 * records(), 0.0);
    }
  }
  void add_product_rows_records(const double* dx_records, double scale, Eigen::VectorXd& df,
                                int plan) const override {
    const RowPlan& p = plans_[static_cast<std::size_t>(plan)];
    for (int group : p.groups) {
      const std::size_t first = static_cast<std::size_t>(group) * L;
      detail::group_dot_records(*batches_, group, gradient(group), record_.data(), dx_records,
                                &factor_[first], scale, &p.s[first]);
    }
    if (p.rows_gathered) {
      detail::add_row_sums(incidences(p), p.s.data(), df.data());
      return;
    }
    for (std::size_t r = 0; r < p.rows.size(); ++r) {
      double f[3] = {0.0, 0.0, 0.0};
      for (int i = p.row_start[r]; i < p.row_start[r + 1]; ++i) {
        const double s = p.s[static_cast<std::size_t>(p.lane[i])];
        const double* g = g_.data() + p.g_at[i];
        for (int c = 0; c < 3; ++c)
          f[c] += s * g[c * L];
      }
      for (int c = 0; c < 3; ++c)
        df[3 * p.rows[r] + c] += f[c];
    }
  }

  bool starts_by_rows() const override { return true; }
  // As add_product_rows, with two dot products per element and three sums per row.
  void start_rows(const Eigen::VectorXd& dx1, Eigen::VectorXd& f, const Eigen::VectorXd& dx2,
                  Eigen::VectorXd& df2, double cx, std::vector<Eigen::Matrix3d>& blocks,
                  int plan) const override {
    const RowPlan& p = plans_[static_cast<std::size_t>(plan)];
    to_own_records(dx1, p.read, p.x1);
    to_own_records(dx2, p.read, p.x2);
    for (int group : p.groups) {
      const std::size_t first = static_cast<std::size_t>(group) * L;
      detail::group_dot_pair_records(*batches_, group, gradient(group), record_.data(), p.x1.data(),
                                     p.x2.data(), &factor_[first], &force_[first], &p.s[first],
                                     &p.s2[first]);
    }
    detail::start_row_sums(incidences(p), p.g_at.data(), g_.data(), p.g_rows.data(), p.s.data(),
                           p.s2.data(), scale_.data(), cx / 36.0, p.row_out.data());
    for (std::size_t r = 0; r < p.rows.size(); ++r) {
      const double* sums = p.row_out.data() + 16 * r;  // f1, f2, diagonal, off-diagonal (xy yz zx)
      const int node = p.rows[r];
      for (int q = 0; q < 3; ++q) {
        f[3 * node + q] += sums[q];
        df2[3 * node + q] += sums[4 + q];
      }
      const double* e = sums + 8;
      double* m = blocks[static_cast<std::size_t>(node)].data();  // column-major
      m[0] -= e[0];
      m[4] -= e[1];
      m[8] -= e[2];
      m[1] -= e[4];
      m[3] -= e[4];
      m[5] -= e[5];
      m[7] -= e[5];
      m[2] -= e[6];
      m[6] -= e[6];
    }
    p.rows_gathered = true;
  }

  // The field has no velocity term: cv does not enter.
  void add_diagonal_blocks_part(double cx, double, std::vector<Eigen::Matrix3d>& blocks, int part,
                                int parts) const override {
    for_each_group(part, parts, [&](int group) { add_group_blocks(group, cx, blocks); });
  }

 private:
  static constexpr int L = detail::kVolumeLanes;

  void set_group(int group) {
    double volume[L];
    detail::group_gradient(*batches_, group, x_->data(), gradient(group), volume);
    for (int l = 0; l < L; ++l) {
      const std::size_t lane = static_cast<std::size_t>(group) * L + l;
      force_[lane] = scale_[lane] * (volume[l] - rest_[lane]) / 6.0;
    }
  }

  // Each group slot's record in the records the products read (record_of_node_'s order).
  void set_records() {
    record_.resize(batches_->offset.size());
    for (std::size_t i = 0; i < record_.size(); ++i) {
      const int node = batches_->offset[i] / 3;
      record_[i] = 4 * (record_of_node_.empty() ? node : record_of_node_[node]);
    }
  }

  // What does not change with the state, per group lane (scale 0 on the lanes a group does not
  // fill), and each node's record in the group layout.
  void set_lane_constants() {
    set_records();
    const auto& elements = field_->elements_;
    const std::size_t lanes = static_cast<std::size_t>(batches_->num_groups()) * L;
    scale_.assign(lanes, 0.0);
    factor_.assign(lanes, 0.0);
    rest_.assign(lanes, 0.0);
    force_.assign(lanes, 0.0);
    for (std::size_t lane = 0; lane < lanes; ++lane) {
      const int e = batches_->element[lane];
      rest_[lane] = elements.rest_volume[e];
      if (static_cast<int>(lane % L) < batches_->group_lanes[lane / L])
        scale_[lane] = elements.modulus[e] / std::abs(rest_[lane]);
      factor_[lane] = -scale_[lane] / 36.0;
    }
  }

  // blocks[i] −= cx κ/|V⁰| g_i g_iᵀ / 36 at the group's nodes: the six distinct entries over the
  // lanes first (a vector loop), then added lane by lane.
  void add_group_blocks(int group, double cx, std::vector<Eigen::Matrix3d>& blocks) const {
    const double* g = gradient(group);
    const int* offset = batches_->offset.data() + batches_->group_start[group];
    const int lanes = batches_->group_lanes[group];
    double c[L];
    for (int l = 0; l < L; ++l)
      c[l] = cx * scale_[static_cast<std::size_t>(group) * L + l] / 36.0;
    for (int k = 0; k < batches_->nodes(group); ++k) {
      const double* gx = g + 3 * k * L;
      const double* gy = gx + L;
      const double* gz = gy + L;
      alignas(64) double e[6][L];
      for (int l = 0; l < L; ++l) {
        const double cgx = c[l] * gx[l], cgy = c[l] * gy[l];
        e[0][l] = cgx * gx[l];
        e[1][l] = cgy * gy[l];
        e[2][l] = c[l] * gz[l] * gz[l];
        e[3][l] = cgx * gy[l];
        e[4][l] = cgx * gz[l];
        e[5][l] = cgy * gz[l];
      }
      for (int l = 0; l < lanes; ++l) {
        double* m = blocks[static_cast<std::size_t>(offset[k * L + l] / 3)].data();  // column-major
        m[0] -= e[0][l];
        m[4] -= e[1][l];
        m[8] -= e[2][l];
        m[1] -= e[3][l];
        m[3] -= e[3][l];
        m[2] -= e[4][l];
        m[6] -= e[4][l];
        m[5] -= e[5][l];
        m[7] -= e[5][l];
      }
    }
  }

  // df −= κ/|V⁰| (g·dx)/36 g over the group's lanes.
  void add_group_product(int group, const Eigen::VectorXd& dx, Eigen::VectorXd& df) const {
    const double* g = gradient(group);
    double s[L];
    detail::group_dot(*batches_, group, g, dx.data(), &factor_[static_cast<std::size_t>(group) * L],
                      s);
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
    set_lane_constants();
  }
  // How many records a vector takes in record_'s order.
  std::size_t records() const {
    if (record_of_node_.empty()) return static_cast<std::size_t>(x_->size() / 3);
    return 1 + static_cast<std::size_t>(
                   *std::max_element(record_of_node_.begin(), record_of_node_.end()));
  }
  // A vector at nodes `nodes` into records of four doubles (x y z, the fourth unread) in record_'s
  // order, for the dot kernels (volume_rows.hpp): one load per node and a transpose of four
  // instead of three scalar loads put together lane by lane. A plan converts only the nodes its
  // groups read.
  void to_own_records(const Eigen::VectorXd& dx, const std::vector<int>& nodes,
                      std::vector<double>& records) const {
    for (int node : nodes) {
      const std::size_t at =
          4 * static_cast<std::size_t>(record_of_node_.empty() ? node : record_of_node_[node]);
      for (int c = 0; c < 3; ++c)
        records[at + c] = dx[3 * static_cast<Eigen::Index>(node) + c];
    }
  }
  double* gradient(int group) { return g_.data() + 3 * batches_->group_start[group]; }
  const double* gradient(int group) const { return g_.data() + 3 * batches_->group_start[group]; }

  struct RowPlan {
    std::vector<int> rows;           // the nodes
    std::vector<int> row_start;      // per row + 1: its incidences
    std::vector<int> lane;           // per incidence: its element's group lane (group·L + l)
    std::vector<int> g_at;           // per incidence: where its g_x is in g_ (g_y, g_z L and 2L on)
    std::vector<int> groups;         // the groups with an element at a row
    std::vector<int> read;           // the nodes of those groups' elements, ascending
    mutable std::vector<double> s;   // per group lane: −κ/|V⁰| (g·dx)/36 at `groups`
    mutable std::vector<double> s2;  // per group lane: start_rows's second factor
    // Per incidence, its g (x y z 0) in row order, gathered by start_rows for the step's products.
    mutable std::vector<double> g_rows;
    mutable std::vector<double> row_out;  // per row: start_row_sums's 16 sums
    mutable std::vector<double> x1, x2;   // the products' vectors in records (to_own_records)
    mutable bool rows_gathered = false;
  };
  static detail::RowIncidences incidences(const RowPlan& p) {
    return {static_cast<int>(p.rows.size()), p.rows.data(), p.row_start.data(), p.lane.data(),
            p.g_rows.data()};
  }

  const VolumeForceField* field_;
  const detail::VolumeBatches* batches_;  // the field's, or own_batches_ once rows are planned
  detail::VolumeBatches own_batches_;
  const Eigen::VectorXd* x_;
  std::vector<double> g_;       // per group, g[(3k + c)·L + l] (group_gradient's layout)
  std::vector<double> scale_;   // per group lane: κ/|V⁰|, 0 on lanes the group does not fill
  std::vector<double> factor_;  // per group lane: −κ/|V⁰| / 36, a product's factor on g·dx
  std::vector<double> rest_;    // per group lane: V⁰
  std::vector<int> record_;     // per group slot (b.offset's layout): 4 × the node's record
  std::vector<int> record_of_node_;  // the caller's record order (set_record_order); empty: node
  std::vector<double> force_;        // per group lane: κ (V − V⁰)/|V⁰| / 6 at set_part, on g
  std::vector<RowPlan> plans_;
};

std::unique_ptr<ForceField::Tangent> VolumeForceField::tangent(const Eigen::VectorXd& x,
                                                               const Eigen::VectorXd& v,
                                                               Linearisation mode) const {
  if (mode == Linearisation::exact) return ForceField::tangent(x, v, mode);
  return std::make_unique<DefiniteVolumeTangent>(*this, x);
}

}  // namespace msfem::massspring
