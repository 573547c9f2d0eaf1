// The P1 space of the P2 problem's mesh as the coarse level of its preconditioner (see
// two_level_preconditioner in petsc_linear_system.cpp for why).
#include <deal.II/fe/fe_system.h>

#include <array>
#include <cmath>
#include <vector>

#include "elasticity_problem_impl.hpp"
#include "msfem/fem_reference/errors.hpp"
#include "petsc_linear_system.hpp"

namespace msfem::fem_reference {

using namespace dealii;

detail::CoarseSpace ElasticityProblem::Implementation::p1_coarse_space() const {
  constexpr int d = dim;
  const std::size_t n_nodes = dof_handler.n_dofs() / d;
  // Per P2 node its two P1 parents: a vertex is its own parent twice, an edge midpoint has the
  // edge's vertices. Read from the barycentric coordinates of the element's support points, so no
  // assumption on deal.II's edge numbering.
  constexpr long unset = -1;
  std::vector<std::array<long, 2>> parents(n_nodes, {{unset, unset}});
  const std::vector<Point<d>>& unit = fe.get_unit_support_points();
  std::vector<types::global_dof_index> dofs(fe.n_dofs_per_cell());
  const auto barycentric = [](const Point<d>& x) {
    return std::array<double, 4>{{1.0 - x[0] - x[1] - x[2], x[0], x[1], x[2]}};
  };
  for (const auto& cell : dof_handler.active_cell_iterators()) {
    cell->get_dof_indices(dofs);
    std::array<long, 4> vertex_node{{unset, unset, unset, unset}};
    for (unsigned int i = 0; i < dofs.size(); ++i) {
      if (fe.system_to_component_index(i).first != 0) continue;
      const auto b = barycentric(unit[i]);
      for (int k = 0; k < 4; ++k)
        if (std::abs(b[std::size_t(k)] - 1.0) < 1e-12)
          vertex_node[std::size_t(k)] = long(dofs[i] / d);
    }
    for (unsigned int i = 0; i < dofs.size(); ++i) {
      if (fe.system_to_component_index(i).first != 0) continue;
      const auto b = barycentric(unit[i]);
      // A vertex (one coordinate 1) is its own parent twice; an edge midpoint (two of 1/2) has two.
      std::array<long, 2> p{{unset, unset}};
      std::size_t found = 0;
      for (std::size_t k = 0; k < 4 && found < 2; ++k) {
        if (std::abs(b[k] - 1.0) < 1e-12) {
          p = {{vertex_node[k], vertex_node[k]}};
          found = 2;
        } else if (std::abs(b[k] - 0.5) < 1e-12) {
          p[found++] = vertex_node[k];
        }
      }
      if (found != 2 || p[0] == unset || p[1] == unset)
        throw FemError("P2 support point of cell " + std::to_string(cell->active_cell_index()) +
                       " is neither a vertex nor an edge midpoint");
      parents[dofs[i] / d] = p;
    }
  }
  // P1 numbering: the vertex nodes in P2 node order, so each rank owns a contiguous range.
  std::vector<long> coarse_node(n_nodes, unset);
  long next = 0;
  for (std::size_t node = 0; node < n_nodes; ++node)
    if (parents[node][0] == long(node)) coarse_node[node] = next++;

  const IndexSet owned = dof_handler.locally_owned_dofs();
  const std::size_t first = owned.n_elements() > 0 ? owned.nth_index_in_set(0) : 0;
  const std::size_t end = first + owned.n_elements();
  detail::CoarseSpace space;
  space.row_begin.reserve(end - first + 1);
  space.row_begin.push_back(0);
  for (std::size_t row = first; row < end; ++row) {
    const std::size_t node = row / d, component = row % d;
    const auto [a, b] = parents[node];
    if (a == long(node)) {
      space.columns.push_back(PetscInt(d * coarse_node[node] + long(component)));
      space.weights.push_back(1.0);
      if (component == 0) {
        ++space.owned_coarse_rows;
        for (int c = 0; c < d; ++c)
          space.node_coordinates.push_back(dof_support_points[row][c]);
      }
    } else {
      for (const long parent : {a, b}) {
        space.columns.push_back(PetscInt(d * coarse_node[std::size_t(parent)] + long(component)));
        space.weights.push_back(0.5);
      }
    }
    space.row_begin.push_back(PetscInt(space.columns.size()));
  }
  space.owned_coarse_rows *= d;
  return space;
}

}  // namespace msfem::fem_reference
