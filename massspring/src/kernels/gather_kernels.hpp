#pragma once

// The node-centric kernels of the fast steppers (internal): the explicit step, the RK4 stage, and
// the backward-Euler linearisation and matrix-vector product. One body (gather_kernel_body.inc),
// written against a small set of vector operations, instantiated for a portable lane-array set (any
// CPU) and on x86 for AVX2 (float 8 lanes, double 4) and AVX-512 (float 16); `Kernels` picks one at
// run time.

#include <cmath>
#include <type_traits>

#include "node_gather_layout.hpp"

#if (defined(__x86_64__) || defined(__i386__)) && defined(__GNUC__)
#define MSFEM_HAVE_X86_DISPATCH 1
#define MSFEM_INLINE inline __attribute__((always_inline))
#include "gather_kernels_x86.hpp"
#else
#define MSFEM_HAVE_X86_DISPATCH 0
#define MSFEM_INLINE inline
#endif

namespace msfem::massspring::detail {

// Which stage of an RK4 step a kernel pass runs: the first reads its state from the step's start
// and starts the combination, the last finishes it and has no next stage to write.
enum class RkStage { first, middle, last };

// W lanes as a plain array; the compiler vectorises what it can. Same results as the x86 sets up
// to rounding (an exact 1/√ here).
template <class R, int N>
struct PortableLanes {
  using Real = R;
  static constexpr int W = N;
  struct V {
    R v[N];
  };
  template <class F>
  static MSFEM_INLINE V map(F f) {
    V out;
    for (int l = 0; l < N; ++l)
      out.v[l] = f(l);
    return out;
  }
  // From and to R, or float (a double solve's float coefficients).
  template <class T>
  static MSFEM_INLINE V load(const T* p) {
    return map([&](int l) { return static_cast<R>(p[l]); });
  }
  template <class T>
  static MSFEM_INLINE void store(T* p, V a) {
    for (int l = 0; l < N; ++l)
      p[l] = static_cast<T>(a.v[l]);
  }
  static MSFEM_INLINE V set1(R a) {
    return map([&](int) { return a; });
  }
  static MSFEM_INLINE V add(V a, V b) {
    return map([&](int l) { return a.v[l] + b.v[l]; });
  }
  static MSFEM_INLINE V sub(V a, V b) {
    return map([&](int l) { return a.v[l] - b.v[l]; });
  }
  static MSFEM_INLINE V mul(V a, V b) {
    return map([&](int l) { return a.v[l] * b.v[l]; });
  }
  static MSFEM_INLINE V max(V a, V b) {
    return map([&](int l) { return a.v[l] > b.v[l] ? a.v[l] : b.v[l]; });
  }
  static MSFEM_INLINE V fmadd(V a, V b, V c) {
    return map([&](int l) { return a.v[l] * b.v[l] + c.v[l]; });
  }
  static MSFEM_INLINE V fnmadd(V a, V b, V c) {
    return map([&](int l) { return c.v[l] - a.v[l] * b.v[l]; });
  }
  static MSFEM_INLINE V where_positive(V a, V b) {
    return map([&](int l) { return a.v[l] > R(0) ? b.v[l] : R(0); });
  }
  static MSFEM_INLINE V div(V a, V b) {
    return map([&](int l) { return a.v[l] / b.v[l]; });
  }
  static MSFEM_INLINE V sqrt(V a) {
    return map([&](int l) { return std::sqrt(a.v[l]); });
  }
  static MSFEM_INLINE V sqrt_to_float(V a) { return sqrt(a); }
  static MSFEM_INLINE V inverse_sqrt(V a) {
    return map([&](int l) { return R(1) / std::sqrt(a.v[l]); });
  }
  static MSFEM_INLINE double sum(V a) {
    double total = 0.0;
    for (int l = 0; l < N; ++l)
      total += a.v[l];
    return total;
  }
  template <bool WithVelocity, int Stride = kRecord>
  static MSFEM_INLINE void load_records(const R* base, const int* index, V (&out)[6]) {
    for (int q = 0; q < (WithVelocity ? 6 : 3); ++q)
      for (int l = 0; l < N; ++l)
        out[q].v[l] = record_at<Stride>(base, index[l])[q];
  }
  static MSFEM_INLINE void store_directions(R* base, const int* index, const V (&in)[3]) {
    for (int l = 0; l < N; ++l) {
      for (int q = 0; q < 3; ++q)
        record_at<kDirection>(base, index[l])[q] = in[q].v[l];
      record_at<kDirection>(base, index[l])[3] = R(0);
    }
  }
  static MSFEM_INLINE void store_records(R* base, const int* index, const V (&in)[6]) {
    for (int l = 0; l < N; ++l)
      for (int q = 0; q < 6; ++q)
        record_at(base, index[l])[q] = in[q].v[l];
  }
};

// A double model larger than a core's L2 (the brain: 11.5 MB a step) has its neighbours' records
// in L3, and a slot's long chain of arithmetic waits on their loads: the out-of-order window
// holds about three slot vectors of the linearising pass, not enough to hide an L3 load behind the
// ones before. So the force and linearising loops fetch the records 4 slot vectors ahead (they
// know the neighbours from the slot list, which a hardware prefetcher cannot follow). Measured
// on the brain, alternated in one process: explicit step +9 % on two threads (+11 % on one),
// implicit step +8 %; on the seed sphere, whose records stay in L2, no change. Float records are
// half a cache line and 16 lanes a vector: 16 prefetches per vector cost the float step 5 %, so
// float does without.
template <class S>
constexpr int kPrefetchSlots = std::is_same_v<typename S::Real, double> ? 4 * S::W : 0;

// Prefetches the `Stride` records of slot vector `slot` + kPrefetchSlots, if there is one.
template <class S, int Stride = kRecord>
MSFEM_INLINE void prefetch_neighbours(const typename S::Real* base,
                                      const AlignedVector<int>& neighbour, int slot) {
#if defined(__GNUC__)
  constexpr int kAhead = kPrefetchSlots<S>;
  if constexpr (kAhead > 0) {
    const int ahead = slot + kAhead;
    if (ahead + S::W > static_cast<int>(neighbour.size())) return;
    for (int l = 0; l < S::W; ++l)
      __builtin_prefetch(record_at<Stride>(base, neighbour[static_cast<std::size_t>(ahead + l)]));
  }
#endif
}

#define MSFEM_GATHER_TARGET
#define MSFEM_KERNEL(name) name##_portable
#include "gather_kernel_body.inc"
#undef MSFEM_GATHER_TARGET
#undef MSFEM_KERNEL

#if MSFEM_HAVE_X86_DISPATCH
#define MSFEM_GATHER_TARGET MSFEM_TARGET_AVX2
#define MSFEM_KERNEL(name) name##_avx2
#include "gather_kernel_body.inc"
#undef MSFEM_GATHER_TARGET
#undef MSFEM_KERNEL
#define MSFEM_GATHER_TARGET MSFEM_TARGET_AVX512
#define MSFEM_KERNEL(name) name##_avx512
#include "gather_kernel_body.inc"
#undef MSFEM_GATHER_TARGET
#undef MSFEM_KERNEL

inline bool cpu_has_avx2() {
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
}
inline bool cpu_has_avx512() {
  return cpu_has_avx2() && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl");
}
#else
inline bool cpu_has_avx2() {
  return false;
}
inline bool cpu_has_avx512() {
  return false;
}
#endif

// Lanes per chunk for a precision and a model, where the CPU has AVX-512 and `allow_avx512`:
// doubles take 8 (one 512-bit vector; against 4 lanes of AVX2 with the same 1/√ estimate,
// measured alternated in one process: the brain's implicit step +7 %, its explicit step +5 %,
// the seed sphere's implicit step +19 % on one thread, 10x brain's explicit step -2 %).
// Floats take 16 only while the springs and node records stay well inside one core complex's L3
// (32 MB on the Zen machine; sysconf reports the whole socket's, so a fixed bound): measured there,
// 16 lanes were ~15 % faster than 8 at brain scale (5 MB) and ~15-20 % slower at 10x brain
// (47 MB), where the step streams from memory. Otherwise a 256-bit vector's (AVX2 or portable).
template <class Real>
int preferred_lanes(bool allow_avx512, long springs, long nodes) {
  const bool avx512 = allow_avx512 && cpu_has_avx512();
  if (!std::is_same_v<Real, float>) return avx512 ? 8 : 4;
  constexpr long kCacheBytes = 24L << 20;
  const long bytes = 2 * springs * 3 * static_cast<long>(sizeof(Real)) + 2 * nodes * 32;
  return avx512 && bytes < kCacheBytes ? 16 : 8;
}

#if MSFEM_HAVE_X86_DISPATCH
#define MSFEM_DISPATCH(NAME, ...)                           \
  if constexpr (W * sizeof(Real) == 64) {                   \
    return NAME##_avx512<Avx512<Real>>(__VA_ARGS__);        \
  } else if constexpr (W == 32 / sizeof(Real)) {            \
    if (avx2_) return NAME##_avx2<Avx2<Real>>(__VA_ARGS__); \
  }                                                         \
  return NAME##_portable<PortableLanes<Real, W>>(__VA_ARGS__)
#else
#define MSFEM_DISPATCH(NAME, ...) return NAME##_portable<PortableLanes<Real, W>>(__VA_ARGS__)
#endif

// The kernels for one precision and lane count, the instruction set chosen once: a 512-bit
// vector's lanes (16 floats, 8 doubles) are AVX-512's, which the caller chose them for
// (preferred_lanes); a 256-bit vector's AVX2's where the CPU has it; else the portable lanes.
template <class Real, int W>
class Kernels {
 public:
  Kernels() : avx2_(cpu_has_avx2()) {}

  // symplectic false: explicit Euler (x advances with the step's starting v).
  double explicit_step(const NodeGatherLayout<Real, W>& g, const Real* cur, Real* next, int begin,
                       int end, Real h, bool symplectic = true) const {
    if (!symplectic) return explicit_step_damped<false>(g, cur, next, begin, end, h);
    return explicit_step_damped<true>(g, cur, next, begin, end, h);
  }
  // One stage of classical RK4 (rk4_stage_chunks): `out` the next stage's state, `acc` the running
  // combination; c and w the stage's h-scaled step to the next stage and weight.
  double rk4_stage(const NodeGatherLayout<Real, W>& g, RkStage stage, const Real* in,
                   const Real* base, Real* out, Real* acc, int begin, int end, Real c,
                   Real w) const {
    switch (stage) {
      case RkStage::first:
        return rk4_stage_damped<RkStage::first>(g, in, base, out, acc, begin, end, c, w);
      case RkStage::middle:
        return rk4_stage_damped<RkStage::middle>(g, in, base, out, acc, begin, end, c, w);
      default:
        return rk4_stage_damped<RkStage::last>(g, in, base, out, acc, begin, end, c, w);
    }
  }
  void linearise_start(const NodeGatherLayout<Real, W>& g, const Real* records,
                       const Real* dv_records, ImplicitCoefficients<Real>& sys,
                       const CgVectors<Real>& cg, Real* p_records, int begin, int end, Real h,
                       double (&sums)[3]) const {
    switch (g.spring_damping) {
      case SpringDamping::none:
        return linearise_start_for<SpringDamping::none>(g, records, dv_records, sys, cg, p_records,
                                                        begin, end, h, sums);
      case SpringDamping::uniform:
        return linearise_start_for<SpringDamping::uniform>(g, records, dv_records, sys, cg,
                                                           p_records, begin, end, h, sums);
      default:
        return linearise_start_for<SpringDamping::per_spring>(g, records, dv_records, sys, cg,
                                                              p_records, begin, end, h, sums);
    }
  }
  void cg_advance(const NodeGatherLayout<Real, W>& g, const CgVectors<Real>& cg, Real* records,
                  Real* dv_records, int begin, int end, Real h) const {
    MSFEM_DISPATCH(cg_advance_chunks, g, cg, records, dv_records, begin, end, h);
  }
  double product(const NodeGatherLayout<Real, W>& g, const ImplicitCoefficients<Real>& sys,
                 const Real* p_records, Real* const (&p)[3], Real* const (&y)[3], int begin,
                 int end) const {
    if constexpr (std::is_same_v<Real, double>)
      if (sys.single) return product_for<true>(g, sys, p_records, p, y, begin, end);
    return product_for<false>(g, sys, p_records, p, y, begin, end);
  }
  void cg_iterate(const NodeGatherLayout<Real, W>& g, const CgVectors<Real>& cg,
                  Real* const (&direction)[3], Real* const (&direction_product)[3], Real* u_records,
                  Real alpha, Real beta, int begin, int end, double (&sums)[3]) const {
    MSFEM_DISPATCH(cg_iterate_chunks, g, cg, direction, direction_product, u_records, alpha, beta,
                   begin, end, sums);
  }

 private:
#if MSFEM_HAVE_X86_DISPATCH
  template <class T>
  using Avx2 = std::conditional_t<std::is_same_v<T, float>, Avx2Float, Avx2Double>;
  template <class T>
  using Avx512 = std::conditional_t<std::is_same_v<T, float>, Avx512Float, Avx512Double>;
#endif
  template <bool Symplectic>
  double explicit_step_damped(const NodeGatherLayout<Real, W>& g, const Real* cur, Real* next,
                              int begin, int end, Real h) const {
    switch (g.spring_damping) {
      case SpringDamping::none:
        return explicit_step_for<SpringDamping::none, Symplectic>(g, cur, next, begin, end, h);
      case SpringDamping::uniform:
        return explicit_step_for<SpringDamping::uniform, Symplectic>(g, cur, next, begin, end, h);
      default:
        return explicit_step_for<SpringDamping::per_spring, Symplectic>(g, cur, next, begin, end,
                                                                        h);
    }
  }
  template <SpringDamping Damped, bool Symplectic>
  double explicit_step_for(const NodeGatherLayout<Real, W>& g, const Real* cur, Real* next,
                           int begin, int end, Real h) const {
#if MSFEM_HAVE_X86_DISPATCH
    if constexpr (W * sizeof(Real) == 64) {
      return explicit_chunks_avx512<Avx512<Real>, Damped, Symplectic>(g, cur, next, begin, end, h);
    } else if constexpr (W == 32 / sizeof(Real)) {
      if (avx2_)
        return explicit_chunks_avx2<Avx2<Real>, Damped, Symplectic>(g, cur, next, begin, end, h);
    }
#endif
    return explicit_chunks_portable<PortableLanes<Real, W>, Damped, Symplectic>(g, cur, next, begin,
                                                                                end, h);
  }
  template <RkStage Stage>
  double rk4_stage_damped(const NodeGatherLayout<Real, W>& g, const Real* in, const Real* base,
                          Real* out, Real* acc, int begin, int end, Real c, Real w) const {
    switch (g.spring_damping) {
      case SpringDamping::none:
        return rk4_stage_for<SpringDamping::none, Stage>(g, in, base, out, acc, begin, end, c, w);
      case SpringDamping::uniform:
        return rk4_stage_for<SpringDamping::uniform, Stage>(g, in, base, out, acc, begin, end, c,
                                                            w);
      default:
        return rk4_stage_for<SpringDamping::per_spring, Stage>(g, in, base, out, acc, begin, end, c,
                                                               w);
    }
  }
  template <SpringDamping Damped, RkStage Stage>
  double rk4_stage_for(const NodeGatherLayout<Real, W>& g, const Real* in, const Real* base,
                       Real* out, Real* acc, int begin, int end, Real c, Real w) const {
#if MSFEM_HAVE_X86_DISPATCH
    if constexpr (W * sizeof(Real) == 64) {
      return rk4_stage_chunks_avx512<Avx512<Real>, Damped, Stage>(g, in, base, out, acc, begin, end,
                                                                  c, w);
    } else if constexpr (W == 32 / sizeof(Real)) {
      if (avx2_)
        return rk4_stage_chunks_avx2<Avx2<Real>, Damped, Stage>(g, in, base, out, acc, begin, end,
                                                                c, w);
    }
#endif
    return rk4_stage_chunks_portable<PortableLanes<Real, W>, Damped, Stage>(g, in, base, out, acc,
                                                                            begin, end, c, w);
  }
  template <SpringDamping Damped>
  void linearise_start_for(const NodeGatherLayout<Real, W>& g, const Real* records,
                           const Real* dv_records, ImplicitCoefficients<Real>& sys,
                           const CgVectors<Real>& cg, Real* p_records, int begin, int end, Real h,
                           double (&sums)[3]) const {
    if constexpr (std::is_same_v<Real, double>)
      if (sys.single)
        return linearise_start_terms<Damped, true>(g, records, dv_records, sys, cg, p_records,
                                                   begin, end, h, sums);
    return linearise_start_terms<Damped, false>(g, records, dv_records, sys, cg, p_records, begin,
                                                end, h, sums);
  }
  template <SpringDamping Damped, bool Single>
  void linearise_start_terms(const NodeGatherLayout<Real, W>& g, const Real* records,
                             const Real* dv_records, ImplicitCoefficients<Real>& sys,
                             const CgVectors<Real>& cg, Real* p_records, int begin, int end, Real h,
                             double (&sums)[3]) const {
#if MSFEM_HAVE_X86_DISPATCH
    if constexpr (W * sizeof(Real) == 64) {
      return linearise_start_chunks_avx512<Avx512<Real>, Damped, Single>(
          g, records, dv_records, sys, cg, p_records, begin, end, h, sums);
    } else if constexpr (W == 32 / sizeof(Real)) {
      if (avx2_)
        return linearise_start_chunks_avx2<Avx2<Real>, Damped, Single>(
            g, records, dv_records, sys, cg, p_records, begin, end, h, sums);
    }
#endif
    return linearise_start_chunks_portable<PortableLanes<Real, W>, Damped, Single>(
        g, records, dv_records, sys, cg, p_records, begin, end, h, sums);
  }
  template <bool Single>
  double product_for(const NodeGatherLayout<Real, W>& g, const ImplicitCoefficients<Real>& sys,
                     const Real* p_records, Real* const (&p)[3], Real* const (&y)[3], int begin,
                     int end) const {
#if MSFEM_HAVE_X86_DISPATCH
    if constexpr (W * sizeof(Real) == 64) {
      return product_chunks_avx512<Avx512<Real>, Single>(g, sys, p_records, p, y, begin, end);
    } else if constexpr (W == 32 / sizeof(Real)) {
      if (avx2_)
        return product_chunks_avx2<Avx2<Real>, Single>(g, sys, p_records, p, y, begin, end);
    }
#endif
    return product_chunks_portable<PortableLanes<Real, W>, Single>(g, sys, p_records, p, y, begin,
                                                                   end);
  }

  bool avx2_;
};

#undef MSFEM_DISPATCH

}  // namespace msfem::massspring::detail
