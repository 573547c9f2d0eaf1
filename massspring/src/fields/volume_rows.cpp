#include "volume_rows.hpp"

#include <cstring>

#include "volume_batches.hpp"

namespace msfem::massspring::detail {

// Written with the compiler's vector types rather than intrinsics: one source for every target,
// four lanes of AVX2 in the x86-64-v3 clone (chosen at load time; the library is built without
// -march), pairs of SSE2 lanes otherwise. The clones may round differently (the first contracts
// to fused multiply-adds), but a process runs one of them on every thread.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && \
    !defined(__SANITIZE_ADDRESS__)
#define MSFEM_ROW_CLONES __attribute__((target_clones("arch=x86-64-v3", "default")))
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
inline void store4(double* p, Double4 v) {
  std::memcpy(p, &v, sizeof v);
}
inline Double4 broadcast(double a) {
  return Double4{a, a, a, a};
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

}  // namespace msfem::massspring::detail
