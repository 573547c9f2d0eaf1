// Structure-of-arrays explicit stepping on a thread team (see fast_stepper.hpp for the scheme).

#include "msfem/massspring/fast_stepper.hpp"

#include <cmath>
#include <sstream>

#include "msfem/massspring/errors.hpp"
#include "msfem/massspring/stability.hpp"
#include "soa_layout.hpp"
#include "thread_team.hpp"

#if (defined(__x86_64__) || defined(__i386__)) && defined(__GNUC__)
#define MSFEM_HAVE_X86_DISPATCH 1
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

// Node state packed per node, x y z vx vy vz and two pad slots (one 64-byte line in double): a
// spring reads both its nodes with two cache lines instead of twelve scattered ones.
constexpr int kStride = 8;
// Per-thread force buffers: fx fy fz and a pad slot per node.
constexpr int kForceStride = 4;

// Accumulates every spring's force into this thread's node-force buffer (scatter; no other
// thread writes it): f_a += F, f_b -= F, F = [k (l - l0) / l + c (w·d) / l²] d, d = x_b - x_a.
template <class Real, bool Damped>
MSFEM_ALWAYS_INLINE void spring_kernel(const detail::SoaLayout<Real>& soa, const Real* state,
                                       Real* buffer, int begin, int end) {
  const int* __restrict a = soa.a.data();
  const int* __restrict b = soa.b.data();
  const Real* __restrict k = soa.stiffness.data();
  const Real* __restrict k_l0 = soa.stiffness_rest.data();
  const Real* __restrict c = soa.damping.data();
  const Real* __restrict p = state;
  Real* __restrict f = buffer;
  for (int s = begin; s < end; ++s) {
    const Real* __restrict pi = p + kStride * a[s];
    const Real* __restrict pj = p + kStride * b[s];
    const Real dx = pj[0] - pi[0];
    const Real dy = pj[1] - pi[1];
    const Real dz = pj[2] - pi[2];
    const Real inverse_length = Real(1) / std::sqrt(dx * dx + dy * dy + dz * dz);
    Real factor = k[s] - k_l0[s] * inverse_length;
    if constexpr (Damped) {
      const Real w = (pj[3] - pi[3]) * dx + (pj[4] - pi[4]) * dy + (pj[5] - pi[5]) * dz;
      factor += c[s] * w * inverse_length * inverse_length;
    }
    Real* __restrict fi = f + kForceStride * a[s];
    Real* __restrict fj = f + kForceStride * b[s];
    fi[0] += factor * dx;
    fi[1] += factor * dy;
    fi[2] += factor * dz;
    fj[0] -= factor * dx;
    fj[1] -= factor * dy;
    fj[2] -= factor * dz;
  }
}

// Sums the threads' buffers for each free node (and clears them for the next step), then
// v += h f / m, x += h v. Returns Σ v² as a cheap finiteness check.
template <class Real>
MSFEM_ALWAYS_INLINE double node_kernel(const detail::SoaLayout<Real>& soa, Real* state,
                                       std::vector<std::vector<Real>>& buffers, int begin, int end,
                                       Real h) {
  const Real* __restrict damping = soa.node_damping.data();
  const Real* __restrict anchor = soa.anchor_stiffness.data();
  const Real* __restrict inverse_mass = soa.inverse_mass.data();
  const Real* __restrict lx = soa.load[0].data();
  const Real* __restrict ly = soa.load[1].data();
  const Real* __restrict lz = soa.load[2].data();
  Real sum = 0;
  for (int i = begin; i < end; ++i) {
    Real* __restrict node = state + kStride * i;
    Real gx = lx[i] - damping[i] * node[3] - anchor[i] * node[0];
    Real gy = ly[i] - damping[i] * node[4] - anchor[i] * node[1];
    Real gz = lz[i] - damping[i] * node[5] - anchor[i] * node[2];
    for (auto& buffer : buffers) {
      Real* __restrict f = buffer.data() + kForceStride * i;
      gx += f[0];
      gy += f[1];
      gz += f[2];
      f[0] = f[1] = f[2] = Real(0);
    }
    const Real scale = h * inverse_mass[i];
    node[3] += scale * gx;
    node[4] += scale * gy;
    node[5] += scale * gz;
    node[0] += h * node[3];
    node[1] += h * node[4];
    node[2] += h * node[5];
    sum += node[3] * node[3] + node[4] * node[4] + node[5] * node[5];
  }
  return static_cast<double>(sum);
}

// The same kernels compiled for the baseline x86-64 and for AVX2+FMA, chosen at run time: no
// -march flag, so the library runs on any x86-64 and still uses 256-bit vectors where it can.
template <class Real, bool Damped>
void spring_kernel_default(const detail::SoaLayout<Real>& soa, const Real* state, Real* buffer,
                           int begin, int end) {
  spring_kernel<Real, Damped>(soa, state, buffer, begin, end);
}
template <class Real>
double node_kernel_default(const detail::SoaLayout<Real>& soa, Real* state,
                           std::vector<std::vector<Real>>& buffers, int begin, int end, Real h) {
  return node_kernel<Real>(soa, state, buffers, begin, end, h);
}
#if MSFEM_HAVE_X86_DISPATCH
#define MSFEM_TARGET_AVX2 __attribute__((target("avx2,fma")))
bool cpu_has_avx2() {
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
}
#else
#define MSFEM_TARGET_AVX2
bool cpu_has_avx2() {
  return false;
}
#endif
template <class Real, bool Damped>
MSFEM_TARGET_AVX2 void spring_kernel_avx2(const detail::SoaLayout<Real>& soa, const Real* state,
                                          Real* buffer, int begin, int end) {
  spring_kernel<Real, Damped>(soa, state, buffer, begin, end);
}
template <class Real>
MSFEM_TARGET_AVX2 double node_kernel_avx2(const detail::SoaLayout<Real>& soa, Real* state,
                                          std::vector<std::vector<Real>>& buffers, int begin,
                                          int end, Real h) {
  return node_kernel<Real>(soa, state, buffers, begin, end, h);
}

template <class Real>
class SoaExplicitStepper final : public FastExplicitStepper::Implementation {
 public:
  SoaExplicitStepper(const MassSpringModel& model, const FastStepperOptions& options)
      : model_(&model),
        team_(std::max(options.threads, 1)),
        soa_(model, options.reorder_nodes, team_.size()) {
    buffers_.assign(team_.size(), std::vector<Real>(kForceStride * soa_.num_nodes, Real(0)));
    pack();
  }

  void update_parameters(const MassSpringModel& model) override {
    unpack();  // keep the current state; load_parameters moves only the supports
    soa_.load_parameters(model);
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
        out.x[3 * soa_.order[i] + c] = state_[kStride * i + c];
        out.v[3 * soa_.order[i] + c] = state_[kStride * i + 3 + c];
      }
    return out;
  }

  void step(double dt, int count) override {
    check_time_step(dt);
    const Real h = static_cast<Real>(dt);
    std::vector<double> check(team_.size(), 0.0);
    const std::function<void(int)> job = [&](int member) {
      double sum = 0.0;
      for (int n = 0; n < count; ++n) {
        if (soa_.has_spring_damping)
          spring_pass<true>(member);
        else
          spring_pass<false>(member);
        team_.barrier();
        sum = node_pass(soa_.node_begin[member], soa_.node_begin[member + 1], h);
        team_.barrier();
      }
      check[member] = sum;
    };
    team_.run(job);
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
  template <bool Damped>
  void spring_pass(int member) {
    const int begin = soa_.spring_begin[member], end = soa_.spring_begin[member + 1];
    Real* buffer = buffers_[member].data();
    if (use_avx2_)
      spring_kernel_avx2<Real, Damped>(soa_, state_.data(), buffer, begin, end);
    else
      spring_kernel_default<Real, Damped>(soa_, state_.data(), buffer, begin, end);
  }

  double node_pass(int begin, int end, Real h) {
    return use_avx2_ ? node_kernel_avx2<Real>(soa_, state_.data(), buffers_, begin, end, h)
                     : node_kernel_default<Real>(soa_, state_.data(), buffers_, begin, end, h);
  }

  // The packed node state <-> the layout's per-component arrays.
  void pack() {
    state_.assign(kStride * soa_.num_nodes, Real(0));
    for (int i = 0; i < soa_.num_nodes; ++i)
      for (int c = 0; c < 3; ++c) {
        state_[kStride * i + c] = soa_.x[c][i];
        state_[kStride * i + 3 + c] = soa_.v[c][i];
      }
  }
  void unpack() {
    for (int i = 0; i < soa_.num_nodes; ++i)
      for (int c = 0; c < 3; ++c) {
        soa_.x[c][i] = state_[kStride * i + c];
        soa_.v[c][i] = state_[kStride * i + 3 + c];
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
  std::vector<Real> state_;                 // packed x, v per node (kStride)
  std::vector<std::vector<Real>> buffers_;  // per member: node forces (kForceStride)
  double time_ = 0.0;
  bool use_avx2_ = cpu_has_avx2();
};

}  // namespace

FastExplicitStepper::FastExplicitStepper(const MassSpringModel& model,
                                         const FastStepperOptions& options) {
  if (options.single_precision)
    impl_ = std::make_unique<SoaExplicitStepper<float>>(model, options);
  else
    impl_ = std::make_unique<SoaExplicitStepper<double>>(model, options);
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
