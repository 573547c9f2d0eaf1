// Queries on a solved ElasticityProblem: displacements at vertices and points, errors against a
// known field, ParaView output (VTU/PVTU + PVD) and HDF5 + XDMF.

#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/lac/vector.h>
#include <deal.II/numerics/data_out.h>

#include <unistd.h>

#include <cmath>
#include <fstream>
#include <stdexcept>
#include <string>

#include "elasticity_problem_impl.hpp"
#include "msfem/fem_reference/elasticity_problem.hpp"
#include "petsc_linear_system.hpp"

namespace msfem::fem_reference {

using namespace dealii;

namespace {
void require_solved(bool solved, const char* query) {
  if (!solved) throw std::logic_error(std::string(query) + " before run()");
}

void add_displacement(DataOut<3>& data_out, const Vector<double>& solution) {
  const std::vector<std::string> names(3, "displacement");
  const std::vector<DataComponentInterpretation::DataComponentInterpretation> vector_field(
      3, DataComponentInterpretation::component_is_part_of_vector);
  data_out.add_data_vector(solution, names, DataOut<3>::type_dof_data, vector_field);
}

/// `<basename>.h5` and `<basename>.xdmf` from the patches of `data_out` (built with one
/// subdivision), written collectively by the ranks of `communicator`. Each file goes to a temporary
/// name in `directory` first and is renamed when complete, the .h5 before the .xdmf that names it,
/// so a reader never finds half a result.
std::filesystem::path write_hdf5_and_xdmf(const DataOut<3>& data_out, MPI_Comm communicator,
                                          const std::filesystem::path& directory,
                                          const std::string& basename) {
  std::filesystem::create_directories(directory);
  // Merged duplicate vertices: one node per mesh vertex and rank. Right for the continuous
  // displacement only (a cell field would take one cell's value per node), hence no cell fields.
  DataOutBase::DataOutFilter filter(DataOutBase::DataOutFilterFlags(true, true));
  data_out.write_filtered_data(filter);
  const bool root = Utilities::MPI::this_mpi_process(communicator) == 0;
  // The HDF5 file is created collectively, so every rank needs the same temporary name.
  long tag = long(getpid());
  MPI_Bcast(&tag, 1, MPI_LONG, 0, communicator);
  const std::string h5 = basename + ".h5", xdmf = basename + ".xdmf";
  const std::filesystem::path h5_temporary = directory / (h5 + ".tmp." + std::to_string(tag)),
                              xdmf_temporary = directory / (xdmf + ".tmp." + std::to_string(tag));
  try {
    data_out.write_hdf5_parallel(filter, h5_temporary.string(), communicator);
    // The XDMF names the .h5 relative to its own folder (as ParaView resolves it) and by its final
    // name.
    const XDMFEntry entry = data_out.create_xdmf_entry(filter, h5, 0.0, communicator);
    data_out.write_xdmf_file({entry}, xdmf_temporary.string(), communicator);
    MPI_Barrier(communicator);
    if (root) {
      std::filesystem::rename(h5_temporary, directory / h5);
      std::filesystem::rename(xdmf_temporary, directory / xdmf);
    }
  } catch (...) {
    if (root) {
      std::error_code ignored;
      std::filesystem::remove(h5_temporary, ignored);
      std::filesystem::remove(xdmf_temporary, ignored);
    }
    throw;
  }
  // Both files are in place on every rank's return.
  MPI_Barrier(communicator);
  return directory / xdmf;
}
}  // namespace

Eigen::Vector3d ElasticityProblem::Implementation::evaluate(const PointLocation& location) const {
  // The point on deal.II's reference tetrahedron is (b1, b2, b3): cell vertex k is tetrahedron row
  // entry k (checked in setup_system), so no mapping inversion is needed.
  const CellIterator& cell = cell_of_tetrahedron[std::size_t(location.cell)];
  const Point<dim> reference(location.barycentric[1], location.barycentric[2],
                             location.barycentric[3]);
  std::vector<types::global_dof_index> dofs(fe.n_dofs_per_cell());
  cell->get_dof_indices(dofs);
  Eigen::Vector3d u = Eigen::Vector3d::Zero();
  for (unsigned int i = 0; i < dofs.size(); ++i)
    u[fe.system_to_component_index(i).first] += solution[dofs[i]] * fe.shape_value(i, reference);
  return u;
}

Eigen::MatrixX3d ElasticityProblem::vertex_displacements() const {
  require_solved(impl_->solved, "vertex_displacements()");
  Eigen::MatrixX3d u(impl_->mesh.num_vertices(), 3);
  for (const auto& cell : impl_->dof_handler.active_cell_iterators())
    for (unsigned int v = 0; v < cell->n_vertices(); ++v)
      for (unsigned int c = 0; c < 3; ++c)
        u(cell->vertex_index(v), c) = impl_->solution[cell->vertex_dof_index(v, c)];
  return u;
}

Eigen::MatrixX3d ElasticityProblem::displacements_at(const Eigen::MatrixX3d& points) const {
  require_solved(impl_->solved, "displacements_at()");
  if (!impl_->locator) impl_->locator = std::make_unique<PointLocator>(impl_->mesh);
  Eigen::MatrixX3d u(points.rows(), 3);
  for (Eigen::Index p = 0; p < points.rows(); ++p)
    u.row(p) = impl_->evaluate(impl_->locator->locate(points.row(p).transpose())).transpose();
  return u;
}

double ElasticityProblem::relative_l2_error(const VectorField& exact) const {
  require_solved(impl_->solved, "relative_l2_error()");
  const Implementation& p = *impl_;
  FEValues<3> fe_values(p.mapping, p.fe, QGaussSimplex<3>(p.fe.degree + 2),
                        update_values | update_quadrature_points | update_JxW_values);
  Vector<double> solution(p.solution.begin(), p.solution.end());
  std::vector<Vector<double>> values(fe_values.n_quadrature_points, Vector<double>(3));
  double error_squared = 0.0, norm_squared = 0.0;
  for (const auto& cell : p.dof_handler.active_cell_iterators()) {
    if (!cell->is_locally_owned()) continue;
    fe_values.reinit(cell);
    fe_values.get_function_values(solution, values);
    for (unsigned int q = 0; q < fe_values.n_quadrature_points; ++q) {
      const Eigen::Vector3d u = exact(to_eigen(fe_values.quadrature_point(q)));
      for (unsigned int c = 0; c < 3; ++c) {
        error_squared += std::pow(values[q][c] - u[c], 2) * fe_values.JxW(q);
        norm_squared += u[c] * u[c] * fe_values.JxW(q);
      }
    }
  }
  error_squared = Utilities::MPI::sum(error_squared, p.communicator);
  norm_squared = Utilities::MPI::sum(norm_squared, p.communicator);
  return norm_squared > 0.0 ? std::sqrt(error_squared / norm_squared) : std::sqrt(error_squared);
}

double ElasticityProblem::max_nodal_error(const VectorField& exact) const {
  require_solved(impl_->solved, "max_nodal_error()");
  double largest = 0.0;
  for (std::size_t node = 0; node < impl_->solution.size(); node += 3) {
    const Eigen::Vector3d u = exact(to_eigen(impl_->dof_support_points[node]));
    for (unsigned int c = 0; c < 3; ++c)
      largest = std::max(largest, std::abs(impl_->solution[node + c] - u[c]));
  }
  return largest;
}

std::filesystem::path ElasticityProblem::output_results(const std::filesystem::path& directory,
                                                        const std::string& basename) const {
  require_solved(impl_->solved, "output_results()");
  const Implementation& p = *impl_;
  std::filesystem::create_directories(directory);
  Vector<double> solution(p.solution.begin(), p.solution.end());
  DataOut<3> data_out;
  data_out.attach_dof_handler(p.dof_handler);
  add_displacement(data_out, solution);
  Vector<float> partition(p.triangulation.n_active_cells()),
      youngs_modulus(p.triangulation.n_active_cells());
  for (const auto& cell : p.triangulation.active_cell_iterators()) {
    partition[cell->active_cell_index()] = float(cell->subdomain_id());
    const Material& m = p.model.material;
    youngs_modulus[cell->active_cell_index()] =
        float(m.youngs_modulus_field ? m.youngs_modulus_field(to_eigen(cell->center()))
                                     : m.youngs_modulus);
  }
  data_out.add_data_vector(partition, "partition");
  data_out.add_data_vector(youngs_modulus, "youngs_modulus");
  data_out.build_patches(p.mapping, p.fe.degree);
  const std::string pvtu =
      data_out.write_vtu_with_pvtu_record(directory.string() + "/", basename, 0, p.communicator, 1);
  const std::filesystem::path pvd = directory / (basename + ".pvd");
  if (Utilities::MPI::this_mpi_process(p.communicator) == 0) {
    std::ofstream out(pvd);
    DataOutBase::write_pvd_record(out, {{0.0, pvtu}});
  }
  // Every rank's files are complete when any rank returns.
  MPI_Barrier(p.communicator);
  return pvd;
}

std::filesystem::path ElasticityProblem::output_hdf5(const std::filesystem::path& directory,
                                                     const std::string& basename) const {
  require_solved(impl_->solved, "output_hdf5()");
  const Implementation& p = *impl_;
  Vector<double> solution(p.solution.begin(), p.solution.end());
  DataOut<3> data_out;
  data_out.attach_dof_handler(p.dof_handler);
  add_displacement(data_out, solution);
  data_out.build_patches(p.mapping, 1);
  return write_hdf5_and_xdmf(data_out, p.communicator, directory, basename);
}

std::filesystem::path write_vertex_displacement_hdf5(const VolumeMesh& mesh,
                                                     const Eigen::MatrixX3d& displacement,
                                                     const std::filesystem::path& directory,
                                                     const std::string& basename) {
  if (displacement.rows() != mesh.num_vertices())
    throw std::invalid_argument("displacement has " + std::to_string(displacement.rows()) +
                                " rows for a mesh of " + std::to_string(mesh.num_vertices()) +
                                " vertices");
  // Parallel HDF5 needs MPI, even on one process; PETSc is not used here (its start is collective,
  // and under mpirun only one rank writes the fields).
  detail::ensure_mpi_initialized();
  Triangulation<3> triangulation;
  create_triangulation(mesh, triangulation);
  // P1 interpolates the vertex values exactly, so the patches carry them unchanged.
  const FESystem<3> fe(FE_SimplexP<3>(1), 3);
  DoFHandler<3> dof_handler(triangulation);
  dof_handler.distribute_dofs(fe);
  Vector<double> values(dof_handler.n_dofs());
  for (const auto& cell : dof_handler.active_cell_iterators())
    for (unsigned int v = 0; v < cell->n_vertices(); ++v)
      for (unsigned int c = 0; c < 3; ++c)
        values[cell->vertex_dof_index(v, c)] = displacement(cell->vertex_index(v), c);
  DataOut<3> data_out;
  data_out.attach_dof_handler(dof_handler);
  add_displacement(data_out, values);
  data_out.build_patches(MappingFE<3>(FE_SimplexP<3>(1)), 1);
  return write_hdf5_and_xdmf(data_out, MPI_COMM_SELF, directory, basename);
}

}  // namespace msfem::fem_reference
