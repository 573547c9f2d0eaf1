#include "msfem/compare/writers/sweep_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <tuple>

#include "msfem/compare/pipeline/atomic_file.hpp"
#include "msfem/compare/pipeline/json_values.hpp"
#include "msfem/compare/writers/plots.hpp"
#include "msfem/compare/writers/run_summary.hpp"

namespace msfem::compare {
namespace {

// One point as sweep.json lists it.
nlohmann::json point_json(const SweepPoint& p) {
  return {{"variant", p.variant},
          {"volume_preservation", p.volume_preservation},
          {"contact_refinement_edge_m", json_or_null(p.contact_edge_m)},
          {"integrator", p.integrator},
          {"stepper", p.stepper},
          {"precision", p.precision},
          {"resolution", p.resolution},
          {"surface_vertices", p.surface_vertices},
          {"nodes", p.nodes},
          {"springs", p.springs},
          {"rel_l2_error", p.rel_l2_error},
          {"reaction_force_rel_error", p.reaction_force_rel_error},
          {"stable_dt_s", p.stable_dt_s},
          {"steps_per_second", p.steps_per_second},
          {"realtime_factor", p.realtime_factor},
          {"dt_s", p.dt_s},
          {"ms_per_60hz_frame", p.ms_per_60hz_frame},
          {"fem_estimated_rel_l2_error", json_or_null(p.fem_estimated_rel_l2_error)},
          {"fem_estimated_force_rel_error", json_or_null(p.fem_estimated_force_rel_error)},
          {"not_resolved_by_reference", metric_names(p.not_resolved_by_reference)}};
}

}  // namespace

nlohmann::json sweep_json(const cases::CaseParameters& parameters, const SweepResult& result) {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& p : result.points)
    list.push_back(point_json(p));
  nlohmann::json failed = nlohmann::json::array();
  for (const auto& [resolution, why] : result.failed_resolutions)
    failed.push_back({{"resolution", resolution}, {"error", why}});
  nlohmann::json failed_variants = nlohmann::json::array();
  for (const auto& f : result.failed_variants)
    failed_variants.push_back(
        {{"resolution", f.resolution}, {"variant", f.model}, {"error", f.error}});
  return {{"case", parameters.name},
          {"git_revision", git_revision()},
          {"machine", machine_description()},
          {"units", {{"length", "m"}, {"time", "s"}}},
          {"points", list},
          {"failed_resolutions", failed},
          {"failed_variants", failed_variants},
          {"networks_at_own_resolution",
           result.networks ? nlohmann::json{{"resolution", result.networks->resolution},
                                            {"networks", result.networks->networks},
                                            {"note", result.networks->note}}
                           : nlohmann::json(nullptr)}};
}

std::string sweep_table(const std::vector<SweepPoint>& points) {
  std::ostringstream out;
  out << "| variant | integrator (stepper) | resolution | surface vertices | nodes | springs | "
         "rel L2 | force err | FEM own err (L2 / force) | stable dt s | steps/s | realtime factor "
         "| "
         "ms/60 Hz frame |\n"
         "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  char row[512];
  auto number = [](const std::optional<double>& x) {
    char cell[32] = "-";
    if (x) std::snprintf(cell, sizeof cell, "%.4f", *x);
    return std::string(cell);
  };
  auto flag = [](const SweepPoint& p, Metric metric) {
    return contains(p.not_resolved_by_reference, metric) ? " ‡" : "";
  };
  bool any_flag = false;
  for (const auto& p : points) {
    std::snprintf(row, sizeof row,
                  "| %s | %s (%s) | %d | %d | %d | %d | %.4f%s | %.4f%s | %s / %s | %.3g | %.0f | "
                  "%.3g | %.3f |\n",
                  p.model().c_str(), p.integrator.c_str(),
                  (p.stepper + (p.precision == "float" ? ", float" : "")).c_str(), p.resolution,
                  p.surface_vertices, p.nodes, p.springs, p.rel_l2_error,
                  flag(p, Metric::rel_l2_error), p.reaction_force_rel_error,
                  flag(p, Metric::reaction_force_rel_error),
                  number(p.fem_estimated_rel_l2_error).c_str(),
                  number(p.fem_estimated_force_rel_error).c_str(), p.stable_dt_s,
                  p.steps_per_second, p.realtime_factor, p.ms_per_60hz_frame);
    out << row;
    any_flag = any_flag || !p.not_resolved_by_reference.empty();
  }
  if (any_flag)
    out << "\n‡ within 3x of the reference's own error: not resolved by this reference\n";
  return out.str();
}

std::string convergence_section(const std::vector<VariantConvergence>& convergence) {
  std::ostringstream out;
  out << "## Error against resolution\n\n| variant | rel L2 at surface vertices | observed order |"
         "\n|---|---|---|\n";
  std::string diverging;
  char cell[64];
  for (const auto& v : convergence) {
    out << "| " << v.variant << " | ";
    for (std::size_t i = 0; i < v.error_at_vertices.size(); ++i) {
      std::snprintf(cell, sizeof cell, "%s%.4f @ %d", i ? ", " : "", v.error_at_vertices[i].second,
                    v.error_at_vertices[i].first);
      out << cell;
    }
    std::snprintf(cell, sizeof cell, "%.2f", v.observed_order.value_or(0.0));
    out << " | " << (v.observed_order ? cell : "-") << " |\n";
    if (v.observed_order && *v.observed_order < 0)
      diverging += (diverging.empty() ? "" : ", ") + v.variant;
  }
  out << "\nObserved order p from e ∝ h^p, h ∝ N^(-1/2), between the coarsest and the finest "
         "resolution. ";
  if (!diverging.empty())
    out << "**Not converging: " << diverging
        << "** (the error grows as the model is refined: refining does not make this model "
           "approach the FEM).";
  out << "\n\n";
  return out.str();
}

namespace {

std::string configuration(const SweepPoint& p) {
  return p.model() + ", " + p.integrator + ", resolution " + std::to_string(p.resolution) + " (" +
         std::to_string(p.nodes) + " nodes)";
}

bool flagged(const SweepPoint& p, Metric metric) {
  return contains(p.not_resolved_by_reference, metric);
}

bool resolved(const SweepPoint& p) {
  return p.not_resolved_by_reference.empty();
}

// A configuration whose error the reference does not resolve is named only with that said in its
// own row: its error is within 3x of the FEM's own, so it may not be the least.
std::string answer_row(const std::string& budget, const SweepPoint* p) {
  if (!p) return "| " + budget + " | none of the swept configurations | | | |\n";
  const std::string caveat =
      resolved(*p) ? ""
                   : " — **not resolved by this reference** (‡: within 3x of the FEM's own "
                     "error; no resolved configuration meets this budget; a finer fem/cell size "
                     "decides)";
  char row[768];
  std::snprintf(row, sizeof row, "| %s | %s%s | %.4f%s | %.4f%s | %.3g |\n", budget.c_str(),
                configuration(*p).c_str(), caveat.c_str(), p->rel_l2_error,
                flagged(*p, Metric::rel_l2_error) ? " ‡" : "", p->reaction_force_rel_error,
                flagged(*p, Metric::reaction_force_rel_error) ? " ‡" : "", p->realtime_factor);
  return row;
}

// The best point that `admits` among those the reference resolves; only where none is resolved,
// the best of the others (answer_row says so).
template <typename Admits, typename Better>
const SweepPoint* best_point(const std::vector<SweepPoint>& points, Admits admits, Better better) {
  const SweepPoint* best = nullptr;
  for (bool only_resolved : {true, false}) {
    for (const auto& p : points)
      if (admits(p) && (!only_resolved || resolved(p)) && (!best || better(p, *best))) best = &p;
    if (best) return best;
  }
  return nullptr;
}

}  // namespace

std::string sweep_answer(const std::vector<SweepPoint>& points, std::optional<double> max_error) {
  const auto less_error = [](const SweepPoint& a, const SweepPoint& b) {
    return std::tie(a.rel_l2_error, a.reaction_force_rel_error) <
           std::tie(b.rel_l2_error, b.reaction_force_rel_error);
  };
  auto least_error = [&](double rate) {
    return best_point(
        points, [&](const SweepPoint& p) { return keeps_real_time(p, rate); }, less_error);
  };
  std::ostringstream out;
  out << "## Answer\n\n"
         "| budget | configuration | rel L2 | force err | real-time factor |\n"
         "|---|---|---|---|---|\n"
      << answer_row("least error, 60 Hz visual loop in real time", least_error(60.0))
      << answer_row("least error, 1 kHz haptic loop in real time", least_error(1000.0));
  if (max_error) {
    const SweepPoint* cheapest = best_point(
        points, [&](const SweepPoint& p) { return p.rel_l2_error <= *max_error; },
        [](const SweepPoint& a, const SweepPoint& b) {
          return a.realtime_factor > b.realtime_factor;
        });
    char budget[96];
    std::snprintf(budget, sizeof budget, "cheapest with rel L2 <= %g", *max_error);
    out << answer_row(budget, cheapest);
  }
  out << "\nA loop of rate f keeps real time when each tick's ceil(1 / (f dt)) steps, at the step "
         "dt the sweep timed (half the measured stable step; implicit Euler at 1 ms, a haptic "
         "loop's own step), take at most 1/f s on this machine. "
      << (max_error ? "" : "`--max-error E` adds the cheapest configuration within rel L2 E. ")
      << "Configurations the reference resolves are preferred. ‡: within 3x of the reference's "
         "own error, so not resolved by this reference.\n\n";
  return out.str();
}

namespace {

// Colour per variant, marker per integrator, the configurations that keep a 1 kHz loop ringed.
std::filesystem::path pareto_plot(const std::filesystem::path& file, const std::string& name,
                                  const std::vector<SweepPoint>& points) {
  std::vector<ParetoPoint> pareto_points;
  for (const auto& p : points)
    pareto_points.push_back({p.model() + " " + p.integrator + " @" + std::to_string(p.resolution),
                             p.realtime_factor, p.rel_l2_error, p.model(), p.integrator,
                             keeps_real_time(p, 1000.0)});
  return pareto(file, "Relative error against real-time factor: " + name, pareto_points);
}

// The Pareto plot and the error against resolution, as report.md's image lines.
std::string sweep_plots(const std::filesystem::path& directory, const std::string& name,
                        const std::vector<SweepPoint>& points,
                        const std::vector<VariantConvergence>& convergence) {
  if (!gnuplot_available()) return "(plots skipped: gnuplot is not installed)";
  const auto pareto = pareto_plot(directory / "pareto.png", name, points);
  std::vector<Series> series;
  for (const auto& v : convergence) {
    Series s{v.variant, {}, {}};
    for (const auto& [vertices, error] : v.error_at_vertices) {
      s.x.push_back(vertices);
      s.y.push_back(error);
    }
    series.push_back(std::move(s));
  }
  const auto resolution =
      xy_lines(directory / "convergence.png", "Error against resolution: " + name,
               "surface vertices", "relative error (rel L2)", series, true, true);
  return "![Pareto plot](" + pareto.filename().string() + ")\n\n![Error against resolution](" +
         resolution.filename().string() + ")";
}

}  // namespace

std::string write_sweep_outputs(const std::filesystem::path& directory,
                                const cases::CaseParameters& parameters, const SweepResult& result,
                                std::optional<double> max_error, bool json) {
  const nlohmann::json j = sweep_json(parameters, result);
  write_text_atomically(directory / "sweep.json", j.dump(2) + "\n");
  const std::vector<VariantConvergence> convergence = convergence_by_variant(result.points);
  const std::string plots = sweep_plots(directory, parameters.name, result.points, convergence);
  const std::string answer = sweep_answer(result.points, max_error);
  std::string table = sweep_table(result.points);
  for (const auto& [resolution, why] : result.failed_resolutions)
    table += "\n> **resolution " + std::to_string(resolution) +
             " failed** and is left out of the table and plot: " + why + "\n";
  for (const auto& f : result.failed_variants)
    table += "\n> **" + f.model + " failed at resolution " + std::to_string(f.resolution) +
             "** and is left out of the table and plot: " + f.error + "\n";
  if (result.networks) table += "\n> " + result.networks->note + ".\n";
  write_text_atomically(directory / "report.md",
                        "# msfem sweep: " + parameters.name + "\n\n" + answer +
                            convergence_section(convergence) + "## Every configuration\n\n" +
                            table +
                            "\nrel L2 against the FEM at each resolution; steps/s at half of "
                            "each integrator's measured stable step (median after warm-up); "
                            "real-time factor = stable step × steps/s. On the plot, ringed "
                            "points keep a 1 kHz loop in real time.\n\n" +
                            plots + "\n");
  return json ? j.dump(2) + "\n" : table + "\n" + answer;
}

}  // namespace msfem::compare
