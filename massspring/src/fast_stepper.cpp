// Node-centric explicit stepping on a thread team (see fast_stepper.hpp for the scheme).

#include "msfem/massspring/fast_stepper.hpp"

#include <atomic>
#include <cmath>
#include <sstream>
#include <type_traits>

#include "msfem/massspring/errors.hpp"
#include "msfem/massspring/stability.hpp"
#include "node_gather_layout.hpp"
#include "soa_layout.hpp"
#include "thread_team.hpp"

#if (defined(__x86_64__) || defined(__i386__)) && defined(__GNUC__)
#define MSFEM_HAVE_X86_DISPATCH 1
#include "gather_kernels_x86.hpp"
#define MSFEM_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define MSFEM_HAVE_X86_DISPATCH 0
#define MSFEM_ALWAYS_INLINE inline
#endif

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
};

namespace {

using detail::kRecord;
using detail::NodeGatherLayout;

// Portable kernel (baseline x86-64, other CPUs, and double precision): every chunk of W nodes
// gathers its springs from the records of the previous step, `cur`, and writes the new x and v of
// its nodes to `next` (symplectic Euler). Returns Σ v² as a cheap finiteness check.
//   f_i = Σ_j [k - k l0 / l + c (w·d) / l²] d,   d = x_j - x_i, w = v_j - v_i, l = |d|
template <class Real, int W, bool Damped>
MSFEM_ALWAYS_INLINE double gather_chunks(const NodeGatherLayout<Real, W>& g,
                                         const Real* __restrict cur, Real* __restrict next,
                                         int begin, int end, Real h) {
  Real sum = 0;
  for (int chunk = begin; chunk < end; ++chunk) {
    const int* lanes = g.lane_node.data() + chunk * W;
    Real own[6][W], force[3][W];
    for (int lane = 0; lane < W; ++lane) {
      for (int q = 0; q < 6; ++q)
        own[q][lane] = cur[kRecord * lanes[lane] + q];
      force[0][lane] = force[1][lane] = force[2][lane] = Real(0);
    }
    for (int slot = g.chunk_slot[chunk]; slot < g.chunk_slot[chunk + 1]; slot += W) {
      for (int lane = 0; lane < W; ++lane) {
        const Real* __restrict p = cur + kRecord * g.neighbour[slot + lane];
        const Real dx = p[0] - own[0][lane];
        const Real dy = p[1] - own[1][lane];
        const Real dz = p[2] - own[2][lane];
        const Real inverse_length = Real(1) / std::sqrt(dx * dx + dy * dy + dz * dz);
        Real factor = g.k[slot + lane] - g.k_l0[slot + lane] * inverse_length;
        if constexpr (Damped) {
          const Real w =
              (p[3] - own[3][lane]) * dx + (p[4] - own[4][lane]) * dy + (p[5] - own[5][lane]) * dz;
          factor += g.c[slot + lane] * w * inverse_length * inverse_length;
        }
        force[0][lane] += factor * dx;
        force[1][lane] += factor * dy;
        force[2][lane] += factor * dz;
      }
    }
    for (int lane = 0; lane < W; ++lane) {
      const int at = chunk * W + lane;
      Real* __restrict out = next + kRecord * lanes[lane];
      const Real scale = h * g.inverse_mass[at];
      for (int d = 0; d < 3; ++d) {
        const Real total = force[d][lane] + g.load[d][at] - g.damping[at] * own[3 + d][lane] -
                           g.anchor[at] * own[d][lane];
        out[3 + d] = own[3 + d][lane] + scale * total;
        out[d] = own[d][lane] + h * out[3 + d];
        sum += out[3 + d] * out[3 + d];
      }
    }
  }
  return static_cast<double>(sum);
}

#if MSFEM_HAVE_X86_DISPATCH
bool cpu_has_avx2() {
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
}
bool cpu_has_avx512() {
  return cpu_has_avx2() && __builtin_cpu_supports("avx512f");
}

template <class Real, int W, bool Damped>
MSFEM_TARGET_AVX2 double gather_chunks_avx2_generic(const NodeGatherLayout<Real, W>& g,
                                                    const Real* cur, Real* next, int begin, int end,
                                                    Real h) {
  return gather_chunks<Real, W, Damped>(g, cur, next, begin, end, h);
}
#else
bool cpu_has_avx2() {
  return false;
}
bool cpu_has_avx512() {
  return false;
}
#endif

template <class Real, int W, bool Damped>
double gather_chunks_default(const NodeGatherLayout<Real, W>& g, const Real* cur, Real* next,
                             int begin, int end, Real h) {
  return gather_chunks<Real, W, Damped>(g, cur, next, begin, end, h);
}

template <class Real, int W, bool Damped>
double run_chunks(bool avx2, const NodeGatherLayout<Real, W>& g, const Real* cur, Real* next,
                  int begin, int end, Real h) {
#if MSFEM_HAVE_X86_DISPATCH
  if (avx2) {
    if constexpr ((std::is_same_v<Real, float> && W == 8) ||
                  (std::is_same_v<Real, double> && W == 4))
      return detail::gather_chunks_avx2<Damped>(g, cur, next, begin, end, h);
    else if constexpr (std::is_same_v<Real, float> && W == 16)
      return detail::gather_chunks_avx512<Damped>(g, cur, next, begin, end, h);
    else
      return gather_chunks_avx2_generic<Real, W, Damped>(g, cur, next, begin, end, h);
  }
#endif
  (void)avx2;
  return gather_chunks_default<Real, W, Damped>(g, cur, next, begin, end, h);
}

// Lanes per chunk: one 256-bit vector.
template <class Real>
constexpr int kLanes = 32 / sizeof(Real);

template <class Real, int W>
class GatherExplicitStepper final : public FastExplicitStepper::Implementation {
 public:
  GatherExplicitStepper(const MassSpringModel& model, const FastStepperOptions& options)
      : model_(&model),
        team_(std::max(options.threads, 1)),
        soa_(model, options.reorder_nodes, team_.size()),
        gather_(soa_),
        records_{detail::AlignedArray<Real>(kRecord * (soa_.num_nodes + 2)),
                 detail::AlignedArray<Real>(kRecord * (soa_.num_nodes + 2))} {
    pack();
  }

  void update_parameters(const MassSpringModel& model) override {
    unpack();  // keep the current state; load_parameters moves only the supports
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
    const Real h = static_cast<Real>(dt);
    std::vector<double> check(team_.size(), 0.0);
    const bool damped = soa_.has_spring_damping;
    // Blocks are taken from one ticket counter. In each step every member draws tickets until it
    // gets one past the step's blocks, so a step uses exactly blocks + members tickets and the
    // next step's tickets start at a known number without resetting the counter.
    const long blocks = static_cast<long>(gather_.block_begin.size()) - 1;
    const long per_step = blocks + team_.size();
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
          sum += damped ? run_chunks<Real, W, true>(use_avx2_, gather_, cur, next, begin, end, h)
                        : run_chunks<Real, W, false>(use_avx2_, gather_, cur, next, begin, end, h);
        }
        from = 1 - from;
        if (n + 1 < count) team_.barrier();  // run() itself waits for the last step
      }
      check[member] = sum;
    };
    team_.run(job);
    current_ = (current_ + count) % 2;
    time_ += dt * count;
    double total = 0.0;
    for (double value : check)
      total += value;
    if (!std::isfinite(total)) report_divergence(dt);
  }

  int num_nodes() const override { return soa_.num_nodes; }
  int num_springs() const override { return soa_.num_springs; }
  int threads() const override { return team_.size(); }

 private:
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
  detail::SoaLayout<Real> soa_;
  NodeGatherLayout<Real, W> gather_;
  detail::AlignedArray<Real> records_[2];  // x, v per node (kRecord), previous and next step
  std::atomic<long> ticket_{0};
  int current_ = 0;
  double time_ = 0.0;
  bool use_avx2_ = cpu_has_avx2();
};

}  // namespace

FastExplicitStepper::FastExplicitStepper(const MassSpringModel& model,
                                         const FastStepperOptions& options) {
  if (options.single_precision && options.allow_avx512 && cpu_has_avx512())
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

}  // namespace msfem::massspring
