#include "msfem/cases/surface_refinement.hpp"

#include <algorithm>
#include <array>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>

namespace msfem::cases {
namespace {

using EdgeKey = std::pair<int, int>;

EdgeKey key(int a, int b) {
  return a < b ? EdgeKey{a, b} : EdgeKey{b, a};
}

class Bisection {
 public:
  Bisection(std::vector<Eigen::Vector3d>& vertices, std::vector<std::array<int, 3>>& out)
      : vertices_(vertices), out_(out) {}

  double length(int a, int b) const { return (vertices_[a] - vertices_[b]).norm(); }

  /// Local edge (0: v0-v1, 1: v1-v2, 2: v2-v0) of the longest edge. Ties go to the smaller
  /// vertex pair, so both triangles sharing an edge agree on it.
  int longest_edge(const std::array<int, 3>& t) const {
    int best = 0;
    for (int e = 1; e < 3; ++e) {
      const double le = length(t[e], t[(e + 1) % 3]), lb = length(t[best], t[(best + 1) % 3]);
      if (le > lb || (le == lb && key(t[e], t[(e + 1) % 3]) < key(t[best], t[(best + 1) % 3])))
        best = e;
    }
    return best;
  }

  std::map<EdgeKey, int>& marked() { return midpoint_; }

  /// Splits (a, b, c) at its longest marked edge and recurses into the halves, whose only edge
  /// that can be marked is the parent's edge they inherit whole.
  void split(const std::array<int, 3>& t) {
    int chosen = -1;
    double chosen_length = -1;
    for (int e = 0; e < 3; ++e) {
      const auto it = midpoint_.find(key(t[e], t[(e + 1) % 3]));
      if (it == midpoint_.end()) continue;
      const double l = length(t[e], t[(e + 1) % 3]);
      if (l > chosen_length) chosen = e, chosen_length = l;
    }
    if (chosen < 0) {
      out_.push_back(t);
      return;
    }
    // Rotate so the split edge is (a, b) and c is opposite it.
    const int a = t[chosen], b = t[(chosen + 1) % 3], c = t[(chosen + 2) % 3];
    int& m = midpoint_[key(a, b)];
    if (m < 0) {
      m = static_cast<int>(vertices_.size());
      vertices_.push_back(0.5 * (vertices_[a] + vertices_[b]));
    }
    const int mid = m;
    split({a, mid, c});
    split({mid, b, c});
  }

 private:
  std::vector<Eigen::Vector3d>& vertices_;
  std::vector<std::array<int, 3>>& out_;
  std::map<EdgeKey, int> midpoint_;  // marked edge -> midpoint vertex (-1 until created)
};

bool reaches_into(const std::vector<Eigen::Vector3d>& v, const std::array<int, 3>& t,
                  const RefinementBall& ball) {
  // Bounding-sphere test: the triangle's centroid and the farthest corner from it. It may admit a
  // triangle that only comes near the ball, which merely refines a little more than asked.
  const Eigen::Vector3d centroid = (v[t[0]] + v[t[1]] + v[t[2]]) / 3.0;
  double reach = 0;
  for (int k = 0; k < 3; ++k)
    reach = std::max(reach, (v[t[k]] - centroid).norm());
  return (centroid - ball.center).norm() <= ball.radius + reach;
}

}  // namespace

SurfaceRefinement refine_near(const Surface& surface, const std::vector<RefinementBall>& balls,
                              double max_edge, int max_passes) {
  if (!(max_edge > 0.0))
    throw std::invalid_argument("surface refinement: edge length " + std::to_string(max_edge) +
                                " m must be > 0");
  for (const auto& b : balls)
    if (!(b.radius >= 0.0) || !b.center.allFinite())
      throw std::invalid_argument(
          "surface refinement: a ball needs a finite centre and radius >= 0");

  std::vector<Eigen::Vector3d> vertices(static_cast<std::size_t>(surface.num_vertices()));
  for (Eigen::Index i = 0; i < surface.num_vertices(); ++i)
    vertices[i] = surface.vertices.row(i).transpose();
  std::vector<std::array<int, 3>> triangles(static_cast<std::size_t>(surface.num_triangles()));
  for (Eigen::Index t = 0; t < surface.num_triangles(); ++t)
    triangles[t] = {surface.triangles(t, 0), surface.triangles(t, 1), surface.triangles(t, 2)};

  SurfaceRefinement result;
  for (int pass = 0; pass < max_passes; ++pass) {
    std::vector<std::array<int, 3>> next;
    Bisection bisection(vertices, next);
    auto& marked = bisection.marked();
    for (const auto& t : triangles) {
      const int e = bisection.longest_edge(t);
      if (bisection.length(t[e], t[(e + 1) % 3]) <= max_edge) continue;
      for (const auto& ball : balls)
        if (reaches_into(vertices, t, ball)) {
          marked.emplace(key(t[e], t[(e + 1) % 3]), -1);
          break;
        }
    }
    if (marked.empty()) break;
    // Conformity: a triangle with any marked edge has its longest edge marked too, so each
    // triangle is bisected at its longest edge first (this is what bounds the angles).
    for (bool changed = true; changed;) {
      changed = false;
      for (const auto& t : triangles) {
        bool any = false;
        for (int e = 0; e < 3 && !any; ++e)
          any = marked.count(key(t[e], t[(e + 1) % 3])) > 0;
        if (!any) continue;
        const int e = bisection.longest_edge(t);
        changed |= marked.emplace(key(t[e], t[(e + 1) % 3]), -1).second;
      }
    }
    for (const auto& t : triangles)
      bisection.split(t);
    triangles = std::move(next);
    ++result.passes;
  }

  result.surface.vertices.resize(static_cast<Eigen::Index>(vertices.size()), 3);
  for (std::size_t i = 0; i < vertices.size(); ++i)
    result.surface.vertices.row(static_cast<Eigen::Index>(i)) = vertices[i].transpose();
  result.surface.triangles.resize(static_cast<Eigen::Index>(triangles.size()), 3);
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (int k = 0; k < 3; ++k)
      result.surface.triangles(static_cast<Eigen::Index>(t), k) = triangles[t][k];
  result.added_vertices = static_cast<int>(vertices.size() - surface.num_vertices());
  return result;
}

}  // namespace msfem::cases
