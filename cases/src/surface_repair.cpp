#include "msfem/cases/surface_repair.hpp"

#include <CGAL/Polygon_mesh_processing/connected_components.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/repair.h>
#include <CGAL/Polygon_mesh_processing/repair_degeneracies.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/stitch_borders.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <vector>

#include "cgal_surface_mesh.hpp"
#include "msfem/cases/errors.hpp"
#include "surface_wrap.hpp"

namespace msfem::cases {
namespace {

namespace PMP = CGAL::Polygon_mesh_processing;
using detail::CgalMesh;
using Point = detail::Kernel::Point_3;
// Vectors, not arrays: repair_polygon_soup can only drop a repeated corner from a polygon it can
// shrink, and orient_polygon_soup does not terminate on one left in.
using Triangle = std::vector<std::size_t>;

struct Soup {
  std::vector<Point> points;
  std::vector<Triangle> triangles;
};

Soup to_soup(const Surface& s) {
  Soup soup;
  for (Eigen::Index v = 0; v < s.num_vertices(); ++v) {
    if (!s.vertices.row(v).allFinite())
      throw InputError("vertex " + std::to_string(v) + " has a non-finite coordinate");
    // CGAL's predicates overflow past this (the alpha wrap dies with SIGFPE); read_surface refuses
    // such files before, this guards surfaces made in memory.
    if (!(s.vertices.row(v).cwiseAbs().maxCoeff() <= 1e6))
      throw InputError("vertex " + std::to_string(v) + " is more than 1e6 m from the origin");
    soup.points.emplace_back(s.vertices(v, 0), s.vertices(v, 1), s.vertices(v, 2));
  }
  for (Eigen::Index t = 0; t < s.num_triangles(); ++t) {
    Triangle tri(3);
    for (int c = 0; c < 3; ++c) {
      const int id = s.triangles(t, c);
      if (id < 0 || id >= s.num_vertices())
        throw InputError("triangle " + std::to_string(t) + " refers to vertex " +
                         std::to_string(id) + ", outside [0, " + std::to_string(s.num_vertices()) +
                         ")");
      tri[static_cast<std::size_t>(c)] = static_cast<std::size_t>(id);
    }
    soup.triangles.push_back(tri);
  }
  return soup;
}

Surface to_surface(const Soup& soup) {
  Surface s;
  s.vertices.resize(static_cast<Eigen::Index>(soup.points.size()), 3);
  for (std::size_t v = 0; v < soup.points.size(); ++v)
    s.vertices.row(static_cast<Eigen::Index>(v)) << soup.points[v].x(), soup.points[v].y(),
        soup.points[v].z();
  s.triangles.resize(static_cast<Eigen::Index>(soup.triangles.size()), 3);
  for (std::size_t t = 0; t < soup.triangles.size(); ++t)
    for (int c = 0; c < 3; ++c)
      s.triangles(static_cast<Eigen::Index>(t), c) =
          static_cast<int>(soup.triangles[t][static_cast<std::size_t>(c)]);
  return s;
}

// repair_polygon_soup says only that it cleaned; the user is told what, so the repeated-corner and
// duplicate triangles are counted first on the corners as repair_polygon_soup will merge them
// (exactly equal points).
void count_soup_defects(const Soup& soup, RepairReport& r) {
  std::map<Point, std::size_t> canonical;
  for (const auto& p : soup.points)
    canonical.emplace(p, canonical.size());
  std::set<Triangle> seen;
  for (const auto& t : soup.triangles) {
    Triangle c{canonical.at(soup.points[t[0]]), canonical.at(soup.points[t[1]]),
               canonical.at(soup.points[t[2]])};
    std::sort(c.begin(), c.end());
    if (c[0] == c[1] || c[1] == c[2]) {
      ++r.degenerate_triangles;
    } else if (!seen.insert(c).second) {
      ++r.duplicate_triangles;
    }
  }
}

void clean_soup(Soup& soup, RepairReport& r) {
  count_soup_defects(soup, r);
  const std::size_t points = soup.points.size();
  PMP::repair_polygon_soup(soup.points, soup.triangles);
  r.merged_vertices = static_cast<int>(points - soup.points.size());
  if (soup.triangles.empty())
    throw InputError("no triangle with three distinct corners is left after cleaning");
}

bool same_cycle(const Triangle& a, const Triangle& b) {
  for (int k = 0; k < 3; ++k)
    if (a[0] == b[k] && a[1] == b[(k + 1) % 3] && a[2] == b[(k + 2) % 3]) return true;
  return false;
}

// orient_polygon_soup may keep the few reversed triangles or reverse all the others, whichever its
// seed gives, and the outward step may reverse them all again; only the net change against the
// input means anything, so that is what is counted, by the corners' positions.
int count_reversed(const Soup& input, const Surface& result) {
  std::map<Point, std::size_t> id;
  for (std::size_t v = 0; v < input.points.size(); ++v)
    id.emplace(input.points[v], v);
  std::map<Triangle, Triangle> by_corners;
  for (const auto& t : input.triangles) {
    Triangle key = t;
    std::sort(key.begin(), key.end());
    by_corners.emplace(key, t);
  }
  int reversed = 0;
  for (Eigen::Index t = 0; t < result.num_triangles(); ++t) {
    Triangle now(3);
    bool known = true;
    for (int c = 0; c < 3; ++c) {
      const auto v = result.vertices.row(result.triangles(t, c));
      const auto it = id.find(Point(v(0), v(1), v(2)));
      known = known && it != id.end();
      now[static_cast<std::size_t>(c)] = known ? it->second : 0;
    }
    if (!known) continue;  // a corner moved by the degenerate-face removal
    Triangle key = now;
    std::sort(key.begin(), key.end());
    const auto it = by_corners.find(key);
    reversed += it != by_corners.end() && !same_cycle(it->second, now);
  }
  return reversed;
}

void remove_zero_area_faces(CgalMesh& mesh, RepairReport& r) {
  const auto faces = mesh.number_of_faces();
  PMP::remove_degenerate_faces(mesh);
  PMP::remove_isolated_vertices(mesh);
  mesh.collect_garbage();
  r.degenerate_triangles += static_cast<int>(faces - mesh.number_of_faces());
}

void keep_largest(CgalMesh& mesh, RepairReport& r) {
  const auto faces = mesh.number_of_faces();
  r.dropped_components = static_cast<int>(PMP::keep_largest_connected_components(mesh, 1));
  mesh.collect_garbage();
  r.dropped_triangles = static_cast<int>(faces - mesh.number_of_faces());
}

// A defect the options allow: several pieces when the user asked to keep them all.
bool acceptable(const SurfaceReport& report, const RepairOptions& options) {
  for (const auto& d : report.defects)
    if (!(options.keep_all_components && d.kind == DefectKind::multiple_components)) return false;
  return true;
}

std::string defect_names(const SurfaceReport& report) {
  std::string names;
  for (const auto& d : report.defects)
    if (d.kind != DefectKind::multiple_components)
      names += (names.empty() ? "" : ", ") + to_string(d.kind);
  return names;
}

// Cleaning without the wrap: consistent orientation, stitching, zero-area faces. The result still
// holds every piece, so that pieces overlapping each other are seen as self-intersections.
CgalMesh clean_mesh(const Soup& cleaned, RepairReport& r) {
  Soup soup = cleaned;
  PMP::orient_polygon_soup(soup.points, soup.triangles);
  CgalMesh mesh;
  PMP::polygon_soup_to_polygon_mesh(soup.points, soup.triangles, mesh);
  r.stitched_edges += static_cast<int>(PMP::stitch_borders(mesh));
  remove_zero_area_faces(mesh, r);
  return mesh;
}

// PMP::orient turns every closed piece outward (by its extreme vertex, as is_outward_oriented).
Surface finish(CgalMesh& mesh, const RepairOptions& options, RepairReport& r) {
  if (CGAL::is_closed(mesh)) PMP::orient(mesh);
  if (!options.keep_all_components) keep_largest(mesh, r);
  Surface s = detail::from_cgal(mesh);
  r.result = orient_and_validate(s);
  return s;
}

std::optional<double> closed_volume(const Surface& input) {
  const auto report = validate(input, /*check_self_intersections=*/false);
  for (auto kind :
       {DefectKind::invalid_index, DefectKind::non_finite_vertex, DefectKind::boundary_edge,
        DefectKind::non_manifold_edge, DefectKind::inconsistent_orientation})
    if (report.find(kind)) return std::nullopt;
  return std::abs(report.volume);
}

Surface wrap(const Soup& cleaned, const RepairOptions& options, RepairReport& r) {
  const Surface soup = to_surface(cleaned);
  r.wrapped = true;
  r.alpha = options.alpha.value_or(default_wrap_alpha(soup));
  r.offset = options.offset.value_or(r.alpha / 30.0);
  if (!(r.alpha > 0) || !(r.offset > 0))
    throw InputError("the wrap's alpha and offset must be positive");
  // The surface's size is the wrap's only scale: far below it the wrap refines for hours (alpha)
  // or stalls on degenerate steps (offset), far above it CGAL's arithmetic overflows (SIGFPE).
  const auto box = bounding_box(soup);
  const double diagonal = (box.row(1) - box.row(0)).stableNorm();
  const auto within = [&](const char* what, double value, double low, double high,
                          const char* range) {
    if (value >= low * diagonal && value <= high * diagonal) return;
    char text[256];
    std::snprintf(text, sizeof text,
                  "the wrap's %s %g m must be %s the surface's bounding-box diagonal, %g m", what,
                  value, range, diagonal);
    throw InputError(text);
  };
  within("alpha", r.alpha, 1.0 / 500, 10.0, "between 1/500 and 10 times");
  within("offset", r.offset, 1e-6, 1.0, "between 1e-6 and 1 times");
  // The wrap's faces are the weighted cells of a Delaunay triangulation and cannot fold, so only
  // what the options ask (largest piece, outward) is done to them; a new count would mislead.
  CgalMesh mesh = detail::to_cgal(detail::alpha_wrap_surface(soup, r.alpha, r.offset));
  Surface s = finish(mesh, options, r);
  if (!acceptable(r.result, options))
    throw InputError("even the alpha wrap (alpha " + std::to_string(r.alpha) + " m, offset " +
                     std::to_string(r.offset) + " m) leaves " + r.result.defects.front().message);
  return s;
}

}  // namespace

double default_wrap_alpha(const Surface& surface) {
  const auto box = bounding_box(surface);
  const double diagonal = (box.row(1) - box.row(0)).norm();
  const auto edges = unique_edges(surface);
  double total = 0.0;
  for (const auto& e : edges)
    total += (surface.vertices.row(e[0]) - surface.vertices.row(e[1])).norm();
  const double mean = edges.empty() ? diagonal : total / static_cast<double>(edges.size());
  return std::clamp(mean, diagonal / 200.0, diagonal / 20.0);
}

Surface repair_surface(const Surface& input, const RepairOptions& options, RepairReport& r) {
  r = RepairReport{};
  r.input_vertices = input.num_vertices();
  r.input_triangles = input.num_triangles();
  if (input.num_triangles() == 0) throw InputError("the surface has no triangles");
  Soup cleaned = to_soup(input);
  r.input_volume = closed_volume(input);
  clean_soup(cleaned, r);

  CgalMesh mesh = clean_mesh(cleaned, r);
  // Every piece is checked together first: two pieces that pass alone may cross each other, and
  // keeping the larger would then silently throw half of the organ away.
  const auto whole = validate(detail::from_cgal(mesh));
  RepairOptions all = options;
  all.keep_all_components = true;
  if (!acceptable(whole, all) || options.always_wrap) {
    r.wrap_reason = options.always_wrap ? "asked for" : defect_names(whole);
    return wrap(cleaned, options, r);
  }
  Surface s = finish(mesh, options, r);
  if (acceptable(r.result, options)) {
    r.flipped_triangles = count_reversed(cleaned, s);
    return s;
  }
  r.wrap_reason = defect_names(r.result);
  return wrap(cleaned, options, r);
}

}  // namespace msfem::cases
