#pragma once

// The volume tangent's row sums (internal to the volume field): a node's row of a product is the
// sum over the elements at the node of the element's factor times its gradient there. Each
// incidence keeps its gradient as a four-double record (gx gy gz 0) in row order, so a row sums
// one vector multiply-add per incidence instead of three scalar chains: in scalar form the
// start's twelve accumulators spilled to the stack, and the loop ran at the latency of a store
// and a reload.

namespace msfem::massspring::detail {

struct VolumeBatches;

/// Incidences in row order: row r holds [row_start[r], row_start[r + 1]); incidence i takes its
/// element's factor from lane[i] and its gradient from the record g_rows[4i .. 4i + 3].
struct RowIncidences {
  int rows = 0;
  const int* row_node = nullptr;  ///< per row: its node
  const int* row_start = nullptr;
  const int* lane = nullptr;
  const double* g_rows = nullptr;
};

/// df[3 node + c] += Σ_i s[lane[i]] g_i[c] over each row's incidences.
void add_row_sums(const RowIncidences& rows, const double* s, double* df);

/// The start of a step by rows. First each incidence's gradient into its record, from the group
/// layout (g[g_at[i]], g[g_at[i] + L], g[g_at[i] + 2L], L = kVolumeLanes). Then per row, 16
/// doubles at out + 16 r: Σ s1 g, Σ s2 g, the diagonal of Σ k g gᵀ and its off-diagonal entries
/// (xy, yz, zx), each padded to four, with k = c·scale[lane].
void start_row_sums(const RowIncidences& rows, const int* g_at, const double* g, double* g_rows,
                    const double* s1, const double* s2, const double* scale, double c, double* out);

/// group_dot (volume_batches.hpp) from vectors in records: x4 at record[k·L + l] (4 × the node
/// record, the group layout of b.offset) for node k of lane l. One vector: out1 = scale factor
/// Σ g·x1.
/// Two: also out2 = factor Σ g·x2, and base1 (where not null) added to out1.
void group_dot_records(const VolumeBatches& b, int group, const double* g, const int* record,
                       const double* x1, const double* factor, double scale, double* out1);
void group_dot_pair_records(const VolumeBatches& b, int group, const double* g, const int* record,
                            const double* x1, const double* x2, const double* factor,
                            const double* base1, double* out1, double* out2);

}  // namespace msfem::massspring::detail
