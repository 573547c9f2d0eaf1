// Backward Euler with matrix-free, block-Jacobi preconditioned CG on the node-centric layout of the
// explicit stepper (fast_implicit_stepper.hpp).

#include "msfem/massspring/fast_implicit_stepper.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>

#include "implicit_fields.hpp"
#include "kernels/adaptive_threads.hpp"
#include "kernels/gather_kernels.hpp"
#include "kernels/soa_layout.hpp"
#include "kernels/thread_team.hpp"
#include "solvers/fast_lanes.hpp"
#include "solvers/warm_start_trend.hpp"

namespace msfem::massspring {

class FastImplicitStepper::Implementation {
 public:
  virtual ~Implementation() = default;
  virtual void update_parameters(const MechanicalSystem& model) = 0;
  virtual void set_state(const State& state) = 0;
  virtual State state() const = 0;
  virtual void step(double h) = 0;
  virtual int last_iterations() const = 0;
  virtual int last_threads() const = 0;
  virtual bool single_precision_terms() const = 0;
  virtual int num_nodes() const = 0;
  virtual int num_springs() const = 0;
};

namespace {

using detail::kRecord;

template <class Real, int W>
class GatherImplicitStepper final : public FastImplicitStepper::Implementation {
 public:
  GatherImplicitStepper(const MechanicalSystem& model, const FastImplicitOptions& options)
      : model_(&model),
        options_(options),
        team_(std::max(options.threads, 1)),
        threads_(team_.size(), options.adaptive_threads),
        soa_(model, options.reorder_nodes, kRelative),
        gather_(soa_),
        records_(kRecord * (soa_.num_nodes + 2)),
        p_records_(detail::kDirection * (soa_.num_nodes + 2)),
        dv_records_(detail::kDirection * (soa_.num_nodes + 2)),
        fields_(soa_, gather_, team_.size()) {
    gather_.partition_for(team_.size());
    const std::size_t lanes = gather_.lane_node.size();
    system_.resize(gather_.chunk_slot.back(), lanes,
                   options.single_precision_terms && options.cg_tolerance >= kSingleTermsTolerance);
    for (int c = 0; c < 3; ++c)
      for (auto* v :
           {&dv_[c], &residual_[c], &u_[c], &w_[c], &direction_[c], &direction_product_[c]}) {
        v->assign(lanes, Real(0));
        cg_.dv[c] = dv_[c].data();
        cg_.r[c] = residual_[c].data();
        cg_.p[c] = u_[c].data();  // what the products read: u = B⁻¹ r
        cg_.y[c] = w_[c].data();  // w = A u
        direction_pointers_[c] = direction_[c].data();
        direction_product_pointers_[c] = direction_product_[c].data();
      }
    for (int c = 0; c < 3; ++c) {
      last_dv_[c].assign(lanes, Real(0));
      trend_[c].assign(lanes, Real(0));
    }
    for (int e = 0; e < 6; ++e) {
      inverse_block_[e].assign(lanes, Real(0));
      cg_.inverse_block[e] = inverse_block_[e].data();
    }
    take_fields(model);
    for (auto& sums : block_sums_)
      sums.assign(3 * static_cast<std::size_t>(blocks()), 0.0);
    trend_sums_.assign(2 * static_cast<std::size_t>(blocks()), 0.0);
    pack();
  }

  void update_parameters(const MechanicalSystem& model) override {
    unpack();
    soa_.load_parameters(model);
    gather_.load_parameters(soa_);
    model_ = &model;
    take_fields(model);
    pack();
    forget_trend();
  }
  void set_state(const State& state) override {
    soa_.set_state(*model_, state);
    time_ = state.time;
    pack();
    forget_trend();
  }
  State state() const override {
    State out{Eigen::VectorXd(3 * soa_.num_nodes), Eigen::VectorXd(3 * soa_.num_nodes), time_};
    for (int i = 0; i < soa_.num_nodes; ++i)
      for (int c = 0; c < 3; ++c) {
        out.x[3 * soa_.order[i] + c] = soa_.frame_at(c, i) + records_[kRecord * i + c];
        out.v[3 * soa_.order[i] + c] = records_[kRecord * i + 3 + c];
      }
    return out;
  }
  int last_iterations() const override { return last_iterations_; }
  int last_threads() const override { return threads_.last(); }
  bool single_precision_terms() const override { return system_.single; }
  int num_nodes() const override { return soa_.num_nodes; }
  int num_springs() const override { return soa_.num_springs; }

  // Solves (M - h D - h² K) Δv = h (f + h K v) by CG from the last step's Δv or its trend, to
  // ‖r‖ <= cg_tolerance ‖b‖ (or b's rounding noise, spring_rounding) or cg_max_iterations, then
  // v += Δv, x += h v.
  void step(double dt) override {
    check_time_step(dt);
    const Real h = static_cast<Real>(dt);
    const int members = threads_.choose();
    const auto start = std::chrono::steady_clock::now();
    const bool follow = following_trend(dt);
    const Real theta = follow ? static_cast<Real>(trend_theta()) : Real(0);
    int iterations = 0;
    const std::function<void(int)> job = [&](int member) {
      const int b0 = members == 1 ? 0 : member_block_[member];
      const int b1 = members == 1 ? blocks() : member_block_[member + 1];
      int parity = 0;
      // Runs a kernel over this member's blocks, then sums the per-block values over all blocks
      // in block order (the same sums for any number of members).
      auto reduced = [&](auto kernel, double(&values)[3]) {
        for (int block = b0; block < b1; ++block) {
          double* sums = &block_sums_[parity][3 * block];
          kernel(block, sums);
        }
        if (members > 1) team_.barrier();
        for (int k = 0; k < 3; ++k) {
          values[k] = 0.0;
          for (int block = 0; block < blocks(); ++block)
            values[k] += block_sums_[parity][3 * block + k];
        }
        // Two alternating buffers: one is written again only after every member has passed the
        // barrier of the other.
        parity ^= 1;
      };
      if (theta > 0) {
        start_on_trend(b0, b1, theta);
        if (members > 1) team_.barrier();
      }
      // One pass: linearise, and start CG from the warm start (the last step's Δv, cg_advance,
      // or its trend).
      double sums[3];  // r·u, r·r, b·b; the barrier also completes the u records
      if (!fields_.empty()) fields_.gather_state(b0, b1, records_.data(), dv_records_.data(), h);
      reduced(
          [&](int block, double* out) {
            double local[3];
            kernels_.linearise_start(gather_, records_.data(), dv_records_.data(), system_, cg_,
                                     p_records_.data(), gather_.block_begin[block],
                                     gather_.block_begin[block + 1], h, local);
            std::copy(local, local + 3, out);
          },
          sums);
      const int plan = fields_.member_plan(member, members);
      if (!fields_.empty()) {
        fields_.start_part(member, members, dt);
        if (members > 1) team_.barrier();
        fields_.start_apply(b0, b1, members, plan, cg_, p_records_.data(), dt);
        reduced(
            [&](int block, double* out) {
              start_sums(block, out);
              if (fields_.rows()) fields_.share_direction(plan, block, p_records_.data(), dt);
            },
            sums);
      }
      double gamma = sums[0], rr = sums[1], alpha = 0.0, previous_gamma = 0.0;
      // ‖r‖ ≤ cg_tolerance ‖b‖, or the rounding noise of b where that is larger: near rest b is
      // at its springs' rounding, and a CG that chased it would only fit noise.
      const double target =
          std::max(options_.cg_tolerance * options_.cg_tolerance * sums[2], dt * dt * rounding_);
      int iteration = 0;
      while (iteration < options_.cg_max_iterations && rr > target) {
        double delta[3];  // u·A u
        if (fields_.rows())
          fields_.rows_product(plan, p_records_.data(), dt);
        else if (!fields_.empty())
          fields_.gather_direction(b0, b1, p_records_.data(), dt);
        reduced(
            [&](int block, double* out) {
              out[0] = kernels_.product(gather_, system_, p_records_.data(), cg_.p, cg_.y,
                                        gather_.block_begin[block], gather_.block_begin[block + 1]);
              if (fields_.rows())
                out[0] += fields_.rows_apply(plan, block, cg_, p_records_.data(), dt);
              out[1] = out[2] = 0.0;
            },
            delta);
        if (!fields_.empty() && !fields_.rows()) {
          fields_.product_part(member, members);
          if (members > 1) team_.barrier();
          delta[0] += fields_.product_apply(b0, b1, members, cg_, dt);
        }
        // Chronopoulos-Gear: d·A d = δ - β γ / α_previous, so one reduction per product.
        const double beta = iteration == 0 ? 0.0 : gamma / previous_gamma;
        const double curvature = iteration == 0 ? delta[0] : delta[0] - beta * gamma / alpha;
        if (!(curvature > 0.0)) break;
        alpha = gamma / curvature;
        double next[3];  // r·u, r·r; the barrier also completes the u records
        reduced(
            [&](int block, double* out) {
              double local[3];
              kernels_.cg_iterate(gather_, cg_, direction_pointers_, direction_product_pointers_,
                                  p_records_.data(), static_cast<Real>(alpha),
                                  static_cast<Real>(beta), gather_.block_begin[block],
                                  gather_.block_begin[block + 1], local);
              std::copy(local, local + 3, out);
              if (fields_.rows()) fields_.share_direction(plan, block, p_records_.data(), dt);
            },
            next);
        previous_gamma = gamma;
        gamma = next[0];
        rr = next[1];
        ++iteration;
      }
      // No barrier: every product of this step has ended at the last reduction, and the next
      // step's first pass reads the records after the step returns.
      kernels_.cg_advance(gather_, cg_, records_.data(), dv_records_.data(),
                          gather_.block_begin[b0], gather_.block_begin[b1], h);
      if (follow)
        for (int block = b0; block < b1; ++block)
          follow_trend(block);
      if (member == 0) iterations = iteration;
    };
    if (members == 1)
      job(0);
    else
      team_.run(job);
    last_iterations_ = iterations;
    warm_start_.record(iterations);
    if (follow) trend_steps_ = std::min(trend_steps_ + 1, kTrendSteps);
    time_ += dt;
    const std::chrono::duration<double> took = std::chrono::steady_clock::now() - start;
    threads_.record(members, took.count() / (iterations + 2.0));  // per product
  }

 private:
  int blocks() const { return static_cast<int>(gather_.block_begin.size()) - 1; }

  // The members' first blocks, then the number of blocks: equal shares of the work, the springs'
  // slots and the fields' rows (ImplicitFields::block_work) in one count.
  void share_blocks() {
    std::vector<double> work = fields_.block_work();
    for (int block = 0; block < blocks(); ++block)
      work[static_cast<std::size_t>(block)] += gather_.chunk_slot[gather_.block_begin[block + 1]] -
                                               gather_.chunk_slot[gather_.block_begin[block]];
    const double total = std::accumulate(work.begin(), work.end(), 0.0);
    member_block_.assign(1, 0);
    double done = 0.0;
    for (int block = 0; block < blocks(); ++block) {
      const double share = total * static_cast<double>(member_block_.size()) / team_.size();
      // The boundary goes before this block where that leaves the member nearer its share.
      if (static_cast<int>(member_block_.size()) < team_.size() &&
          done + 0.5 * work[static_cast<std::size_t>(block)] > share)
        member_block_.push_back(block);
      done += work[static_cast<std::size_t>(block)];
    }
    while (static_cast<int>(member_block_.size()) <= team_.size())
      member_block_.push_back(blocks());
  }

  // The fields and the right-hand side vector they add to (kept by the linearising pass only
  // then: it costs a model without fields a store per lane).
  void take_fields(const MechanicalSystem& model) {
    rounding_ = spring_rounding();
    fields_.take(model);
    share_blocks();
    fields_.plan(member_block_);
    const std::size_t lanes = gather_.lane_node.size();
    for (int c = 0; c < 3; ++c) {
      rhs_[c].assign(fields_.empty() ? 0 : lanes, Real(0));
      cg_.b[c] = fields_.empty() ? nullptr : rhs_[c].data();
    }
    for (int e = 0; e < 6; ++e) {
      block_[e].assign(fields_.empty() ? 0 : lanes, Real(0));
      cg_.block[e] = fields_.empty() ? nullptr : block_[e].data();
    }
  }

  // ‖noise‖² / h² of the springs' part of b: a spring's force k (1 - l0 / l) d carries about the
  // unit round-off u of k l0 (1 - l0 / l is a difference of numbers near 1), independently at
  // each end and spring: u² Σ (k l0)² over the spring ends at free nodes. On the brain's three
  // tiers in float, u h √(that) = 3.5e-10 N·s, and ‖b‖ at rest after a ring-down measured
  // 3.6e-10.
  double spring_rounding() const {
    const double unit = 0.5 * static_cast<double>(std::numeric_limits<Real>::epsilon());
    double sum = 0.0;
    for (int s = 0; s < soa_.num_springs; ++s) {
      const double force = static_cast<double>(soa_.stiffness_rest[static_cast<std::size_t>(s)]);
      const int free_ends = (soa_.a[static_cast<std::size_t>(s)] < soa_.num_free) +
                            (soa_.b[static_cast<std::size_t>(s)] < soa_.num_free);
      sum += free_ends * force * force;
    }
    return unit * unit * sum;
  }

  // Whether this step keeps the trend (warm_start_trend.hpp): while CG is slow at this dt. The
  // history starts anew each time, so a model whose CG converges fast pays nothing for it.
  bool following_trend(double dt) {
    if (dt != trend_dt_) {
      forget_trend();
      trend_dt_ = dt;
    }
    if (options_.trend_start && warm_start_.slow()) return true;
    trend_steps_ = 0;
    return false;
  }
  // θ = (Δv_n − Δv_n−1)·(Δv_n−1 − Δv_n−2) / |Δv_n−1 − Δv_n−2|², summed by block, in [0, 1];
  // 0 until kTrendSteps steps have kept the trend.
  double trend_theta() const {
    if (trend_steps_ < kTrendSteps) return 0.0;
    double along = 0.0, squared = 0.0;
    for (int block = 0; block < blocks(); ++block) {
      along += trend_sums_[2 * static_cast<std::size_t>(block)];
      squared += trend_sums_[2 * static_cast<std::size_t>(block) + 1];
    }
    return squared > 0.0 ? std::clamp(along / squared, 0.0, 1.0) : 0.0;
  }
  void forget_trend() {
    trend_steps_ = 0;
    warm_start_ = {};
  }
  // The warm start Δv_n + θ (Δv_n − Δv_n−1) at this member's lanes, in cg.dv and the Δv records.
  void start_on_trend(int b0, int b1, Real theta) {
    const std::size_t first = static_cast<std::size_t>(gather_.block_begin[b0]) * W,
                      last = static_cast<std::size_t>(gather_.block_begin[b1]) * W;
    for (std::size_t lane = first; lane < last; ++lane) {
      if (gather_.lane_node[lane] == gather_.idle_record) continue;
      Real* record =
          detail::record_at<detail::kDirection>(dv_records_.data(), gather_.lane_offset[lane]);
      for (int c = 0; c < 3; ++c)
        record[c] = dv_[c][lane] = last_dv_[c][lane] + theta * trend_[c][lane];
    }
  }
  // After the step, at block `block`'s lanes: the sums of trend_theta's fit, then Δv_n − Δv_n−1
  // and Δv_n kept for the next.
  void follow_trend(int block) {
    const std::size_t first = static_cast<std::size_t>(gather_.block_begin[block]) * W,
                      last = static_cast<std::size_t>(gather_.block_begin[block + 1]) * W;
    double along = 0.0, squared = 0.0;
    for (int c = 0; c < 3; ++c)
      for (std::size_t lane = first; lane < last; ++lane) {
        const Real change = dv_[c][lane] - last_dv_[c][lane], before = trend_[c][lane];
        along += static_cast<double>(change) * before;
        squared += static_cast<double>(before) * before;
        trend_[c][lane] = change;
        last_dv_[c][lane] = dv_[c][lane];
      }
    trend_sums_[2 * static_cast<std::size_t>(block)] = along;
    trend_sums_[2 * static_cast<std::size_t>(block) + 1] = squared;
  }

  // r·u, r·r and b·b over the lanes of block `block`, once the fields have changed r and u.
  void start_sums(int block, double* out) const {
    double sums[3] = {0.0, 0.0, 0.0};
    const std::size_t begin = static_cast<std::size_t>(gather_.block_begin[block]) * W,
                      end = static_cast<std::size_t>(gather_.block_begin[block + 1]) * W;
    for (std::size_t lane = begin; lane < end; ++lane)
      for (int c = 0; c < 3; ++c) {
        const double r = cg_.r[c][lane], b = cg_.b[c][lane];
        sums[0] += r * cg_.p[c][lane];
        sums[1] += r * r;
        sums[2] += b * b;
      }
    std::copy(sums, sums + 3, out);
  }

  // The node records from the layout's arrays. The Δv records keep Δv for the next warm start
  // (zero at construction, as Δv is).
  void pack() {
    std::fill(records_.data(), records_.data() + records_.size(), Real(0));
    for (int c = 0; c < 3; ++c)
      records_[kRecord * gather_.far_record + c] = Real(1e15);
    for (int i = 0; i < soa_.num_nodes; ++i)
      for (int c = 0; c < 3; ++c) {
        records_[kRecord * i + c] = soa_.x[c][i];
        records_[kRecord * i + 3 + c] = soa_.v[c][i];
      }
  }
  void unpack() {
    for (int i = 0; i < soa_.num_nodes; ++i)
      for (int c = 0; c < 3; ++c) {
        soa_.x[c][i] = records_[kRecord * i + c];
        soa_.v[c][i] = records_[kRecord * i + 3 + c];
      }
  }

  // Float records hold displacements from a rest frame, as the explicit stepper's do
  // (soa_layout.hpp): float positions 1.5 m from the origin are good to 1e-7 m, a millimetre
  // spring's length to a ten-thousandth of itself.
  static constexpr bool kRelative = std::is_same_v<Real, float>;

  const MechanicalSystem* model_;
  FastImplicitOptions options_;
  detail::ThreadTeam team_;
  detail::AdaptiveThreads threads_;
  detail::SoaLayout<Real> soa_;
  detail::NodeGatherLayout<Real, W> gather_;
  detail::Kernels<Real, W> kernels_;
  detail::AlignedVector<Real> records_;     // x, v per node
  detail::AlignedVector<Real> p_records_;   // u = B⁻¹ r per node (zero on constrained nodes)
  detail::AlignedVector<Real> dv_records_;  // the last step's Δv per node (zero on constrained)
  // The trend start (warm_start_trend.hpp): per lane Δv_n and Δv_n − Δv_n−1; per block the fit's
  // two sums.
  detail::AlignedVector<Real> last_dv_[3], trend_[3];
  std::vector<double> trend_sums_;
  detail::WarmStartTrend warm_start_;
  static constexpr int kTrendSteps = 3;  // a fit needs three Δv at one dt
  int trend_steps_ = 0;
  double trend_dt_ = 0.0;
  detail::ImplicitCoefficients<Real> system_;
  detail::ImplicitFields<Real, W> fields_;
  detail::AlignedVector<Real> rhs_[3];  // b in lane order, with fields only
  // CG vectors in lane order: Δv, r, u = B⁻¹ r, w = A u, the direction d and s = A d.
  detail::AlignedVector<Real> dv_[3], residual_[3], u_[3], w_[3], direction_[3],
      direction_product_[3];
  Real* direction_pointers_[3];
  Real* direction_product_pointers_[3];
  detail::AlignedVector<Real> inverse_block_[6];
  detail::AlignedVector<Real> block_[6];  // uninverted, where fields add to the blocks
  detail::CgVectors<Real> cg_;
  std::vector<int> member_block_;      // the members' first blocks, then the number of blocks
  std::vector<double> block_sums_[2];  // per block of chunks: three partial sums
  double time_ = 0.0;
  int last_iterations_ = 0;
  double rounding_ = 0.0;  // spring_rounding()
};

}  // namespace

FastImplicitStepper::FastImplicitStepper(const MechanicalSystem& model,
                                         const FastImplicitOptions& options)
    : single_(options.single_precision) {
  if (options.threads > 64) throw ModelError("fast implicit stepper: at most 64 threads");
  impl_ = detail::kernel_for_lanes<GatherImplicitStepper, Implementation>(model, options, true);
}
FastImplicitStepper::~FastImplicitStepper() = default;

void FastImplicitStepper::update_parameters(const MechanicalSystem& model) {
  impl_->update_parameters(model);
}
void FastImplicitStepper::set_state(const State& state) {
  impl_->set_state(state);
}
State FastImplicitStepper::state() const {
  return impl_->state();
}
void FastImplicitStepper::step(double dt, int count) {
  for (int n = 0; n < count; ++n)
    impl_->step(dt);
}
int FastImplicitStepper::last_cg_iterations() const {
  return impl_->last_iterations();
}
int FastImplicitStepper::last_step_threads() const {
  return impl_->last_threads();
}
bool FastImplicitStepper::single_precision_terms() const {
  return impl_->single_precision_terms();
}
int FastImplicitStepper::num_nodes() const {
  return impl_->num_nodes();
}
int FastImplicitStepper::num_springs() const {
  return impl_->num_springs();
}

}  // namespace msfem::massspring
