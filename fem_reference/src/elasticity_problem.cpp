#include "msfem/fem_reference/elasticity_problem.hpp"

#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/grid/tria.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "elasticity_problem_impl.hpp"
#include "msfem/fem_reference/errors.hpp"
#include "petsc_linear_system.hpp"

namespace msfem::fem_reference {

using namespace dealii;

namespace {

constexpr int dim = 3;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

void validate(const ElasticityModel& model) {
  if (model.degree != 1 && model.degree != 2)
    throw std::invalid_argument("element degree must be 1 or 2, got " +
                                std::to_string(model.degree));
  const Material& m = model.material;
  if (!m.youngs_modulus_field && !(m.youngs_modulus > 0.0 && std::isfinite(m.youngs_modulus)))
    throw std::invalid_argument("Young's modulus must be positive, got " +
                                std::to_string(m.youngs_modulus) + " Pa");
  if (!(m.poisson_ratio > -1.0 && m.poisson_ratio < 0.5))
    throw std::invalid_argument("Poisson's ratio must lie in (-1, 0.5), got " +
                                std::to_string(m.poisson_ratio));
  if (!(m.density >= 0.0)) throw std::invalid_argument("density must not be negative");
  if (model.supports.empty())
    throw FemError(
        "no support: without a fixed region or prescribed displacement the stiffness "
        "matrix is singular (rigid-body motion)");
  for (const Support& s : model.supports)
    if (!s.region) throw std::invalid_argument("support '" + s.name + "' has no region");
  for (const SphereObstacle& o : model.obstacles)
    if (!(o.radius > 0.0 && std::isfinite(o.radius)) || !o.center.allFinite() ||
        !(o.push_direction.norm() > 0.0) || !o.push_direction.allFinite() ||
        !(o.penalty_factor > 0.0 && std::isfinite(o.penalty_factor)) || o.max_iterations < 1)
      throw std::invalid_argument("obstacle '" + o.name +
                                  "' needs a finite positive radius, penalty factor and iteration "
                                  "limit, a finite centre and a non-zero push direction");
  for (const Traction& t : model.tractions)
    if (!t.region || !t.traction)
      throw std::invalid_argument("traction '" + t.name + "' is incomplete");
}

/// Rank 0's mesh on every rank: the shared triangulation needs the same coarse mesh everywhere, and
/// meshing on each rank need not give identical meshes.
VolumeMesh broadcast_from_rank_zero(const VolumeMesh& mesh, MPI_Comm communicator) {
  if (Utilities::MPI::n_mpi_processes(communicator) == 1) return mesh;
  std::array<long long, 3> sizes{
      {mesh.num_vertices(), mesh.num_tetrahedra(), mesh.num_surface_vertices}};
  MPI_Bcast(sizes.data(), 3, MPI_LONG_LONG, 0, communicator);
  VolumeMesh result = mesh;
  if (Utilities::MPI::this_mpi_process(communicator) != 0) {
    result.vertices.resize(Eigen::Index(sizes[0]), 3);
    result.tetrahedra.resize(Eigen::Index(sizes[1]), 4);
    result.num_surface_vertices = Eigen::Index(sizes[2]);
  }
  MPI_Bcast(result.vertices.data(), int(result.vertices.size()), MPI_DOUBLE, 0, communicator);
  MPI_Bcast(result.tetrahedra.data(), int(result.tetrahedra.size()), MPI_INT, 0, communicator);
  return result;
}

/// PETSc's preallocation for the owned rows [first, end): per row, the columns in the owned block
/// and outside it. Counted per node (DoFs 3k..3k+2 share their cells, checked in setup_system) from
/// each owned node's cells, nine times fewer insertions than a DoF sparsity pattern and no pattern
/// kept: this was a third of the set-up of a 1 M-DoF P1 problem.
void count_row_nonzeros(const DoFHandler<dim>& dof_handler, types::global_dof_index first,
                        types::global_dof_index end, std::vector<PetscInt>& diagonal,
                        std::vector<PetscInt>& off_diagonal) {
  const FiniteElement<dim>& fe = dof_handler.get_fe();
  const std::size_t first_node = first / dim, end_node = end / dim,
                    owned_nodes = end_node - first_node;
  std::vector<types::global_dof_index> dofs(fe.n_dofs_per_cell()), nodes;
  const auto cell_nodes = [&](const DoFHandler<dim>::active_cell_iterator& cell) {
    cell->get_dof_indices(dofs);
    nodes.clear();
    for (unsigned int i = 0; i < dofs.size(); ++i)
      if (fe.system_to_component_index(i).first == 0) nodes.push_back(dofs[i] / dim);
  };
  // Owned node -> its cells' nodes, duplicates included (CSR), then sorted and made unique per
  // node.
  std::vector<std::size_t> offsets(owned_nodes + 1, 0);
  for (const auto& cell : dof_handler.active_cell_iterators()) {
    cell_nodes(cell);
    for (const auto node : nodes)
      if (node >= first_node && node < end_node) offsets[node - first_node + 1] += nodes.size();
  }
  for (std::size_t k = 0; k < owned_nodes; ++k)
    offsets[k + 1] += offsets[k];
  std::vector<types::global_dof_index> neighbours(offsets.back());
  std::vector<std::size_t> fill(offsets.begin(), offsets.end() - 1);
  for (const auto& cell : dof_handler.active_cell_iterators()) {
    cell_nodes(cell);
    for (const auto node : nodes)
      if (node >= first_node && node < end_node)
        for (const auto other : nodes)
          neighbours[fill[node - first_node]++] = other;
  }
  diagonal.assign(end - first, 0);
  off_diagonal.assign(end - first, 0);
  for (std::size_t k = 0; k < owned_nodes; ++k) {
    const auto begin = neighbours.begin() + std::ptrdiff_t(offsets[k]);
    const auto last = neighbours.begin() + std::ptrdiff_t(offsets[k + 1]);
    std::sort(begin, last);
    const auto stop = std::unique(begin, last);
    PetscInt inside = 0, outside = 0;
    for (auto it = begin; it != stop; ++it)
      ++(*it >= first_node && *it < end_node ? inside : outside);
    for (unsigned int c = 0; c < dim; ++c) {
      diagonal[dim * k + c] = dim * inside;
      off_diagonal[dim * k + c] = dim * outside;
    }
  }
}

}  // namespace

void create_triangulation(const VolumeMesh& mesh, Triangulation<3>& triangulation) {
  std::vector<Point<dim>> vertices(std::size_t(mesh.num_vertices()));
  for (Eigen::Index i = 0; i < mesh.num_vertices(); ++i)
    vertices[std::size_t(i)] =
        Point<dim>(mesh.vertices(i, 0), mesh.vertices(i, 1), mesh.vertices(i, 2));
  std::vector<CellData<dim>> cells(std::size_t(mesh.num_tetrahedra()), CellData<dim>(4));
  for (Eigen::Index e = 0; e < mesh.num_tetrahedra(); ++e)
    for (unsigned int k = 0; k < 4; ++k)
      cells[std::size_t(e)].vertices[k] = unsigned(mesh.tetrahedra(e, k));
  triangulation.create_triangulation(vertices, cells, SubCellData());
}

namespace {

/// With constant E and body force, P_k's stiffness integrand is a polynomial of degree 2(k - 1) and
/// its load integrand of degree k: QGaussSimplex(k) (1 point, exact to degree 1; 4 points, exact to
/// degree 2) integrates both exactly with a quarter (P1) or 40 % (P2) of the points of
/// QGaussSimplex(k + 1), whose extra points cost a third of a 1 M-DoF P1 assembly. A varying E(x)
/// is then integrated to second (P1) or third (P2) order, no worse than the discretisation.
QGaussSimplex<3> cell_quadrature(unsigned int degree) {
  return QGaussSimplex<3>(degree);
}

/// Local cell matrix and load vector of linear elasticity,
///   K_ij = int lambda div(phi_i) div(phi_j) + 2 mu eps(phi_i) : eps(phi_j) dx,
///   f_i  = int phi_i . b dx + int_{loaded faces} phi_i . t ds,
/// with Lame parameters from E(x), nu at each quadrature point.
class CellAssembler {
 public:
  explicit CellAssembler(const ElasticityProblem::Implementation& problem)
      : problem_(problem),
        model_(problem.model),
        fe_values_(problem.mapping, problem.fe, cell_quadrature(problem.fe.degree),
                   update_values | update_gradients | update_quadrature_points | update_JxW_values),
        face_values_(
            problem.mapping, problem.fe, QGaussSimplex<dim - 1>(problem.fe.degree + 1),
            update_values | update_quadrature_points | update_normal_vectors | update_JxW_values),
        symmetric_gradients_(problem.fe.n_dofs_per_cell()),
        divergences_(problem.fe.n_dofs_per_cell()),
        loaded_faces_(problem.model.tractions.size(), 0) {}

  void assemble(const ElasticityProblem::Implementation::CellIterator& cell,
                std::vector<double>& matrix, std::vector<double>& rhs, Eigen::Vector3d& load_sum) {
    const unsigned int n = problem_.fe.n_dofs_per_cell();
    matrix.assign(n * n, 0.0);
    rhs.assign(n, 0.0);
    fe_values_.reinit(cell);
    const FEValuesExtractors::Vector displacement(0);
    const Material& material = model_.material;
    const double nu = material.poisson_ratio;
    for (unsigned int q = 0; q < fe_values_.n_quadrature_points; ++q) {
      const Eigen::Vector3d x = to_eigen(fe_values_.quadrature_point(q));
      const double E = youngs_modulus_at(x);
      const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
      const double JxW = fe_values_.JxW(q);
      for (unsigned int i = 0; i < n; ++i) {
        symmetric_gradients_[i] = fe_values_[displacement].symmetric_gradient(i, q);
        divergences_[i] = trace(symmetric_gradients_[i]);
      }
      for (unsigned int i = 0; i < n; ++i)
        for (unsigned int j = i; j < n; ++j)
          matrix[i * n + j] += (lambda * divergences_[i] * divergences_[j] +
                                2 * mu * (symmetric_gradients_[i] * symmetric_gradients_[j])) *
                               JxW;
      Eigen::Vector3d body = material.density * material.gravity;
      if (model_.body_force) body += model_.body_force(x);
      for (unsigned int i = 0; i < n; ++i) {
        const unsigned int c = problem_.fe.system_to_component_index(i).first;
        const double contribution = fe_values_.shape_value(i, q) * body[c] * JxW;
        rhs[i] += contribution;
        load_sum[c] += contribution;
      }
    }
    for (unsigned int i = 0; i < n; ++i)
      for (unsigned int j = 0; j < i; ++j)
        matrix[i * n + j] = matrix[j * n + i];
    if (!model_.tractions.empty()) assemble_tractions(cell, rhs, load_sum);
  }

  const std::vector<long>& loaded_faces() const { return loaded_faces_; }
  double youngs_modulus_min() const { return youngs_modulus_min_; }
  double youngs_modulus_max() const { return youngs_modulus_max_; }

 private:
  double youngs_modulus_at(const Eigen::Vector3d& x) const {
    const Material& material = model_.material;
    if (!material.youngs_modulus_field) return material.youngs_modulus;
    const double E = material.youngs_modulus_field(x);
    if (!(E > 0.0 && std::isfinite(E)))
      throw std::invalid_argument("Young's modulus field must be positive, got " +
                                  std::to_string(E) + " Pa at (" + std::to_string(x.x()) + ", " +
                                  std::to_string(x.y()) + ", " + std::to_string(x.z()) + ")");
    youngs_modulus_min_ = std::min(youngs_modulus_min_, E);
    youngs_modulus_max_ = std::max(youngs_modulus_max_, E);
    return E;
  }

  void assemble_tractions(const ElasticityProblem::Implementation::CellIterator& cell,
                          std::vector<double>& rhs, Eigen::Vector3d& load_sum) {
    for (const unsigned int f : cell->face_indices()) {
      if (!cell->face(f)->at_boundary()) continue;
      const Eigen::Vector3d centroid = to_eigen(cell->face(f)->center());
      for (std::size_t t = 0; t < model_.tractions.size(); ++t) {
        const Traction& traction = model_.tractions[t];
        if (!traction.region(centroid)) continue;
        ++loaded_faces_[t];
        face_values_.reinit(cell, f);
        for (unsigned int q = 0; q < face_values_.n_quadrature_points; ++q) {
          const Eigen::Vector3d x = to_eigen(face_values_.quadrature_point(q));
          const Tensor<1, dim> normal = face_values_.normal_vector(q);
          const Eigen::Vector3d load =
              traction.traction(x, Eigen::Vector3d(normal[0], normal[1], normal[2]));
          for (unsigned int i = 0; i < problem_.fe.n_dofs_per_cell(); ++i) {
            const unsigned int c = problem_.fe.system_to_component_index(i).first;
            const double contribution =
                face_values_.shape_value(i, q) * load[c] * face_values_.JxW(q);
            rhs[i] += contribution;
            load_sum[c] += contribution;
          }
        }
      }
    }
  }

  const ElasticityProblem::Implementation& problem_;
  const ElasticityModel& model_;
  FEValues<dim> fe_values_;
  FEFaceValues<dim> face_values_;
  std::vector<SymmetricTensor<2, dim>> symmetric_gradients_;
  std::vector<double> divergences_;
  std::vector<long> loaded_faces_;  ///< boundary faces each traction was applied to
  // What the field gave at this rank's quadrature points (youngs_modulus_at is const: a record).
  mutable double youngs_modulus_min_ = std::numeric_limits<double>::infinity();
  mutable double youngs_modulus_max_ = -std::numeric_limits<double>::infinity();
};

}  // namespace

ElasticityProblem::Implementation::Implementation(const VolumeMesh& mesh_, ElasticityModel model_)
    : communicator(MPI_COMM_WORLD),
      mesh(broadcast_from_rank_zero(mesh_, communicator)),
      model(std::move(model_)),
      triangulation(communicator, Triangulation<dim>::none, false,
                    parallel::shared::Triangulation<dim>::partition_custom_signal),
      fe(FE_SimplexP<dim>(model.degree == 2 ? 2 : 1), dim),
      mapping(FE_SimplexP<dim>(1)),
      dof_handler(triangulation) {
  // The shared triangulation leaves a custom partition to this signal, emitted while it is created
  // and before it records the owners.
  triangulation.signals.create.connect([this] {
    const std::vector<unsigned int> part =
        partition_cells(mesh, Utilities::MPI::n_mpi_processes(communicator));
    for (const auto& cell : triangulation.active_cell_iterators())
      cell->set_subdomain_id(part[cell->active_cell_index()]);
  });
}

ElasticityProblem::Implementation::~Implementation() = default;

ElasticityProblem::ElasticityProblem(const VolumeMesh& mesh, ElasticityModel model) {
  validate(model);
  detail::ensure_petsc_initialized();
  impl_ = std::make_unique<Implementation>(mesh, std::move(model));
  check_volume_mesh(impl_->mesh);  // rank 0's, which every rank now holds
}

ElasticityProblem::~ElasticityProblem() = default;

void ElasticityProblem::run() {
  impl_->setup_system();
  impl_->assemble_system();
  impl_->solve();
  impl_->compute_reactions();
}

SolveStatistics ElasticityProblem::statistics() const {
  return impl_->statistics;
}

Eigen::Vector3d ElasticityProblem::reaction_force(const std::string& support_name) const {
  if (!impl_->solved) throw std::logic_error("reaction_force() before run()");
  for (std::size_t s = 0; s < impl_->model.supports.size(); ++s)
    if (impl_->model.supports[s].name == support_name) return impl_->support_reactions[s];
  throw std::invalid_argument("no support named '" + support_name + "'");
}

Eigen::Vector3d ElasticityProblem::total_applied_load() const {
  return impl_->applied_load;
}

double ElasticityProblem::equilibrium_defect() const {
  Eigen::Vector3d sum = impl_->applied_load;
  double scale = impl_->applied_load.norm();
  for (const Eigen::Vector3d& r : impl_->support_reactions) {
    sum += r;
    scale = std::max(scale, r.norm());
  }
  for (const ContactReport& c : impl_->contact_reports) {
    sum += c.force;
    scale = std::max(scale, c.force.norm());
  }
  return scale > 0.0 ? sum.norm() / scale : 0.0;
}

void ElasticityProblem::Implementation::setup_system() {
  const auto start = Clock::now();
  create_triangulation(mesh, triangulation);
  // The partition comes from the create signal; should a deal.II version stop emitting it before
  // the owners are recorded, rank 0 would silently own everything.
  const unsigned int ranks = Utilities::MPI::n_mpi_processes(communicator);
  if (ranks > 1 && triangulation.n_active_cells() >= ranks &&
      Utilities::MPI::min(triangulation.n_locally_owned_active_cells(), communicator) == 0)
    throw FemError("the mesh partition left a rank without cells");
  cell_of_tetrahedron.assign(std::size_t(mesh.num_tetrahedra()), dof_handler.end());
  dof_handler.distribute_dofs(fe);
  for (const auto& cell : dof_handler.active_cell_iterators()) {
    const auto index = std::size_t(cell->active_cell_index());
    for (unsigned int k = 0; k < 4; ++k)
      if (cell->vertex_index(k) != unsigned(mesh.tetrahedra(Eigen::Index(index), k)))
        throw FemError("deal.II reordered the vertices of cell " + std::to_string(index));
    cell_of_tetrahedron[index] = cell;
  }
  const IndexSet owned = dof_handler.locally_owned_dofs();
  // PETSc's block size 3 needs each rank to own whole nodes with x, y, z consecutive: deal.II
  // numbers a FESystem's DoFs node by node, and a node's DoFs share an owner.
  if (!owned.is_contiguous() || owned.n_elements() % 3 != 0 ||
      (owned.n_elements() > 0 && owned.nth_index_in_set(0) % 3 != 0))
    throw FemError("DoFs are not interleaved by node; cannot use block size 3");
  locate_dof_support_points();
  collect_prescribed_dofs();

  const types::global_dof_index first = owned.n_elements() > 0 ? owned.nth_index_in_set(0) : 0;
  std::vector<PetscInt> diagonal_nonzeros, off_diagonal_nonzeros;
  count_row_nonzeros(dof_handler, first, first + owned.n_elements(), diagonal_nonzeros,
                     off_diagonal_nonzeros);
  linear_system = std::make_unique<detail::PetscLinearSystem>(
      communicator, PetscInt(dof_handler.n_dofs()), PetscInt(first), PetscInt(owned.n_elements()),
      diagonal_nonzeros, off_diagonal_nonzeros,
      two_level() ? detail::MatrixStorage::node_blocks : detail::MatrixStorage::scalar);

  statistics.dofs = dof_handler.n_dofs();
  statistics.cells = triangulation.n_active_cells();
  statistics.vertices = triangulation.n_vertices();
  statistics.mpi_ranks = int(Utilities::MPI::n_mpi_processes(communicator));
  statistics.setup_time_s = seconds_since(start);
}

void ElasticityProblem::Implementation::locate_dof_support_points() {
  const std::size_t n_dofs = dof_handler.n_dofs();
  dof_support_points.assign(n_dofs, Point<dim>());
  dof_on_boundary.assign(n_dofs, false);
  const std::vector<Point<dim>>& unit_points = fe.get_unit_support_points();
  std::vector<types::global_dof_index> dofs(fe.n_dofs_per_cell());
  for (const auto& cell : dof_handler.active_cell_iterators()) {
    cell->get_dof_indices(dofs);
    // The mapping is affine (P1): x = v0 + sum_k xi_k (v_k - v0).
    const Point<dim> v0 = cell->vertex(0);
    for (unsigned int i = 0; i < dofs.size(); ++i) {
      Point<dim> x = v0;
      for (unsigned int k = 0; k < dim; ++k)
        x += unit_points[i][k] * (cell->vertex(k + 1) - v0);
      dof_support_points[dofs[i]] = x;
    }
    // A DoF lies on face f iff its barycentric coordinate of the vertex opposite f is zero.
    for (const unsigned int f : cell->face_indices()) {
      if (!cell->face(f)->at_boundary()) continue;
      unsigned int opposite = 0;
      for (unsigned int k = 0; k < 4; ++k) {
        bool on_face = false;
        for (unsigned int j = 0; j < 3; ++j)
          on_face |= cell->face(f)->vertex_index(j) == cell->vertex_index(k);
        if (!on_face) opposite = k;
      }
      for (unsigned int i = 0; i < dofs.size(); ++i) {
        const Point<dim>& xi = unit_points[i];
        const double barycentric = opposite == 0 ? 1.0 - xi[0] - xi[1] - xi[2] : xi[opposite - 1];
        if (std::abs(barycentric) < 1e-12) dof_on_boundary[dofs[i]] = true;
      }
    }
  }
}

void ElasticityProblem::Implementation::collect_prescribed_dofs() {
  const std::size_t n_dofs = dof_handler.n_dofs();
  dof_support.assign(n_dofs, -1);
  prescribed_value.assign(n_dofs, 0.0);
  std::vector<long> caught(model.supports.size(), 0);
  // DoFs 3k, 3k+1, 3k+2 are one node (checked in setup_system): test each region once per node.
  for (std::size_t node = 0; node < n_dofs; node += 3) {
    const Eigen::Vector3d x = to_eigen(dof_support_points[node]);
    for (std::size_t s = 0; s < model.supports.size(); ++s) {
      const Support& support = model.supports[s];
      if (support.boundary_nodes_only && !dof_on_boundary[node]) continue;
      if (!support.region(x)) continue;
      const Eigen::Vector3d u =
          support.displacement ? support.displacement(x) : Eigen::Vector3d::Zero();
      bool any = false;
      for (unsigned int c = 0; c < dim; ++c) {
        if (!support.components[c] || dof_support[node + c] >= 0) continue;
        dof_support[node + c] = int(s);
        prescribed_value[node + c] = u[c];
        any = true;
      }
      if (any) ++caught[s];
    }
  }
  statistics.prescribed_dofs = 0;
  for (int s : dof_support)
    statistics.prescribed_dofs += s >= 0;
  for (std::size_t s = 0; s < model.supports.size(); ++s)
    if (caught[s] == 0)
      throw std::invalid_argument("support '" + model.supports[s].name +
                                  "' catches no node of the mesh");
}

void ElasticityProblem::Implementation::assemble_system() {
  const auto start = Clock::now();
  CellAssembler assembler(*this);
  std::vector<double> matrix, rhs;
  std::vector<types::global_dof_index> dofs(fe.n_dofs_per_cell());
  std::vector<PetscInt> petsc_dofs(fe.n_dofs_per_cell());
  Eigen::Vector3d load = Eigen::Vector3d::Zero();
  // A bad E(x) may show on one rank's cells only: every rank must learn of it before the
  // collective assembly, or the others would wait for ever.
  std::string bad_input;
  try {
    for (const auto& cell : dof_handler.active_cell_iterators()) {
      if (!cell->is_locally_owned()) continue;
      assembler.assemble(cell, matrix, rhs, load);
      cell->get_dof_indices(dofs);
      for (std::size_t i = 0; i < dofs.size(); ++i)
        petsc_dofs[i] = PetscInt(dofs[i]);
      linear_system->add_cell(petsc_dofs, matrix, rhs);
    }
  } catch (const std::invalid_argument& e) {
    bad_input = e.what();
  }
  if (Utilities::MPI::max(int(!bad_input.empty()), communicator) > 0)
    throw std::invalid_argument(bad_input.empty()
                                    ? std::string("Young's modulus field is not positive on "
                                                  "another rank's cells")
                                    : bad_input);
  linear_system->finish_assembly();
  const bool field = bool(model.material.youngs_modulus_field);
  statistics.youngs_modulus_min =
      field ? Utilities::MPI::min(assembler.youngs_modulus_min(), communicator)
            : model.material.youngs_modulus;
  statistics.youngs_modulus_max =
      field ? Utilities::MPI::max(assembler.youngs_modulus_max(), communicator)
            : model.material.youngs_modulus;
  for (int c = 0; c < dim; ++c)
    applied_load[c] = Utilities::MPI::sum(load[c], communicator);
  for (std::size_t t = 0; t < model.tractions.size(); ++t)
    if (Utilities::MPI::sum(assembler.loaded_faces()[t], communicator) == 0)
      throw std::invalid_argument("traction '" + model.tractions[t].name +
                                  "' catches no boundary face");
  statistics.assemble_time_s = seconds_since(start);
}

void ElasticityProblem::Implementation::solve() {
  const auto start = Clock::now();
  const IndexSet owned = dof_handler.locally_owned_dofs();
  const types::global_dof_index first = owned.n_elements() > 0 ? owned.nth_index_in_set(0) : 0;
  std::vector<PetscInt> rows;
  std::vector<double> values, coordinates(owned.n_elements());
  for (types::global_dof_index i = first; i < first + owned.n_elements(); ++i) {
    coordinates[i - first] = dof_support_points[i][i % dim];
    if (dof_support[i] < 0) continue;
    rows.push_back(PetscInt(i));
    values.push_back(prescribed_value[i]);
  }
  linear_system->apply_prescribed_values(rows, values);
  if (two_level()) linear_system->set_coarse_space(p1_coarse_space());
  const detail::KrylovReport report = model.obstacles.empty()
                                          ? linear_system->solve(model.solver, coordinates)
                                          : solve_with_contact(coordinates);
  solution = linear_system->gathered_solution();
  linear_system.reset();
  // Prescribed values exactly, not up to the solver's tolerance.
  for (std::size_t i = 0; i < solution.size(); ++i)
    if (dof_support[i] >= 0) solution[i] = prescribed_value[i];
  statistics.iterations = report.iterations;
  statistics.residual_norm = report.residual_norm;
  statistics.solve_time_s = seconds_since(start);
  solved = true;
}

void ElasticityProblem::Implementation::compute_reactions() {
  // The residual K u - f at the prescribed DoFs, rebuilt from the cells that touch them, is the
  // force each support exerts on the body (not a stress integral: exact for the discrete system).
  CellAssembler assembler(*this);
  std::vector<double> matrix, rhs;
  std::vector<types::global_dof_index> dofs(fe.n_dofs_per_cell());
  std::vector<Eigen::Vector3d> reactions(model.supports.size(), Eigen::Vector3d::Zero());
  Eigen::Vector3d unused_load = Eigen::Vector3d::Zero();
  const unsigned int n = fe.n_dofs_per_cell();
  for (const auto& cell : dof_handler.active_cell_iterators()) {
    if (!cell->is_locally_owned()) continue;
    cell->get_dof_indices(dofs);
    bool touches_support = false;
    for (const auto dof : dofs)
      touches_support |= dof_support[dof] >= 0;
    if (!touches_support) continue;
    assembler.assemble(cell, matrix, rhs, unused_load);
    for (unsigned int i = 0; i < n; ++i) {
      const int s = dof_support[dofs[i]];
      if (s < 0) continue;
      double residual = -rhs[i];
      for (unsigned int j = 0; j < n; ++j)
        residual += matrix[i * n + j] * solution[dofs[j]];
      reactions[std::size_t(s)][fe.system_to_component_index(i).first] += residual;
    }
  }
  // K u - f at a prescribed DoF also holds the contact force on its node; the support's own
  // reaction is the rest.
  for (const auto& [dof, force] : contact_dof_force)
    if (dof_support[dof] >= 0) reactions[std::size_t(dof_support[dof])][dof % dim] -= force;
  support_reactions.resize(reactions.size());
  for (std::size_t s = 0; s < reactions.size(); ++s)
    for (int c = 0; c < dim; ++c)
      support_reactions[s][c] = Utilities::MPI::sum(reactions[s][c], communicator);
}

}  // namespace msfem::fem_reference
