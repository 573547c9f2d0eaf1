#include "volume_rows.hpp"

#include <cstring>

#include "volume_batches.hpp"

namespace msfem::massspring::detail {

// Written with the compiler's vector types rather than intrinsics: one source for every target,
// four lanes of AVX2 in the x86-64-v3 clone and in the x86-64-v4 one (chosen at load time; the
// library is built without -march), pairs of SSE2 lanes otherwise. The v4 clone keeps the same
// four lanes but has AVX-512's 32 vector registers, where the start's sums no longer spill: its
// row sums took 10 % less of the brain's step start, measured against the linearising pass in
// one profile each. The clones may round differently (the first two contract to fused
// multiply-adds), but a process runs one of them on every thread.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && \
    !defined(__SANITIZE_ADDRESS__)
#define MSFEM_ROW_CLONES \
  __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#else
#define MSFEM_ROW_CLONES
#endif

namespace {

// The helpers are inlined into the cloned kernels: no call passes a vector across the ABI
// boundary the warning is about.
#pragma GCC diagnostic ignored "-Wpsabi"
using Double4 = double __attribute__((vector_size(32)));

inline Double4 load4(const double* p) {
  Double4 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline void store4(double* p, const Double4& v) {
  std::memcpy(p, &v, sizeof v);
}
inline Double4 broadcast(double a) {
  return Double4{a, a, a, a};
}

// Four records' x, y and z as three vectors of the four lanes.
inline void transpose(const Double4 (&r)[4], Double4 (&xyz)[3]) {
  const Double4 t0 = __builtin_shufflevector(r[0], r[1], 0, 4, 2, 6);  // x0 x1 z0 z1
  const Double4 t1 = __builtin_shufflevector(r[0], r[1], 1, 5, 3, 7);  // y0 y1 . .
  const Double4 t2 = __builtin_shufflevector(r[2], r[3], 0, 4, 2, 6);
  const Double4 t3 = __builtin_shufflevector(r[2], r[3], 1, 5, 3, 7);
  xyz[0] = __builtin_shufflevector(t0, t2, 0, 1, 4, 5);
  xyz[1] = __builtin_shufflevector(t1, t3, 0, 1, 4, 5);
  xyz[2] = __builtin_shufflevector(t0, t2, 2, 3, 6, 7);
}

// Σ_k g_k · x[node k] per lane, for V vectors at once, over the group's lanes in fours.
template <int V>
inline void dot_records(const VolumeBatches& b, int group, const double* g, const int* record,
                        const double* const (&x)[V], Double4 (&sum)[V][kVolumeLanes / 4]) {
  constexpr int L = kVolumeLanes;
  for (auto& per_vector : sum)
    for (Double4& s : per_vector)
      s = broadcast(0.0);
  const int nodes = b.nodes(group);
  const int* at = record + b.group_start[group];
  for (int k = 0; k < nodes; ++k)
    for (int q = 0; q < L / 4; ++q) {
      const double* gk = g + 3 * k * L + 4 * q;
      const Double4 gx = load4(gk), gy = load4(gk + L), gz = load4(gk + 2 * L);
      const int* lanes = at + k * L + 4 * q;
      for (int v = 0; v < V; ++v) {
        const Double4 r[4] = {load4(x[v] + lanes[0]), load4(x[v] + lanes[1]),
                              load4(x[v] + lanes[2]), load4(x[v] + lanes[3])};
        Double4 xyz[3];
        transpose(r, xyz);
        sum[v][q] += gx * xyz[0] + gy * xyz[1] + gz * xyz[2];
      }
    }
}

}  // namespace

MSFEM_ROW_CLONES void add_row_sums(const RowIncidences& rows, const double* s, double* df) {
  const int* __restrict row_start = rows.row_start;
  const int* __restrict lane = rows.lane;
  const double* __restrict g_rows = rows.g_rows;
  for (int r = 0; r < rows.rows; ++r) {
    Double4 f = broadcast(0.0);
    for (int i = row_start[r]; i < row_start[r + 1]; ++i)
      f += broadcast(s[lane[i]]) * load4(g_rows + 4 * static_cast<long>(i));
    double* at = df + 3 * static_cast<long>(rows.row_node[r]);
    at[0] += f[0];
    at[1] += f[1];
    at[2] += f[2];
  }
}

MSFEM_ROW_CLONES void start_row_sums(const RowIncidences& rows, const int* g_at, const double* g,
                                     double* g_rows, const double* s1, const double* s2,
                                     const double* scale, double c, double* out) {
  constexpr int L = kVolumeLanes;
  const int* __restrict row_start = rows.row_start;
  const int* __restrict lane = rows.lane;
  for (int r = 0; r < rows.rows; ++r) {
    Double4 f1 = broadcast(0.0), f2 = f1, diagonal = f1, off = f1;
    for (int i = row_start[r]; i < row_start[r + 1]; ++i) {
      const double* gi = g + g_at[i];
      const Double4 gv = {gi[0], gi[L], gi[2 * L], 0.0};
      store4(g_rows + 4 * static_cast<long>(i), gv);
      const int e = lane[i];
      f1 += broadcast(s1[e]) * gv;
      f2 += broadcast(s2[e]) * gv;
      const Double4 kg = broadcast(c * scale[e]) * gv;
      diagonal += kg * gv;
      off += kg * __builtin_shufflevector(gv, gv, 1, 2, 0, 3);
    }
    double* o = out + 16 * static_cast<long>(r);
    store4(o, f1);
    store4(o + 4, f2);
    store4(o + 8, diagonal);
    store4(o + 12, off);
  }
}

MSFEM_ROW_CLONES void group_dot_records(const VolumeBatches& b, int group, const double* g,
                                        const int* record, const double* x1, const double* factor,
                                        double scale, double* out1) {
  Double4 sum[1][kVolumeLanes / 4];
  dot_records<1>(b, group, g, record, {x1}, sum);
  const Double4 by = broadcast(scale);
  for (int q = 0; q < kVolumeLanes / 4; ++q)
    store4(out1 + 4 * q, by * load4(factor + 4 * q) * sum[0][q]);
}

MSFEM_ROW_CLONES void group_dot_pair_records(const VolumeBatches& b, int group, const double* g,
                                             const int* record, const double* x1, const double* x2,
                                             const double* factor, const double* base1,
                                             double* out1, double* out2) {
  Double4 sum[2][kVolumeLanes / 4];
  dot_records<2>(b, group, g, record, {x1, x2}, sum);
  for (int q = 0; q < kVolumeLanes / 4; ++q) {
    const Double4 f = load4(factor + 4 * q);
    const Double4 base = base1 ? load4(base1 + 4 * q) : broadcast(0.0);
    store4(out1 + 4 * q, base + f * sum[0][q]);
    store4(out2 + 4 * q, f * sum[1][q]);
  }
}

}  // namespace msfem::massspring::detail
