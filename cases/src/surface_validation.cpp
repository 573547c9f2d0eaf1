#include "msfem/cases/surface_validation.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <tuple>

namespace msfem::cases {
namespace {

class DisjointSets {
 public:
  explicit DisjointSets(std::size_t n) : parent_(n) {
    std::iota(parent_.begin(), parent_.end(), 0);
  }
  std::size_t find(std::size_t i) {
    while (parent_[i] != i)
      i = parent_[i] = parent_[parent_[i]];
    return i;
  }
  void unite(std::size_t a, std::size_t b) { parent_[find(a)] = find(b); }

 private:
  std::vector<std::size_t> parent_;
};

constexpr std::size_t listed_ids = 10;

// "<count> <what>: <first ids>…" with ids grouped by `arity` (1 = vertex/triangle, 2 = edge/pair).
Defect make_defect(DefectKind kind, std::vector<int> elements, int arity, const std::string& what) {
  std::ostringstream msg;
  const std::size_t count = elements.size() / static_cast<std::size_t>(arity);
  msg << count << ' ' << what << ':';
  for (std::size_t i = 0; i < std::min(count, listed_ids); ++i) {
    msg << (i ? ", " : " ");
    if (arity == 1) {
      msg << elements[i];
    } else {
      msg << '(' << elements[2 * i] << ',' << elements[2 * i + 1] << ')';
    }
  }
  if (count > listed_ids) msg << ", ... (" << count - listed_ids << " more)";
  return {kind, std::move(elements), msg.str()};
}

// One entry per triangle side: the undirected edge, the triangle, and whether the triangle runs
// along the edge from its smaller to its larger vertex.
struct HalfEdge {
  int lo, hi, triangle;
  bool forward;
  bool operator<(const HalfEdge& o) const {
    return std::tie(lo, hi, triangle) < std::tie(o.lo, o.hi, o.triangle);
  }
};

std::vector<HalfEdge> sorted_half_edges(const Surface& s) {
  std::vector<HalfEdge> h;
  h.reserve(3 * static_cast<std::size_t>(s.num_triangles()));
  for (int t = 0; t < s.num_triangles(); ++t) {
    for (int c = 0; c < 3; ++c) {
      const int a = s.triangles(t, c), b = s.triangles(t, (c + 1) % 3);
      if (a == b) continue;  // a degenerate triangle's collapsed side is no edge
      h.push_back({std::min(a, b), std::max(a, b), t, a < b});
    }
  }
  std::sort(h.begin(), h.end());
  return h;
}

// Corner id of vertex v in triangle t (3t + c).
std::size_t corner_of(const Surface& s, int t, int v) {
  for (int c = 0; c < 3; ++c)
    if (s.triangles(t, c) == v) return 3 * static_cast<std::size_t>(t) + c;
  return 3 * static_cast<std::size_t>(t);
}

bool indices_valid(const Surface& s, SurfaceReport& r) {
  std::vector<int> bad;
  for (int t = 0; t < s.num_triangles(); ++t)
    for (int c = 0; c < 3; ++c)
      if (s.triangles(t, c) < 0 || s.triangles(t, c) >= s.num_vertices()) {
        bad.push_back(t);
        break;
      }
  if (bad.empty()) return true;
  r.defects.push_back(make_defect(DefectKind::invalid_index, std::move(bad), 1,
                                  "triangles with a vertex id out of range"));
  return false;
}

void check_vertices(const Surface& s, SurfaceReport& r) {
  std::vector<int> bad;
  for (int v = 0; v < s.num_vertices(); ++v)
    if (!s.vertices.row(v).allFinite()) bad.push_back(v);
  if (!bad.empty())
    r.defects.push_back(make_defect(DefectKind::non_finite_vertex, std::move(bad), 1,
                                    "vertices with a non-finite coordinate"));
}

void check_degenerate(const Surface& s, SurfaceReport& r) {
  const double diagonal = (r.bounding_box.row(1) - r.bounding_box.row(0)).norm();
  // Relative to the model's size so that the test does not depend on the unit.
  const double min_twice_area = 1e-12 * diagonal * diagonal;
  std::vector<int> bad;
  for (int t = 0; t < s.num_triangles(); ++t) {
    const int a = s.triangles(t, 0), b = s.triangles(t, 1), c = s.triangles(t, 2);
    const Eigen::Vector3d pa = s.vertices.row(a), pb = s.vertices.row(b), pc = s.vertices.row(c);
    if (a == b || b == c || c == a || !((pb - pa).cross(pc - pa).norm() > min_twice_area))
      bad.push_back(t);
  }
  if (!bad.empty())
    r.defects.push_back(make_defect(DefectKind::degenerate_triangle, std::move(bad), 1,
                                    "degenerate triangles (repeated corner or zero area)"));
}

struct EdgeTopology {
  bool closed = true, edge_manifold = true, consistent = true;
};

EdgeTopology check_edges(const Surface& s, const std::vector<HalfEdge>& h, DisjointSets& corners,
                         SurfaceReport& r) {
  EdgeTopology topo;
  std::vector<int> boundary, non_manifold, inconsistent;
  for (std::size_t i = 0; i < h.size();) {
    std::size_t j = i;
    while (j < h.size() && h[j].lo == h[i].lo && h[j].hi == h[i].hi)
      ++j;
    ++r.edges;
    const std::size_t uses = j - i;
    if (uses == 1) {
      boundary.insert(boundary.end(), {h[i].lo, h[i].hi});
    } else if (uses > 2) {
      non_manifold.insert(non_manifold.end(), {h[i].lo, h[i].hi});
    } else {
      const int t1 = h[i].triangle, t2 = h[i + 1].triangle;
      if (h[i].forward == h[i + 1].forward) inconsistent.insert(inconsistent.end(), {t1, t2});
      // The two triangles are neighbours in the fans of both end vertices.
      for (int v : {h[i].lo, h[i].hi})
        corners.unite(corner_of(s, t1, v), corner_of(s, t2, v));
    }
    i = j;
  }
  topo.closed = boundary.empty();
  topo.edge_manifold = non_manifold.empty();
  topo.consistent = inconsistent.empty();
  if (!boundary.empty())
    r.defects.push_back(make_defect(DefectKind::boundary_edge, std::move(boundary), 2,
                                    "boundary edges (surface not closed), as vertex pairs"));
  if (!non_manifold.empty())
    r.defects.push_back(make_defect(DefectKind::non_manifold_edge, std::move(non_manifold), 2,
                                    "non-manifold edges (3+ triangles), as vertex pairs"));
  if (!inconsistent.empty())
    r.defects.push_back(
        make_defect(DefectKind::inconsistent_orientation, std::move(inconsistent), 2,
                    "triangle pairs with inconsistent orientation across their shared edge"));
  return topo;
}

bool check_vertex_fans(const Surface& s, DisjointSets& corners, SurfaceReport& r) {
  std::vector<std::vector<std::size_t>> fans(static_cast<std::size_t>(s.num_vertices()));
  for (int t = 0; t < s.num_triangles(); ++t)
    for (int c = 0; c < 3; ++c) {
      const std::size_t root = corners.find(3 * static_cast<std::size_t>(t) + c);
      auto& f = fans[static_cast<std::size_t>(s.triangles(t, c))];
      if (std::find(f.begin(), f.end(), root) == f.end()) f.push_back(root);
    }
  std::vector<int> bad, unreferenced;
  for (int v = 0; v < s.num_vertices(); ++v) {
    if (fans[v].empty()) unreferenced.push_back(v);
    if (fans[v].size() > 1) bad.push_back(v);
  }
  const bool manifold = bad.empty();
  if (!bad.empty())
    r.defects.push_back(make_defect(DefectKind::non_manifold_vertex, std::move(bad), 1,
                                    "non-manifold vertices (more than one fan of triangles)"));
  if (!unreferenced.empty())
    r.defects.push_back(make_defect(DefectKind::unreferenced_vertex, std::move(unreferenced), 1,
                                    "vertices used by no triangle"));
  return manifold;
}

int count_components(const Surface& s, SurfaceReport& r) {
  DisjointSets sets(static_cast<std::size_t>(s.num_vertices()));
  for (int t = 0; t < s.num_triangles(); ++t) {
    sets.unite(s.triangles(t, 0), s.triangles(t, 1));
    sets.unite(s.triangles(t, 1), s.triangles(t, 2));
  }
  // Component id of each triangle, reported by the first triangle of every component but the
  // largest, so that the user sees which pieces are extra.
  std::vector<int> size(static_cast<std::size_t>(s.num_vertices()), 0), first(size.size(), -1);
  for (int t = 0; t < s.num_triangles(); ++t) {
    const std::size_t root = sets.find(s.triangles(t, 0));
    if (size[root]++ == 0) first[root] = t;
  }
  std::vector<std::size_t> roots;
  for (std::size_t v = 0; v < size.size(); ++v)
    if (size[v] > 0) roots.push_back(v);
  if (roots.size() > 1) {
    std::sort(roots.begin(), roots.end(),
              [&](std::size_t a, std::size_t b) { return size[a] > size[b]; });
    std::vector<int> extra;
    for (std::size_t k = 1; k < roots.size(); ++k)
      extra.push_back(first[roots[k]]);
    r.defects.push_back(
        make_defect(DefectKind::multiple_components, std::move(extra), 1,
                    "extra connected components besides the largest, by a triangle in each"));
  }
  return static_cast<int>(roots.size());
}

}  // namespace

std::string to_string(DefectKind kind) {
  switch (kind) {
    case DefectKind::invalid_index:
      return "invalid_index";
    case DefectKind::non_finite_vertex:
      return "non_finite_vertex";
    case DefectKind::degenerate_triangle:
      return "degenerate_triangle";
    case DefectKind::boundary_edge:
      return "boundary_edge";
    case DefectKind::non_manifold_edge:
      return "non_manifold_edge";
    case DefectKind::non_manifold_vertex:
      return "non_manifold_vertex";
    case DefectKind::inconsistent_orientation:
      return "inconsistent_orientation";
    case DefectKind::multiple_components:
      return "multiple_components";
    case DefectKind::unreferenced_vertex:
      return "unreferenced_vertex";
    case DefectKind::self_intersection:
      return "self_intersection";
  }
  return "unknown";
}

const Defect* SurfaceReport::find(DefectKind kind) const {
  for (const auto& d : defects)
    if (d.kind == kind) return &d;
  return nullptr;
}

SurfaceReport validate(const Surface& s, bool check_self_intersections) {
  SurfaceReport r;
  r.vertices = s.num_vertices();
  r.triangles = s.num_triangles();
  if (!indices_valid(s, r)) return r;  // nothing else can be indexed safely
  check_vertices(s, r);
  const bool finite = r.defects.empty();
  if (finite) {
    r.bounding_box = bounding_box(s);
    r.volume = signed_volume(s);
    r.area = area(s);
    check_degenerate(s, r);
  }

  DisjointSets corners(3 * static_cast<std::size_t>(s.num_triangles()));
  const EdgeTopology topo = check_edges(s, sorted_half_edges(s), corners, r);
  const bool vertex_manifold = check_vertex_fans(s, corners, r);
  r.components = count_components(s, r);

  const bool closed_manifold = topo.closed && topo.edge_manifold && vertex_manifold;
  if (closed_manifold) {
    const auto referenced =
        r.vertices -
        (r.find(DefectKind::unreferenced_vertex)
             ? static_cast<Eigen::Index>(r.find(DefectKind::unreferenced_vertex)->elements.size())
             : 0);
    const Eigen::Index euler = referenced - r.edges + r.triangles;  // = 2C - 2g
    r.genus = static_cast<int>((2 * r.components - euler) / 2);
  }
  if (closed_manifold && topo.consistent && finite && r.volume < 0)
    r.fixes.push_back("orientation is inward (volume " + std::to_string(r.volume) +
                      " m^3): every triangle must be flipped");

  if (check_self_intersections && finite && topo.edge_manifold && vertex_manifold &&
      topo.consistent) {
    std::vector<int> pairs;
    try {
      for (const auto& p : self_intersecting_pairs(s))
        pairs.insert(pairs.end(), {p[0], p[1]});
      r.self_intersections_checked = true;
    } catch (const std::invalid_argument&) {
      // A configuration CGAL's halfedge mesh cannot hold (e.g. a triangle with a repeated corner)
      // is already reported above; the intersection test waits until it is fixed.
    }
    if (!pairs.empty()) {
      // Tools that skip adjacent triangles count only the pairs sharing no vertex; say both.
      std::size_t neighbours = 0;
      for (std::size_t k = 0; k < pairs.size(); k += 2) {
        const auto a = s.triangles.row(pairs[k]), b = s.triangles.row(pairs[k + 1]);
        bool share = false;
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            share = share || a[i] == b[j];
        neighbours += share;
      }
      const std::size_t disjoint = pairs.size() / 2 - neighbours;
      r.defects.push_back(make_defect(DefectKind::self_intersection, std::move(pairs), 2,
                                      "pairs of self-intersecting triangles (" +
                                          std::to_string(disjoint) + " sharing no vertex, " +
                                          std::to_string(neighbours) +
                                          " neighbours folded over each other)"));
    }
  }
  return r;
}

SurfaceReport orient_and_validate(Surface& s, bool check_self_intersections) {
  SurfaceReport r = validate(s, check_self_intersections);
  if (!r.fixes.empty()) {
    s.triangles.col(1).swap(s.triangles.col(2));
    r.volume = -r.volume;
    r.fixes.back() = "orientation was inward: flipped all " + std::to_string(r.triangles) +
                     " triangles (volume now " + std::to_string(r.volume) + " m^3)";
  }
  return r;
}

}  // namespace msfem::cases
