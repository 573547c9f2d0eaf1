// The tool's trajectory for msfem haptic: read from a device log or made at the case's tool, and
// the points along it where the FEM answers.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "msfem/cases/errors.hpp"
#include "msfem/cases/surface.hpp"
#include "msfem/cases/text.hpp"
#include "msfem/compare/pipeline/haptic.hpp"

namespace msfem::compare {
namespace {

using cases::trimmed;

std::vector<std::string> fields_of(const std::string& line) {
  std::vector<std::string> fields;
  std::stringstream in(line);
  std::string field;
  while (std::getline(in, field, ','))
    fields.push_back(trimmed(field));
  if (!line.empty() && line.back() == ',') fields.emplace_back();
  return fields;
}

std::optional<double> number(const std::string& text) {
  if (text.empty()) return std::nullopt;
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size() || !std::isfinite(value)) return std::nullopt;
  return value;
}

// The surface's outward normal at a point of it, interpolated from the vertex normals.
Eigen::Vector3d normal_at(const Problem& problem, const Eigen::MatrixX3d& normals,
                          const SurfacePoint& at) {
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  for (int k = 0; k < 3; ++k)
    n += at.weights[k] * normals.row(problem.surface.triangles(at.triangle, k)).transpose();
  return n.normalized();
}

ToolPlacement placement_with_normals(const Problem& problem, const Eigen::MatrixX3d& normals,
                                     const Eigen::Vector3d& center, double radius) {
  const SurfacePoint q = closest_surface_point(problem.surface, center);
  const Eigen::Vector3d n = normal_at(problem, normals, q);
  const double standoff = (center - q.point).dot(n);  // > 0: the centre is outside
  ToolPlacement t;
  Eigen::Index corner = 0;
  q.weights.maxCoeff(&corner);
  t.vertex = problem.surface.triangles(q.triangle, static_cast<int>(corner));
  t.outward_normal = n;
  t.radius = radius;
  t.depth = radius - standoff;
  t.contact_point = center - standoff * n;  // so that pushed_center() is the centre itself
  t.frictionless = true;
  return t;
}

}  // namespace

ToolPath::ToolPath(std::vector<double> times, std::vector<Eigen::Vector3d> centers,
                   bool had_orientation)
    : times_(std::move(times)), centers_(std::move(centers)), had_orientation_(had_orientation) {
  if (times_.size() < 2 || times_.size() != centers_.size())
    throw std::invalid_argument("a tool path needs two samples or more, each with a time");
  for (std::size_t i = 0; i < times_.size(); ++i)
    if (!std::isfinite(times_[i]) || !centers_[i].allFinite() ||
        (i > 0 && !(times_[i] > times_[i - 1])))
      throw std::invalid_argument("a tool path's times must increase and be finite");
}

Eigen::Vector3d ToolPath::at(double t) const {
  if (!(t > times_.front())) return centers_.front();
  if (t >= times_.back()) return centers_.back();
  const auto next = std::upper_bound(times_.begin(), times_.end(), t) - times_.begin();
  const auto i = static_cast<std::size_t>(next - 1);
  const double w = (t - times_[i]) / (times_[i + 1] - times_[i]);
  return (1 - w) * centers_[i] + w * centers_[i + 1];
}

ToolPath read_tool_path(const std::filesystem::path& csv) {
  std::ifstream in(csv);
  if (!in) throw cases::InputError(csv.string() + ": cannot open the tool path");
  std::vector<double> times;
  std::vector<Eigen::Vector3d> centers;
  std::size_t columns = 0;
  std::string line;
  for (int number_of_line = 1; std::getline(in, line); ++number_of_line) {
    if (number_of_line == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);  // UTF-8 BOM
    line = trimmed(line);
    if (line.empty() || line[0] == '#') continue;
    const std::string where = csv.string() + ":" + std::to_string(number_of_line) + ": ";
    const std::vector<std::string> f = fields_of(line);
    if (f.size() != 4 && f.size() != 8)
      throw cases::InputError(where + std::to_string(f.size()) +
                              " columns; a tool path row is t_s, x_m, y_m, z_m and optionally an "
                              "orientation quaternion qw, qx, qy, qz");
    const bool no_numbers = std::none_of(
        f.begin(), f.end(), [](const std::string& x) { return number(x).has_value(); });
    if (columns == 0 && times.empty() && no_numbers) {  // the header row
      columns = f.size();
      continue;
    }
    if (columns != 0 && f.size() != columns)
      throw cases::InputError(where + std::to_string(f.size()) +
                              " columns where the rows above have " + std::to_string(columns));
    columns = f.size();
    double v[8];
    for (std::size_t k = 0; k < f.size(); ++k) {
      const auto value = number(f[k]);
      if (!value)
        throw cases::InputError(where + "column " + std::to_string(k + 1) + " '" + f[k] +
                                "' is not a finite number");
      v[k] = *value;
    }
    if (!times.empty() && !(v[0] > times.back()))
      throw cases::InputError(where + "time " + f[0] + " s does not come after the row above's " +
                              std::to_string(times.back()) + " s");
    if (f.size() == 8) {
      const double norm = std::sqrt(v[4] * v[4] + v[5] * v[5] + v[6] * v[6] + v[7] * v[7]);
      if (std::abs(norm - 1.0) > 1e-3)
        throw cases::InputError(where + "the orientation quaternion has norm " +
                                std::to_string(norm) + ", not 1");
    }
    times.push_back(v[0]);
    centers.emplace_back(v[1], v[2], v[3]);
  }
  if (times.size() < 2)
    throw cases::InputError(csv.string() + ": a tool path needs two rows or more (it has " +
                            std::to_string(times.size()) + ")");
  return ToolPath(std::move(times), std::move(centers), columns == 8);
}

void write_tool_path(const ToolPath& path, const std::filesystem::path& csv) {
  std::ofstream out(csv);
  out << "t_s,x_m,y_m,z_m\n" << std::setprecision(17);
  for (std::size_t i = 0; i < path.times().size(); ++i) {
    const Eigen::Vector3d& c = path.centers()[i];
    out << path.times()[i] << ',' << c.x() << ',' << c.y() << ',' << c.z() << '\n';
  }
  if (!out) throw std::runtime_error("cannot write " + csv.string());
}

ToolPath default_tool_path(const Problem& problem) {
  if (problem.tools.empty())
    throw cases::InputError(problem.parameters.file.string() +
                            ": loads/tool is off, so there is no tool point for the default path: "
                            "enable the tool (its radius is the replayed tool's) or give --path");
  const ToolPlacement& tool = problem.tools.front();
  const double r = tool.radius, d = tool.depth, off = 0.005, slide = 0.010;
  const Eigen::Vector3d& n = tool.outward_normal;
  Eigen::Index axis = 0;
  n.cwiseAbs().minCoeff(&axis);
  const Eigen::Vector3d along = n.cross(Eigen::Vector3d::Unit(axis)).normalized();
  const Eigen::MatrixX3d normals = cases::vertex_normals(problem.surface);

  std::vector<double> t = {0.0, 0.5, 1.5};
  std::vector<Eigen::Vector3d> c = {tool.contact_point + (r + off) * n, tool.contact_point + r * n,
                                    tool.pushed_center()};
  // The slide: points 0.5 mm apart along the surface, the tool kept at the case's depth.
  const int knots = 20;
  Eigen::Vector3d last_point = tool.contact_point, last_normal = n;
  for (int k = 0; k <= knots; ++k) {
    const SurfacePoint q =
        closest_surface_point(problem.surface, tool.contact_point + slide * k / knots * along);
    last_point = q.point;
    last_normal = normal_at(problem, normals, q);
    t.push_back(2.0 + 2.0 * k / knots);
    c.push_back(last_point + (r - d) * last_normal);
  }
  t.insert(t.end(), {4.5, 5.5, 6.0});
  c.insert(c.end(), {c.back(), last_point + r * last_normal, last_point + (r + off) * last_normal});
  return ToolPath(std::move(t), std::move(c));
}

ToolPlacement placement_at(const Problem& problem, const Eigen::Vector3d& center, double radius) {
  return placement_with_normals(problem, cases::vertex_normals(problem.surface), center, radius);
}

std::vector<PathSample> path_samples(const Problem& problem, const ToolPath& path, double seconds,
                                     int count, const std::string& path_name) {
  const double radius = problem.parameters.loads.tool.radius_m;
  const Eigen::MatrixX3d normals = cases::vertex_normals(problem.surface);
  const int scan = 1000;
  double first = -1, last = -1, deepest = 0;
  for (int i = 0; i <= scan; ++i) {
    const double t = seconds * i / scan;
    const double depth =
        placement_with_normals(problem, normals, path.at(path.start() + t), radius).depth;
    if (depth <= 0) continue;
    if (first < 0) first = t;
    last = t;
    deepest = std::max(deepest, depth);
  }
  if (first < 0)
    throw cases::InputError(path_name + ": the tool (radius " + std::to_string(radius) +
                            " m, loads/tool/radius) never touches the case's surface in the " +
                            std::to_string(seconds) + " s replayed");
  std::vector<PathSample> samples;
  for (int k = 0; k < count; ++k) {
    const double t = first + (k + 0.5) * (last - first) / count;
    ToolPlacement tool =
        placement_with_normals(problem, normals, path.at(path.start() + t), radius);
    // Barely touching, the force is too small to measure an error against.
    if (tool.depth > 0.05 * deepest) samples.push_back({t, tool});
  }
  if (samples.empty())
    throw cases::InputError(path_name + ": the tool touches the surface only in passing (at " +
                            std::to_string(first) + " s and " + std::to_string(last) +
                            " s), never at the times the FEM is compared; replay a path that "
                            "presses");
  return samples;
}

VariantAlongPath measure_along_path(
    HapticReplay replay, const std::vector<PathSample>& samples,
    const std::vector<LoadReference>& references,
    const std::vector<std::optional<Eigen::Vector3d>>& static_forces) {
  VariantAlongPath v;
  double fem_squares = 0, squares = 0, static_squares = 0;
  bool all_static = true;
  for (std::size_t k = 0; k < samples.size(); ++k) {
    PathForceError e;
    e.t_s = samples[k].t_s;
    e.fem_force = references[k].fem.tool_force;
    e.fem_force_rel_error = references[k].fem_error.force_rel_error;
    e.static_force = static_forces[k];
    int ticks = 0;
    for (const HapticTick& tick : replay.trace)
      if (std::abs(tick.t_s - e.t_s) <= 0.5 * force_window_s) {
        e.haptic_force += tick.force;
        ++ticks;
      }
    if (ticks > 0) {
      e.haptic_force /= ticks;
    } else if (!replay.trace.empty()) {  // ticks sparser than the window: the nearest one
      e.haptic_force = std::min_element(replay.trace.begin(), replay.trace.end(),
                                        [&](const HapticTick& a, const HapticTick& b) {
                                          return std::abs(a.t_s - e.t_s) < std::abs(b.t_s - e.t_s);
                                        })
                           ->force;
    }
    const double error = (e.haptic_force - e.fem_force).norm();
    squares += error * error;
    if (e.static_force) static_squares += (*e.static_force - e.fem_force).squaredNorm();
    all_static = all_static && e.static_force;
    fem_squares += e.fem_force.squaredNorm();
    v.max_error_n = std::max(v.max_error_n, error);
    v.samples.push_back(e);
  }
  const double n = std::max<std::size_t>(samples.size(), 1);
  v.rms_error_n = std::sqrt(squares / n);
  if (all_static) v.static_rms_error_n = std::sqrt(static_squares / n);
  v.relative_error = fem_squares > 0 ? std::sqrt(squares / fem_squares) : 0.0;
  v.replay = std::move(replay);
  return v;
}

}  // namespace msfem::compare
