// Node-centric explicit stepping on a thread team (see fast_stepper.hpp for the scheme).

#include "msfem/massspring/fast_stepper.hpp"

#include <atomic>
#include <chrono>
#include <cmath>
#include <sstream>

#include "adaptive_threads.hpp"
#include "gather_kernels.hpp"
#include "msfem/massspring/errors.hpp"
#include "msfem/massspring/stability.hpp"
#include "soa_layout.hpp"
#include "thread_team.hpp"

namespace msfem::massspring {

class FastExplicitStepper::Implementation {
 public:
  virtual ~Implementation() = default;
  virtual void update_parameters(const MassSpringModel& model) = 0;
  virtual void set_state(const State& state) = 0;
  virtual State state() const = 0;
  virtual void step(double dt, int count) = 0;
  virtual int num_nodes() const = 0;
  virtual int num_springs() const = 0;
  virtual int threads() const = 0;
  virtual int last_step_threads() const = 0;
  virtual std::size_t streamed_bytes_per_step() const = 0;
};

namespace {

using detail::kRecord;
using detail::NodeGatherLayout;

template <class Real, int W>
class GatherExplicitStepper final : public FastExplicitStepper::Implementation {
 public:
  GatherExplicitStepper(const MassSpringModel& model, const FastStepperOptions& options)
      : model_(&model),
        team_(std::max(options.threads, 1)),
        threads_(team_.size(), options.adaptive_threads),
        soa_(model, options.reorder_nodes),
        gather_(soa_),
        records_{detail::AlignedVector<Real>(kRecord * (soa_.num_nodes + 2)),
                 detail::AlignedVector<Real>(kRecord * (soa_.num_nodes + 2))},
        symplectic_(options.symplectic) {
    take_fields(model);
    pack();
  }

  void update_parameters(const MassSpringModel& model) override {
    unpack();  // keep the current state; load_parameters moves only the supports
    soa_.load_parameters(model);
    gather_.load_parameters(soa_);
    model_ = &model;
    take_fields(model);
    pack();
  }
  void set_state(const State& state) override {
    soa_.set_state(*model_, state);
    time_ = state.time;
    pack();
  }
  State state() const override {
    const Real* r = records_[current_].data();
    State out{Eigen::VectorXd(3 * soa_.num_nodes), Eigen::VectorXd(3 * soa_.num_nodes), time_};
    for (int i = 0; i < soa_.num_nodes; ++i)
      for (int c = 0; c < 3; ++c) {
        out.x[3 * soa_.order[i] + c] = r[kRecord * i + c];
        out.v[3 * soa_.order[i] + c] = r[kRecord * i + 3 + c];
      }
    return out;
  }

  void step(double dt, int count) override {
    check_time_step(dt);
    const int members = threads_.choose();
    const auto start = std::chrono::steady_clock::now();
    step_springs(dt, count, members);
    const std::chrono::duration<double> took = std::chrono::steady_clock::now() - start;
    threads_.record(members, took.count() / count);  // per step
  }

 private:
  void step_springs(double dt, int count, int members) {
    const Real h = static_cast<Real>(dt);
    std::vector<double> check(team_.size(), 0.0);
    // Blocks are taken from one ticket counter. In each step every member draws tickets until it
    // gets one past the step's blocks, so a step uses exactly blocks + members tickets and the
    // next step's tickets start at a known number without resetting the counter.
    const long blocks = static_cast<long>(gather_.block_begin.size()) - 1;
    const long per_step = blocks + members;
    field_diverged_.store(false, std::memory_order_relaxed);
    ticket_.store(0, std::memory_order_relaxed);
    const std::function<void(int)> job = [&](int member) {
      int from = current_;
      double sum = 0.0;
      for (int n = 0; n < count; ++n) {
        const Real* cur = records_[from].data();
        Real* next = records_[1 - from].data();
        sum = 0.0;
        for (long block = ticket_.fetch_add(1, std::memory_order_relaxed) - n * per_step;
             block < blocks;
             block = ticket_.fetch_add(1, std::memory_order_relaxed) - n * per_step) {
          const int begin = gather_.block_begin[block], end = gather_.block_begin[block + 1];
          sum += kernels_.explicit_step(gather_, cur, next, begin, end, h, symplectic_);
        }
        from = 1 - from;
        if (!fields_.empty())
          add_field_impulses(member, members, dt, records_[1 - from].data(), records_[from].data());
        // run() itself waits for the last step
        if (n + 1 < count && members > 1) team_.barrier();
      }
      check[member] = sum;
    };
    if (members == 1)
      job(0);
    else
      team_.run(job);
    current_ = (current_ + count) % 2;
    time_ += dt * count;
    double total = 0.0;
    for (double value : check)
      total += value;
    if (!std::isfinite(total) || field_diverged_.load()) report_divergence(dt);
  }

 public:
  int num_nodes() const override { return soa_.num_nodes; }
  int num_springs() const override { return soa_.num_springs; }
  int threads() const override { return team_.size(); }
  int last_step_threads() const override { return threads_.last(); }
  std::size_t streamed_bytes_per_step() const override {
    const std::size_t lanes = gather_.lane_offset.size(), slots = gather_.neighbour.size();
    const std::size_t per_slot =
        sizeof(int) +
        (gather_.spring_damping == detail::SpringDamping::per_spring ? 3 : 2) * sizeof(Real);
    return lanes * (sizeof(int) + 6 * sizeof(Real)) + slots * per_slot +
           gather_.chunk_slot.size() * sizeof(int) + 2 * records_[0].size() * sizeof(Real);
  }

 private:
  // The model's force fields and the nodes they read and push: gathered into full-size vectors
  // at those nodes only, so a field on a few nodes (the tool's contact) costs a step little.
  void take_fields(const MassSpringModel& model) {
    fields_.clear();
    std::vector<char> used(static_cast<std::size_t>(soa_.num_nodes), 0);
    for (const auto& field : model.fields()) {
      fields_.push_back(field.field);
      for (int node : field.field->nodes())
        used[static_cast<std::size_t>(node)] = 1;
    }
    field_nodes_.clear();
    for (int node = 0; node < soa_.num_nodes; ++node)
      if (used[static_cast<std::size_t>(node)]) field_nodes_.push_back(node);
    const Eigen::Index dofs = 3 * static_cast<Eigen::Index>(soa_.num_nodes);
    field_x_ = Eigen::VectorXd::Zero(fields_.empty() ? 0 : dofs);
    field_v_ = field_x_;
    field_f_.assign(static_cast<std::size_t>(team_.size()), field_x_);
  }

  // Member `member`'s share [n·m/M, n·(m+1)/M) of the field nodes.
  std::pair<std::size_t, std::size_t> field_share(int member, int members) const {
    const std::size_t n = field_nodes_.size();
    return {n * member / members, n * (member + 1) / members};
  }

  // Symplectic Euler with the fields' force f_F(x, v) of the step's start: v' = v'_springs +
  // h M⁻¹ f_F and x' = x + h v' = x'_springs + h² M⁻¹ f_F, on the free nodes (explicit Euler: x'
  // advances with the starting v, so only v' takes the field's impulse). The members share
  // the work: each gathers its share of the field nodes' x and v, adds its part of every field
  // (ForceField::add_force_part) into its own force vector, and once all have, sums the members'
  // forces at its share of the nodes and applies them. Two barriers; none when alone.
  void add_field_impulses(int member, int members, double dt, const Real* before, Real* after) {
    Eigen::VectorXd& f = field_f_[static_cast<std::size_t>(member)];
    for (int node : field_nodes_)
      f.segment<3>(3 * node).setZero();
    const auto [first, last] = field_share(member, members);
    for (std::size_t k = first; k < last; ++k) {
      const int node = field_nodes_[k];
      const int i = soa_.new_id[static_cast<std::size_t>(node)];
      for (int c = 0; c < 3; ++c) {
        field_x_[3 * node + c] = before[kRecord * i + c];
        field_v_[3 * node + c] = before[kRecord * i + 3 + c];
      }
    }
    if (members > 1) team_.barrier();  // x, v gathered; every member's springs written to `after`
    for (const auto& field : fields_)
      field->add_force_part(field_x_, field_v_, f, member, members);
    if (members > 1) team_.barrier();
    bool diverged = false;
    for (std::size_t k = first; k < last; ++k) {
      const int node = field_nodes_[k];
      const int i = soa_.new_id[static_cast<std::size_t>(node)];
      if (i >= soa_.num_free) continue;
      for (int c = 0; c < 3; ++c) {
        double force = 0.0;
        for (int m = 0; m < members; ++m)
          force += field_f_[static_cast<std::size_t>(m)][3 * node + c];
        if (!std::isfinite(force)) diverged = true;
        const Real dv = static_cast<Real>(dt * soa_.inverse_mass[i] * force);
        after[kRecord * i + 3 + c] += dv;
        if (symplectic_) after[kRecord * i + c] += static_cast<Real>(dt) * dv;
      }
    }
    if (diverged) field_diverged_.store(true, std::memory_order_relaxed);
  }

  // Both record buffers from the layout's per-component arrays: the constrained nodes are read
  // from either, and the idle and far records never change.
  void pack() {
    for (auto& records : records_) {
      Real* r = records.data();
      std::fill(r, r + records.size(), Real(0));
      for (int i = 0; i < soa_.num_nodes; ++i)
        for (int c = 0; c < 3; ++c) {
          r[kRecord * i + c] = soa_.x[c][i];
          r[kRecord * i + 3 + c] = soa_.v[c][i];
        }
      for (int c = 0; c < 3; ++c)
        r[kRecord * gather_.far_record + c] = Real(1e15);
    }
  }
  void unpack() {
    const Real* r = records_[current_].data();
    for (int i = 0; i < soa_.num_nodes; ++i)
      for (int c = 0; c < 3; ++c) {
        soa_.x[c][i] = r[kRecord * i + c];
        soa_.v[c][i] = r[kRecord * i + 3 + c];
      }
  }

  [[noreturn]] void report_divergence(double dt) {
    const double stable =
        predicted_stable_dt(*model_, IntegratorKind::central_difference, model_->initial_state());
    std::ostringstream out;
    out << "fast stepper diverged by t = " << time_ << " s with dt = " << dt
        << " s: non-finite state; predicted stable dt = " << stable
        << " s (largest eigenvalue of M^-1 K)";
    throw DivergenceError(out.str(), dt, stable);
  }

  const MassSpringModel* model_;
  detail::ThreadTeam team_;
  detail::AdaptiveThreads threads_;
  detail::SoaLayout<Real> soa_;
  NodeGatherLayout<Real, W> gather_;
  detail::AlignedVector<Real> records_[2];  // x, v per node (kRecord), previous and next step
  std::vector<std::shared_ptr<const ForceField>> fields_;
  std::vector<int> field_nodes_;  ///< original node ids
  Eigen::VectorXd field_x_, field_v_;
  std::vector<Eigen::VectorXd> field_f_;  ///< per member
  std::atomic<bool> field_diverged_{false};
  std::atomic<long> ticket_{0};
  int current_ = 0;
  double time_ = 0.0;
  bool symplectic_ = true;
  detail::Kernels<Real, W> kernels_;
};

}  // namespace

FastExplicitStepper::FastExplicitStepper(const MassSpringModel& model,
                                         const FastStepperOptions& options) {
  if (options.single_precision &&
      detail::preferred_lanes<float>(options.allow_avx512, model.network().num_springs(),
                                     model.num_nodes()) == 16)
    impl_ = std::make_unique<GatherExplicitStepper<float, 16>>(model, options);
  else if (options.single_precision)
    impl_ = std::make_unique<GatherExplicitStepper<float, 8>>(model, options);
  else
    impl_ = std::make_unique<GatherExplicitStepper<double, 4>>(model, options);
}

FastExplicitStepper::~FastExplicitStepper() = default;

void FastExplicitStepper::update_parameters(const MassSpringModel& model) {
  impl_->update_parameters(model);
}
void FastExplicitStepper::set_state(const State& state) {
  impl_->set_state(state);
}
State FastExplicitStepper::state() const {
  return impl_->state();
}
void FastExplicitStepper::step(double dt, int count) {
  impl_->step(dt, count);
}
int FastExplicitStepper::num_nodes() const {
  return impl_->num_nodes();
}
int FastExplicitStepper::num_springs() const {
  return impl_->num_springs();
}
int FastExplicitStepper::threads() const {
  return impl_->threads();
}
int FastExplicitStepper::last_step_threads() const {
  return impl_->last_step_threads();
}
std::size_t FastExplicitStepper::streamed_bytes_per_step() const {
  return impl_->streamed_bytes_per_step();
}

}  // namespace msfem::massspring
