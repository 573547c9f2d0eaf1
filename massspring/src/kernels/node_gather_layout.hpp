#pragma once

// Node-centric (gather) layout for the explicit stepper (internal), built on SoaLayout's numbering.
// Free nodes go in chunks of W lanes; a chunk holds, slot by slot, one spring of each of its W
// nodes (sliced ELLPACK, "SELL-W-σ"): slot j of lane l is node l's j-th neighbour with that
// spring's k, k l0 and c, stored contiguously so that a vector of W lanes reads them with plain
// loads. Every spring appears twice (once per free end): twice the arithmetic of a spring loop, but
// a node computes its own force from the previous step's positions, so no scatter, no per-thread
// force buffers and one barrier per step.
//
// Chunks are padded to their widest node. Sorting nodes by degree inside windows of kSortWindow
// (reverse Cuthill-McKee order between windows) keeps the padding small and the locality.
//
// Node records are kRecord reals per node: x y z vx vy vz and two pad slots, so that a neighbour is
// one 32-byte (float) or 64-byte (double) line. Two records past the last node: an idle one for
// the empty lanes of the last chunk, at the origin, and a far one that padding slots point to, so
// that a padded slot (k = k l0 = c = 0) never sees a zero-length spring.

#include <algorithm>
#include <cstddef>
#include <new>
#include <numeric>
#include <type_traits>
#include <vector>

#include "soa_layout.hpp"

namespace msfem::massspring::detail {

constexpr int kRecord = 8;
// CG direction records of the implicit stepper: x y z and a pad slot, half a node record, so that
// the direction the products gather from stays in the per-core cache.
constexpr int kDirection = 4;
constexpr int kSortWindow = 64;

// Records are addressed by byte offset (index × record bytes), stored once: a kernel then reads a
// neighbour with one load and one addressing mode instead of a multiply and a sign extension per
// record, which the 16-lane transposes do 16 times per slot vector. Direction records (kDirection)
// are half as long, so their offset is half the node record's.
template <int Stride = kRecord, class T>
inline T* record_at(T* base, int offset) {
  static_assert(Stride == kRecord || 2 * Stride == kRecord);
  const unsigned bytes =
      Stride == kRecord ? static_cast<unsigned>(offset) : static_cast<unsigned>(offset) >> 1;
  using Byte = std::conditional_t<std::is_const_v<T>, const char, char>;
  return reinterpret_cast<T*>(reinterpret_cast<Byte*>(base) + bytes);
}
constexpr int kBlockSlots = 4096;

// Vectors whose data start on a cache line: the kernels' full-width vector loads and stores of
// per-slot and per-lane arrays then never straddle two lines.
template <class T>
struct CacheLineAllocator {
  using value_type = T;
  CacheLineAllocator() = default;
  template <class U>
  CacheLineAllocator(const CacheLineAllocator<U>&) {}
  T* allocate(std::size_t n) {
    return static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t(64)));
  }
  void deallocate(T* p, std::size_t) { ::operator delete(p, std::align_val_t(64)); }
  template <class U>
  bool operator==(const CacheLineAllocator<U>&) const {
    return true;
  }
  template <class U>
  bool operator!=(const CacheLineAllocator<U>&) const {
    return false;
  }
};
template <class T>
using AlignedVector = std::vector<T, CacheLineAllocator<T>>;

enum class SpringDamping { none, uniform, per_spring };

template <class Real, int W>
struct NodeGatherLayout {
  int num_chunks = 0;
  int idle_record = 0, far_record = 0;  // num_nodes, num_nodes + 1
  AlignedVector<int> lane_node;         // chunk * W + lane -> SoA node (idle_record when empty)
  AlignedVector<int> lane_offset;       // the lane's record offset (record_at)
  std::vector<int> chunk_slot, chunk_width;
  AlignedVector<int> neighbour;    // per slot: the neighbour's record offset (record_at)
  std::vector<int> slot_spring;    // per slot; -1: padding
  AlignedVector<Real> k, k_l0, c;  // per slot
  SpringDamping spring_damping = SpringDamping::none;
  Real uniform_c = 0;  // every spring's c when spring_damping == uniform
  AlignedVector<Real> mass, inverse_mass, damping, anchor, load[3];  // per lane (idle: mass 1)
  std::vector<int> block_begin;  // chunk ranges handed out to the threads
  // Relative records (soa_layout.hpp): per slot, the frame's edge X_j - X_i from the lane's node
  // to its neighbour (the idle and far records' frame at the origin), read in slot order beside
  // k and k l0 so that a spring's rest geometry costs three plain loads per W slots instead of a
  // second gather and transpose; empty otherwise.
  AlignedVector<Real> rest_edge[3];

  explicit NodeGatherLayout(const SoaLayout<Real>& soa) {
    idle_record = soa.num_nodes;
    far_record = soa.num_nodes + 1;
    std::vector<int> free(soa.num_free);
    std::iota(free.begin(), free.end(), 0);
    auto degree = [&](int i) { return soa.offset[i + 1] - soa.offset[i]; };
    for (int w = 0; w < soa.num_free; w += kSortWindow)
      std::stable_sort(free.begin() + w, free.begin() + std::min(w + kSortWindow, soa.num_free),
                       [&](int p, int q) { return degree(p) > degree(q); });
    num_chunks = (soa.num_free + W - 1) / W;
    lane_node.assign(static_cast<std::size_t>(num_chunks) * W, idle_record);
    std::copy(free.begin(), free.end(), lane_node.begin());
    chunk_slot.assign(num_chunks + 1, 0);
    chunk_width.assign(num_chunks, 0);
    for (int chunk = 0; chunk < num_chunks; ++chunk) {
      for (int lane = 0; lane < W; ++lane) {
        const int i = lane_node[chunk * W + lane];
        if (i != idle_record) chunk_width[chunk] = std::max(chunk_width[chunk], degree(i));
      }
      chunk_slot[chunk + 1] = chunk_slot[chunk] + chunk_width[chunk] * W;
    }
    neighbour.assign(chunk_slot.back(), record_offset(far_record));
    lane_offset.resize(lane_node.size());
    for (std::size_t lane = 0; lane < lane_node.size(); ++lane)
      lane_offset[lane] = record_offset(lane_node[lane]);
    slot_spring.assign(chunk_slot.back(), -1);
    for (int chunk = 0; chunk < num_chunks; ++chunk)
      for (int lane = 0; lane < W; ++lane) {
        const int i = lane_node[chunk * W + lane];
        if (i == idle_record) continue;
        for (int e = soa.offset[i]; e < soa.offset[i + 1]; ++e) {
          const int slot = chunk_slot[chunk] + (e - soa.offset[i]) * W + lane;
          const int s = soa.incident[e];
          neighbour[slot] = record_offset(soa.a[s] == i ? soa.b[s] : soa.a[s]);
          slot_spring[slot] = s;
        }
      }
    k.assign(chunk_slot.back(), Real(0));
    k_l0.assign(chunk_slot.back(), Real(0));
    c.assign(chunk_slot.back(), Real(0));
    mass.assign(lane_node.size(), Real(1));
    inverse_mass.assign(lane_node.size(), Real(0));
    damping.assign(lane_node.size(), Real(0));
    anchor.assign(lane_node.size(), Real(0));
    for (auto& l : load)
      l.assign(lane_node.size(), Real(0));
    load_parameters(soa);
    partition();
    if (soa.relative) load_rest_edges(soa);
  }

  bool relative() const { return !rest_edge[0].empty(); }

  static int record_offset(int node) { return node * kRecord * static_cast<int>(sizeof(Real)); }

  // Copies the per-spring and per-node constants of the SoA layout into slot and lane order.
  void load_parameters(const SoaLayout<Real>& soa) {
    spring_damping = SpringDamping::none;
    uniform_c = soa.num_springs > 0 ? soa.damping[0] : Real(0);
    for (int s = 0; s < soa.num_springs; ++s)  // uniform: padding told apart by k = 0
      if (soa.damping[s] != uniform_c || !(soa.stiffness[s] > Real(0)))
        spring_damping = SpringDamping::per_spring;
    if (spring_damping == SpringDamping::none && uniform_c != Real(0))
      spring_damping = SpringDamping::uniform;
    else if (spring_damping == SpringDamping::per_spring && !soa.has_spring_damping)
      spring_damping = SpringDamping::none;
    for (std::size_t slot = 0; slot < slot_spring.size(); ++slot) {
      const int s = slot_spring[slot];
      if (s < 0) continue;
      k[slot] = soa.stiffness[s];
      k_l0[slot] = soa.stiffness_rest[s];
      c[slot] = soa.damping[s];
    }
    for (std::size_t lane = 0; lane < lane_node.size(); ++lane) {
      const int i = lane_node[lane];
      if (i == idle_record) continue;
      mass[lane] = soa.mass[i];
      inverse_mass[lane] = soa.inverse_mass[i];
      damping[lane] = soa.node_damping[i];
      anchor[lane] = soa.anchor_stiffness[i];
      for (int d = 0; d < 3; ++d)
        load[d][lane] = soa.load[d][i];
    }
  }

  // The frame is float-representable, so X_j - X_i in double rounds once: the float difference.
  void load_rest_edges(const SoaLayout<Real>& soa) {
    auto frame = [&](int d, int node) {
      return node < soa.num_nodes ? soa.frame_at(d, node) : 0.0;
    };
    for (int d = 0; d < 3; ++d)
      rest_edge[d].assign(chunk_slot.back(), Real(0));
    for (int chunk = 0; chunk < num_chunks; ++chunk)
      for (int lane = 0; lane < W; ++lane) {
        const int i = lane_node[chunk * W + lane];
        for (int slot = chunk_slot[chunk] + lane; slot < chunk_slot[chunk + 1]; slot += W) {
          const int j = neighbour[slot] / record_offset(1);
          for (int d = 0; d < 3; ++d)
            rest_edge[d][slot] = static_cast<Real>(frame(d, j) - frame(d, i));
        }
      }
  }

  // Blocks of consecutive chunks, about kBlockSlots slots each, the units the steppers share out
  // among their threads (see fast_stepper.cpp): small enough that a thread the OS pre-empts holds
  // up the others for one block only, large enough that taking one costs nothing.
  void partition(int block_slots = kBlockSlots) {
    block_begin.assign(1, 0);
    for (int chunk = 0; chunk < num_chunks; ++chunk)
      if (chunk_slot[chunk + 1] - chunk_slot[block_begin.back()] >= block_slots)
        block_begin.push_back(chunk + 1);
    if (block_begin.back() != num_chunks) block_begin.push_back(num_chunks);
  }
  // Smaller blocks on a small model, about 32 a member: with kBlockSlots the seed sphere has five
  // blocks, and two members' shares of a pass could differ by one, a fifth of the work.
  void partition_for(int members) {
    partition(std::clamp(chunk_slot.back() / (32 * members), 256, kBlockSlots));
  }
};

// The linearised backward-Euler system of one step in slot and lane order (fast implicit stepper):
// per slot y += α q + (e·q) e for q = p_j - p_i, stored per group of W slots as W α, then W of each
// component of e (one stream for the product to read); per lane the diagonal term m + h c + h² k_a.
// A double solve may keep the slot terms in float (`single`, in single_terms): every CG product
// streams them, and from the L3 cache that stream bounds the product.
template <class Real>
struct ImplicitCoefficients {
  AlignedVector<Real> slot_terms;     // 4 per slot, unless single
  AlignedVector<float> single_terms;  // 4 per slot where single
  AlignedVector<Real> own;            // per lane
  bool single = false;

  template <bool Single>
  auto* terms() {
    if constexpr (Single)
      return single_terms.data();
    else
      return slot_terms.data();
  }
  template <bool Single>
  const auto* terms() const {
    if constexpr (Single)
      return single_terms.data();
    else
      return slot_terms.data();
  }

  void resize(std::size_t slots, std::size_t lanes, bool single_terms_wanted = false) {
    single = single_terms_wanted && !std::is_same_v<Real, float>;
    slot_terms.assign(single ? 0 : 4 * slots, Real(0));
    single_terms.assign(single ? 4 * slots : 0, 0.0f);
    own.assign(lanes, Real(1));
  }
};

// The CG vectors of the fast implicit stepper in lane order (pointers into its arrays), with the
// inverted 3x3 diagonal blocks (xx yy zz xy xz yz) of the block-Jacobi preconditioner.
template <class Real>
struct CgVectors {
  Real *dv[3], *r[3], *p[3], *y[3], *inverse_block[6];
  Real* b[3] = {nullptr, nullptr,
                nullptr};  ///< the right-hand side, kept only where fields add to it
  /// The diagonal blocks before inversion, kept only where fields add to them.
  Real* block[6] = {nullptr, nullptr, nullptr, nullptr, nullptr, nullptr};
};

}  // namespace msfem::massspring::detail
