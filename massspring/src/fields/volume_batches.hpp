#pragma once

// Volume elements in lane groups (internal to the volume field). Elements of one shape — the same
// number of distinct nodes and the same tetrahedra over them with the same weights: every shell
// prism of tier_prisms, every tetrahedron of a volume mesh — go in groups of kVolumeLanes, one
// element per lane, so that a group's cross products run on all its lanes at once (the lane loops
// vectorise) and only the gather of positions and the scatter of forces go lane by lane. One
// element at a time, a prism's nine tetrahedra left the vector units idle: the force pass cost
// four times the springs' on the brain.

#include <array>
#include <cstdint>
#include <utility>
#include <vector>

namespace msfem::massspring::detail {

constexpr int kVolumeLanes = 8;
constexpr int kMaxShapeNodes = 16;

struct VolumeShape {
  int nodes = 0;
  std::vector<std::array<std::uint8_t, 4>> tets;  ///< corners as indices into the nodes
  std::vector<double> weights;                    ///< per tetrahedron
};

struct VolumeBatches {
  std::vector<VolumeShape> shapes;
  std::vector<int> group_shape;  ///< per group
  std::vector<int> group_lanes;  ///< the lanes a group fills (the rest repeat its first element)
  std::vector<int> group_start;  ///< per group + 1: its start in `offset` (nodes × lanes)
  /// Node-major per group: offset[start + k·L + l] = 3·id of node k of lane l's element.
  std::vector<int> offset;
  std::vector<int> element;  ///< per group × L: the element id

  int num_groups() const { return static_cast<int>(group_shape.size()); }
  /// Groups [G·part/parts, G·(part+1)/parts).
  std::pair<int, int> group_range(int part, int parts) const;
  int nodes(int group) const { return shapes[static_cast<std::size_t>(group_shape[group])].nodes; }
};

/// Groups the elements by shape, in element order within a shape (elements built in surface
/// order keep their neighbours close), or in the order `order` lists them. `element_start` /
/// `element_offset`: each element's distinct nodes as 3·id; `local_tets`: each tetrahedron's
/// corners as indices into them; `tet_start`, `tet_weight`: the elements' tetrahedra.
VolumeBatches batch_elements(const std::vector<int>& element_start,
                             const std::vector<int>& element_offset,
                             const std::vector<std::array<std::uint8_t, 4>>& local_tets,
                             const std::vector<int>& tet_start, const double* tet_weight,
                             const std::vector<int>* order = nullptr);

/// The lanes' volumes V and g = −6 ∂V/∂x at their nodes (g[(3k + c)·L + l]), from positions x.
void group_gradient(const VolumeBatches& b, int group, const double* x, double* g, double* volume);

/// out[l] = factor[l] Σ_k g_k(l) · x[node k of lane l] on every lane (group_gradient's g layout;
/// factor and out at the group's first lane).
void group_dot(const VolumeBatches& b, int group, const double* g, const double* x,
               const double* factor, double* out);

/// f[node k of lane l] += s[l] g_k(l) for the group's filled lanes.
void scatter_group(const VolumeBatches& b, int group, const double* g, const double* s, double* f);

/// group_dot for two vectors in one pass over g: out1 from x1 plus base1 (where not null), out2
/// from x2.
void group_dot_pair(const VolumeBatches& b, int group, const double* g, const double* x1,
                    const double* x2, const double* factor, const double* base1, double* out1,
                    double* out2);

/// scatter_group for two vectors in one pass over g: f1 with s1, f2 with s2.
void scatter_group_pair(const VolumeBatches& b, int group, const double* g, const double* s1,
                        double* f1, const double* s2, double* f2);

}  // namespace msfem::massspring::detail
