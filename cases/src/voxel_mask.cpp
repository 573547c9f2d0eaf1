// The organ as one solid: selection, its largest component, its cavities filled. 6-connectivity
// throughout: two voxels that touch only along an edge or at a corner would meet the surface at a
// non-manifold edge or vertex, so they count as separate pieces.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <string>

#include "msfem/cases/errors.hpp"
#include "voxel_volume.hpp"

namespace msfem::cases::detail {
namespace {

// Labels of every voxel of component `id` get `id`; returns its size.
template <typename Accept>
long flood(const Grid& g, long seed, int id, std::vector<int>& labels, const Accept& accept) {
  std::vector<long> stack{seed};
  labels[seed] = id;
  long size = 0;
  const long steps[3] = {1, g.size[0], g.size[0] * g.size[1]};
  while (!stack.empty()) {
    const long v = stack.back();
    stack.pop_back();
    ++size;
    long rest = v;
    for (int axis = 0; axis < 3; ++axis) {
      const long coordinate = rest % g.size[axis];
      rest /= g.size[axis];
      for (int side : {-1, 1}) {
        if ((side < 0 && coordinate == 0) || (side > 0 && coordinate == g.size[axis] - 1)) continue;
        const long w = v + side * steps[axis];
        if (labels[w] == 0 && accept(w)) {
          labels[w] = id;
          stack.push_back(w);
        }
      }
    }
  }
  return size;
}

bool on_border(const Grid& g, long v) {
  for (int axis = 0; axis < 3; ++axis) {
    const long c = v % g.size[axis];
    if (c == 0 || c == g.size[axis] - 1) return true;
    v /= g.size[axis];
  }
  return false;
}

std::string present_labels(const std::vector<float>& values) {
  std::set<float> labels(values.begin(), values.end());
  std::string text;
  int shown = 0;
  for (float l : labels) {
    if (shown++ == 40) return text + ", ... (" + std::to_string(labels.size()) + " in all)";
    char number[32];
    std::snprintf(number, sizeof number, "%s%g", text.empty() ? "" : ", ", l);
    text += number;
  }
  return text;
}

}  // namespace

Mask select_voxels(const VoxelVolume& volume, const ImageSelection& s, const std::string& file) {
  Mask mask(volume.values.size(), 0);
  long count = 0;
  for (std::size_t v = 0; v < mask.size(); ++v) {
    const double x = volume.values[v];
    mask[v] = s.label ? x == static_cast<double>(*s.label) : x >= s.low && x <= s.high;
    count += mask[v];
  }
  if (count > 0) return mask;
  if (s.label)
    throw InputError(file + ": label " + std::to_string(*s.label) +
                     " is not in the image; labels present: " + present_labels(volume.values));
  const auto [lo, hi] = std::minmax_element(volume.values.begin(), volume.values.end());
  char range[96];
  std::snprintf(range, sizeof range, "[%g, %g]", *lo, *hi);
  throw InputError(file + ": no voxel has " + s.describe() + "; the image's values span " + range);
}

int keep_largest_component(const Grid& g, Mask& mask) {
  std::vector<int> labels(mask.size(), 0);
  std::vector<long> sizes{0};
  for (long v = 0; v < g.count(); ++v)
    if (mask[v] && labels[v] == 0)
      sizes.push_back(flood(g, v, static_cast<int>(sizes.size()), labels,
                            [&](long w) { return mask[w] != 0; }));
  const int largest =
      static_cast<int>(std::max_element(sizes.begin(), sizes.end()) - sizes.begin());
  for (long v = 0; v < g.count(); ++v)
    mask[v] = labels[v] == largest;
  return static_cast<int>(sizes.size()) - 2;
}

long fill_cavities(const Grid& g, Mask& mask) {
  std::vector<int> outside(mask.size(), 0);
  for (long v = 0; v < g.count(); ++v)
    if (!mask[v] && outside[v] == 0 && on_border(g, v))
      flood(g, v, 1, outside, [&](long w) { return mask[w] == 0; });
  long filled = 0;
  for (long v = 0; v < g.count(); ++v)
    if (!mask[v] && outside[v] == 0) {
      mask[v] = 1;
      ++filled;
    }
  return filled;
}

bool touches_border(const Grid& g, const Mask& mask) {
  for (long v = 0; v < g.count(); ++v)
    if (mask[v] && on_border(g, v)) return true;
  return false;
}

Mask padded(const Grid& g, const Mask& mask, Grid& out) {
  out.size = {g.size[0] + 2, g.size[1] + 2, g.size[2] + 2};
  Mask result(static_cast<std::size_t>(out.count()), 0);
  for (long k = 0; k < g.size[2]; ++k)
    for (long j = 0; j < g.size[1]; ++j)
      std::copy_n(mask.begin() + g.index(0, j, k), g.size[0],
                  result.begin() + out.index(1, j + 1, k + 1));
  return result;
}

}  // namespace msfem::cases::detail
