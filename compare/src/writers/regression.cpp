#include "msfem/compare/writers/regression.hpp"

#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <iterator>
#include <sstream>

#include "msfem/compare/pipeline/atomic_file.hpp"
#include "msfem/compare/pipeline/content_hash.hpp"
#include "msfem/compare/pipeline/fem_cache.hpp"
#include "msfem/compare/writers/fields_h5.hpp"
#include "msfem/compare/writers/run_summary.hpp"

namespace msfem::compare {
namespace {

constexpr int format_version = 2;
// Default tolerances written into a new baseline (numdiff style: |now − base| <= abs + rel |base|).
constexpr double metric_abs_tol = 1e-9, metric_rel_tol = 1e-3;
constexpr double field_abs_tol_m = 1e-9, field_rel_tol = 1e-3;  // rel: of the largest |u|

// The baseline holds each variant at the run's first load.
double metric_value(const ToolLoadVariant& v, Metric metric) {
  switch (metric) {
    case Metric::rel_l2_error:
      return v.displacement.all.rel_l2_error;
    case Metric::max_error_m:
      return v.displacement.all.max_error_m;
    case Metric::reaction_force_rel_error:
      return v.force_measured ? v.reaction_force_rel_error : std::nan("");
    case Metric::patch_displacement_rel_error:
      return v.patch_displacement_rel_error.value_or(std::nan(""));
    case Metric::volume_change:
      return v.volume_change;
  }
  return std::nan("");
}

std::string six_digits(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", x);
  return text;
}

bool finite(const nlohmann::json& j) {
  return j.is_number() && std::isfinite(j.get<double>());
}

void compare_metric(const std::string& case_name, const ToolLoadVariant& v, Metric metric,
                    const nlohmann::json& base, std::vector<RegressionRow>& rows) {
  const std::string name = metric_name(metric);
  RegressionRow row{case_name, v.name, name, "-", six_digits(metric_value(v, metric)), "-", "ok"};
  const double now = metric_value(v, metric);
  if (!base.contains(name)) {
    row.status = "MISSING";
    rows.push_back(row);
    return;
  }
  const auto& b = base.at(name);
  if (!finite(b.value("value", nlohmann::json())) || !std::isfinite(now)) {
    row.status = "NON-FINITE";
    rows.push_back(row);
    return;
  }
  const double value = b.at("value"), abs_tol = b.at("abs_tol"), rel_tol = b.at("rel_tol");
  const bool magnitude = metric == Metric::volume_change;
  const double base_v = magnitude ? std::abs(value) : value,
               now_v = magnitude ? std::abs(now) : now;
  const double tol = abs_tol + rel_tol * std::abs(value);
  row.baseline = six_digits(value);
  row.tolerance = six_digits(tol);
  if (now_v > base_v + tol) row.status = "WORSE";
  if (now_v < base_v - tol) row.status = "improved";
  rows.push_back(row);
}

void compare_field(const std::string& case_name, const ToolLoadVariant& v,
                   const nlohmann::json& base, const std::filesystem::path& fields_file,
                   std::vector<RegressionRow>& rows) {
  RegressionRow row{case_name, v.name, "surface_displacement", "-", "-", "-", "ok"};
  Eigen::MatrixXd reference;
  try {
    const auto& f = base.at("field");
    reference = read_h5_matrix(fields_file, f.at("dataset").get<std::string>());
  } catch (const std::exception& e) {
    // A file that is there but cannot be read (truncated, not HDF5, the dataset gone) is corrupt,
    // not missing: the fix is different (restore it, not write it).
    row.baseline = fields_file.filename().string();
    const bool present = std::filesystem::is_regular_file(fields_file);
    row.status = present ? "CORRUPT" : "MISSING";
    if (present) row.now = std::string("unreadable: ") + e.what();
    rows.push_back(row);
    return;
  }
  const Eigen::Index n = v.surface_displacement.rows();
  if (reference.rows() != n || reference.cols() != 3) {
    row.baseline = std::to_string(reference.rows()) + " vertices";
    row.now = std::to_string(n) + " vertices";
    row.status = "STALE";
    rows.push_back(row);
    return;
  }
  for (Eigen::Index i = 0; i < n; ++i)
    if (!reference.row(i).allFinite() || !v.surface_displacement.row(i).allFinite()) {
      row.baseline = "vertex " + std::to_string(i);
      row.status = "NON-FINITE";
      rows.push_back(row);
      return;
    }
  const double max_base = reference.rowwise().norm().maxCoeff();
  const double max_diff = (v.surface_displacement - reference).cwiseAbs().maxCoeff();
  const auto& f = base.at("field");
  const double tol = f.at("abs_tol_m").get<double>() + f.at("rel_tol").get<double>() * max_base;
  row.baseline = "max |u| " + six_digits(max_base);
  row.now = "max diff " + six_digits(max_diff);
  row.tolerance = six_digits(tol);
  if (max_diff > tol) row.status = "WORSE";
  rows.push_back(row);
}

std::string reference_hash(const CaseRun& run) {
  const std::vector<ToolPlacement>& tools = run.problem.tools;
  return reference_inputs_hash(
      run.problem, tools,
      tools.empty() ? std::nullopt : std::optional<ToolPlacement>(tools.front()));
}

}  // namespace

const std::vector<Metric>& regression_metrics() {
  static const std::vector<Metric> metrics = {Metric::rel_l2_error, Metric::max_error_m,
                                              Metric::reaction_force_rel_error,
                                              Metric::volume_change};
  return metrics;
}

std::string file_hash(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return ContentHash().bytes(bytes.data(), bytes.size()).hex();
}

std::string surface_hash(const cases::Surface& s) {
  return ContentHash()
      .bytes(s.vertices.data(), sizeof(double) * static_cast<std::size_t>(s.vertices.size()))
      .bytes(s.triangles.data(), sizeof(int) * static_cast<std::size_t>(s.triangles.size()))
      .hex();
}

nlohmann::json write_baseline(const CaseRun& run, const std::filesystem::path& directory) {
  const auto& p = run.problem.parameters;
  char date[32];
  const std::time_t now = std::time(nullptr);
  std::strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  const std::string fields_file = p.name + ".fields.h5";
  nlohmann::json variants = nlohmann::json::object();
  std::vector<VariantField> fields;
  for (const auto& v : run.variants) {
    nlohmann::json metrics = nlohmann::json::object();
    for (const auto& m : regression_metrics())
      if (std::isfinite(metric_value(v.loads.front(), m)))  // an outside answer without a force
        metrics[metric_name(m)] = {{"value", metric_value(v.loads.front(), m)},
                                   {"abs_tol", metric_abs_tol},
                                   {"rel_tol", metric_rel_tol}};
    variants[v.name] = {{"metrics", metrics},
                        {"field",
                         {{"dataset", "/variants/" + v.name + "/displacement"},
                          {"units", "m"},
                          {"abs_tol_m", field_abs_tol_m},
                          {"rel_tol", field_rel_tol}}}};
    fields.push_back({v.name, v.loads.front().surface_displacement, v.loads.front().error});
  }
  const nlohmann::json baseline = {{"format_version", format_version},
                                   {"case", p.name},
                                   {"case_file", p.file.lexically_normal().string()},
                                   {"case_file_hash", file_hash(p.file)},
                                   {"mesh_hash", surface_hash(run.problem.surface)},
                                   {"reference_hash", reference_hash(run)},
                                   {"units", {{"length", "m"}}},
                                   {"degree", p.fem.degree},
                                   {"git_revision", git_revision()},
                                   {"date", date},
                                   {"fields_file", fields_file},
                                   {"variants", variants}};
  std::filesystem::create_directories(directory);
  FemField fem{run.mesh.vertices, run.mesh.tetrahedra, run.loads.front().fem.vertex_displacement};
  write_fields_h5(directory / fields_file, run.problem.surface.vertices,
                  run.problem.surface.triangles, fem, fields);
  write_text_atomically(directory / (p.name + ".json"), baseline.dump(1) + "\n");
  return baseline;
}

std::vector<RegressionRow> compare_with_baseline(const CaseRun& run, const nlohmann::json& base,
                                                 const std::filesystem::path& directory) {
  const auto& p = run.problem.parameters;
  std::vector<RegressionRow> rows;
  auto header = [&](const std::string& what, const std::string& b, const std::string& now) {
    rows.push_back({p.name, "-", what, b, now, "-", "STALE"});
  };
  if (base.value("format_version", 0) != format_version) {
    header("format_version", base.value("format_version", nlohmann::json()).dump(),
           std::to_string(format_version));
    return rows;
  }
  if (base.value("case_file_hash", "") != file_hash(p.file))
    header("case_file_hash (stale baseline, run --update)", base.value("case_file_hash", ""),
           file_hash(p.file));
  if (base.value("mesh_hash", "") != surface_hash(run.problem.surface))
    header("mesh_hash (stale baseline, run --update)", base.value("mesh_hash", ""),
           surface_hash(run.problem.surface));
  // The same file run with --set another material, load or support solves another problem: its
  // numbers are not comparable, metric by metric, with the baseline's.
  if (base.value("reference_hash", "") != reference_hash(run))
    header(
        "reference_hash (another FEM problem: material, loads, supports or fem settings "
        "differ from the baseline's; run --update)",
        base.value("reference_hash", "(none)"), reference_hash(run));
  if (!rows.empty()) return rows;
  const auto& variants = base.at("variants");
  for (const auto& v : run.variants) {
    if (!variants.contains(v.name)) {
      rows.push_back({p.name, v.name, "baseline", "-", "present", "-", "MISSING"});
      continue;
    }
    const auto& metrics = variants.at(v.name).at("metrics");
    for (const auto& m : regression_metrics())
      // An outside answer without a force has no force error, here or in its baseline.
      if (metrics.contains(metric_name(m)) || std::isfinite(metric_value(v.loads.front(), m)))
        compare_metric(p.name, v.loads.front(), m, metrics, rows);
    compare_field(p.name, v.loads.front(), variants.at(v.name),
                  directory / base.value("fields_file", ""), rows);
  }
  for (const auto& [name, unused] : variants.items()) {
    bool ran = false;
    for (const auto& v : run.variants)
      ran = ran || v.name == name;
    if (!ran) rows.push_back({p.name, name, "run", "present", "-", "-", "MISSING"});
  }
  return rows;
}

std::string regression_table(const std::vector<RegressionRow>& rows) {
  std::ostringstream out;
  char line[512];
  std::snprintf(line, sizeof line, "%-20s %-13s %-46s %-18s %-18s %-11s %s\n", "case", "variant",
                "metric", "baseline", "now", "tolerance", "status");
  out << line;
  for (const auto& r : rows) {
    std::snprintf(line, sizeof line, "%-20s %-13s %-46s %-18s %-18s %-11s %s\n",
                  r.case_name.c_str(), r.variant.c_str(), r.metric.c_str(), r.baseline.c_str(),
                  r.now.c_str(), r.tolerance.c_str(), r.status.c_str());
    out << line;
  }
  return out.str();
}

}  // namespace msfem::compare
