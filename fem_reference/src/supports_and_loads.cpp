#include "msfem/fem_reference/supports_and_loads.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "msfem/fem_reference/surface_mesher.hpp"

namespace msfem::fem_reference {

namespace {

Eigen::Vector3d unit(const Eigen::Vector3d& v, const char* what) {
  const double n = v.norm();
  if (!(n > 0.0) || !std::isfinite(n))
    throw std::invalid_argument(std::string(what) + " must be a non-zero finite vector");
  return v / n;
}

/// Distance along the ray from `origin` in unit direction `d` to the triangle (a, b, c), or
/// +infinity (Moeller-Trumbore).
double ray_triangle_distance(const Eigen::Vector3d& origin, const Eigen::Vector3d& d,
                             const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                             const Eigen::Vector3d& c) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  const Eigen::Vector3d e1 = b - a, e2 = c - a, p = d.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) < 1e-30) return inf;
  const Eigen::Vector3d s = origin - a;
  const double u = s.dot(p) / det;
  if (u < -1e-12 || u > 1.0 + 1e-12) return inf;
  const Eigen::Vector3d q = s.cross(e1);
  const double v = d.dot(q) / det;
  if (v < -1e-12 || u + v > 1.0 + 1e-12) return inf;
  const double t = e2.dot(q) / det;
  return t > 0.0 ? t : inf;
}

/// A star-shaped closed surface seen from its centre: radial distance to the surface along a
/// direction, with a quick accept/reject by the smallest and largest vertex distances.
struct StarShapedSurface {
  Eigen::MatrixX3d vertices;
  Eigen::MatrixX3i triangles;
  Eigen::Vector3d center;
  double min_radius = 0.0;  ///< a lower bound of the surface's distance from the centre
  double max_radius = 0.0;

  double radius_along(const Eigen::Vector3d& direction) const {
    double r = std::numeric_limits<double>::infinity();
    for (Eigen::Index t = 0; t < triangles.rows(); ++t)
      r = std::min(
          r, ray_triangle_distance(center, direction, vertices.row(triangles(t, 0)),
                                   vertices.row(triangles(t, 1)), vertices.row(triangles(t, 2))));
    return r;
  }
};

}  // namespace

Region half_space(const Eigen::Vector3d& point, const Eigen::Vector3d& normal, double tolerance) {
  const Eigen::Vector3d n = unit(normal, "half-space normal");
  return
      [point, n, tolerance](const Eigen::Vector3d& x) { return (x - point).dot(n) >= -tolerance; };
}

Region plane(const Eigen::Vector3d& point, const Eigen::Vector3d& normal, double tolerance) {
  const Eigen::Vector3d n = unit(normal, "plane normal");
  return [point, n, tolerance](const Eigen::Vector3d& x) {
    return std::abs((x - point).dot(n)) <= tolerance;
  };
}

Region ball(const Eigen::Vector3d& center, double radius) {
  if (!(radius > 0.0)) throw std::invalid_argument("ball radius must be positive");
  return [center, radius](const Eigen::Vector3d& x) { return (x - center).norm() <= radius; };
}

Region inner_core(const Eigen::MatrixX3d& vertices, const Eigen::MatrixX3i& triangles,
                  double scale_divisor) {
  if (!(scale_divisor > 1.0))
    throw std::invalid_argument("inner core scale divisor must exceed 1, got " +
                                std::to_string(scale_divisor));
  check_closed_surface(vertices, triangles);
  auto surface = std::make_shared<StarShapedSurface>();
  surface->vertices = vertices;
  surface->triangles = triangles;
  surface->center = vertices.colwise().mean().transpose();
  // A point is surely inside when closer to the centre than every triangle's plane distance's
  // lower bound; the smallest distance from the centre to a triangle plane bounds the surface.
  double min_plane_distance = std::numeric_limits<double>::infinity();
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    const Eigen::Vector3d a = vertices.row(triangles(t, 0)), b = vertices.row(triangles(t, 1)),
                          c = vertices.row(triangles(t, 2));
    const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
    min_plane_distance = std::min(min_plane_distance, std::abs((a - surface->center).dot(n)));
  }
  surface->min_radius = min_plane_distance;
  surface->max_radius =
      (vertices.rowwise() - surface->center.transpose()).rowwise().norm().maxCoeff();
  return [surface, scale_divisor](const Eigen::Vector3d& x) {
    // x is in the core iff its image c + s (x - c) is inside the surface.
    const Eigen::Vector3d offset = scale_divisor * (x - surface->center);
    const double distance = offset.norm();
    if (distance <= surface->min_radius) return true;
    if (distance > surface->max_radius) return false;
    return distance <= surface->radius_along(offset / distance);
  };
}

Support tool_support(const ToolIndentation& tool, const std::string& name) {
  if (!(tool.radius > 0.0)) throw std::invalid_argument("tool radius must be positive");
  if (!(tool.depth >= 0.0)) throw std::invalid_argument("tool depth must not be negative");
  const Eigen::Vector3d n = unit(tool.outward_normal, "tool normal");
  const Eigen::Vector3d center = tool.contact_point + (tool.radius - tool.depth) * n;
  const double radius = tool.radius;
  Support support;
  support.name = name;
  support.boundary_nodes_only = true;
  support.region = [center, radius](const Eigen::Vector3d& x) {
    return (x - center).norm() < radius;
  };
  if (tool.mode == ToolPatchMode::uniform) {
    const Eigen::Vector3d u = -tool.depth * n;
    support.displacement = [u](const Eigen::Vector3d&) { return u; };
  } else {
    support.displacement = [center, radius, n](const Eigen::Vector3d& x) -> Eigen::Vector3d {
      const Eigen::Vector3d r = x - center;
      const double distance = r.norm();
      // The sphere's centre itself has no radial direction; push it along the inward normal.
      const Eigen::Vector3d direction =
          distance > 0.0 ? Eigen::Vector3d(r / distance) : Eigen::Vector3d(-n);
      return center + radius * direction - x;
    };
  }
  return support;
}

Support fixed_support(const std::string& name, Region region, bool boundary_nodes_only) {
  Support support;
  support.name = name;
  support.region = std::move(region);
  support.boundary_nodes_only = boundary_nodes_only;
  return support;
}

TractionField pressure(double p) {
  return
      [p](const Eigen::Vector3d&, const Eigen::Vector3d& n) -> Eigen::Vector3d { return -p * n; };
}

TractionField uniform_traction(const Eigen::Vector3d& traction) {
  return [traction](const Eigen::Vector3d&, const Eigen::Vector3d&) { return traction; };
}

}  // namespace msfem::fem_reference
