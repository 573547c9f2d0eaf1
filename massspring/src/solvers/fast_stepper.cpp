// Node-centric explicit stepping on a thread team (see fast_stepper.hpp for the scheme).

#include "msfem/massspring/fast_stepper.hpp"

#include <atomic>
#include <chrono>
#include <cmath>
#include <initializer_list>
#include <sstream>
#include <type_traits>

#include "kernels/adaptive_threads.hpp"
#include "kernels/gather_kernels.hpp"
#include "kernels/soa_layout.hpp"
#include "kernels/thread_team.hpp"
#include "msfem/massspring/errors.hpp"
#include "msfem/massspring/nodal_load_field.hpp"
#include "msfem/massspring/stability.hpp"
#include "solvers/fast_lanes.hpp"

namespace msfem::massspring {

class FastExplicitStepper::Implementation {
 public:
  virtual ~Implementation() = default;
  virtual void update_parameters(const MechanicalSystem& model) = 0;
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
  GatherExplicitStepper(const MechanicalSystem& model, const FastStepperOptions& options)
      : model_(&model),
        team_(std::max(options.threads, 1)),
        threads_(team_.size(), options.adaptive_threads),
        soa_(model, options.reorder_nodes, std::is_same_v<Real, float>),
        gather_(soa_),
        records_{detail::AlignedVector<Real>(kRecord * (soa_.num_nodes + 2)),
                 detail::AlignedVector<Real>(kRecord * (soa_.num_nodes + 2))},
        range_tickets_(static_cast<std::size_t>(team_.size())),
        integrator_(options.integrator) {
    gather_.partition_for(team_.size());
    if (integrator_ == IntegratorKind::rk4)
      for (auto& stage : stages_)
        stage.resize(records_[0].size());
    take_fields(model);
    pack();
  }

  void update_parameters(const MechanicalSystem& model) override {
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
        out.x[3 * soa_.order[i] + c] = soa_.frame_at(c, i) + r[kRecord * i + c];
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
    std::vector<double> check(team_.size(), 0.0);
    const long blocks = static_cast<long>(gather_.block_begin.size()) - 1;
    field_diverged_.store(false, std::memory_order_relaxed);
    for (auto& ticket : range_tickets_)
      ticket.value.store(0, std::memory_order_relaxed);
    const std::function<void(int)> job = [&](int member) {
      long pass = 0;
      // This member's share of one pass: kernel(begin, end) on the blocks it draws (take_blocks).
      const auto share = [&](const auto& kernel) {
        double sum = 0.0;
        take_blocks(member, members, blocks, pass++, [&](long block) {
          sum += kernel(gather_.block_begin[block], gather_.block_begin[block + 1]);
        });
        return sum;
      };
      int from = current_;
      double sum = 0.0;
      for (int n = 0; n < count; ++n) {
        const Real* cur = records_[from].data();
        Real* next = records_[1 - from].data();
        if (integrator_ == IntegratorKind::rk4) {
          sum = rk4_step(member, members, dt, cur, next, share);
        } else {
          const Real h = static_cast<Real>(dt);
          const bool symplectic = integrator_ == IntegratorKind::symplectic_euler;
          sum = share([&](int begin, int end) {
            return kernels_.explicit_step(gather_, cur, next, begin, end, h, symplectic);
          });
          if (!fields_.empty())  // symplectic: x' = x + h v' takes the impulse too
            add_field_impulses(member, members, cur, {{next, dt, symplectic ? dt : 0.0}});
        }
        from = 1 - from;
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

  // Each member has a home range of the blocks, the same every pass, and takes its blocks from it
  // first, then what is left of the others' ranges: a thread the OS pre-empts holds a pass up by a
  // block, not by its whole range. The blocks come from one ticket counter per range (on its own
  // cache line). In each pass every member draws from every range until it gets a ticket past
  // the range's end, so a pass uses exactly size + members tickets of each counter, and the next
  // pass's tickets start at a known number without a reset. Home ranges, not one counter for all
  // blocks: a member then writes the same nodes' records every step, and reads the other's only
  // at the ranges' boundaries. With a single counter each step's blocks went to whichever member
  // drew them, so a member read records the other had written the step before; when the host put
  // the two vCPUs on different core complexes (a cache line between them 335 ns instead of 100),
  // two threads stepped the brain no faster than one.
  template <class Take>
  void take_blocks(int member, int members, long blocks, long pass, const Take& take) {
    for (int k = 0; k < members; ++k) {
      const int range = (member + k) % members;
      const long first = blocks * range / members;
      const long size = blocks * (range + 1) / members - first, per_pass = size + members;
      std::atomic<long>& counter = range_tickets_[static_cast<std::size_t>(range)].value;
      for (long t = counter.fetch_add(1, std::memory_order_relaxed) - pass * per_pass; t < size;
           t = counter.fetch_add(1, std::memory_order_relaxed) - pass * per_pass)
        take(first + t);
    }
  }

  // Classical RK4 as Integrator::step has it, one kernel pass per stage: stage s reads the state
  // the last stage wrote (`cur` for the first) and every neighbour's part of it, hence a barrier
  // between stages; stage states alternate between stages_[0] and [1], and `next` holds the
  // running combination until it is the result. A field's force at the stage state is an extra
  // acceleration: it moves the next stage's v by c and the combination's v by w times it.
  template <class Share>
  double rk4_step(int member, int members, double dt, const Real* cur, Real* next,
                  const Share& share) {
    static constexpr double kToNext[3] = {0.5, 0.5, 1.0};
    static constexpr double kWeight[4] = {1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0};
    const Real* in = cur;
    double sum = 0.0;
    for (int s = 0; s < 4; ++s) {
      const detail::RkStage stage = s == 0   ? detail::RkStage::first
                                    : s == 3 ? detail::RkStage::last
                                             : detail::RkStage::middle;
      Real* out = s < 3 ? stages_[s % 2].data() : nullptr;
      const double c = s < 3 ? kToNext[s] * dt : 0.0, w = kWeight[s] * dt;
      sum = share([&](int begin, int end) {
        return kernels_.rk4_stage(gather_, stage, in, cur, out, next, begin, end,
                                  static_cast<Real>(c), static_cast<Real>(w));
      });
      if (!fields_.empty())
        add_field_impulses(member, members, in, {{out, c, 0.0}, {next, w, 0.0}});
      if (s < 3 && members > 1) team_.barrier();
      in = out;
    }
    return sum;
  }

 public:
  int num_nodes() const override { return soa_.num_nodes; }
  int num_springs() const override { return soa_.num_springs; }
  int threads() const override { return team_.size(); }
  int last_step_threads() const override { return threads_.last(); }
  std::size_t streamed_bytes_per_step() const override {
    const std::size_t lanes = gather_.lane_offset.size(), slots = gather_.neighbour.size();
    // A relative layout reads each slot's rest edge too.
    const std::size_t per_slot =
        sizeof(int) + ((gather_.spring_damping == detail::SpringDamping::per_spring ? 3 : 2) +
                       (gather_.relative() ? 3 : 0)) *
                          sizeof(Real);
    const std::size_t pass = lanes * (sizeof(int) + 6 * sizeof(Real)) + slots * per_slot +
                             gather_.chunk_slot.size() * sizeof(int);
    const std::size_t buffer = records_[0].size() * sizeof(Real);
    // RK4's record buffers: the first stage reads `in` and writes out and acc (3), the middle two
    // read in, base and acc and write out and acc (5 each), the last reads in and acc and writes
    // acc (3).
    if (integrator_ == IntegratorKind::rk4) return 4 * pass + (3 + 5 + 5 + 3) * buffer;
    return pass + 2 * buffer;
  }

 private:
  // The model's force fields and the nodes they read and push: gathered into full-size vectors
  // at those nodes only, so a field on a few nodes (the tool's contact) costs a step little.
  void take_fields(const MechanicalSystem& model) {
    fields_.clear();
    std::vector<char> used(static_cast<std::size_t>(soa_.num_nodes), 0);
    const ForceField* springs = &spring_field(model, "the fast stepper");
    const ForceField* loads = model.find_field<NodalLoadField>();
    for (const auto& field : model.fields()) {
      if (field.get() == springs || field.get() == loads) continue;  // the kernels' own
      fields_.push_back(field);
      for (int node : field->nodes())
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

  // A buffer a pass wrote whose free nodes take the fields' force: Δv = v_scale M⁻¹ f_F into v and
  // x_scale Δv into x. No records: nothing to take it.
  struct FieldTarget {
    Real* records;
    double v_scale, x_scale;
  };

  // The fields' force f_F(x, v) at the state `before` the pass read, added to the targets the pass
  // wrote: symplectic Euler v' = v'_springs + h M⁻¹ f_F and x' = x + h v' = x'_springs +
  // h² M⁻¹ f_F (explicit Euler: x' advances with the starting v, so only v' takes the impulse;
  // RK4: see rk4_step). The members share the work: each gathers its share of the field nodes' x
  // and v, adds its part of every field (ForceField::add_force_part) into its own force vector,
  // and once all have, sums the members' forces at its share of the nodes and applies them. Two
  // barriers; none when alone.
  void add_field_impulses(int member, int members, const Real* before,
                          std::initializer_list<FieldTarget> targets) {
    Eigen::VectorXd& f = field_f_[static_cast<std::size_t>(member)];
    for (int node : field_nodes_)
      f.segment<3>(3 * node).setZero();
    const auto [first, last] = field_share(member, members);
    for (std::size_t k = first; k < last; ++k) {
      const int node = field_nodes_[k];
      const int i = soa_.new_id[static_cast<std::size_t>(node)];
      for (int c = 0; c < 3; ++c) {
        field_x_[3 * node + c] = soa_.frame_at(c, i) + before[kRecord * i + c];
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
        for (const FieldTarget& target : targets) {
          if (!target.records) continue;
          const Real dv = static_cast<Real>(target.v_scale * soa_.inverse_mass[i] * force);
          target.records[kRecord * i + 3 + c] += dv;
          if (target.x_scale != 0.0)
            target.records[kRecord * i + c] += static_cast<Real>(target.x_scale) * dv;
        }
      }
    }
    if (diverged) field_diverged_.store(true, std::memory_order_relaxed);
  }

  // Both record buffers from the layout's per-component arrays: the constrained nodes are read
  // from either, and the idle and far records never change.
  void pack() {
    for (auto* records : {&records_[0], &records_[1], &stages_[0], &stages_[1]}) {
      if (records->empty()) continue;
      Real* r = records->data();
      std::fill(r, r + records->size(), Real(0));
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
    const IntegratorKind kind =
        integrator_ == IntegratorKind::rk4 ? integrator_ : IntegratorKind::central_difference;
    const double stable = predicted_stable_dt(*model_, kind, model_->initial_state());
    std::ostringstream out;
    out << "fast stepper diverged by t = " << time_ << " s with dt = " << dt
        << " s: non-finite state; predicted stable dt = " << stable
        << " s (largest eigenvalue of M^-1 K)";
    throw DivergenceError(out.str(), dt, stable);
  }

  const MechanicalSystem* model_;
  detail::ThreadTeam team_;
  detail::AdaptiveThreads threads_;
  detail::SoaLayout<Real> soa_;
  NodeGatherLayout<Real, W> gather_;
  detail::AlignedVector<Real> records_[2];  // x, v per node (kRecord), previous and next step
  detail::AlignedVector<Real> stages_[2];   // RK4's stage states (empty for the Euler schemes)
  std::vector<std::shared_ptr<const ForceField>> fields_;
  std::vector<int> field_nodes_;  ///< original node ids
  Eigen::VectorXd field_x_, field_v_;
  std::vector<Eigen::VectorXd> field_f_;  ///< per member
  std::atomic<bool> field_diverged_{false};
  struct alignas(64) Ticket {
    std::atomic<long> value{0};
  };
  std::vector<Ticket> range_tickets_;  ///< one per team member (take_blocks)
  int current_ = 0;
  double time_ = 0.0;
  IntegratorKind integrator_;
  detail::Kernels<Real, W> kernels_;
};

}  // namespace

FastExplicitStepper::FastExplicitStepper(const MechanicalSystem& model,
                                         const FastStepperOptions& options)
    : kind_(options.integrator), single_(options.single_precision) {
  if (options.integrator != IntegratorKind::symplectic_euler &&
      options.integrator != IntegratorKind::explicit_euler &&
      options.integrator != IntegratorKind::rk4)
    throw ModelError("fast explicit stepper: integrator '" + to_string(options.integrator) +
                     "' not supported (symplectic_euler, explicit_euler, rk4)");
  impl_ = detail::kernel_for_lanes<GatherExplicitStepper, Implementation>(model, options,
                                                                          options.allow_avx512);
}

FastExplicitStepper::~FastExplicitStepper() = default;

void FastExplicitStepper::update_parameters(const MechanicalSystem& model) {
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
