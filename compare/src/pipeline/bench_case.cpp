#include "msfem/compare/pipeline/bench_case.hpp"

#include <filesystem>
#include <optional>

#include "msfem/compare/pipeline/fem_run.hpp"
#include "msfem/compare/pipeline/variant_run.hpp"

namespace msfem::compare {

massspring::BenchmarkCase sweep_bench_case(const std::string& name, const std::string& case_file,
                                           cases::Variant variant,
                                           const std::vector<std::string>& settings) {
  const std::filesystem::path file = std::filesystem::path(MSFEM_DEFAULT_CASES_DIR) / case_file;
  const cases::CaseParameters parameters = cases::read_case(file, settings);
  const Problem problem = make_problem(parameters);
  fem_reference::VolumeMesh mesh;
  if (variant == cases::Variant::tet_edges) mesh = mesh_problem(problem);
  std::optional<ToolPlacement> tool;
  if (!problem.tools.empty()) tool = problem.tools.front();
  BuiltVariant built = build_variant(variant, problem, mesh, tool);
  massspring::BenchmarkCase c;
  c.name = name;
  c.description = built.name + " of " + case_file + " as msfem sweep times it";
  for (const std::string& setting : settings)
    c.description += ", " + setting;
  c.network = built.model->network();
  c.volume_preservation = parameters.mass_spring.volume_preservation;
  // A pressed model's contact costs what its trajectory pushes into the tool, so the bench's own
  // explicit steps (on the pressed seed sphere a quarter of the sweep's for symplectic Euler, a
  // six-hundredth for RK4) would time another state of it.
  const auto sweep_dt = [&](massspring::IntegratorKind kind) {
    cases::TimingParameters timing = parameters.timing;
    timing.integrator = kind;
    timing.dt_s = 0.0;
    return timed_dt(*built.model, timing);
  };
  c.timed_dt.symplectic_euler = sweep_dt(massspring::IntegratorKind::symplectic_euler);
  c.timed_dt.explicit_euler = sweep_dt(massspring::IntegratorKind::explicit_euler);
  c.timed_dt.rk4 = sweep_dt(massspring::IntegratorKind::rk4);
  c.model = std::move(built.model);
  return c;
}

}  // namespace msfem::compare
