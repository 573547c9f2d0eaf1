// An outside simulator's answer read and measured as a variant (docs/external.md).
#include "msfem/compare/pipeline/external_result.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "msfem/cases/errors.hpp"
#include "msfem/cases/surface_io.hpp"
#include "msfem/cases/vtk_surface.hpp"

namespace msfem::compare {
namespace {

std::string number(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", x);
  return text;
}

[[noreturn]] void refuse(const std::string& where, const std::filesystem::path& file,
                         const std::string& what) {
  throw cases::InputError(where + ": " + file.string() + ": " + what);
}

// The displacement of each case vertex from the answer's points, checked for count, order and unit:
// no vertex moves more than half the surface's size (a file in millimetres, or in another vertex
// order, moves nearly every vertex by far more).
Eigen::MatrixX3d displacement_from(const Eigen::MatrixX3d& points,
                                   const std::optional<Eigen::MatrixXd>& displacement,
                                   const Problem& problem, const std::string& where,
                                   const std::filesystem::path& file) {
  const Eigen::MatrixX3d& rest = problem.surface.vertices;
  if (points.rows() != rest.rows())
    refuse(where, file,
           std::to_string(points.rows()) + " vertices where the case's surface has " +
               std::to_string(rest.rows()) + " (msfem export-load's surface.vtu, in its order)");
  const double size = (rest.colwise().maxCoeff() - rest.colwise().minCoeff()).norm();
  Eigen::MatrixX3d u = points - rest;
  if (displacement) {
    if (displacement->cols() != 3)
      refuse(where, file,
             "point data 'displacement' has " + std::to_string(displacement->cols()) +
                 " components; a displacement has 3");
    // The file's points are the rest positions or the deformed ones; either way in the case's
    // order.
    for (Eigen::Index v = 0; v < rest.rows(); ++v) {
      const double off = std::min(u.row(v).norm(), (u.row(v) - displacement->row(v)).norm());
      if (off > 1e-6 * size)
        refuse(where, file,
               "vertex " + std::to_string(v) + " lies " + number(off) +
                   " m from the case's vertex " + std::to_string(v) +
                   " at rest and deformed: not surface.vtu's vertex order, or not in metres");
    }
    u = *displacement;
  }
  for (Eigen::Index v = 0; v < u.rows(); ++v)
    if (!(u.row(v).norm() <= 0.5 * size))
      refuse(where, file,
             "vertex " + std::to_string(v) + " moves " + number(u.row(v).norm()) +
                 " m, more than half the surface's size (" + number(size) +
                 " m): not surface.vtu's vertex order, or not in metres");
  return u;
}

// STEM.force.json: {"schema": "msfem-force", "version": 1, "tool_force_n": [fx, fy, fz]}.
Eigen::Vector3d force_from_json(const std::filesystem::path& file, const std::string& where) {
  std::ifstream in(file);
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    refuse(where, file, std::string("not JSON: ") + e.what());
  }
  if (!j.is_object() || j.value("schema", "") != external::force_schema)
    refuse(where, file,
           std::string("'schema' is not \"") + external::force_schema + "\" (docs/external.md)");
  if (j.value("version", -1) != external::force_version)
    refuse(where, file,
           "schema version " + (j.contains("version") ? j["version"].dump() : "(none)") +
               "; msfem reads version " + std::to_string(external::force_version));
  const auto& f = j.value("tool_force_n", nlohmann::json());
  if (!f.is_array() || f.size() != 3)
    refuse(where, file,
           "'tool_force_n' has " + std::to_string(f.is_array() ? f.size() : 0) +
               " components; a force has 3");
  Eigen::Vector3d force;
  for (int c = 0; c < 3; ++c) {
    if (!f[std::size_t(c)].is_number() || !std::isfinite(f[std::size_t(c)].get<double>()))
      refuse(where, file, "'tool_force_n' component " + std::to_string(c) + " is not a number");
    force[c] = f[std::size_t(c)].get<double>();
  }
  return force;
}

// STEM.curve.csv: depth_m, fx, fy, fz per line (a header line of words is skipped).
std::vector<ForceDepthPoint> curve_from_csv(const std::filesystem::path& file,
                                            const std::string& where) {
  std::ifstream in(file);
  std::vector<ForceDepthPoint> curve;
  int number_of_line = 0;
  for (std::string line; std::getline(in, line);) {
    ++number_of_line;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    if (number_of_line == 1 && line.find_first_of("abcdefghijklmnopqrstuvwxyz") != line.npos)
      continue;
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream fields(line);
    ForceDepthPoint p;
    std::string extra;
    if (!(fields >> p.depth_m >> p.force_n.x() >> p.force_n.y() >> p.force_n.z()) ||
        (fields >> extra) || !std::isfinite(p.depth_m) || !p.force_n.allFinite())
      refuse(where, file,
             "line " + std::to_string(number_of_line) + ": not four numbers depth_m, fx, fy, fz");
    curve.push_back(p);
  }
  return curve;
}

std::filesystem::path beside(const std::filesystem::path& file, const std::string& suffix) {
  return file.parent_path() / (file.stem().string() + suffix);
}

}  // namespace

ExternalAnswer read_external_answer(const std::filesystem::path& file, const Problem& problem,
                                    const std::string& where) {
  ExternalAnswer a;
  std::optional<Eigen::Vector3d> field_force;
  try {
    if (file.extension() == ".vtu") {
      const cases::VtkSurface s = cases::read_vtk_surface(file);
      std::optional<Eigen::MatrixXd> displacement;
      for (const auto& [name, values] : s.point_data)
        if (name == "displacement")
          displacement = values;
        else if (name != "vertex_id" && name != "fixed")
          refuse(where, file, "point data '" + name + "' is not one msfem reads (displacement)");
      for (const auto& [name, values] : s.field_data) {
        if (name != "tool_force")
          refuse(where, file, "field data '" + name + "' is not one msfem reads (tool_force)");
        if (values.size() != 3)
          refuse(where, file,
                 "field data 'tool_force' has " + std::to_string(values.size()) +
                     " components; a force has 3");
        field_force = Eigen::Map<const Eigen::Vector3d>(values.data());
      }
      a.surface_displacement = displacement_from(s.points, displacement, problem, where, file);
    } else if (file.extension() == ".obj") {
      const cases::Surface s = cases::read_surface(file);
      a.surface_displacement = displacement_from(s.vertices, std::nullopt, problem, where, file);
    } else {
      refuse(where, file, "a result is a .vtu or an .obj of the deformed surface");
    }
  } catch (const cases::InputError& e) {
    const std::string what = e.what();
    throw cases::InputError(what.rfind(where, 0) == 0 ? what : where + ": " + what);
  }
  const std::filesystem::path json = beside(file, ".force.json");
  if (std::filesystem::exists(json)) {
    if (field_force)
      refuse(
          where, file,
          "the force is given twice (field data tool_force and " + json.filename().string() + ")");
    a.tool_force = force_from_json(json, where);
  } else {
    a.tool_force = field_force;
  }
  if (const auto csv = beside(file, ".curve.csv"); std::filesystem::exists(csv))
    a.curve = curve_from_csv(csv, where);
  return a;
}

void check_results_fit(const Problem& problem) {
  const auto& p = problem.parameters;
  const std::size_t loads = std::max<std::size_t>(1, problem.tools.size());
  for (const auto& r : p.mass_spring.results) {
    const std::string where = p.file.string() + ": mass spring/results: " + r.name;
    if (r.files.size() != loads)
      throw cases::InputError(where + ": " + std::to_string(r.files.size()) +
                              " files for the case's " + std::to_string(loads) +
                              " loads (one deformed surface per load, in load order)");
    for (const auto& file : r.files)
      read_external_answer(file, problem, where);
  }
}

std::vector<VariantResult> external_variants(const CaseRun& run) {
  const auto& p = run.problem.parameters;
  std::vector<VariantResult> results;
  for (const auto& r : p.mass_spring.results) {
    const std::string where = p.file.string() + ": mass spring/results: " + r.name;
    VariantResult v;
    v.name = r.name;
    v.spec = {r.name, std::nullopt, r.files.front()};
    v.external = true;
    v.nodes = static_cast<int>(run.problem.surface.num_vertices());
    v.timing.stepper = "external";
    for (const auto& f : r.files)
      v.parameters.external_files.push_back(f.string());
    // A run at the first tool only (a sweep) takes the first file.
    for (std::size_t k = 0; k < run.loads.size(); ++k) {
      ExternalAnswer a = read_external_answer(r.files.at(k), run.problem, where);
      v.loads.push_back(measure_at_load(run.problem, r.name, a.surface_displacement, a.tool_force,
                                        std::move(a.curve), run.loads[k]));
      if (run.loads[k].tool && !a.tool_force)
        v.warnings.push_back(
            {Warning::Kind::no_tool_force, "no tool force given: the force columns are empty", k});
    }
    results.push_back(std::move(v));
  }
  return results;
}

}  // namespace msfem::compare
