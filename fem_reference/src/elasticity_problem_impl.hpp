#pragma once

// The deal.II side of ElasticityProblem, shared by elasticity_problem.cpp (set-up, assembly,
// solve, reactions) and elasticity_postprocessing.cpp (evaluation, errors, output). Not installed.

#include <deal.II/base/point.h>
#include <deal.II/distributed/shared_tria.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/mapping_fe.h>

#include <Eigen/Core>
#include <memory>
#include <utility>
#include <vector>

#include "msfem/fem_reference/elasticity_problem.hpp"
#include "msfem/fem_reference/point_locator.hpp"

namespace msfem::fem_reference::detail {
class PetscLinearSystem;
struct CoarseSpace;
struct KrylovReport;
}  // namespace msfem::fem_reference::detail

namespace msfem::fem_reference {

inline Eigen::Vector3d to_eigen(const dealii::Point<3>& p) {
  return {p[0], p[1], p[2]};
}

/// The triangulation's coarse cells are the mesh's tetrahedra in row order, vertices as given.
void create_triangulation(const VolumeMesh& mesh, dealii::Triangulation<3>& triangulation);

struct ElasticityProblem::Implementation {
  static constexpr int dim = 3;
  using CellIterator = dealii::DoFHandler<dim>::active_cell_iterator;

  Implementation(const VolumeMesh& mesh, ElasticityModel model);

  // The pipeline (step-8 order).
  void setup_system();
  void assemble_system();
  void solve();
  void compute_reactions();
  /// The obstacles' active-set iteration around the linear solve (sphere_contact.cpp).
  detail::KrylovReport solve_with_contact(const std::vector<double>& owned_node_coordinates);

  void locate_dof_support_points();
  void collect_prescribed_dofs();
  Eigen::Vector3d evaluate(const PointLocation& location) const;
  /// P2 only: the P1 space of the same mesh as the preconditioner's coarse level
  /// (coarse_space.cpp).
  detail::CoarseSpace p1_coarse_space() const;
  /// P2 with CG + GAMG solves with the two-level preconditioner (SolverSettings::p_multigrid).
  bool two_level() const {
    return model.degree == 2 && model.solver.preconditioner == Preconditioner::gamg &&
           model.solver.p_multigrid;
  }

  MPI_Comm communicator;
  VolumeMesh mesh;
  ElasticityModel model;
  dealii::parallel::shared::Triangulation<dim> triangulation;
  dealii::FESystem<dim> fe;
  dealii::MappingFE<dim> mapping;
  dealii::DoFHandler<dim> dof_handler;
  /// Active cells in the order of mesh.tetrahedra (same vertex order as the rows).
  std::vector<CellIterator> cell_of_tetrahedron;

  // Per DoF, on every rank (the shared triangulation holds every cell everywhere).
  std::vector<dealii::Point<dim>> dof_support_points;
  std::vector<bool> dof_on_boundary;
  std::vector<int> dof_support;  ///< index into model.supports, or -1 for a free DoF
  std::vector<double> prescribed_value;

  std::vector<double> solution;  ///< all DoFs, gathered on every rank
  std::vector<Eigen::Vector3d> support_reactions;
  std::vector<ContactReport> contact_reports;  ///< per model.obstacles entry
  /// This rank's contact force per owned DoF (DoF, N), for the reactions of supports that share
  /// a node with the contact (symmetry planes).
  std::vector<std::pair<std::size_t, double>> contact_dof_force;
  Eigen::Vector3d applied_load = Eigen::Vector3d::Zero();
  SolveStatistics statistics;
  bool solved = false;
  std::unique_ptr<detail::PetscLinearSystem> linear_system;  ///< from setup_system to solve
  mutable std::unique_ptr<PointLocator> locator;

  ~Implementation();
};

}  // namespace msfem::fem_reference
