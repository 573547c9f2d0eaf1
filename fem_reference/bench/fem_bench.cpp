// fem_reference_bench: the FEM reference's stages (Gmsh mesh, set-up, assembly, solve), iterations
// and peak memory on its two speed benchmarks (the P1 sphere, the P2 brain; results/BENCHMARKS.md),
// serially or under mpirun. The parallel efficiency from 1 to N ranks is the ratio of two such
// runs, taken back to back.
//
//   fem_reference_bench sphere|brain [--degree 1|2] [--cell-size M] [--level L] [--algorithm 1|10]
//                       [--relocate 0|1]
//
// sphere: icosphere of radius 5 cm (level L, default 5), inner core (surface / 2) fixed, a 5 mm
// tool pressed 5 mm at the pole. brain: cases/data/brain_icbm152_lh_9177_mm.obj, base below z = -30
// mm fixed, a 5 mm tool pressed 4 mm at the top. Both refine to half the cell size within 1 cm of
// the tool, as `msfem run` does. Meshing runs on rank 0 (the problem broadcasts rank 0's mesh). One
// JSON object on stdout (with the worst cell's quality, see cell_quality); PETSc options
// (PETSC_OPTIONS, e.g. GAMG's) apply to the solve.
#include <mpi.h>
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <string>

#include "msfem/cases/surface.hpp"
#include "msfem/cases/surface_generators.hpp"
#include "msfem/cases/surface_io.hpp"
#include "msfem/fem_reference/elasticity_problem.hpp"
#include "msfem/fem_reference/supports_and_loads.hpp"
#include "msfem/fem_reference/surface_mesher.hpp"

namespace {

using namespace msfem;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

std::string load_average() {
  std::ifstream in("/proc/loadavg");
  std::string one, five, fifteen;
  in >> one >> five >> fifteen;
  return one + " " + five + " " + fifteen;
}

// This process's CPU time: under a load from other programs it counts only what this one ran,
// so two settings compare more fairly than by wall time (an MPI rank waiting spins, and counts).
double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// PETSC_OPTIONS as given (quotes and backslashes escaped for JSON): a run records its solver
// options.
std::string petsc_options() {
  const char* value = std::getenv("PETSC_OPTIONS");
  std::string out;
  for (const char* c = value ? value : ""; *c; ++c) {
    if (*c == '"' || *c == '\\') out += '\\';
    out += *c;
  }
  return out;
}

double peak_rss_mb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return double(usage.ru_maxrss) / 1024.0;  // kB on Linux
}

struct Settings {
  std::string shape;
  unsigned int degree = 1;
  double cell_size = 0.0;
  int level = 5;
  int algorithm = 1;
  bool relocate = true;  ///< 0: MeshOptions::relocate_below_quality = 0 (never)
};

Settings parse(int argc, char** argv) {
  Settings s;
  if (argc < 2) throw std::invalid_argument("usage: fem_reference_bench sphere|brain [options]");
  s.shape = argv[1];
  if (s.shape != "sphere" && s.shape != "brain")
    throw std::invalid_argument("shape must be sphere or brain, got '" + s.shape + "'");
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string key = argv[i], value = argv[i + 1];
    if (key == "--degree")
      s.degree = unsigned(std::stoi(value));
    else if (key == "--cell-size")
      s.cell_size = std::stod(value);
    else if (key == "--level")
      s.level = std::stoi(value);
    else if (key == "--algorithm")
      s.algorithm = std::stoi(value);
    else if (key == "--relocate")
      s.relocate = std::stoi(value) != 0;
    else
      throw std::invalid_argument("unknown option '" + key + "'");
  }
  if (!(s.cell_size > 0.0)) throw std::invalid_argument("--cell-size M (metres) is required");
  return s;
}

struct Setup {
  cases::Surface surface;
  fem_reference::ToolIndentation tool;
  fem_reference::Support fixed;
};

Setup make_setup(const Settings& s) {
  Setup setup;
  if (s.shape == "sphere") {
    setup.surface = cases::icosphere(s.level, 0.05);
    setup.tool = {Eigen::Vector3d(0, 0, 0.05), Eigen::Vector3d::UnitZ(), 0.005, 0.005};
    setup.fixed = fem_reference::fixed_support(
        "fixed", fem_reference::inner_core(setup.surface.vertices, setup.surface.triangles, 2.0));
    return setup;
  }
  setup.surface =
      cases::read_surface(std::string(MSFEM_CASES_DIR) + "/data/brain_icbm152_lh_9177_mm.obj",
                          cases::LengthUnit::millimetre);
  if (cases::signed_volume(setup.surface) < 0.0)
    setup.surface.triangles.col(1).swap(
        setup.surface.triangles.col(2));  // the mesher wants outward triangles
  // The top of the hemisphere, with the direction from the centroid as its normal.
  const Eigen::Vector3d centroid = setup.surface.vertices.colwise().mean().transpose();
  Eigen::Index top = 0;
  setup.surface.vertices.col(2).maxCoeff(&top);
  const Eigen::Vector3d p = setup.surface.vertices.row(top).transpose();
  setup.tool = {p, (p - centroid).normalized(), 0.005, 0.004};
  setup.fixed = fem_reference::fixed_support(
      "fixed", fem_reference::half_space(Eigen::Vector3d(0, 0, -0.030), -Eigen::Vector3d::UnitZ()));
  return setup;
}

}  // namespace

int main(int argc, char** argv) {
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_SERIALIZED, &provided);
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  int status = 0;
  try {
    const Settings settings = parse(argc, argv);
    const std::string load_before = load_average();
    const auto start = Clock::now();
    const Setup setup = make_setup(settings);
    fem_reference::MeshOptions mesh_options;
    mesh_options.cell_size = settings.cell_size;
    mesh_options.algorithm_3d = settings.algorithm;
    if (!settings.relocate) mesh_options.relocate_below_quality = 0.0;
    mesh_options.refinements.push_back({setup.tool.contact_point, 2 * setup.tool.radius,
                                        2 * setup.tool.radius, 0.5 * settings.cell_size});
    const auto mesh_start = Clock::now();
    fem_reference::VolumeMesh mesh;
    if (rank == 0)
      mesh = fem_reference::mesh_closed_surface(setup.surface.vertices, setup.surface.triangles,
                                                mesh_options);
    const double mesh_s = seconds_since(mesh_start);
    const double rss_after_mesh = peak_rss_mb();
    const double worst_quality = rank == 0 ? fem_reference::cell_quality(mesh).minCoeff() : 0.0;

    fem_reference::ElasticityModel model;
    model.degree = settings.degree;
    model.material = {3e3, {}, 0.45, 1040, Eigen::Vector3d(0, 0, -9.81)};
    model.supports.push_back(fem_reference::tool_support(setup.tool));
    model.supports.push_back(setup.fixed);
    const auto problem_start = Clock::now();
    const double problem_cpu_start = cpu_seconds();
    fem_reference::ElasticityProblem problem(mesh, model);
    problem.run();
    const double problem_s = seconds_since(problem_start);
    const double problem_cpu_s = cpu_seconds() - problem_cpu_start;
    const fem_reference::SolveStatistics st = problem.statistics();
    const Eigen::Vector3d force = -problem.reaction_force("tool");
    const double total_s = seconds_since(start);

    double rss = peak_rss_mb(), rss_max = 0.0, rss_sum = 0.0;
    MPI_Reduce(&rss, &rss_max, 1, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
    MPI_Reduce(&rss, &rss_sum, 1, MPI_DOUBLE, MPI_SUM, 0, MPI_COMM_WORLD);
    if (rank == 0)
      std::printf(
          "{\"shape\": \"%s\", \"degree\": %u, \"cell_size_m\": %g, \"algorithm_3d\": %d, "
          "\"relocate\": %d, \"worst_cell_quality\": %.4f, \"mpi_ranks\": %d, \"dofs\": %zu, "
          "\"cells\": %zu, \"vertices\": %zu, "
          "\"iterations\": %d, \"mesh_s\": %.3f, \"setup_s\": %.3f, \"assemble_s\": %.3f, "
          "\"solve_s\": %.3f, \"problem_s\": %.3f, \"problem_cpu_s_rank0\": %.3f, "
          "\"mesh_assemble_solve_s\": %.3f, "
          "\"total_s\": %.3f, \"tool_force_z_n\": %.6g, \"equilibrium_defect\": %.3g, "
          "\"peak_rss_mb_rank0_after_mesh\": %.0f, \"peak_rss_mb_largest_rank\": %.0f, "
          "\"peak_rss_mb_all_ranks\": %.0f, \"load_average_before\": \"%s\", "
          "\"load_average_after\": \"%s\", \"petsc_options\": \"%s\"}\n",
          settings.shape.c_str(), settings.degree, settings.cell_size, settings.algorithm,
          int(settings.relocate), worst_quality, ranks, st.dofs, st.cells, st.vertices,
          st.iterations, mesh_s, st.setup_time_s, st.assemble_time_s, st.solve_time_s, problem_s,
          problem_cpu_s, mesh_s + st.assemble_time_s + st.solve_time_s, total_s, force.z(),
          problem.equilibrium_defect(), rss_after_mesh, rss_max, rss_sum, load_before.c_str(),
          load_average().c_str(), petsc_options().c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fem_reference_bench (rank %d): error: %s\n", rank, e.what());
    status = 2;
  }
  // PETSc is finalised from MPI_Finalize (fem_reference hooks it there).
  if (status != 0) MPI_Abort(MPI_COMM_WORLD, status);
  MPI_Finalize();
  return status;
}
