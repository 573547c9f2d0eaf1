// What `msfem calibrate` writes: calibration.json, the report, the convergence plot,
// calibrated.prm.
#include <algorithm>
#include <cstdio>
#include <sstream>

#include "msfem/cases/network_file.hpp"
#include "msfem/cases/setting_names.hpp"
#include "msfem/compare/pipeline/atomic_file.hpp"
#include "msfem/compare/pipeline/json_values.hpp"
#include "msfem/compare/writers/calibration_outputs.hpp"
#include "msfem/compare/writers/plots.hpp"
#include "msfem/compare/writers/run_summary.hpp"
#include "msfem/compare/writers/text_format.hpp"

namespace msfem::compare {
namespace {

nlohmann::json errors_json(const std::vector<CalibrationErrors>& errors) {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& e : errors)
    list.push_back({{"load", e.load},
                    {"rel_l2_error", e.displacement.all.rel_l2_error},
                    {"mean_error_over_max_disp", e.displacement.all.mean_error_over_max_disp},
                    {"reaction_force_rel_error", e.reaction_force_rel_error},
                    {"reaction_force_N", {e.tool_force.x(), e.tool_force.y(), e.tool_force.z()}},
                    {"tool_patch_nodes", e.tool_patch_nodes}});
  return list;
}

// The reference's own error at every load (null where fem/error estimate left it out).
nlohmann::json estimates_json(const CaseCalibration& c) {
  nlohmann::json out = nlohmann::json::object();
  for (const auto& [side, references] :
       {std::pair{"train", &c.train}, std::pair{"test", &c.test}}) {
    nlohmann::json list = nlohmann::json::array();
    for (const CalibrationLoad& r : *references)
      list.push_back({{"load", r.load.label()},
                      {"estimated_rel_l2_error", json_or_null(r.fem_error.rel_l2_error)},
                      {"estimated_force_rel_error", json_or_null(r.fem_error.force_rel_error)}});
    out[side] = list;
  }
  return out;
}

nlohmann::json side_json(const ErrorsOnLoads& e, double objective) {
  return {{"train", errors_json(e.train)}, {"test", errors_json(e.test)}, {"objective", objective}};
}

template <typename Field>
double mean_of(const std::vector<CalibrationErrors>& errors, Field field) {
  double sum = 0;
  for (const auto& e : errors)
    sum += field(e);
  return errors.empty() ? 0.0 : sum / static_cast<double>(errors.size());
}

std::string loads_table(const CaseCalibration& c) {
  std::ostringstream t;
  t << "| set | load (direction@depth m) | rel L2 before | rel L2 after | mean err/max disp before "
       "| after | force err before | force err after |\n|---|---|---|---|---|---|---|---|\n";
  auto rows = [&](const char* set, const std::vector<CalibrationErrors>& before,
                  const std::vector<CalibrationErrors>& after) {
    for (std::size_t i = 0; i < before.size(); ++i)
      t << "| " << set << " | " << before[i].load << " | "
        << fmt("%.4f", before[i].displacement.all.rel_l2_error) << " | "
        << fmt("%.4f", after[i].displacement.all.rel_l2_error) << " | "
        << fmt("%.4f", before[i].displacement.all.mean_error_over_max_disp) << " | "
        << fmt("%.4f", after[i].displacement.all.mean_error_over_max_disp) << " | "
        << fmt("%.4f", before[i].reaction_force_rel_error) << " | "
        << fmt("%.4f", after[i].reaction_force_rel_error) << " |\n";
  };
  rows("train", c.fit.before.train, c.fit.after.train);
  rows("test", c.fit.before.test, c.fit.after.test);
  return t.str();
}

std::string coefficients_table(const CaseCalibration& c) {
  std::ostringstream t;
  // The volume group's "stiffness" is its modulus κ in Pa, over volume elements, not springs.
  t << "| group | springs (elements) | start (mean) | fitted (mean) | unit | factor | group scale "
       "to write |\n|---|---|---|---|---|---|---|\n";
  for (const auto& g : c.fit.groups)
    t << "| " << g.group << " | " << g.springs << " | " << fmt("%.5g", g.start_stiffness_n_per_m)
      << " | " << fmt("%.5g", g.fitted_stiffness_n_per_m) << " | " << g.unit << " | "
      << fmt("%.4f", g.factor) << " | " << fmt("%.6g", g.case_factor) << " |\n";
  return t.str();
}

std::string report_markdown(const CaseCalibration& c, const std::string& plot) {
  const auto& p = c.problem.parameters;
  const auto& fit = c.fit;
  std::ostringstream md;
  md << "# msfem calibrate: " << p.name << ", variant " << c.variant.name << "\n\n"
     << "- case file: `" << p.file.string() << "`; surface " << c.problem.surface.num_vertices()
     << " vertices; E = " << p.material.youngs_modulus_pa << " Pa, ν = " << p.material.poisson_ratio
     << "\n"
     << "- FEM reference: P" << p.fem.degree << " on " << c.mesh.num_tetrahedra()
     << " tetrahedra refined near every tool position; " << c.fem_solves << " solved, "
     << c.fem_from_cache << " from the cache (" << fmt("%.1f", c.fem_time_s) << " s)\n"
     << "- objective: J = mean over the " << c.train.size()
     << " training loads of rel_l2_error² + w · reaction_force_rel_error², w = "
     << c.options.force_weight
     << " (under a prescribed tool the displacement fixes the stiffness ratios, the force their "
        "overall scale)\n"
     << "- spring model solved: "
     << (c.options.linear ? "linearised at rest (one Cholesky factorisation per load)"
                          : "nonlinear static equilibrium (Newton, as `msfem run`)")
     << "\n"
     << "- optimiser: NLopt BOBYQA on log(k/k_start) within ±log(" << c.options.bound_factor
     << "), start = the analytic stiffness with the case's group scales; " << fit.evaluations
     << " evaluations in " << fmt("%.1f", fit.time_s) << " s; "
     << (fit.converged ? "converged" : "NOT converged") << " (" << fit.stop_reason << ")\n"
     << "- J: " << fmt("%.5g", fit.objective_before) << " before, "
     << fmt("%.5g", fit.objective_after) << " after\n"
     << "- git " << git_revision() << ", " << machine_description() << "\n\n";
  for (const auto& n : c.notes)
    md << "> note: " << n << "\n\n";
  md << "## Errors per load, before and after\n\n" << loads_table(c) << "\n";
  const auto l2 = [](const LoadErrors& e) { return e.displacement.all.rel_l2_error; };
  const auto force = [](const LoadErrors& e) { return e.reaction_force_rel_error; };
  md << "Held-out means: rel L2 " << fmt("%.4f", mean_of(fit.before.test, l2)) << " → "
     << fmt("%.4f", mean_of(fit.after.test, l2)) << ", force error "
     << fmt("%.4f", mean_of(fit.before.test, force)) << " → "
     << fmt("%.4f", mean_of(fit.after.test, force)) << ".\n\n";
  md << "## Fitted coefficients\n\n" << coefficients_table(c) << "\n";
  md << "## Damping and mass\n\n"
     << "- tool-response mode of the calibrated model (its static deflection under the first "
        "training load, as a Rayleigh quotient): "
     << fmt("%.4g", c.damping.frequency_hz) << " Hz; its damping ratio is "
     << fmt("%.4g", c.damping.modal_ratio_per_unit_r)
     << " per unit of the per-spring damping ratio, so "
     << (c.damping.reachable ? "`damping ratio = " + fmt("%.4g", c.damping.case_damping_ratio) +
                                   "` gives the target " + fmt("%.3g", c.damping.target)
                             : std::string("no per-spring damping ratio reaches the target ") +
                                   fmt("%.3g", c.damping.target) +
                                   " (the mode barely stretches the springs); the case's is kept")
     << "\n"
     << "- lumped mass " << fmt("%.6g", c.lumped_mass_kg) << " kg against the FEM's ρV "
     << fmt("%.6g", c.fem_mass_kg) << " kg (ratio " << fmt("%.4f", c.lumped_mass_kg / c.fem_mass_kg)
     << ")"
     << (std::abs(c.lumped_mass_kg / c.fem_mass_kg - 1) > 0.02 ? ": they differ" : ": they match")
     << "\n\n";
  md << "## Variants on the held-out loads\n\n"
     << (c.options.linear ? "All solved linearised at rest, as the fit was.\n\n" : "")
     << "| variant | mean rel L2 | mean force err |\n|---|---|---|\n";
  for (const auto& v : c.variants)
    md << "| " << v.name << (v.calibrated ? " (calibrated)" : " (as the case has it)") << " | "
       << fmt("%.4f", v.mean_rel_l2_error) << " | " << fmt("%.4f", v.mean_reaction_force_rel_error)
       << " |\n";
  if (!c.variants.empty())
    md << "\nBest on the held-out loads: **" << c.variants.front().name << "**.\n\n";
  if (!plot.empty()) md << "## Convergence\n\n![objective per evaluation](" << plot << ")\n\n";
  md << "## Files\n\n- `calibration.json`: every number above\n"
        "- `calibrated.prm`: the case with the fitted group scales and damping ratio (`msfem run "
        "calibrated.prm`)\n";
  if (c.hand_back)
    md << "- `" << c.hand_back->file_name << "`: " << c.hand_back->original.filename().string()
       << " with the fitted groups' stiffness"
       << (c.hand_back->damping ? " and the fitted damping" : "")
       << " put in, every other array and the cell order kept (calibrated.prm runs it as "
       << c.variant.name << ")\n";
  return md.str();
}

}  // namespace

nlohmann::json calibration_json(const CaseCalibration& c) {
  nlohmann::json coefficients = nlohmann::json::array();
  for (const auto& g : c.fit.groups) {
    nlohmann::json entry = {
        {"group", g.group}, {"unit", g.unit}, {"factor", g.factor}, {"group_scale", g.case_factor}};
    if (g.spring_group) {
      entry["springs"] = g.springs;
      entry["start_stiffness_N_per_m"] = g.start_stiffness_n_per_m;
      entry["fitted_stiffness_N_per_m"] = g.fitted_stiffness_n_per_m;
    } else if (g.group == volume_group) {  // volume elements and their modulus κ
      entry["elements"] = g.springs;
      entry["start_modulus_Pa"] = g.start_stiffness_n_per_m;
      entry["fitted_modulus_Pa"] = g.fitted_stiffness_n_per_m;
    } else {  // another field's group: its coefficients' mean
      entry["coefficients"] = g.springs;
      entry["start_mean"] = g.start_stiffness_n_per_m;
      entry["fitted_mean"] = g.fitted_stiffness_n_per_m;
    }
    coefficients.push_back(entry);
  }
  nlohmann::json variants = nlohmann::json::array();
  for (const auto& v : c.variants)
    variants.push_back({{"name", v.name},
                        {"calibrated", v.calibrated},
                        {"mean_test_rel_l2_error", v.mean_rel_l2_error},
                        {"mean_test_reaction_force_rel_error", v.mean_reaction_force_rel_error}});
  return {{"case", c.problem.parameters.name},
          {"variant", c.variant.name},
          {"calibrated_network", c.hand_back ? nlohmann::json(c.hand_back->file_name) : nullptr},
          {"git_revision", git_revision()},
          {"objective",
           {{"definition",
             "mean over training loads of rel_l2_error^2 + "
             "force_weight * reaction_force_rel_error^2"},
            {"force_weight", c.options.force_weight}}},
          {"model", c.options.linear ? "linear" : "nonlinear"},
          {"nonlinear_check", errors_json({c.nonlinear_check}).at(0)},
          {"optimiser",
           {{"method", "NLopt BOBYQA on log(k / k_start)"},
            {"evaluations", c.fit.evaluations},
            {"max_evaluations", c.options.max_evaluations},
            {"converged", c.fit.converged},
            {"stop_reason", c.fit.stop_reason},
            {"time_s", c.fit.time_s},
            {"history", c.fit.history},
            {"warm_started_evaluations", c.fit.warm_started_evaluations},
            {"refitted_from_rest", !c.fit.refit_reason.empty()}}},
          {"before", side_json(c.fit.before, c.fit.objective_before)},
          {"after", side_json(c.fit.after, c.fit.objective_after)},
          {"coefficients", coefficients},
          {"damping",
           {{"target_modal_damping_ratio", c.damping.target},
            {"mode_frequency_hz", c.damping.frequency_hz},
            {"modal_ratio_per_unit_damping_ratio", c.damping.modal_ratio_per_unit_r},
            {"damping_ratio", c.damping.case_damping_ratio},
            {"reachable", c.damping.reachable}}},
          {"mass",
           {{"lumped_kg", c.lumped_mass_kg},
            {"fem_kg", c.fem_mass_kg},
            {"ratio", c.lumped_mass_kg / c.fem_mass_kg}}},
          {"variants_on_test", variants},
          {"fem",
           {{"tetrahedra", c.mesh.num_tetrahedra()},
            {"solves", c.fem_solves},
            {"from_cache", c.fem_from_cache},
            {"time_s", c.fem_time_s},
            {"error_estimate", estimates_json(c)}}},
          {"notes", c.notes},
          {"wall_time_s", c.total_time_s}};
}

std::string calibration_table(const CaseCalibration& c) {
  std::ostringstream out;
  out << loads_table(c) << "\n" << coefficients_table(c);
  out << "\noptimiser: " << c.fit.evaluations << " evaluations, "
      << (c.fit.converged ? "converged" : "NOT converged") << " (" << c.fit.stop_reason << "); J "
      << fmt("%.5g", c.fit.objective_before) << " -> " << fmt("%.5g", c.fit.objective_after)
      << "\n";
  if (!c.variants.empty())
    out << "best on the held-out loads: " << c.variants.front().name << " (mean rel L2 "
        << fmt("%.4f", c.variants.front().mean_rel_l2_error) << ")\n";
  return out.str();
}

void write_calibration_outputs(const CaseCalibration& c, const std::filesystem::path& dir) {
  std::string plot;
  if (gnuplot_available() && !c.fit.history.empty()) {
    Series all{"objective", {}, {}}, best{"best so far", {}, {}};
    double lowest = c.fit.history.front();
    for (std::size_t i = 0; i < c.fit.history.size(); ++i) {
      lowest = std::min(lowest, c.fit.history[i]);
      all.x.push_back(static_cast<double>(i + 1));
      all.y.push_back(std::max(c.fit.history[i], 1e-300));
      best.x.push_back(static_cast<double>(i + 1));
      best.y.push_back(std::max(lowest, 1e-300));
    }
    plot = xy_lines(dir / "convergence.png", "calibration of " + c.variant.name, "evaluation",
                    "objective J", {all, best}, false, true)
               .filename()
               .string();
  }
  write_text_atomically(dir / "report.md", report_markdown(c, plot));
  write_text_atomically(dir / "calibration.json", calibration_json(c).dump(2) + "\n");
  if (c.hand_back)
    cases::write_network_with_coefficients(c.hand_back->original, dir / c.hand_back->file_name,
                                           c.hand_back->stiffness, c.hand_back->damping);
  std::vector<std::string> overrides = c.calibrated_overrides;
  std::string header = "# Calibrated by msfem calibrate (variant " + c.variant.name + ", git " +
                       git_revision() + ") from " + c.problem.parameters.file.string() + "\n";
  write_text_atomically(dir / "calibrated.prm",
                        header + cases::case_file_text(c.problem.parameters.file, overrides));
}

}  // namespace msfem::compare
