#include "msfem/fem_reference/verification.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "msfem/fem_reference/closed_forms.hpp"
#include "msfem/fem_reference/elasticity_problem.hpp"
#include "msfem/fem_reference/shape_mesher.hpp"
#include "msfem/fem_reference/supports_and_loads.hpp"
#include "verification_detail.hpp"

namespace msfem::fem_reference {

namespace detail {

RefinementLevel level_of(const ElasticityProblem& problem, const VolumeMesh& mesh, double error) {
  const SolveStatistics s = problem.statistics();
  RefinementLevel level;
  level.cell_size = std::cbrt(volume(mesh) / double(mesh.num_tetrahedra()));
  level.dofs = s.dofs;
  level.cells = s.cells;
  level.rel_l2_error = error;
  level.iterations = s.iterations;
  level.solve_time_s = s.solve_time_s;
  return level;
}

/// log(e_coarse / e_fine) / log(h_coarse / h_fine) over the two finest levels.
double observed_order(const std::vector<RefinementLevel>& levels) {
  const RefinementLevel& coarse = levels[levels.size() - 2];
  const RefinementLevel& fine = levels.back();
  return std::log(coarse.rel_l2_error / fine.rel_l2_error) /
         std::log(coarse.cell_size / fine.cell_size);
}

}  // namespace detail

using detail::level_of;
using detail::observed_order;

namespace {

constexpr double lame_inner_radius = 0.5, lame_outer_radius = 1.0, lame_pressure = 1e3;
constexpr double youngs_modulus = 1e5;  // Pa; the checks are linear, the value only scales u

/// Displacement error of the Lame octant (see check_lame) on one mesh.
RefinementLevel solve_lame(const VolumeMesh& mesh, unsigned int degree, double poisson_ratio) {
  const LameHollowSphere exact{lame_inner_radius, lame_outer_radius, lame_pressure, youngs_modulus,
                               poisson_ratio};
  const double a = lame_inner_radius, b = lame_outer_radius, plane_tolerance = 1e-9 * b;
  ElasticityModel model;
  model.degree = degree;
  model.material.youngs_modulus = youngs_modulus;
  model.material.poisson_ratio = poisson_ratio;
  // The inner surface's nodes: vertices on r = a, P2 edge midpoints of its facets just inside.
  Support inner;
  inner.name = "inner";
  inner.boundary_nodes_only = true;
  inner.region = [a](const Eigen::Vector3d& x) { return x.norm() <= a * (1 + 1e-9); };
  inner.displacement = [exact](const Eigen::Vector3d& x) { return exact.displacement(x); };
  model.supports.push_back(inner);
  for (int axis = 0; axis < 3; ++axis) {
    Support symmetry = fixed_support(
        "symmetry_" + std::string(1, char('x' + axis)),
        plane(Eigen::Vector3d::Zero(), Eigen::Vector3d::Unit(axis), plane_tolerance), true);
    symmetry.components = {{axis == 0, axis == 1, axis == 2}};
    model.supports.push_back(symmetry);
  }
  Traction outer;
  outer.name = "outer_pressure";
  outer.region = [a, b, plane_tolerance](const Eigen::Vector3d& centroid) {
    return centroid.norm() > 0.5 * (a + b) && centroid.minCoeff() > plane_tolerance;
  };
  outer.traction = [exact](const Eigen::Vector3d& x, const Eigen::Vector3d& n) -> Eigen::Vector3d {
    return exact.stress(x) * n;
  };
  model.tractions.push_back(outer);
  ElasticityProblem problem(mesh, model);
  problem.run();
  const double error = problem.relative_l2_error(
      [exact](const Eigen::Vector3d& x) { return exact.displacement(x); });
  return level_of(problem, mesh, error);
}

std::string format_nu(double nu) {
  std::ostringstream out;
  out << nu;
  return out.str();
}

}  // namespace

VerificationCheck check_patch() {
  VerificationCheck check;
  check.name = "patch";
  check.tolerance = 1e-10;
  const VolumeMesh mesh = mesh_ball(Eigen::Vector3d(0.1, -0.2, 0.3), 1.0, 0.3);
  Eigen::Matrix3d gradient;
  gradient << 1e-3, 2e-4, -3e-4, -1e-4, 2e-3, 5e-4, 3e-4, -2e-4, -1e-3;
  const Eigen::Vector3d offset(1e-3, -2e-3, 5e-4);
  const VectorField linear = [gradient, offset](const Eigen::Vector3d& x) -> Eigen::Vector3d {
    return offset + gradient * x;
  };
  double scale = 0.0;
  for (Eigen::Index i = 0; i < mesh.num_vertices(); ++i)
    scale = std::max(scale, linear(mesh.vertices.row(i).transpose()).norm());
  for (unsigned int degree : {1u, 2u}) {
    ElasticityModel model;
    model.degree = degree;
    model.material.youngs_modulus = youngs_modulus;
    model.material.poisson_ratio = 0.3;
    Support boundary = fixed_support(
        "boundary", [](const Eigen::Vector3d&) { return true; }, true);
    boundary.displacement = linear;
    model.supports.push_back(boundary);
    model.solver.preconditioner =
        Preconditioner::mumps;  // direct: no solver tolerance in the error
    ElasticityProblem problem(mesh, model);
    problem.run();
    const double error = problem.max_nodal_error(linear) / scale;
    check.rel_l2_error = std::max(check.rel_l2_error, error);
    check.levels.push_back(level_of(problem, mesh, error));
  }
  check.passed = check.rel_l2_error <= check.tolerance;
  check.note = "max nodal error / max |u|, P1 and P2, ball mesh, MUMPS";
  return check;
}

VerificationCheck check_lame(unsigned int degree, double poisson_ratio,
                             const std::vector<double>& cell_sizes) {
  VerificationCheck check;
  check.name = "lame_p" + std::to_string(degree) + "_nu" + format_nu(poisson_ratio);
  for (double h : cell_sizes)
    check.levels.push_back(solve_lame(
        mesh_hollow_sphere(lame_inner_radius, lame_outer_radius, h, true), degree, poisson_ratio));
  check.rel_l2_error = check.levels.back().rel_l2_error;
  check.required_order = degree == 1 ? 1.8 : 2.5;
  check.tolerance = degree == 1 ? 5e-2 : 5e-3;
  if (check.levels.size() >= 2) check.observed_order = observed_order(check.levels);
  check.passed = check.rel_l2_error <= check.tolerance && check.observed_order &&
                 *check.observed_order >= *check.required_order;
  check.note = "octant, exact traction on the faceted outer surface";
  return check;
}

VerificationCheck check_cantilever(double cell_size) {
  constexpr double length = 1.0, height = 0.1, width = 0.1, load = 1.0, nu = 0.3;
  VerificationCheck check;
  check.name = "cantilever_p2";
  check.tolerance = 0.02;
  const VolumeMesh mesh = mesh_box(Eigen::Vector3d(0, -height / 2, -width / 2),
                                   Eigen::Vector3d(length, height / 2, width / 2), cell_size);
  ElasticityModel model;
  model.degree = 2;
  model.material.youngs_modulus = youngs_modulus;
  model.material.poisson_ratio = nu;
  model.supports.push_back(
      fixed_support("clamp", plane(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX()), true));
  Traction end_load;
  end_load.name = "end_load";
  end_load.region = plane(Eigen::Vector3d(length, 0, 0), Eigen::Vector3d::UnitX(), 1e-9);
  end_load.traction = uniform_traction(Eigen::Vector3d(0, -load / (height * width), 0));
  model.tractions.push_back(end_load);
  ElasticityProblem problem(mesh, model);
  problem.run();
  const double deflection = -problem.displacements_at(Eigen::RowVector3d(length, 0, 0))(0, 1);
  const double expected =
      timoshenko_tip_deflection(load, length, height, width, youngs_modulus, nu);
  check.rel_l2_error = std::abs(deflection - expected) / expected;
  check.passed = check.rel_l2_error <= check.tolerance;
  check.levels.push_back(level_of(problem, mesh, check.rel_l2_error));
  std::ostringstream note;
  note << "tip deflection " << deflection << " m vs Timoshenko " << expected << " m";
  check.note = note.str();
  return check;
}

std::vector<LockingRow> locking_table(double cell_size, const std::vector<double>& poisson_ratios) {
  const VolumeMesh mesh = mesh_hollow_sphere(lame_inner_radius, lame_outer_radius, cell_size, true);
  std::vector<LockingRow> rows;
  for (double nu : poisson_ratios)
    rows.push_back(
        {nu, solve_lame(mesh, 1, nu).rel_l2_error, solve_lame(mesh, 2, nu).rel_l2_error});
  return rows;
}

VerificationReport run_verification(const VerificationSettings& settings) {
  VerificationReport report;
  report.checks.push_back(check_patch());
  for (double nu : {0.3, 0.45})
    for (unsigned int degree : {1u, 2u})
      report.checks.push_back(check_lame(degree, nu, settings.lame_cell_sizes));
  report.checks.push_back(check_cantilever(settings.cantilever_cell_size));
  for (unsigned int degree : {1u, 2u})
    report.checks.push_back(check_hertz_contact(
        degree, settings.contact_depth_ratios,
        degree == 1 ? settings.contact_cells_per_radius_p1 : settings.contact_cells_per_radius_p2));
  report.checks.push_back(check_hertz_bonded(settings.contact_depth_ratios,
                                             settings.contact_cells_per_radius_p2.back()));
  if (settings.locking_table)
    report.locking = locking_table(settings.lame_cell_sizes[settings.lame_cell_sizes.size() / 2],
                                   {0.3, 0.45, 0.49, 0.499});
  return report;
}

}  // namespace msfem::fem_reference
