// Node-centric explicit stepping on a thread team (see fast_stepper.hpp for the scheme).

#include "msfem/massspring/fast_stepper.hpp"

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
#include <immintrin.h>
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
#define MSFEM_TARGET_AVX2 __attribute__((target("avx2,fma")))
bool cpu_has_avx2() {
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
}

// Eight node records (x y z vx | vy vz pad pad) -> eight lanes per component, by two 4x4
// transposes inside the 128-bit halves (record l in the low half, l + 4 in the high half): cheaper
// than six gathers on the CPUs we measured.
template <bool WithVelocity>
MSFEM_TARGET_AVX2 MSFEM_ALWAYS_INLINE void load_records(const float* base, const int* index,
                                                        __m256 (&out)[6]) {
  __m256 r[4];
  for (int l = 0; l < 4; ++l)
    r[l] = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_load_ps(base + kRecord * index[l])),
                                _mm_load_ps(base + kRecord * index[l + 4]), 1);
  const __m256 t0 = _mm256_unpacklo_ps(r[0], r[1]), t1 = _mm256_unpackhi_ps(r[0], r[1]);
  const __m256 t2 = _mm256_unpacklo_ps(r[2], r[3]), t3 = _mm256_unpackhi_ps(r[2], r[3]);
  out[0] = _mm256_shuffle_ps(t0, t2, 0x44);
  out[1] = _mm256_shuffle_ps(t0, t2, 0xEE);
  out[2] = _mm256_shuffle_ps(t1, t3, 0x44);
  if constexpr (WithVelocity) {
    out[3] = _mm256_shuffle_ps(t1, t3, 0xEE);
    __m256 s[4];
    for (int l = 0; l < 4; ++l)
      s[l] =
          _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_load_ps(base + kRecord * index[l] + 4)),
                               _mm_load_ps(base + kRecord * index[l + 4] + 4), 1);
    const __m256 u0 = _mm256_unpacklo_ps(s[0], s[1]), u2 = _mm256_unpacklo_ps(s[2], s[3]);
    out[4] = _mm256_shuffle_ps(u0, u2, 0x44);
    out[5] = _mm256_shuffle_ps(u0, u2, 0xEE);
  }
}

// The inverse of load_records, pad slots zeroed.
MSFEM_TARGET_AVX2 MSFEM_ALWAYS_INLINE void store_records(float* base, const int* index,
                                                         const __m256 (&in)[6]) {
  const __m256 zero = _mm256_setzero_ps();
  const __m256 t0 = _mm256_unpacklo_ps(in[0], in[1]), t1 = _mm256_unpackhi_ps(in[0], in[1]);
  const __m256 t2 = _mm256_unpacklo_ps(in[2], in[3]), t3 = _mm256_unpackhi_ps(in[2], in[3]);
  const __m256 u0 = _mm256_unpacklo_ps(in[4], in[5]), u1 = _mm256_unpackhi_ps(in[4], in[5]);
  const __m256 r[4] = {_mm256_shuffle_ps(t0, t2, 0x44), _mm256_shuffle_ps(t0, t2, 0xEE),
                       _mm256_shuffle_ps(t1, t3, 0x44), _mm256_shuffle_ps(t1, t3, 0xEE)};
  const __m256 q[4] = {_mm256_shuffle_ps(u0, zero, 0x44), _mm256_shuffle_ps(u0, zero, 0xEE),
                       _mm256_shuffle_ps(u1, zero, 0x44), _mm256_shuffle_ps(u1, zero, 0xEE)};
  for (int l = 0; l < 4; ++l) {
    _mm256_store_ps(base + kRecord * index[l], _mm256_permute2f128_ps(r[l], q[l], 0x20));
    _mm256_store_ps(base + kRecord * index[l + 4], _mm256_permute2f128_ps(r[l], q[l], 0x31));
  }
}

// 1/√a from the hardware estimate and one Newton step (relative error ~1e-7, float's own).
MSFEM_TARGET_AVX2 MSFEM_ALWAYS_INLINE __m256 inverse_sqrt(__m256 a) {
  const __m256 y = _mm256_rsqrt_ps(a);
  const __m256 half_ay = _mm256_mul_ps(_mm256_mul_ps(_mm256_set1_ps(0.5f), a), y);
  return _mm256_mul_ps(y, _mm256_fnmadd_ps(half_ay, y, _mm256_set1_ps(1.5f)));
}

template <bool Damped>
MSFEM_TARGET_AVX2 double gather_chunks_avx2(const NodeGatherLayout<float, 8>& g,
                                            const float* __restrict cur, float* __restrict next,
                                            int begin, int end, float h) {
  __m256 sum = _mm256_setzero_ps();
  const __m256 step = _mm256_set1_ps(h);
  for (int chunk = begin; chunk < end; ++chunk) {
    const int* lanes = g.lane_node.data() + chunk * 8;
    __m256 own[6];
    load_records<true>(cur, lanes, own);
    __m256 fx = _mm256_setzero_ps(), fy = fx, fz = fx;
    for (int slot = g.chunk_slot[chunk]; slot < g.chunk_slot[chunk + 1]; slot += 8) {
      __m256 p[6];
      load_records<Damped>(cur, g.neighbour.data() + slot, p);
      const __m256 dx = _mm256_sub_ps(p[0], own[0]);
      const __m256 dy = _mm256_sub_ps(p[1], own[1]);
      const __m256 dz = _mm256_sub_ps(p[2], own[2]);
      const __m256 length2 =
          _mm256_fmadd_ps(dz, dz, _mm256_fmadd_ps(dy, dy, _mm256_mul_ps(dx, dx)));
      const __m256 inverse_length = inverse_sqrt(length2);
      __m256 factor = _mm256_fnmadd_ps(_mm256_loadu_ps(g.k_l0.data() + slot), inverse_length,
                                       _mm256_loadu_ps(g.k.data() + slot));
      if constexpr (Damped) {
        __m256 w = _mm256_mul_ps(_mm256_sub_ps(p[3], own[3]), dx);
        w = _mm256_fmadd_ps(_mm256_sub_ps(p[4], own[4]), dy, w);
        w = _mm256_fmadd_ps(_mm256_sub_ps(p[5], own[5]), dz, w);
        const __m256 cw = _mm256_mul_ps(_mm256_loadu_ps(g.c.data() + slot), w);
        factor = _mm256_fmadd_ps(cw, _mm256_mul_ps(inverse_length, inverse_length), factor);
      }
      fx = _mm256_fmadd_ps(factor, dx, fx);
      fy = _mm256_fmadd_ps(factor, dy, fy);
      fz = _mm256_fmadd_ps(factor, dz, fz);
    }
    const int at = chunk * 8;
    const __m256 scale = _mm256_mul_ps(step, _mm256_loadu_ps(g.inverse_mass.data() + at));
    const __m256 damping = _mm256_loadu_ps(g.damping.data() + at);
    const __m256 anchor = _mm256_loadu_ps(g.anchor.data() + at);
    const __m256 force[3] = {fx, fy, fz};
    __m256 out[6];
    for (int d = 0; d < 3; ++d) {
      __m256 total = _mm256_add_ps(force[d], _mm256_loadu_ps(g.load[d].data() + at));
      total = _mm256_fnmadd_ps(damping, own[3 + d], total);
      total = _mm256_fnmadd_ps(anchor, own[d], total);
      out[3 + d] = _mm256_fmadd_ps(scale, total, own[3 + d]);
      out[d] = _mm256_fmadd_ps(step, out[3 + d], own[d]);
      sum = _mm256_fmadd_ps(out[3 + d], out[3 + d], sum);
    }
    store_records(next, lanes, out);
  }
  alignas(32) float lanes_sum[8];
  _mm256_store_ps(lanes_sum, sum);
  double total = 0.0;
  for (float value : lanes_sum)
    total += value;
  return total;
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
    if constexpr (std::is_same_v<Real, float> && W == 8)
      return gather_chunks_avx2<Damped>(g, cur, next, begin, end, h);
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

template <class Real>
class GatherExplicitStepper final : public FastExplicitStepper::Implementation {
  static constexpr int W = kLanes<Real>;

 public:
  GatherExplicitStepper(const MassSpringModel& model, const FastStepperOptions& options)
      : model_(&model),
        team_(std::max(options.threads, 1)),
        soa_(model, options.reorder_nodes, team_.size()),
        gather_(soa_, team_.size()),
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
    const std::function<void(int)> job = [&](int member) {
      const int begin = gather_.chunk_begin[member], end = gather_.chunk_begin[member + 1];
      int from = current_;
      double sum = 0.0;
      for (int n = 0; n < count; ++n) {
        const Real* cur = records_[from].data();
        Real* next = records_[1 - from].data();
        sum = damped ? run_chunks<Real, W, true>(use_avx2_, gather_, cur, next, begin, end, h)
                     : run_chunks<Real, W, false>(use_avx2_, gather_, cur, next, begin, end, h);
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
  int current_ = 0;
  double time_ = 0.0;
  bool use_avx2_ = cpu_has_avx2();
};

}  // namespace

FastExplicitStepper::FastExplicitStepper(const MassSpringModel& model,
                                         const FastStepperOptions& options) {
  if (options.single_precision)
    impl_ = std::make_unique<GatherExplicitStepper<float>>(model, options);
  else
    impl_ = std::make_unique<GatherExplicitStepper<double>>(model, options);
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
