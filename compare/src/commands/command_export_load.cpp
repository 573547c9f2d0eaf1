// msfem export-load CASE.prm OUTDIR: what an outside simulator needs to reproduce each load of the
// case, so that its answer can come back as a variant (mass spring/results, docs/external.md):
// surface.vtu (the case's surface, metres, with vertex_id and fixed) and loads.json.
#include <iostream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "msfem/cases/case_parameters.hpp"
#include "msfem/cases/setting_names.hpp"
#include "msfem/compare/commands/commands.hpp"
#include "msfem/compare/commands/options.hpp"
#include "msfem/compare/pipeline/atomic_file.hpp"
#include "msfem/compare/pipeline/case_run.hpp"
#include "msfem/compare/pipeline/external_result.hpp"
#include "msfem/compare/writers/vtu.hpp"
#include "msfem/massspring/surface_geometry.hpp"

namespace msfem::compare {
namespace {

nlohmann::json vector_json(const Eigen::Vector3d& v) {
  return {v.x(), v.y(), v.z()};
}

// One tool position: where it touches, its sphere's centre at each curve depth and at full depth,
// and for the bonded tool the displacement it prescribes at each surface vertex it holds.
nlohmann::json tool_json(const Problem& problem, const ToolPlacement& tool,
                         const Eigen::Vector3d& direction) {
  nlohmann::json curve = nlohmann::json::array();
  for (const double depth : curve_depths(problem.parameters.loads.tool)) {
    ToolPlacement at = tool;
    at.depth = depth;
    curve.push_back({{"depth_m", depth}, {"center_m", vector_json(at.pushed_center())}});
  }
  nlohmann::json j = {{"mode", tool.frictionless ? "contact" : "prescribed"},
                      {"radius_m", tool.radius},
                      {"direction", vector_json(direction)},
                      {"vertex", tool.vertex},
                      {"contact_point_m", vector_json(tool.contact_point)},
                      {"outward_normal", vector_json(tool.outward_normal)},
                      {"depth_m", tool.depth},
                      {"center_m", vector_json(tool.pushed_center())},
                      {"curve", curve},
                      {"prescribed", nullptr}};
  if (!tool.frictionless) {
    const fem_reference::Support patch = tool_patch_support(tool);
    nlohmann::json held = nlohmann::json::array();
    for (Eigen::Index v = 0; v < problem.surface.num_vertices(); ++v) {
      const Eigen::Vector3d x = problem.surface.vertices.row(v).transpose();
      if (patch.region(x) && !problem.fixed_region(x))
        held.push_back({{"vertex", v}, {"displacement_m", vector_json(patch.displacement(x))}});
    }
    j["prescribed"] = held;
  }
  return j;
}

// The patch force as msfem's variants apply it: the total shared by vertex area.
nlohmann::json patch_force_json(const Problem& problem) {
  const auto& patch = problem.parameters.loads.patch_force;
  if (!patch.enabled) return nullptr;
  const auto& s = problem.surface;
  const Eigen::VectorXd areas = massspring::vertex_areas(s.vertices, s.triangles);
  const std::vector<int> vertices = patch_vertices(problem);
  double total = 0;
  for (const int v : vertices)
    total += areas[v];
  nlohmann::json forces = nlohmann::json::array();
  for (const int v : vertices)
    forces.push_back({{"vertex", v}, {"force_n", vector_json(patch.force_n * areas[v] / total)}});
  return {{"force_n", vector_json(patch.force_n)}, {"vertex_forces", forces}};
}

nlohmann::json loads_json(const Problem& problem) {
  const auto& p = problem.parameters;
  int fixed = 0;
  for (Eigen::Index v = 0; v < problem.surface.num_vertices(); ++v)
    fixed += problem.fixed_region(problem.surface.vertices.row(v).transpose());
  nlohmann::json loads = nlohmann::json::array();
  for (std::size_t t = 0; t < problem.tools.size(); ++t)
    loads.push_back(
        {{"index", t}, {"tool", tool_json(problem, problem.tools[t], p.loads.tool.directions[t])}});
  if (loads.empty()) loads.push_back({{"index", 0}, {"tool", nullptr}});
  return {
      {"schema", external::loads_schema},
      {"version", external::loads_version},
      {"case", p.name},
      {"case_file", p.file.string()},
      {"units",
       {{"length", "m"},
        {"force", "N"},
        {"stress", "Pa"},
        {"acceleration", "m/s^2"},
        {"density", "kg/m^3"}}},
      {"surface",
       {{"file", "surface.vtu"},
        {"vertices", problem.surface.num_vertices()},
        {"triangles", problem.surface.triangles.rows()},
        {"fixed_vertices", fixed}}},
      {"support", cases::name_of(p.support.kind)},
      {"material",
       {{"youngs_modulus_pa", p.material.youngs_modulus_pa},
        {"poisson_ratio", p.material.poisson_ratio},
        {"density_kg_per_m3", p.material.density_kg_per_m3},
        {"youngs_modulus_image", problem.youngs_modulus_image != nullptr}}},
      {"gravity_m_per_s2", vector_json(p.loads.gravity_m_per_s2)},
      {"patch_force", patch_force_json(problem)},
      {"loads", loads},
      {"results",
       "mass spring/results = NAME=FILE[,FILE...]: one deformed surface per load, in this order "
       "(docs/external.md)"}};
}

}  // namespace

int export_load_command(const Arguments& args) {
  const Options opt(args, {}, {"set"});
  if (opt.positional().size() != 2)
    throw std::invalid_argument("usage: msfem export-load CASE.prm OUTDIR [--set K=V]...");
  const cases::CaseParameters parameters = cases::read_case(opt.positional()[0], opt.values("set"));
  const std::filesystem::path out = opt.positional()[1];
  check_output_folder(out);
  const Problem problem = make_problem(parameters);
  const auto& s = problem.surface;
  Eigen::MatrixXd ids(s.num_vertices(), 1), fixed(s.num_vertices(), 1);
  for (Eigen::Index v = 0; v < s.num_vertices(); ++v) {
    ids(v, 0) = double(v);
    fixed(v, 0) = problem.fixed_region(s.vertices.row(v).transpose()) ? 1.0 : 0.0;
  }
  fill_directory_atomically(out, [&](const std::filesystem::path& work) {
    write_surface_vtu(work / "surface.vtu", s.vertices, s.triangles,
                      {{"vertex_id", ids}, {"fixed", fixed}});
    write_text_atomically(work / "loads.json", loads_json(problem).dump(2) + "\n");
  });
  std::cout << (out / "surface.vtu").string() << "\n" << (out / "loads.json").string() << "\n";
  return 0;
}

}  // namespace msfem::compare
