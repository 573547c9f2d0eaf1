// The run's numbers as JSON and as a table: the interface users' scripts and CI read.
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>
#include <thread>

#include "msfem/cases/setting_names.hpp"
#include "msfem/compare/pipeline/json_values.hpp"
#include "msfem/compare/writers/run_summary.hpp"

namespace msfem::compare {
namespace {

// E as the FEM saw it at its quadrature points (the first load's assembly), and where it came from.
nlohmann::json material_json(const CaseRun& run) {
  const auto& m = run.problem.parameters.material;
  const auto& st = run.loads.front().fem.statistics;
  nlohmann::json j = {{"youngs_modulus_pa", m.youngs_modulus_pa},
                      {"youngs_modulus_range_pa", {st.youngs_modulus_min, st.youngs_modulus_max}},
                      {"youngs_modulus_image", nullptr},
                      {"hu_to_youngs", nullptr},
                      {"poisson_ratio", m.poisson_ratio},
                      {"density_kg_per_m3", m.density_kg_per_m3}};
  if (const auto& image = run.problem.youngs_modulus_image) {
    j["youngs_modulus_image"] = image->file().string();
    j["hu_to_youngs"] = image->table().describe();
  }
  return j;
}

nlohmann::json vec(const Eigen::Vector3d& v) {
  return {v.x(), v.y(), v.z()};
}

nlohmann::json optional_vec(const std::optional<Eigen::Vector3d>& v) {
  return v ? vec(*v) : nlohmann::json();
}

// The reference's own error at load `load` (nulls where it was not estimated or, for the force,
// where no force is measured).
nlohmann::json estimate_at(const CaseRun& run, std::size_t load) {
  const LoadErrorEstimate& e = run.loads[load].fem_error;
  return {{"estimated_rel_l2_error", json_or_null(e.rel_l2_error)},
          {"estimated_force_rel_error", json_or_null(e.force_rel_error)}};
}

nlohmann::json zone(const ErrorMetrics& m) {
  return {
      {"rel_l2_error", m.rel_l2_error}, {"max_error_m", m.max_error_m}, {"vertices", m.vertices}};
}

nlohmann::json curve_json(const std::vector<ForceDepthPoint>& curve) {
  nlohmann::json points = nlohmann::json::array();
  for (const auto& pt : curve)
    points.push_back({{"depth_m", pt.depth_m},
                      {"force_N", vec(pt.force_n)},
                      {"inverted_elements", json_or_null(pt.inverted_elements)}});
  return points;
}

nlohmann::json contact_json(const std::optional<fem_reference::ContactReport>& c) {
  if (!c) return nullptr;
  return {{"active_nodes", c->active_nodes},
          {"active_set_iterations", c->iterations},
          {"contact_radius_m", c->contact_radius},
          {"outermost_contact_node_radius_m", c->outermost_node_radius},
          {"max_penetration_m", c->max_penetration}};
}

// The local point distribution at the tools; null where the surface is the case's own.
nlohmann::json refinement_json(const Problem& problem) {
  if (!problem.local_refinement) return nullptr;
  const LocalRefinement& r = *problem.local_refinement;
  return {{"radius_m", r.radius_m},
          {"edge_length_m", r.edge_m},
          {"added_surface_vertices", r.added_vertices}};
}

nlohmann::json load_json(const CaseRun& run, std::size_t load, const ToolLoadVariant& o) {
  const ZonedErrorMetrics& e = o.displacement;
  return {{"tool", load},
          {"not_resolved_by_reference", metric_names(unresolved_metrics(run, o, load))},
          {"rel_l2_error", e.all.rel_l2_error},
          {"rms_error_m", e.all.rms_error_m},
          {"max_error_m", e.all.max_error_m},
          {"mean_error_over_max_disp", e.all.mean_error_over_max_disp},
          {"contact_zone", zone(e.contact_zone)},
          {"far_field", zone(e.far_field)},
          {"reaction_force_N", o.force_measured ? vec(o.tool_force) : nlohmann::json()},
          {"reaction_force_rel_error",
           o.force_measured ? nlohmann::json(o.reaction_force_rel_error) : nlohmann::json()},
          {"volume_change", o.volume_change},
          {"inverted_elements", json_or_null(o.inverted_elements)},
          {"force_depth_monotone", json_or_null(o.force_depth_monotone)},
          {"lost_tool", o.lost_tool},
          {"force_depth_exponent",
           json_or_null(force_depth_exponent(o.force_depth, run.loads[load].tool))},
          {"force_depth", curve_json(o.force_depth)}};
}

// Every tool position of the case as its own load (the first is also the variant's top-level
// numbers), with the means a user comparing variants over the case wants.
nlohmann::json variant_loads(const CaseRun& run, const VariantResult& v) {
  nlohmann::json list = nlohmann::json::array();
  double l2 = 0.0, force = 0.0;
  bool every_force = true;
  const std::vector<ToolLoadVariant>& loads = v.loads;
  for (std::size_t t = 0; t < loads.size(); ++t) {
    list.push_back(load_json(run, t, loads[t]));
    l2 += loads[t].displacement.all.rel_l2_error;
    force += loads[t].reaction_force_rel_error;
    every_force = every_force && loads[t].force_measured;
  }
  const double n = static_cast<double>(loads.size());
  return {{"per_tool", list},
          {"mean_rel_l2_error", l2 / n},
          {"mean_reaction_force_rel_error",
           every_force ? nlohmann::json(force / n) : nlohmann::json()}};
}

std::string command_output(const std::string& command) {
  std::array<char, 256> buffer{};
  std::string out;
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(command.c_str(), "r"), pclose);
  if (!pipe) return "";
  while (fgets(buffer.data(), buffer.size(), pipe.get()))
    out += buffer.data();
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r'))
    out.pop_back();
  return out;
}

}  // namespace

std::string git_revision() {
  const std::string source = std::filesystem::path(MSFEM_DEFAULT_CASES_DIR).parent_path().string();
  const std::string rev =
      command_output("git -C '" + source + "' describe --always --dirty 2>/dev/null");
  return rev.empty() ? "unknown" : rev;
}

std::string machine_description() {
  std::array<char, 256> host{};
  gethostname(host.data(), host.size() - 1);
  std::string cpu = "unknown CPU";
  std::ifstream info("/proc/cpuinfo");
  for (std::string line; std::getline(info, line);)
    if (line.rfind("model name", 0) == 0) {
      cpu = line.substr(line.find(':') + 2);
      break;
    }
  return std::string(host.data()) + ", " + cpu + ", " +
         std::to_string(std::thread::hardware_concurrency()) + " hardware threads";
}

namespace {

// The reference: its solve, its own error estimate, its force-depth curve and contact, per load.
nlohmann::json fem_json(const CaseRun& run) {
  const auto& p = run.problem.parameters;
  const LoadReference& first = run.loads.front();
  const auto& st = first.fem.statistics;
  nlohmann::json fem = {
      {"degree", p.fem.degree},
      {"dofs", st.dofs},
      {"cells", st.cells},
      {"vertices", st.vertices},
      {"solve_time_s", st.solve_time_s},
      {"assemble_time_s", st.assemble_time_s},
      {"iterations", st.iterations},
      {"solver", first.fem.solver.empty() ? cases::name_of(p.fem.solver) : first.fem.solver},
      {"mpi_ranks", st.mpi_ranks},
      {"reaction_force_N", first.tool ? vec(first.fem.tool_force) : nlohmann::json()},
      {"volume_change", first.fem.volume_change},
      {"worst_cell_quality", json_or_null(run.worst_cell_quality)},
      {"cache_key", first.cache_key},
      {"from_cache", run.fem_from_cache},
      {"error_estimate",
       {{"method", run.fem_error.method},
        {"note", run.fem_error.note},
        {"dofs", run.fem_error.dofs},
        {"time_s", run.fem_error.time_s}}}};
  fem.update(estimate_at(run, 0));
  const std::vector<int> patch = patch_vertices(run.problem);
  fem["patch_mean_displacement_m"] =
      patch.empty() ? nlohmann::json()
                    : vec(mean_displacement(first.fem.surface_displacement, patch));
  nlohmann::json curve = nlohmann::json::array();
  for (const auto& pt : first.force_depth)
    curve.push_back({{"depth_m", pt.depth_m},
                     {"force_N", vec(pt.force_n)},
                     {"contact", contact_json(pt.contact)}});
  fem["force_depth"] = curve;
  fem["force_depth_monotone"] = json_or_null(run.fem_force_depth_monotone);
  fem["force_depth_exponent"] = json_or_null(force_depth_exponent(first.force_depth, first.tool));
  fem["contact"] = contact_json(first.fem.contact);

  if (run.loads.size() > 1) {
    nlohmann::json loads = nlohmann::json::array();
    for (std::size_t l = 0; l < run.loads.size(); ++l) {
      const FemSolution& fem_at = run.loads[l].fem;
      loads.push_back({{"tool", l},
                       {"reaction_force_N", vec(fem_at.tool_force)},
                       {"iterations", fem_at.statistics.iterations},
                       {"solve_time_s", fem_at.statistics.solve_time_s},
                       {"contact", contact_json(fem_at.contact)},
                       {"from_cache", run.loads[l].from_cache}});
      loads.back().update(estimate_at(run, l));
    }
    fem["loads"] = loads;
  }
  return fem;
}

// One variant: its errors, force, timing, force-depth curve, and (with more tools) per load.
nlohmann::json parameters_json(const VariantParameters& p) {
  if (!p.external_files.empty()) return {{"external", p.external_files}};
  nlohmann::json groups = nlohmann::json::object();
  for (const auto& [name, g] : p.spring_groups)
    groups[name] = {{"springs", g.springs},
                    {"mean_stiffness_n_per_m", g.mean_stiffness_n_per_m},
                    {"mean_damping_n_s_per_m", g.mean_damping_n_s_per_m}};
  nlohmann::json j = {
      {"spring_groups", groups},
      {"total_mass_kg", p.total_mass_kg},
      {"anchors", p.anchors},
      {"constrained_nodes", p.constrained_nodes},
      {"youngs_modulus_range_pa", {p.youngs_modulus_min_pa, p.youngs_modulus_max_pa}}};
  if (p.volume_preservation)
    j["volume_preservation"] = {{"elements", p.volume_preservation->elements},
                                {"mean_modulus_pa", p.volume_preservation->mean_modulus_pa}};
  return j;
}

nlohmann::json variant_json(const CaseRun& run, const VariantResult& v) {
  const ToolLoadVariant& first = v.loads.front();
  const nlohmann::json fd = curve_json(first.force_depth);
  const bool tool = run.loads.front().tool.has_value() && first.force_measured;
  nlohmann::json j = {
      {"name", v.name},
      {"nodes", v.nodes},
      {"springs", v.springs},
      {"contact_refinement_added_nodes", json_or_null(v.refinement_added_nodes)},
      {"rel_l2_error", first.displacement.all.rel_l2_error},
      {"rms_error_m", first.displacement.all.rms_error_m},
      {"max_error_m", first.displacement.all.max_error_m},
      {"mean_error_over_max_disp", first.displacement.all.mean_error_over_max_disp},
      {"contact_zone", zone(first.displacement.contact_zone)},
      {"far_field", zone(first.displacement.far_field)},
      {"reaction_force_N", tool ? vec(first.tool_force) : nlohmann::json()},
      {"reaction_force_rel_error",
       tool ? nlohmann::json(first.reaction_force_rel_error) : nlohmann::json()},
      {"volume_change", first.volume_change},
      {"patch_mean_displacement_m", optional_vec(first.patch_mean_displacement)},
      {"patch_displacement_rel_error", json_or_null(first.patch_displacement_rel_error)},
      {"not_resolved_by_reference", metric_names(unresolved_metrics(run, first, 0))},
      {"integrator", v.timing.integrator},
      {"stepper", v.timing.stepper},
      {"precision",
       v.timing.precision.empty() ? nlohmann::json() : nlohmann::json(v.timing.precision)},
      {"dt_s", v.timing.dt_s},
      {"steps_per_second", v.timing.steps_per_second},
      {"stable_dt_s", v.timing.stable_dt_s},
      {"predicted_stable_dt_s", v.timing.predicted_stable_dt_s},
      {"realtime_factor", v.timing.realtime_factor},
      {"settle_time_s", v.timing.settle_time_s},
      {"settled", v.timing.settled},
      {"settle_distance_over_travel", v.timing.settle_distance},
      {"ms_per_60hz_frame", v.timing.ms_per_60hz_frame},
      {"newton_iterations", first.newton_iterations},
      {"force_depth", fd},
      {"force_depth_monotone", json_or_null(first.force_depth_monotone)},
      {"lost_tool", first.lost_tool},
      {"force_depth_exponent",
       json_or_null(force_depth_exponent(first.force_depth, run.loads.front().tool))},
      {"inverted_elements", json_or_null(first.inverted_elements)},
      {"warnings", written(v.warnings)},
      {"parameters", parameters_json(v.parameters)}};
  if (run.loads.size() > 1) j["loads"] = variant_loads(run, v);
  return j;
}

nlohmann::json tools_json(const CaseRun& run) {
  nlohmann::json tools = nlohmann::json::array();
  for (const auto& t : run.problem.tools)
    tools.push_back({{"vertex", t.vertex},
                     {"contact_point_m", vec(t.contact_point)},
                     {"outward_normal", vec(t.outward_normal)},
                     {"radius_m", t.radius},
                     {"depth_m", t.depth},
                     {"mode", t.frictionless ? "contact" : "bonded"}});
  return tools;
}

}  // namespace

nlohmann::json summary_json(const CaseRun& run) {
  const auto& p = run.problem.parameters;
  nlohmann::json variants = nlohmann::json::array();
  for (const auto& v : run.variants)
    variants.push_back(variant_json(run, v));
  nlohmann::json failed = nlohmann::json::array();
  for (const auto& [name, why] : run.failed_variants)
    failed.push_back({{"name", name}, {"error", why}});
  const nlohmann::json fem = fem_json(run);
  const nlohmann::json tools = tools_json(run);
  return {{"case", p.name},
          {"case_file", p.file.string()},
          {"git_revision", git_revision()},
          {"machine", machine_description()},
          {"units", {{"length", "m"}, {"force", "N"}, {"time", "s"}, {"stress", "Pa"}}},
          {"material", material_json(run)},
          {"surface",
           {{"source", p.geometry.source},
            {"vertices", run.problem.surface.num_vertices()},
            {"triangles", run.problem.surface.num_triangles()}}},
          {"contact_refinement", refinement_json(run.problem)},
          {"compared_vertices", run.loads.front().compared_vertices.size()},
          {"tools", tools},
          {"notes", run.problem.notes},
          {"fem", fem},
          {"variants", variants},
          {"failed_variants", failed},
          {"wall_time_s", run.wall_time_s}};
}

namespace {

// "0.1234", with ‡ where the reference's own error is within 3x of it.
std::string error_cell(double error, bool unresolved) {
  char cell[32];
  std::snprintf(cell, sizeof cell, "%.4f%s", error, unresolved ? " ‡" : "");
  return cell;
}

// Below the table: the reference's own error, and the patch comparison of a patch-force load.
std::string table_notes(const CaseRun& run) {
  std::ostringstream out;
  const FemErrorEstimate& e = run.fem_error;
  const LoadErrorEstimate& first = run.loads.front().fem_error;
  if (first.rel_l2_error) {
    char line[512];
    std::snprintf(
        line, sizeof line, "FEM reference's own error (%s; %zu DoFs, %.1f s): rel L2 %.4f, %s %s\n",
        e.note.c_str(), e.dofs, e.time_s, *first.rel_l2_error,
        run.problem.tools.empty() && !patch_vertices(run.problem).empty() ? "patch displacement"
                                                                          : "force",
        first.force_rel_error ? error_cell(*first.force_rel_error, false).c_str() : "-");
    out << line;
    if (std::any_of(run.variants.begin(), run.variants.end(),
                    [&](const auto& v) { return !unresolved_metrics(run, v.loads[0], 0).empty(); }))
      out << "‡ within 3x of the reference's own error: not resolved by this reference\n";
  } else {
    out << "FEM reference's own error: " << e.note << "\n";
  }
  const std::vector<int> patch = patch_vertices(run.problem);
  if (!patch.empty()) {
    const Eigen::Vector3d fem =
        mean_displacement(run.loads.front().fem.surface_displacement, patch);
    char line[256];
    std::snprintf(line, sizeof line, "patch force on %zu vertices: mean displacement FEM %.3f mm",
                  patch.size(), 1e3 * fem.norm());
    out << line;
    for (const auto& v : run.variants) {
      const ToolLoadVariant& own = v.loads.front();
      std::snprintf(line, sizeof line, "; %s %.3f mm (err %s)", v.name.c_str(),
                    1e3 * own.patch_mean_displacement->norm(),
                    error_cell(*own.patch_displacement_rel_error,
                               contains(unresolved_metrics(run, own, 0),
                                        Metric::patch_displacement_rel_error))
                        .c_str());
      out << line;
    }
    out << "\n";
  }
  return out.str();
}

}  // namespace

std::string variant_table(const CaseRun& run) {
  std::ostringstream out;
  char line[512];
  std::snprintf(line, sizeof line,
                "| %-12s | %6s | %7s | %9s | %9s | %9s | %9s | %10s | %9s | %9s |\n", "variant",
                "nodes", "springs", "rel L2", "max err mm", "force N", "force err", "steps/s",
                "stable dt", "ms/frame");
  out << line;
  out << "|--------------|--------|---------|-----------|-----------|-----------|-----------|------"
         "------|-----------|-----------|\n";
  // Without a tool no force is measured: dashes, not a zero that reads as a perfect force.
  const LoadReference& reference = run.loads.front();
  const bool tool = reference.tool.has_value();
  char fem_force[32] = "-";
  if (tool) std::snprintf(fem_force, sizeof fem_force, "%.4g", reference.fem.tool_force.norm());
  std::snprintf(line, sizeof line,
                "| %-12s | %6zu | %7s | %9s | %9s | %9s | %9s | %10s | %9s | %9s |\n",
                ("FEM P" + std::to_string(run.problem.parameters.fem.degree)).c_str(),
                static_cast<std::size_t>(reference.fem.statistics.vertices), "-", "-", "-",
                fem_force, "-", "-", "-", "-");
  out << line;
  for (const auto& v : run.variants) {
    // Not timed (--no-timing): dashes, not zeros that read as measurements.
    const bool timed = !v.timing.integrator.empty();
    char steps[32] = "-", dt[32] = "-", frame[32] = "-", force[32] = "-", springs[32] = "-";
    if (v.external) {
      std::snprintf(steps, sizeof steps, "external");
      std::snprintf(dt, sizeof dt, "external");
      std::snprintf(frame, sizeof frame, "external");
    } else {
      std::snprintf(springs, sizeof springs, "%d", v.springs);
    }
    if (timed) {
      std::snprintf(steps, sizeof steps, "%.0f", v.timing.steps_per_second);
      std::snprintf(dt, sizeof dt, "%.3g", v.timing.stable_dt_s);
      std::snprintf(frame, sizeof frame, "%.3f", v.timing.ms_per_60hz_frame);
    }
    const ToolLoadVariant& own = v.loads.front();
    const std::vector<Metric> unresolved = unresolved_metrics(run, own, 0);
    std::string force_error = "-";
    if (tool && !own.force_measured) {
      // An outside answer without a force: empty, never a zero.
    } else if (tool && own.lost_tool) {
      std::snprintf(force, sizeof force, "lost");
      force_error = "lost";
    } else if (tool) {
      std::snprintf(force, sizeof force, "%.4g", own.tool_force.norm());
      force_error = error_cell(own.reaction_force_rel_error,
                               contains(unresolved, Metric::reaction_force_rel_error));
    }
    std::snprintf(
        line, sizeof line, "| %-12s | %6d | %7s | %9s | %9.4f | %9s | %9s | %10s | %9s | %9s |\n",
        v.name.c_str(), v.nodes, springs,
        error_cell(own.displacement.all.rel_l2_error, contains(unresolved, Metric::rel_l2_error))
            .c_str(),
        1e3 * own.displacement.all.max_error_m, force, force_error.c_str(), steps, dt, frame);
    out << line;
  }
  out << table_notes(run);
  return out.str();
}

}  // namespace msfem::compare
