#include "volume_batches.hpp"

#include <map>
#include <tuple>

namespace msfem::massspring::detail {

// The lane loops are written for the vectoriser; these clones give it the AVX-512 and AVX2 units
// where the CPU has them (chosen at load time), since the library is built without -march. With
// AVX-512 the prisms' gradients took a fifth less time than with AVX2 alone.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && \
    !defined(__SANITIZE_ADDRESS__)
#define MSFEM_LANE_CLONES \
  __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#else
#define MSFEM_LANE_CLONES
#endif

namespace {
constexpr int L = kVolumeLanes;
}

std::pair<int, int> VolumeBatches::group_range(int part, int parts) const {
  const long groups = num_groups();
  return {static_cast<int>(groups * part / parts), static_cast<int>(groups * (part + 1) / parts)};
}

VolumeBatches batch_elements(const std::vector<int>& element_start,
                             const std::vector<int>& element_offset,
                             const std::vector<std::array<std::uint8_t, 4>>& local_tets,
                             const std::vector<int>& tet_start, const double* tet_weight,
                             const std::vector<int>* order) {
  VolumeBatches b;
  const int elements = static_cast<int>(tet_start.size()) - 1;
  using Key = std::tuple<int, std::vector<std::array<std::uint8_t, 4>>, std::vector<double>>;
  std::map<Key, int> shape_of;
  std::vector<std::vector<int>> members;
  for (int i = 0; i < elements; ++i) {
    const int e = order ? (*order)[static_cast<std::size_t>(i)] : i;
    VolumeShape shape;
    shape.nodes = element_start[e + 1] - element_start[e];
    for (int t = tet_start[e]; t < tet_start[e + 1]; ++t) {
      shape.tets.push_back(local_tets[static_cast<std::size_t>(t)]);
      shape.weights.push_back(tet_weight[t]);
    }
    const auto [it, added] =
        shape_of.emplace(Key{shape.nodes, shape.tets, shape.weights}, b.shapes.size());
    if (added) {
      b.shapes.push_back(std::move(shape));
      members.emplace_back();
    }
    members[static_cast<std::size_t>(it->second)].push_back(e);
  }
  b.group_start.push_back(0);
  for (std::size_t s = 0; s < members.size(); ++s) {
    const auto& list = members[s];
    const int nodes = b.shapes[s].nodes;
    for (std::size_t first = 0; first < list.size(); first += L) {
      const int lanes = static_cast<int>(std::min<std::size_t>(L, list.size() - first));
      b.group_shape.push_back(static_cast<int>(s));
      b.group_lanes.push_back(lanes);
      const std::size_t start = b.offset.size();
      b.offset.resize(start + static_cast<std::size_t>(nodes) * L);
      for (int l = 0; l < L; ++l) {
        const int e = list[first + static_cast<std::size_t>(l < lanes ? l : 0)];
        b.element.push_back(e);
        for (int k = 0; k < nodes; ++k)
          b.offset[start + static_cast<std::size_t>(k * L + l)] =
              element_offset[element_start[e] + k];
      }
      b.group_start.push_back(static_cast<int>(b.offset.size()));
    }
  }
  return b;
}

// As VolumeForceField::element_gradient, lane by lane: per tetrahedron (c0 c1 c2 c3) of weight w,
// e_i = p_ci − p_c0, g1 = w e2×e3, g2 = w e3×e1, g3 = w e1×e2, 6V += e1·g1, and g_c0 += g1 + g2 +
// g3, g_ci −= gi.
MSFEM_LANE_CLONES void group_gradient(const VolumeBatches& b, int group, const double* x, double* g,
                                      double* volume) {
  const VolumeShape& shape = b.shapes[static_cast<std::size_t>(b.group_shape[group])];
  const int* offset = b.offset.data() + b.group_start[group];
  alignas(64) double p[kMaxShapeNodes][3][L];
  alignas(64) double out[kMaxShapeNodes][3][L];
  for (int k = 0; k < shape.nodes; ++k)
    for (int c = 0; c < 3; ++c)
      for (int l = 0; l < L; ++l) {
        p[k][c][l] = x[offset[k * L + l] + c];
        out[k][c][l] = 0.0;
      }
  alignas(64) double v[L] = {};
  // The lane loop written out without inner loops and over pointers to the corners' rows: GCC
  // vectorises the innermost loop alone, and not through an array indexed by a variable corner.
  for (std::size_t t = 0; t < shape.tets.size(); ++t) {
    const auto& corner = shape.tets[t];
    const double* p0 = p[corner[0]][0];
    const double* p1 = p[corner[1]][0];
    const double* p2 = p[corner[2]][0];
    const double* p3 = p[corner[3]][0];
    const double w = shape.weights[t];
    alignas(64) double g1[3][L], g2[3][L], g3[3][L];
    for (int l = 0; l < L; ++l) {
      const double x0 = p0[l], y0 = p0[L + l], z0 = p0[2 * L + l];
      const double ax = p1[l] - x0, ay = p1[L + l] - y0, az = p1[2 * L + l] - z0;
      const double bx = p2[l] - x0, by = p2[L + l] - y0, bz = p2[2 * L + l] - z0;
      const double cx = p3[l] - x0, cy = p3[L + l] - y0, cz = p3[2 * L + l] - z0;
      g1[0][l] = w * (by * cz - bz * cy);
      g1[1][l] = w * (bz * cx - bx * cz);
      g1[2][l] = w * (bx * cy - by * cx);
      g2[0][l] = w * (cy * az - cz * ay);
      g2[1][l] = w * (cz * ax - cx * az);
      g2[2][l] = w * (cx * ay - cy * ax);
      g3[0][l] = w * (ay * bz - az * by);
      g3[1][l] = w * (az * bx - ax * bz);
      g3[2][l] = w * (ax * by - ay * bx);
      v[l] += ax * g1[0][l] + ay * g1[1][l] + az * g1[2][l];
    }
    for (int c = 0; c < 3; ++c) {
      double* o0 = out[corner[0]][c];
      for (int l = 0; l < L; ++l)
        o0[l] += g1[c][l] + g2[c][l] + g3[c][l];
      double* o1 = out[corner[1]][c];
      for (int l = 0; l < L; ++l)
        o1[l] -= g1[c][l];
      double* o2 = out[corner[2]][c];
      for (int l = 0; l < L; ++l)
        o2[l] -= g2[c][l];
      double* o3 = out[corner[3]][c];
      for (int l = 0; l < L; ++l)
        o3[l] -= g3[c][l];
    }
  }
  for (int k = 0; k < shape.nodes; ++k)
    for (int c = 0; c < 3; ++c)
      for (int l = 0; l < L; ++l)
        g[(3 * k + c) * L + l] = out[k][c][l];
  for (int l = 0; l < L; ++l)
    volume[l] = v[l] / 6.0;
}

MSFEM_LANE_CLONES void group_dot(const VolumeBatches& b, int group, const double* g,
                                 const double* x, const double* factor, double* out) {
  const int nodes = b.nodes(group);
  const int* offset = b.offset.data() + b.group_start[group];
  alignas(64) double sum[L] = {};
  for (int k = 0; k < nodes; ++k) {
    const int* at = offset + k * L;
    const double* gk = g + 3 * k * L;
    for (int l = 0; l < L; ++l)
      sum[l] += gk[l] * x[at[l]] + gk[L + l] * x[at[l] + 1] + gk[2 * L + l] * x[at[l] + 2];
  }
  for (int l = 0; l < L; ++l)
    out[l] = factor[l] * sum[l];
}

void scatter_group(const VolumeBatches& b, int group, const double* g, const double* s, double* f) {
  const int nodes = b.nodes(group), lanes = b.group_lanes[group];
  const int* offset = b.offset.data() + b.group_start[group];
  for (int k = 0; k < nodes; ++k)
    for (int l = 0; l < lanes; ++l) {
      double* at = f + offset[k * L + l];
      for (int c = 0; c < 3; ++c)
        at[c] += s[l] * g[(3 * k + c) * L + l];
    }
}

MSFEM_LANE_CLONES void group_dot_pair(const VolumeBatches& b, int group, const double* g,
                                      const double* x1, const double* x2, const double* factor,
                                      const double* base1, double* out1, double* out2) {
  const int nodes = b.nodes(group);
  const int* offset = b.offset.data() + b.group_start[group];
  alignas(64) double sum1[L] = {}, sum2[L] = {};
  for (int k = 0; k < nodes; ++k) {
    const int* at = offset + k * L;
    const double* gk = g + 3 * k * L;
    for (int l = 0; l < L; ++l) {
      sum1[l] += gk[l] * x1[at[l]] + gk[L + l] * x1[at[l] + 1] + gk[2 * L + l] * x1[at[l] + 2];
      sum2[l] += gk[l] * x2[at[l]] + gk[L + l] * x2[at[l] + 1] + gk[2 * L + l] * x2[at[l] + 2];
    }
  }
  for (int l = 0; l < L; ++l) {
    out1[l] = (base1 ? base1[l] : 0.0) + factor[l] * sum1[l];
    out2[l] = factor[l] * sum2[l];
  }
}

void scatter_group_pair(const VolumeBatches& b, int group, const double* g, const double* s1,
                        double* f1, const double* s2, double* f2) {
  const int nodes = b.nodes(group), lanes = b.group_lanes[group];
  const int* offset = b.offset.data() + b.group_start[group];
  for (int k = 0; k < nodes; ++k)
    for (int l = 0; l < lanes; ++l) {
      double* at1 = f1 + offset[k * L + l];
      double* at2 = f2 + offset[k * L + l];
      for (int c = 0; c < 3; ++c) {
        const double gc = g[(3 * k + c) * L + l];
        at1[c] += s1[l] * gc;
        at2[c] += s2[l] * gc;
      }
    }
}

}  // namespace msfem::massspring::detail
