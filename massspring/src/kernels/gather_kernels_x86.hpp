#pragma once

// x86 vector operations for the node-centric kernels (internal; see gather_kernels.hpp): AVX2
// float (8 lanes), AVX2 double (4), AVX-512 double (8) and AVX-512 float (16). Each set carries its
// own target attribute, so the library needs no -march flag and the steppers pick one at run time.
//
// Neighbour records are not gathered element by element: a record (x y z vx | vy vz pad pad) is one
// or two vector loads, and a register transpose turns W records into six W-lane vectors. On the
// machine we measured this is about twice as fast as six hardware gathers.

#include <immintrin.h>

#include "node_gather_layout.hpp"

#define MSFEM_TARGET_AVX2 __attribute__((target("avx2,fma")))
#define MSFEM_TARGET_AVX512 __attribute__((target("avx512f,avx512vl,avx2,fma")))

namespace msfem::massspring::detail {

struct Avx2Float {
  using Real = float;
  using V = __m256;
  static constexpr int W = 8;
  MSFEM_TARGET_AVX2 static MSFEM_INLINE V load(const float* p) { return _mm256_loadu_ps(p); }
  MSFEM_TARGET_AVX2 static MSFEM_INLINE void store(float* p, V a) { _mm256_storeu_ps(p, a); }
  MSFEM_TARGET_AVX2 static MSFEM_INLINE V max(V a, V b) { return _mm256_max_ps(a, b); }
  MSFEM_TARGET_AVX2 static MSFEM_INLINE V sqrt(V a) { return _mm256_sqrt_ps(a); }
  MSFEM_TARGET_AVX2 static MSFEM_INLINE V sqrt_to_float(V a) { return sqrt(a); }
  MSFEM_TARGET_AVX2 static MSFEM_INLINE V div(V a, V b) { return _mm256_div_ps(a, b); }
  // b where a > 0, else 0
  MSFEM_TARGET_AVX2 static MSFEM_INLINE V where_positive(V a, V b) {
    return _mm256_and_ps(_mm256_cmp_ps(a, _mm256_setzero_ps(), _CMP_GT_OQ), b);
  }
  MSFEM_TARGET_AVX2 static MSFEM_INLINE V set1(float a) { return _mm256_set1_ps(a); }
  MSFEM_TARGET_AVX2 static MSFEM_INLINE V add(V a, V b) { return _mm256_add_ps(a, b); }
  MSFEM_TARGET_AVX2 static MSFEM_INLINE V sub(V a, V b) { return _mm256_sub_ps(a, b); }
  MSFEM_TARGET_AVX2 static MSFEM_INLINE V mul(V a, V b) { return _mm256_mul_ps(a, b); }
  MSFEM_TARGET_AVX2 static MSFEM_INLINE V fmadd(V a, V b, V c) { return _mm256_fmadd_ps(a, b, c); }
  MSFEM_TARGET_AVX2 static MSFEM_INLINE V fnmadd(V a, V b, V c) {
    return _mm256_fnmadd_ps(a, b, c);
  }
  // Hardware estimate and one Newton step: relative error ~1e-7, float's own.
  MSFEM_TARGET_AVX2 static MSFEM_INLINE V inverse_sqrt(V a) {
    const V y = _mm256_rsqrt_ps(a);
    const V half_ay = mul(mul(set1(0.5f), a), y);
    return mul(y, fnmadd(half_ay, y, set1(1.5f)));
  }
  MSFEM_TARGET_AVX2 static MSFEM_INLINE double sum(V a) {
    alignas(32) float lanes[W];
    _mm256_store_ps(lanes, a);
    double total = 0.0;
    for (float value : lanes)
      total += value;
    return total;
  }

  // Record l in the low 128-bit half, record l + 4 in the high half; 4x4 transposes per half.
  template <bool WithVelocity, int Stride = kRecord>
  MSFEM_TARGET_AVX2 static MSFEM_INLINE void load_records(const float* base, const int* index,
                                                          V (&out)[6]) {
    V r[4];
    for (int l = 0; l < 4; ++l)
      r[l] = _mm256_insertf128_ps(
          _mm256_castps128_ps256(_mm_load_ps(record_at<Stride>(base, index[l]))),
          _mm_load_ps(record_at<Stride>(base, index[l + 4])), 1);
    const V t0 = _mm256_unpacklo_ps(r[0], r[1]), t1 = _mm256_unpackhi_ps(r[0], r[1]);
    const V t2 = _mm256_unpacklo_ps(r[2], r[3]), t3 = _mm256_unpackhi_ps(r[2], r[3]);
    out[0] = _mm256_shuffle_ps(t0, t2, 0x44);
    out[1] = _mm256_shuffle_ps(t0, t2, 0xEE);
    out[2] = _mm256_shuffle_ps(t1, t3, 0x44);
    if constexpr (WithVelocity) {
      out[3] = _mm256_shuffle_ps(t1, t3, 0xEE);
      V s[4];
      for (int l = 0; l < 4; ++l)
        s[l] =
            _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_load_ps(record_at(base, index[l]) + 4)),
                                 _mm_load_ps(record_at(base, index[l + 4]) + 4), 1);
      const V u0 = _mm256_unpacklo_ps(s[0], s[1]), u2 = _mm256_unpacklo_ps(s[2], s[3]);
      out[4] = _mm256_shuffle_ps(u0, u2, 0x44);
      out[5] = _mm256_shuffle_ps(u0, u2, 0xEE);
    }
  }
  MSFEM_TARGET_AVX2 static MSFEM_INLINE void store_records(float* base, const int* index,
                                                           const V (&in)[6]) {
    const V zero = _mm256_setzero_ps();
    const V t0 = _mm256_unpacklo_ps(in[0], in[1]), t1 = _mm256_unpackhi_ps(in[0], in[1]);
    const V t2 = _mm256_unpacklo_ps(in[2], in[3]), t3 = _mm256_unpackhi_ps(in[2], in[3]);
    const V u0 = _mm256_unpacklo_ps(in[4], in[5]), u1 = _mm256_unpackhi_ps(in[4], in[5]);
    const V r[4] = {_mm256_shuffle_ps(t0, t2, 0x44), _mm256_shuffle_ps(t0, t2, 0xEE),
                    _mm256_shuffle_ps(t1, t3, 0x44), _mm256_shuffle_ps(t1, t3, 0xEE)};
    const V q[4] = {_mm256_shuffle_ps(u0, zero, 0x44), _mm256_shuffle_ps(u0, zero, 0xEE),
                    _mm256_shuffle_ps(u1, zero, 0x44), _mm256_shuffle_ps(u1, zero, 0xEE)};
    for (int l = 0; l < 4; ++l) {
      _mm256_store_ps(record_at(base, index[l]), _mm256_permute2f128_ps(r[l], q[l], 0x20));
      _mm256_store_ps(record_at(base, index[l + 4]), _mm256_permute2f128_ps(r[l], q[l], 0x31));
    }
  }
  // x y z of eight lanes into records of kDirection floats (x y z 0).
  MSFEM_TARGET_AVX2 static MSFEM_INLINE void store_directions(float* base, const int* index,
                                                              const V (&in)[3]) {
    const V zero = _mm256_setzero_ps();
    const V t0 = _mm256_unpacklo_ps(in[0], in[1]), t1 = _mm256_unpackhi_ps(in[0], in[1]);
    const V t2 = _mm256_unpacklo_ps(in[2], zero), t3 = _mm256_unpackhi_ps(in[2], zero);
    const V r[4] = {_mm256_shuffle_ps(t0, t2, 0x44), _mm256_shuffle_ps(t0, t2, 0xEE),
                    _mm256_shuffle_ps(t1, t3, 0x44), _mm256_shuffle_ps(t1, t3, 0xEE)};
    for (int l = 0; l < 4; ++l) {
      _mm_store_ps(record_at<kDirection>(base, index[l]), _mm256_castps256_ps128(r[l]));
      _mm_store_ps(record_at<kDirection>(base, index[l + 4]), _mm256_extractf128_ps(r[l], 1));
    }
  }
};

struct Avx2Double {
  using Real = double;
  using V = __m256d;
  static constexpr int W = 4;
  MSFEM_TARGET_AVX2 static MSFEM_INLINE V load(const double* p) { return _mm256_loadu_pd(p); }
  MSFEM_TARGET_AVX2 static MSFEM_INLINE void store(double* p, V a) { _mm256_storeu_pd(p, a); }
  // A double solve's float coefficients.
  MSFEM_TARGET_AVX2 static MSFEM_INLINE V load(const float* p) {
    return _mm256_cvtps_pd(_mm_loadu_ps(p));
  }
  MSFEM_TARGET_AVX2 static MSFEM_INLINE void store(float* p, V a) {
    _mm_storeu_ps(p, _mm256_cvtpd_ps(a));
  }
  MSFEM_TARGET_AVX2 static MSFEM_INLINE V max(V a, V b) { return _mm256_max_pd(a, b); }
  MSFEM_TARGET_AVX2 static MSFEM_INLINE V sqrt(V a) { return _mm256_sqrt_pd(a); }
  MSFEM_TARGET_AVX2 static MSFEM_INLINE V sqrt_to_float(V a) { return sqrt(a); }
  MSFEM_TARGET_AVX2 static MSFEM_INLINE V div(V a, V b) { return _mm256_div_pd(a, b); }
  MSFEM_TARGET_AVX2 static MSFEM_INLINE V where_positive(V a, V b) {
    return _mm256_and_pd(_mm256_cmp_pd(a, _mm256_setzero_pd(), _CMP_GT_OQ), b);
  }
  MSFEM_TARGET_AVX2 static MSFEM_INLINE V set1(double a) { return _mm256_set1_pd(a); }
  MSFEM_TARGET_AVX2 static MSFEM_INLINE V add(V a, V b) { return _mm256_add_pd(a, b); }
  MSFEM_TARGET_AVX2 static MSFEM_INLINE V sub(V a, V b) { return _mm256_sub_pd(a, b); }
  MSFEM_TARGET_AVX2 static MSFEM_INLINE V mul(V a, V b) { return _mm256_mul_pd(a, b); }
  MSFEM_TARGET_AVX2 static MSFEM_INLINE V fmadd(V a, V b, V c) { return _mm256_fmadd_pd(a, b, c); }
  MSFEM_TARGET_AVX2 static MSFEM_INLINE V fnmadd(V a, V b, V c) {
    return _mm256_fnmadd_pd(a, b, c);
  }
  // Exact: a CPU with AVX-512 steps double on Avx512Double's eight lanes, which refines the
  // hardware's estimate instead.
  MSFEM_TARGET_AVX2 static MSFEM_INLINE V inverse_sqrt(V a) {
    return _mm256_div_pd(set1(1.0), _mm256_sqrt_pd(a));
  }
  MSFEM_TARGET_AVX2 static MSFEM_INLINE double sum(V a) {
    alignas(32) double lanes[W];
    _mm256_store_pd(lanes, a);
    return lanes[0] + lanes[1] + lanes[2] + lanes[3];
  }

  // One 64-byte record per node: (x y z vx) is one load, (vy vz) half of one.
  template <bool WithVelocity, int Stride = kRecord>
  MSFEM_TARGET_AVX2 static MSFEM_INLINE void load_records(const double* base, const int* index,
                                                          V (&out)[6]) {
    V r[4];
    for (int l = 0; l < 4; ++l)
      r[l] = _mm256_load_pd(record_at<Stride>(base, index[l]));
    const V t0 = _mm256_unpacklo_pd(r[0], r[1]), t1 = _mm256_unpackhi_pd(r[0], r[1]);
    const V t2 = _mm256_unpacklo_pd(r[2], r[3]), t3 = _mm256_unpackhi_pd(r[2], r[3]);
    out[0] = _mm256_permute2f128_pd(t0, t2, 0x20);
    out[1] = _mm256_permute2f128_pd(t1, t3, 0x20);
    out[2] = _mm256_permute2f128_pd(t0, t2, 0x31);
    if constexpr (WithVelocity) {
      out[3] = _mm256_permute2f128_pd(t1, t3, 0x31);
      const V a =
          _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_load_pd(record_at(base, index[0]) + 4)),
                               _mm_load_pd(record_at(base, index[2]) + 4), 1);
      const V b =
          _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_load_pd(record_at(base, index[1]) + 4)),
                               _mm_load_pd(record_at(base, index[3]) + 4), 1);
      out[4] = _mm256_unpacklo_pd(a, b);
      out[5] = _mm256_unpackhi_pd(a, b);
    }
  }
  MSFEM_TARGET_AVX2 static MSFEM_INLINE void store_records(double* base, const int* index,
                                                           const V (&in)[6]) {
    const V t0 = _mm256_unpacklo_pd(in[0], in[1]), t1 = _mm256_unpackhi_pd(in[0], in[1]);
    const V t2 = _mm256_unpacklo_pd(in[2], in[3]), t3 = _mm256_unpackhi_pd(in[2], in[3]);
    const V u0 = _mm256_unpacklo_pd(in[4], in[5]), u1 = _mm256_unpackhi_pd(in[4], in[5]);
    _mm256_store_pd(record_at(base, index[0]), _mm256_permute2f128_pd(t0, t2, 0x20));
    _mm256_store_pd(record_at(base, index[1]), _mm256_permute2f128_pd(t1, t3, 0x20));
    _mm256_store_pd(record_at(base, index[2]), _mm256_permute2f128_pd(t0, t2, 0x31));
    _mm256_store_pd(record_at(base, index[3]), _mm256_permute2f128_pd(t1, t3, 0x31));
    _mm_store_pd(record_at(base, index[0]) + 4, _mm256_castpd256_pd128(u0));
    _mm_store_pd(record_at(base, index[1]) + 4, _mm256_castpd256_pd128(u1));
    _mm_store_pd(record_at(base, index[2]) + 4, _mm256_extractf128_pd(u0, 1));
    _mm_store_pd(record_at(base, index[3]) + 4, _mm256_extractf128_pd(u1, 1));
  }
  MSFEM_TARGET_AVX2 static MSFEM_INLINE void store_directions(double* base, const int* index,
                                                              const V (&in)[3]) {
    const V zero = _mm256_setzero_pd();
    const V t0 = _mm256_unpacklo_pd(in[0], in[1]), t1 = _mm256_unpackhi_pd(in[0], in[1]);
    const V t2 = _mm256_unpacklo_pd(in[2], zero), t3 = _mm256_unpackhi_pd(in[2], zero);
    _mm256_store_pd(record_at<kDirection>(base, index[0]), _mm256_permute2f128_pd(t0, t2, 0x20));
    _mm256_store_pd(record_at<kDirection>(base, index[1]), _mm256_permute2f128_pd(t1, t3, 0x20));
    _mm256_store_pd(record_at<kDirection>(base, index[2]), _mm256_permute2f128_pd(t0, t2, 0x31));
    _mm256_store_pd(record_at<kDirection>(base, index[3]), _mm256_permute2f128_pd(t1, t3, 0x31));
  }
};

// Double on AVX-512's eight 64-bit lanes: records l and l + 4 in the two 256-bit halves of a
// vector, 4x4 transposes per half. 1/√ comes from the hardware's 14-bit estimate and two Newton
// steps (relative error ~2^-14, ~1e-8, then a few ulp) instead of a square root and a division,
// and √ from it: those two share one unit, where the estimate and six multiplies run on the FMA
// pipes beside the rest of the spring's arithmetic (4-5 % on a step, docs/design-notes.md). A few
// ulp from the exact 1/√ is far below what the fast steppers are tested to (1e-9 of the generic
// integrators' trajectories).
struct Avx512Double {
  using Real = double;
  using V = __m512d;
  static constexpr int W = 8;
  MSFEM_TARGET_AVX512 static MSFEM_INLINE V load(const double* p) { return _mm512_loadu_pd(p); }
  MSFEM_TARGET_AVX512 static MSFEM_INLINE void store(double* p, V a) { _mm512_storeu_pd(p, a); }
  MSFEM_TARGET_AVX512 static MSFEM_INLINE V load(const float* p) {
    return _mm512_cvtps_pd(_mm256_loadu_ps(p));
  }
  MSFEM_TARGET_AVX512 static MSFEM_INLINE void store(float* p, V a) {
    _mm256_storeu_ps(p, _mm512_cvtpd_ps(a));
  }
  MSFEM_TARGET_AVX512 static MSFEM_INLINE V max(V a, V b) { return _mm512_max_pd(a, b); }
  MSFEM_TARGET_AVX512 static MSFEM_INLINE V div(V a, V b) { return _mm512_div_pd(a, b); }
  MSFEM_TARGET_AVX512 static MSFEM_INLINE V where_positive(V a, V b) {
    return _mm512_maskz_mov_pd(_mm512_cmp_pd_mask(a, _mm512_setzero_pd(), _CMP_GT_OQ), b);
  }
  MSFEM_TARGET_AVX512 static MSFEM_INLINE V set1(double a) { return _mm512_set1_pd(a); }
  MSFEM_TARGET_AVX512 static MSFEM_INLINE V add(V a, V b) { return _mm512_add_pd(a, b); }
  MSFEM_TARGET_AVX512 static MSFEM_INLINE V sub(V a, V b) { return _mm512_sub_pd(a, b); }
  MSFEM_TARGET_AVX512 static MSFEM_INLINE V mul(V a, V b) { return _mm512_mul_pd(a, b); }
  MSFEM_TARGET_AVX512 static MSFEM_INLINE V fmadd(V a, V b, V c) {
    return _mm512_fmadd_pd(a, b, c);
  }
  MSFEM_TARGET_AVX512 static MSFEM_INLINE V fnmadd(V a, V b, V c) {
    return _mm512_fnmadd_pd(a, b, c);
  }
  MSFEM_TARGET_AVX512 static MSFEM_INLINE V inverse_sqrt(V a) {
    const V half_a = mul(set1(0.5), a);
    V y = _mm512_rsqrt14_pd(a);
    y = mul(y, fnmadd(mul(half_a, y), y, set1(1.5)));
    return mul(y, fnmadd(mul(half_a, y), y, set1(1.5)));
  }
  // √a as a/√a, for the same reason; 0 where a ≤ 0 (the kernels take √ of sums of non-negative
  // terms, zero in padding slots, where the estimate's 0·∞ would be NaN).
  MSFEM_TARGET_AVX512 static MSFEM_INLINE V sqrt(V a) {
    return where_positive(a, mul(a, inverse_sqrt(a)));
  }
  // √a for a value stored in float: one Newton step (~1e-8 relative, below float's 6e-8 rounding)
  // shortens the linearising pass's longest dependency chain by a multiply and a multiply-add.
  MSFEM_TARGET_AVX512 static MSFEM_INLINE V sqrt_to_float(V a) {
    const V y = _mm512_rsqrt14_pd(a);
    const V root = mul(a, y);  // √a to 2^-14, refined: √a (3 - a y²) / 2
    return where_positive(a, mul(mul(set1(0.5), root), fnmadd(root, y, set1(3.0))));
  }
  MSFEM_TARGET_AVX512 static MSFEM_INLINE double sum(V a) {
    alignas(64) double lanes[W];
    _mm512_store_pd(lanes, a);
    double total = 0.0;
    for (double value : lanes)
      total += value;
    return total;
  }

  template <int Stride>
  MSFEM_TARGET_AVX512 static MSFEM_INLINE V halves(const double* base, const int* index, int l,
                                                   int offset) {
    const V r = _mm512_castpd256_pd512(_mm256_load_pd(record_at<Stride>(base, index[l]) + offset));
    return _mm512_insertf64x4(r, _mm256_load_pd(record_at<Stride>(base, index[l + 4]) + offset), 1);
  }
  // Pairs of lanes from two vectors: (0 1 from the second's 0 1) per half, and the same for 2 3.
  MSFEM_TARGET_AVX512 static MSFEM_INLINE __m512i first_pairs() {
    return _mm512_set_epi64(13, 12, 5, 4, 9, 8, 1, 0);
  }
  MSFEM_TARGET_AVX512 static MSFEM_INLINE __m512i second_pairs() {
    return _mm512_set_epi64(15, 14, 7, 6, 11, 10, 3, 2);
  }
  // Four vectors of (a b c d) records, lanes l and l + 4 in each: a, b, c and d as 8-lane vectors.
  MSFEM_TARGET_AVX512 static MSFEM_INLINE void transpose(const V (&r)[4], V (&out)[4]) {
    const V t0 = _mm512_unpacklo_pd(r[0], r[1]), t1 = _mm512_unpackhi_pd(r[0], r[1]);
    const V t2 = _mm512_unpacklo_pd(r[2], r[3]), t3 = _mm512_unpackhi_pd(r[2], r[3]);
    // t0 = a0 a1 c0 c1 | a4 a5 c4 c5, t2 = a2 a3 c2 c3 | a6 a7 c6 c7
    out[0] = _mm512_permutex2var_pd(t0, first_pairs(), t2);
    out[1] = _mm512_permutex2var_pd(t1, first_pairs(), t3);
    out[2] = _mm512_permutex2var_pd(t0, second_pairs(), t2);
    out[3] = _mm512_permutex2var_pd(t1, second_pairs(), t3);
  }
  template <bool WithVelocity, int Stride = kRecord>
  MSFEM_TARGET_AVX512 static MSFEM_INLINE void load_records(const double* base, const int* index,
                                                            V (&out)[6]) {
    V r[4], t[4];
    for (int l = 0; l < 4; ++l)
      r[l] = halves<Stride>(base, index, l, 0);
    transpose(r, t);
    out[0] = t[0];
    out[1] = t[1];
    out[2] = t[2];
    if constexpr (WithVelocity) {
      out[3] = t[3];
      for (int l = 0; l < 4; ++l)
        r[l] = halves<Stride>(base, index, l, 4);
      transpose(r, t);
      out[4] = t[0];
      out[5] = t[1];
    }
  }
  // (GCC 12 warns that the plain extract's unused merge source is uninitialised.)
  MSFEM_TARGET_AVX512 static MSFEM_INLINE __m256d upper_half(V a) {
    return _mm512_maskz_extractf64x4_pd(0xF, a, 1);
  }
  // The inverse of transpose: a, b, c, d as 8-lane vectors to (a b c d) records l and l + 4 in
  // the halves of out[l].
  MSFEM_TARGET_AVX512 static MSFEM_INLINE void untranspose(V a, V b, V c, V d, V (&out)[4]) {
    const V t0 = _mm512_permutex2var_pd(a, first_pairs(), c),
            t2 = _mm512_permutex2var_pd(a, second_pairs(), c);
    const V t1 = _mm512_permutex2var_pd(b, first_pairs(), d),
            t3 = _mm512_permutex2var_pd(b, second_pairs(), d);
    out[0] = _mm512_unpacklo_pd(t0, t1);
    out[1] = _mm512_unpackhi_pd(t0, t1);
    out[2] = _mm512_unpacklo_pd(t2, t3);
    out[3] = _mm512_unpackhi_pd(t2, t3);
  }
  MSFEM_TARGET_AVX512 static MSFEM_INLINE void store_records(double* base, const int* index,
                                                             const V (&in)[6]) {
    const V zero = _mm512_setzero_pd();
    V r[4], q[4];
    untranspose(in[0], in[1], in[2], in[3], r);
    untranspose(in[4], in[5], zero, zero, q);
    for (int l = 0; l < 4; ++l) {
      _mm256_store_pd(record_at(base, index[l]), _mm512_castpd512_pd256(r[l]));
      _mm256_store_pd(record_at(base, index[l + 4]), upper_half(r[l]));
      _mm_store_pd(record_at(base, index[l]) + 4, _mm512_castpd512_pd128(q[l]));
      _mm_store_pd(record_at(base, index[l + 4]) + 4, _mm256_castpd256_pd128(upper_half(q[l])));
    }
  }
  MSFEM_TARGET_AVX512 static MSFEM_INLINE void store_directions(double* base, const int* index,
                                                                const V (&in)[3]) {
    V r[4];
    untranspose(in[0], in[1], in[2], _mm512_setzero_pd(), r);
    for (int l = 0; l < 4; ++l) {
      _mm256_store_pd(record_at<kDirection>(base, index[l]), _mm512_castpd512_pd256(r[l]));
      _mm256_store_pd(record_at<kDirection>(base, index[l + 4]), upper_half(r[l]));
    }
  }
};

struct Avx512Float {
  using Real = float;
  using V = __m512;
  static constexpr int W = 16;
  MSFEM_TARGET_AVX512 static MSFEM_INLINE V load(const float* p) { return _mm512_loadu_ps(p); }
  MSFEM_TARGET_AVX512 static MSFEM_INLINE void store(float* p, V a) { _mm512_storeu_ps(p, a); }
  MSFEM_TARGET_AVX512 static MSFEM_INLINE V max(V a, V b) { return _mm512_max_ps(a, b); }
  MSFEM_TARGET_AVX512 static MSFEM_INLINE V sqrt(V a) { return _mm512_sqrt_ps(a); }
  MSFEM_TARGET_AVX512 static MSFEM_INLINE V sqrt_to_float(V a) { return sqrt(a); }
  MSFEM_TARGET_AVX512 static MSFEM_INLINE V div(V a, V b) { return _mm512_div_ps(a, b); }
  MSFEM_TARGET_AVX512 static MSFEM_INLINE V where_positive(V a, V b) {
    return _mm512_maskz_mov_ps(_mm512_cmp_ps_mask(a, _mm512_setzero_ps(), _CMP_GT_OQ), b);
  }
  MSFEM_TARGET_AVX512 static MSFEM_INLINE V set1(float a) { return _mm512_set1_ps(a); }
  MSFEM_TARGET_AVX512 static MSFEM_INLINE V add(V a, V b) { return _mm512_add_ps(a, b); }
  MSFEM_TARGET_AVX512 static MSFEM_INLINE V sub(V a, V b) { return _mm512_sub_ps(a, b); }
  MSFEM_TARGET_AVX512 static MSFEM_INLINE V mul(V a, V b) { return _mm512_mul_ps(a, b); }
  MSFEM_TARGET_AVX512 static MSFEM_INLINE V fmadd(V a, V b, V c) {
    return _mm512_fmadd_ps(a, b, c);
  }
  MSFEM_TARGET_AVX512 static MSFEM_INLINE V fnmadd(V a, V b, V c) {
    return _mm512_fnmadd_ps(a, b, c);
  }
  // rsqrt14 and one Newton step: ~1e-8 relative before rounding.
  MSFEM_TARGET_AVX512 static MSFEM_INLINE V inverse_sqrt(V a) {
    const V y = _mm512_rsqrt14_ps(a);
    const V half_ay = mul(mul(set1(0.5f), a), y);
    return mul(y, fnmadd(half_ay, y, set1(1.5f)));
  }
  MSFEM_TARGET_AVX512 static MSFEM_INLINE double sum(V a) {
    alignas(64) float lanes[W];
    _mm512_store_ps(lanes, a);
    double total = 0.0;
    for (float value : lanes)
      total += value;
    return total;
  }

  // Records l, l + 4, l + 8, l + 12 in the four 128-bit quarters; 4x4 transposes per quarter.
  MSFEM_TARGET_AVX512 static MSFEM_INLINE __m256 upper_half(V a) {
    return _mm256_castpd_ps(_mm512_extractf64x4_pd(_mm512_castps_pd(a), 1));
  }
  template <int Stride>
  MSFEM_TARGET_AVX512 static MSFEM_INLINE V quarters(const float* base, const int* index, int l,
                                                     int offset) {
    V r = _mm512_castps128_ps512(_mm_load_ps(record_at<Stride>(base, index[l]) + offset));
    r = _mm512_insertf32x4(r, _mm_load_ps(record_at<Stride>(base, index[l + 4]) + offset), 1);
    r = _mm512_insertf32x4(r, _mm_load_ps(record_at<Stride>(base, index[l + 8]) + offset), 2);
    return _mm512_insertf32x4(r, _mm_load_ps(record_at<Stride>(base, index[l + 12]) + offset), 3);
  }
  template <bool WithVelocity, int Stride = kRecord>
  MSFEM_TARGET_AVX512 static MSFEM_INLINE void load_records(const float* base, const int* index,
                                                            V (&out)[6]) {
    V r[4];
    for (int l = 0; l < 4; ++l)
      r[l] = quarters<Stride>(base, index, l, 0);
    const V t0 = _mm512_unpacklo_ps(r[0], r[1]), t1 = _mm512_unpackhi_ps(r[0], r[1]);
    const V t2 = _mm512_unpacklo_ps(r[2], r[3]), t3 = _mm512_unpackhi_ps(r[2], r[3]);
    out[0] = _mm512_shuffle_ps(t0, t2, 0x44);
    out[1] = _mm512_shuffle_ps(t0, t2, 0xEE);
    out[2] = _mm512_shuffle_ps(t1, t3, 0x44);
    if constexpr (WithVelocity) {
      out[3] = _mm512_shuffle_ps(t1, t3, 0xEE);
      V s[4];
      for (int l = 0; l < 4; ++l)
        s[l] = quarters<Stride>(base, index, l, 4);
      const V u0 = _mm512_unpacklo_ps(s[0], s[1]), u2 = _mm512_unpacklo_ps(s[2], s[3]);
      out[4] = _mm512_shuffle_ps(u0, u2, 0x44);
      out[5] = _mm512_shuffle_ps(u0, u2, 0xEE);
    }
  }
  MSFEM_TARGET_AVX512 static MSFEM_INLINE void store_records(float* base, const int* index,
                                                             const V (&in)[6]) {
    const V zero = _mm512_setzero_ps();
    const V t0 = _mm512_unpacklo_ps(in[0], in[1]), t1 = _mm512_unpackhi_ps(in[0], in[1]);
    const V t2 = _mm512_unpacklo_ps(in[2], in[3]), t3 = _mm512_unpackhi_ps(in[2], in[3]);
    const V u0 = _mm512_unpacklo_ps(in[4], in[5]), u1 = _mm512_unpackhi_ps(in[4], in[5]);
    const V r[4] = {_mm512_shuffle_ps(t0, t2, 0x44), _mm512_shuffle_ps(t0, t2, 0xEE),
                    _mm512_shuffle_ps(t1, t3, 0x44), _mm512_shuffle_ps(t1, t3, 0xEE)};
    const V q[4] = {_mm512_shuffle_ps(u0, zero, 0x44), _mm512_shuffle_ps(u0, zero, 0xEE),
                    _mm512_shuffle_ps(u1, zero, 0x44), _mm512_shuffle_ps(u1, zero, 0xEE)};
    // Quarters k of r[l] and q[l] make record l + 4k: pair them up, one 32-byte store per record.
    for (int l = 0; l < 4; ++l) {
      const V low = _mm512_shuffle_f32x4(r[l], q[l], 0x44);   // r0 r1 q0 q1
      const V high = _mm512_shuffle_f32x4(r[l], q[l], 0xEE);  // r2 r3 q2 q3
      const V a = _mm512_shuffle_f32x4(low, low, 0xD8);       // r0 q0 r1 q1
      const V b = _mm512_shuffle_f32x4(high, high, 0xD8);     // r2 q2 r3 q3
      _mm256_store_ps(record_at(base, index[l]), _mm512_castps512_ps256(a));
      _mm256_store_ps(record_at(base, index[l + 4]), upper_half(a));
      _mm256_store_ps(record_at(base, index[l + 8]), _mm512_castps512_ps256(b));
      _mm256_store_ps(record_at(base, index[l + 12]), upper_half(b));
    }
  }
  MSFEM_TARGET_AVX512 static MSFEM_INLINE void store_directions(float* base, const int* index,
                                                                const V (&in)[3]) {
    const V zero = _mm512_setzero_ps();
    const V t0 = _mm512_unpacklo_ps(in[0], in[1]), t1 = _mm512_unpackhi_ps(in[0], in[1]);
    const V t2 = _mm512_unpacklo_ps(in[2], zero), t3 = _mm512_unpackhi_ps(in[2], zero);
    const V r[4] = {_mm512_shuffle_ps(t0, t2, 0x44), _mm512_shuffle_ps(t0, t2, 0xEE),
                    _mm512_shuffle_ps(t1, t3, 0x44), _mm512_shuffle_ps(t1, t3, 0xEE)};
    for (int l = 0; l < 4; ++l) {
      _mm_store_ps(record_at<kDirection>(base, index[l]), _mm512_castps512_ps128(r[l]));
      _mm_store_ps(record_at<kDirection>(base, index[l + 4]), _mm512_extractf32x4_ps(r[l], 1));
      _mm_store_ps(record_at<kDirection>(base, index[l + 8]), _mm512_extractf32x4_ps(r[l], 2));
      _mm_store_ps(record_at<kDirection>(base, index[l + 12]), _mm512_extractf32x4_ps(r[l], 3));
    }
  }
};

}  // namespace msfem::massspring::detail
