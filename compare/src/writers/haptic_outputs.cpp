// msfem haptic's results: haptic.json, report.md with the force against time, the path replayed
// and each variant's force trace.
#include "msfem/compare/writers/haptic_outputs.hpp"

#include <algorithm>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "msfem/compare/pipeline/atomic_file.hpp"
#include "msfem/compare/pipeline/json_values.hpp"
#include "msfem/compare/writers/plots.hpp"
#include "plot_render.hpp"

namespace msfem::compare {
namespace {

using nlohmann::json;

json vector_json(const Eigen::Vector3d& v) {
  return json::array({v.x(), v.y(), v.z()});
}

json tick_json(const TickStatistics& t) {
  return {{"p50", t.p50_ms}, {"p99", t.p99_ms}, {"max", t.max_ms}};
}

std::string trace_file(const std::string& variant) {
  return "trace_" + variant + ".csv";
}

json variant_json(const VariantAlongPath& v) {
  const HapticReplay& r = v.replay;
  json samples = json::array();
  for (const PathForceError& e : v.samples)
    samples.push_back({{"t_s", e.t_s},
                       {"fem_force_n", vector_json(e.fem_force)},
                       {"fem_force_rel_error", json_or_null(e.fem_force_rel_error)},
                       {"force_n", vector_json(e.haptic_force)},
                       {"error_n", (e.haptic_force - e.fem_force).norm()},
                       {"static_force_n", e.static_force ? vector_json(*e.static_force) : json()}});
  json changes = json::array();
  for (const auto& [t, set] : r.changes_applied)
    changes.push_back({{"t_s", t}, {"set", set}});
  return {{"name", r.name},
          {"rate_hz", r.rate_hz},
          {"ticks", r.ticks},
          {"deadline_misses", r.deadline_misses},
          {"deadline_miss_times_s", r.miss_times_s},
          {"step_ms", tick_json(r.tick)},
          {"realtime_priority", r.realtime_priority},
          {"integrator", r.integrator},
          {"stepper", r.stepper},
          {"precision", r.precision},
          {"model_threads", r.model_threads},
          {"model_dt_s", r.model_dt_s},
          {"model_dt_halvings", r.halvings},
          {"model_rate_hz", r.model_rate_hz},
          {"model_capacity_hz", r.model_capacity_hz},
          {"model_busy_fraction", r.model_busy_fraction},
          {"model_update_hz", r.model_update_hz},
          {"realtime_factor", r.realtime_factor},
          {"changes_applied", changes},
          {"force_error_along_path",
           {{"rms_n", v.rms_error_n},
            {"max_n", v.max_error_n},
            {"relative", v.relative_error},
            {"static_rms_n", json_or_null(v.static_rms_error_n)},
            {"window_s", force_window_s},
            {"samples", samples}}},
          {"trace_file", trace_file(r.name)}};
}

void write_trace(const HapticReplay& r, const std::filesystem::path& file) {
  std::ostringstream out;
  out << "t_s,x_m,y_m,z_m,fx_n,fy_n,fz_n\n" << std::setprecision(9);
  for (const HapticTick& t : r.trace)
    out << t.t_s << ',' << t.center.x() << ',' << t.center.y() << ',' << t.center.z() << ','
        << t.force.x() << ',' << t.force.y() << ',' << t.force.z() << '\n';
  write_text_atomically(file, out.str());
}

std::string fixed(double value, int digits) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(digits) << value;
  return s.str();
}

// |F| against time: each variant's rendered force as a line, the FEM's quasi-static answers as
// points with their error bars, the run-time changes as dashed verticals.
std::filesystem::path force_time_plot(const HapticRun& run, const std::filesystem::path& file) {
  std::ostringstream data, commands;
  data << std::setprecision(9);
  for (const PathForceError& e : run.variants.front().samples)
    data << e.t_s << ' ' << e.fem_force.norm() << ' '
         << e.fem_force.norm() * e.fem_force_rel_error.value_or(0.0) << '\n';
  data << "\n\n";
  for (const VariantAlongPath& v : run.variants) {
    const auto& trace = v.replay.trace;
    const std::size_t stride = std::max<std::size_t>(1, trace.size() / 4000);
    for (std::size_t i = 0; i < trace.size(); i += stride)
      data << trace[i].t_s << ' ' << trace[i].force.norm() << '\n';
    data << "\n\n";
  }
  // The force's range at its 99.5th percentile: an explicit model's contact chatter would
  // otherwise flatten the curves into the axis. The peaks clipped are stated in the title.
  std::vector<double> magnitudes;
  double fem_most = 0.0, peak = 0.0;
  for (const PathForceError& e : run.variants.front().samples)
    fem_most = std::max(fem_most, e.fem_force.norm());
  for (const VariantAlongPath& v : run.variants)
    for (const HapticTick& t : v.replay.trace)
      magnitudes.push_back(t.force.norm());
  std::sort(magnitudes.begin(), magnitudes.end());
  if (!magnitudes.empty()) peak = magnitudes.back();
  const double high = magnitudes.empty()
                          ? 0.0
                          : magnitudes[static_cast<std::size_t>(0.995 * (magnitudes.size() - 1))];
  const double top = 1.3 * std::max(high, fem_most);
  const bool clipped = top > 0 && peak > top;
  commands << "set title 'Force on the tool along the replayed path"
           << (clipped ? " (peaks up to " + fixed(peak, 2) + " N clipped)" : std::string())
           << "' noenhanced\n"
           << "set xrange [0:" << run.settings.seconds << "]\n";
  if (top > 0) commands << "set yrange [0:" << top << "]\n";
  commands << "set xlabel 'time (s)'\nset ylabel 'force on the tool (N)'\nset grid\n"
           << "set key top left noenhanced\n";
  for (const ParameterChange& c : run.changes)
    commands << "set arrow from " << c.t_s << ", graph 0 to " << c.t_s
             << ", graph 1 nohead dt 2 lc rgb '#888888'\n";
  commands << "plot data index 0 using 1:2:3 with yerrorbars pt 7 ps 1.2 lc rgb '#000000' "
              "title 'FEM (quasi-static)'";
  for (std::size_t i = 0; i < run.variants.size(); ++i)
    commands << ", \\\n     data index " << i + 1 << " using 1:2 with lines lw 2 lc rgb '"
             << variant_colour(i) << "' title '" << run.variants[i].replay.name << "'";
  commands << "\n";
  return detail::render(file, data.str(), commands.str());
}

std::string report_markdown(const HapticRun& run, const std::string& plot) {
  std::ostringstream md;
  md << "# Haptic replay: " << run.case_name << "\n\n"
     << "The tool path (" << run.path_source << ", `path.csv`) replayed for "
     << run.settings.seconds << " s against each variant, the force rendered at "
     << run.settings.rate_hz
     << " Hz on a thread of its own from the local contact model the variant's own thread hands "
        "over after each batch of steps (docs/haptics.md). The FEM (P"
     << run.fem_degree << ") answers quasi-statically at " << run.samples.size()
     << " points of the path.\n\n";
  if (!plot.empty()) md << "![force against time](" << plot << ")\n\n";
  md << "| variant | haptic Hz | misses | tick p50 ms | p99 ms | max ms | model steps/s | "
        "capacity steps/s | model updates/s | real-time factor | force err rms N | max N | "
        "relative | "
        "equilibrium err rms N |\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const VariantAlongPath& v : run.variants) {
    const HapticReplay& r = v.replay;
    md << "| " << r.name << " | " << fixed(r.rate_hz, 1) << " | " << r.deadline_misses << " | "
       << fixed(r.tick.p50_ms, 3) << " | " << fixed(r.tick.p99_ms, 3) << " | "
       << fixed(r.tick.max_ms, 3) << " | " << fixed(r.model_rate_hz, 0) << " | "
       << fixed(r.model_capacity_hz, 0) << " | " << fixed(r.model_update_hz, 0) << " | "
       << fixed(r.realtime_factor, 2) << " | " << fixed(v.rms_error_n, 4) << " | "
       << fixed(v.max_error_n, 4) << " | " << fixed(v.relative_error, 3) << " | "
       << (v.static_rms_error_n ? fixed(*v.static_rms_error_n, 4) : std::string("-")) << " |\n";
  }
  md << "\nA tick's time runs from when it was due to when its force was ready (the thread's "
        "wake-up included); a miss is a tick ready after the next one was due. The equilibrium "
        "error is the variant's static answer at the same points: what is left of the force "
        "error once the dynamics and the multirate coupling are taken out.\n";
  if (run.fem_error.method != "none")
    md << "\nThe FEM's own force error (" << run.fem_error.method
       << ") is drawn as its error bars.\n";
  for (const auto& [t, set] : run.variants.empty() ? std::vector<std::pair<double, std::string>>{}
                                                   : run.variants.front().replay.changes_applied)
    md << "\nAt " << fixed(t, 3) << " s the model changed: `" << set << "`.";
  for (const auto& [name, why] : run.failed)
    md << "\n\n**" << name << " failed:** " << why;
  for (const std::string& note : run.notes)
    md << "\n\n" << note;
  md << "\n";
  return md.str();
}

}  // namespace

nlohmann::json haptic_json(const HapticRun& run) {
  json variants = json::array();
  double rate = run.variants.empty() ? 0.0 : run.variants.front().replay.rate_hz;
  int misses = 0, ticks = 0;
  TickStatistics worst;
  for (const VariantAlongPath& v : run.variants) {
    variants.push_back(variant_json(v));
    rate = std::min(rate, v.replay.rate_hz);
    misses += v.replay.deadline_misses;
    ticks += v.replay.ticks;
    worst.p50_ms = std::max(worst.p50_ms, v.replay.tick.p50_ms);
    worst.p99_ms = std::max(worst.p99_ms, v.replay.tick.p99_ms);
    worst.max_ms = std::max(worst.max_ms, v.replay.tick.max_ms);
  }
  json changes = json::array();
  for (const ParameterChange& c : run.changes)
    changes.push_back({{"t_s", c.t_s}, {"key", c.key}, {"value", c.value}});
  json failed = json::array();
  for (const auto& [name, why] : run.failed)
    failed.push_back({{"name", name}, {"why", why}});
  return {{"format", "msfem-haptic"},
          {"format_version", 1},
          {"case", run.case_name},
          {"case_file", run.case_file.string()},
          {"requested_rate_hz", run.settings.rate_hz},
          {"seconds", run.settings.seconds},
          {"rate_hz", rate},
          {"deadline_misses", misses},
          {"ticks", ticks},
          {"step_ms", tick_json(worst)},
          {"path", {{"source", run.path_source}, {"file", "path.csv"}}},
          {"changes", changes},
          {"fem",
           {{"degree", run.fem_degree},
            {"samples", run.samples.size()},
            {"error_estimate", run.fem_error.method}}},
          {"variants", variants},
          {"failed", failed},
          {"notes", run.notes}};
}

void write_haptic_outputs(const HapticRun& run, const std::filesystem::path& directory) {
  write_text_atomically(directory / "haptic.json", haptic_json(run).dump(2) + "\n");
  if (run.path) write_tool_path(*run.path, directory / "path.csv");
  for (const VariantAlongPath& v : run.variants)
    write_trace(v.replay, directory / trace_file(v.replay.name));
  std::string plot;
  if (!run.variants.empty() && gnuplot_available()) {
    plot = force_time_plot(run, directory / "force_time.png").filename().string();
  }
  write_text_atomically(directory / "report.md", report_markdown(run, plot));
}

}  // namespace msfem::compare
