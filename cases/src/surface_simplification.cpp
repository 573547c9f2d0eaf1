#include "msfem/cases/surface_simplification.hpp"

#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Bounded_normal_change_filter.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Count_stop_predicate.h>
#include <CGAL/Surface_mesh_simplification/edge_collapse.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "cgal_surface_mesh.hpp"
#include "msfem/cases/surface_validation.hpp"

namespace msfem::cases {

Surface simplify(const Surface& surface, int target_vertices) {
  const SurfaceReport report = validate(surface, /*check_self_intersections=*/false);
  for (const auto& d : report.defects)
    if (d.kind != DefectKind::self_intersection && d.kind != DefectKind::degenerate_triangle)
      throw std::invalid_argument("cannot simplify a surface with defects: " + d.message);
  if (target_vertices < 4 || target_vertices > surface.num_vertices())
    throw std::invalid_argument("simplification target " + std::to_string(target_vertices) +
                                " vertices is outside [4, " +
                                std::to_string(surface.num_vertices()) + "]");

  detail::CgalMesh mesh = detail::to_cgal(surface);
  // A collapse removes 1 vertex and 3 edges, so the edge count at the target is known exactly; the
  // predicate stops once the count falls below its threshold.
  const std::size_t removed = static_cast<std::size_t>(surface.num_vertices() - target_vertices);
  const std::size_t target_edges = mesh.number_of_edges() - 3 * removed;
  namespace SMS = CGAL::Surface_mesh_simplification;
  SMS::Count_stop_predicate<detail::CgalMesh> stop(target_edges + 1);
  // The filter refuses collapses that would turn a triangle over, the usual cause of folds (and
  // so self-intersections) in tightly curved surfaces such as the cortex.
  SMS::edge_collapse(mesh, stop, CGAL::parameters::filter(SMS::Bounded_normal_change_filter<>()));
  mesh.collect_garbage();

  Surface result = detail::from_cgal(mesh);
  if (result.num_vertices() != target_vertices)
    throw std::runtime_error("simplification stopped at " + std::to_string(result.num_vertices()) +
                             " vertices, target " + std::to_string(target_vertices) +
                             ": no further collapse keeps the surface manifold");
  return result;
}

void smooth_taubin(Surface& surface, int iterations, double lambda, double mu) {
  if (iterations < 0) throw std::invalid_argument("smoothing iterations must be >= 0");
  const auto edges = unique_edges(surface);
  const Eigen::Index n = surface.num_vertices();
  Eigen::VectorXd degree = Eigen::VectorXd::Zero(n);
  for (const auto& e : edges) {
    degree[e[0]] += 1;
    degree[e[1]] += 1;
  }
  Eigen::MatrixX3d neighbour_sum(n, 3);
  auto laplacian_step = [&](double factor) {
    neighbour_sum.setZero();
    for (const auto& e : edges) {
      neighbour_sum.row(e[0]) += surface.vertices.row(e[1]);
      neighbour_sum.row(e[1]) += surface.vertices.row(e[0]);
    }
    for (Eigen::Index i = 0; i < n; ++i)
      if (degree[i] > 0)
        surface.vertices.row(i) +=
            factor * (neighbour_sum.row(i) / degree[i] - surface.vertices.row(i));
  };
  for (int k = 0; k < iterations; ++k) {
    laplacian_step(lambda);
    laplacian_step(mu);
  }
}

}  // namespace msfem::cases
