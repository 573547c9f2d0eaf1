// Backward Euler with matrix-free, block-Jacobi preconditioned CG on the node-centric layout of the
// explicit stepper (fast_implicit_stepper.hpp).

#include "msfem/massspring/fast_implicit_stepper.hpp"

#include <algorithm>
#include <cmath>

#include "gather_kernels.hpp"
#include "soa_layout.hpp"
#include "thread_team.hpp"

namespace msfem::massspring {

class FastImplicitStepper::Implementation {
 public:
  virtual ~Implementation() = default;
  virtual void update_parameters(const MassSpringModel& model) = 0;
  virtual void set_state(const State& state) = 0;
  virtual State state() const = 0;
  virtual void step(double h) = 0;
  virtual int last_iterations() const = 0;
  virtual int num_nodes() const = 0;
  virtual int num_springs() const = 0;
};

namespace {

using detail::kRecord;

template <class Real, int W>
class GatherImplicitStepper final : public FastImplicitStepper::Implementation {
 public:
  GatherImplicitStepper(const MassSpringModel& model, const FastImplicitOptions& options)
      : model_(&model),
        options_(options),
        team_(std::max(options.threads, 1)),
        soa_(model, options.reorder_nodes),
        gather_(soa_),
        records_(kRecord * (soa_.num_nodes + 2)),
        p_records_(detail::kDirection * (soa_.num_nodes + 2)) {
    const std::size_t lanes = gather_.lane_node.size();
    system_.resize(gather_.chunk_slot.back(), lanes);
    for (int c = 0; c < 3; ++c)
      for (auto* v : {&dv_[c], &residual_[c], &direction_[c], &product_[c]}) {
        v->assign(lanes, Real(0));
        cg_.dv[c] = dv_[c].data();
        cg_.r[c] = residual_[c].data();
        cg_.p[c] = direction_[c].data();
        cg_.y[c] = product_[c].data();
      }
    for (int e = 0; e < 6; ++e) {
      inverse_block_[e].assign(lanes, Real(0));
      cg_.inverse_block[e] = inverse_block_[e].data();
    }
    // Equal shares of the layout's blocks of chunks (about equal slot counts).
    const int blocks = static_cast<int>(gather_.block_begin.size()) - 1;
    for (int m = 0; m <= team_.size(); ++m)
      chunk_begin_.push_back(gather_.block_begin[static_cast<long>(blocks) * m / team_.size()]);
    pack();
  }

  void update_parameters(const MassSpringModel& model) override {
    unpack();
    soa_.load_parameters(model);
    gather_.load_parameters(soa_);
    model_ = &model;
    pack();
  }
  void set_state(const State& state) override {
    soa_.set_state(*model_, state);
    time_ = state.time;
    pack();
  }
  State state() const override {
    State out{Eigen::VectorXd(3 * soa_.num_nodes), Eigen::VectorXd(3 * soa_.num_nodes), time_};
    for (int i = 0; i < soa_.num_nodes; ++i)
      for (int c = 0; c < 3; ++c) {
        out.x[3 * soa_.order[i] + c] = records_[kRecord * i + c];
        out.v[3 * soa_.order[i] + c] = records_[kRecord * i + 3 + c];
      }
    return out;
  }
  int last_iterations() const override { return last_iterations_; }
  int num_nodes() const override { return soa_.num_nodes; }
  int num_springs() const override { return soa_.num_springs; }

  // Solves (M - h D - h² K) Δv = h (f + h K v) by CG from the last step's Δv, to
  // ‖r‖ <= cg_tolerance ‖b‖ or cg_max_iterations, then v += Δv, x += h v.
  void step(double dt) override {
    check_time_step(dt);
    const Real h = static_cast<Real>(dt);
    int iterations = 0;
    const std::function<void(int)> job = [&](int member) {
      const int c0 = chunk_begin_[member], c1 = chunk_begin_[member + 1];
      // The direction records hold Δv of the last step (cg_advance): the warm start r = b - A Δv.
      kernels_.linearise(gather_, records_.data(), system_, cg_, c0, c1, h);
      kernels_.product(gather_, system_, p_records_.data(), cg_.dv, cg_.y, c0, c1);
      team_.barrier();  // every product has read Δv's records before they are overwritten
      double sums[3];   // r·z, r·r, b·b
      kernels_.cg_start(gather_, system_, cg_, p_records_.data(), c0, c1, sums);
      reduce(member, sums);  // its barrier also completes the direction records
      double rz = sums[0], rr = sums[1];
      const double target = options_.cg_tolerance * options_.cg_tolerance * sums[2];
      int iteration = 0;
      while (iteration < options_.cg_max_iterations && rr > target) {
        double pap[3] = {
            kernels_.product(gather_, system_, p_records_.data(), cg_.p, cg_.y, c0, c1), 0.0, 0.0};
        reduce(member, pap);
        if (!(pap[0] > 0.0)) break;
        double next[3];
        kernels_.cg_update(cg_, static_cast<Real>(rz / pap[0]), c0, c1, next);
        reduce(member, next);
        const Real ratio = static_cast<Real>(next[0] / rz);
        rz = next[0];
        rr = next[1];
        kernels_.cg_direction(gather_, cg_, p_records_.data(), ratio, c0, c1);
        team_.barrier();  // directions complete before the next product reads them
        ++iteration;
      }
      // No barrier: every product of this step has ended at the last reduce or barrier.
      kernels_.cg_advance(gather_, cg_, records_.data(), p_records_.data(), c0, c1, h);
      if (member == 0) iterations = iteration;
    };
    team_.run(job);
    last_iterations_ = iterations;
    time_ += dt;
  }

 private:
  // Sums per-member values over the team; every member gets the same totals. Two alternating
  // buffers: a member can only reuse one after everyone has passed the barrier of the other.
  void reduce(int member, double (&values)[3]) {
    double* mine = partial_[parity_[member]] + 3 * member;
    for (int k = 0; k < 3; ++k)
      mine[k] = values[k];
    team_.barrier();
    const double* all = partial_[parity_[member]];
    for (int k = 0; k < 3; ++k) {
      values[k] = 0.0;
      for (int m = 0; m < team_.size(); ++m)
        values[k] += all[3 * m + k];
    }
    parity_[member] ^= 1;
  }

  // The node records from the layout's arrays. The direction records keep Δv for the next warm
  // start (zero at construction, as Δv is).
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

  const MassSpringModel* model_;
  FastImplicitOptions options_;
  detail::ThreadTeam team_;
  detail::SoaLayout<Real> soa_;
  detail::NodeGatherLayout<Real, W> gather_;
  detail::Kernels<Real, W> kernels_;
  detail::AlignedVector<Real> records_;    // x, v per node
  detail::AlignedVector<Real> p_records_;  // CG direction per node (zero on constrained nodes)
  detail::ImplicitCoefficients<Real> system_;
  detail::AlignedVector<Real> dv_[3], residual_[3], direction_[3], product_[3];  // product_: z too
  detail::AlignedVector<Real> inverse_block_[6];
  detail::CgVectors<Real> cg_;
  std::vector<int> chunk_begin_;
  double partial_[2][3 * 64] = {};
  int parity_[64] = {};
  double time_ = 0.0;
  int last_iterations_ = 0;
};

}  // namespace

FastImplicitStepper::FastImplicitStepper(const MassSpringModel& model,
                                         const FastImplicitOptions& options) {
  if (options.threads > 64) throw ModelError("fast implicit stepper: at most 64 threads");
  if (options.single_precision &&
      detail::preferred_lanes<float>(true, model.network().num_springs(), model.num_nodes()) == 16)
    impl_ = std::make_unique<GatherImplicitStepper<float, 16>>(model, options);
  else if (options.single_precision)
    impl_ = std::make_unique<GatherImplicitStepper<float, 8>>(model, options);
  else
    impl_ = std::make_unique<GatherImplicitStepper<double, 4>>(model, options);
}
FastImplicitStepper::~FastImplicitStepper() = default;

void FastImplicitStepper::update_parameters(const MassSpringModel& model) {
  impl_->update_parameters(model);
}
void FastImplicitStepper::set_state(const State& state) {
  impl_->set_state(state);
}
State FastImplicitStepper::state() const {
  return impl_->state();
}
void FastImplicitStepper::step(double dt) {
  impl_->step(dt);
}
int FastImplicitStepper::last_cg_iterations() const {
  return impl_->last_iterations();
}
int FastImplicitStepper::num_nodes() const {
  return impl_->num_nodes();
}
int FastImplicitStepper::num_springs() const {
  return impl_->num_springs();
}

}  // namespace msfem::massspring
