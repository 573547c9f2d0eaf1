#include "msfem/massspring_bench/benchmark_cases.hpp"

#include "msfem/massspring/mass_spring_model.hpp"
#include "msfem/massspring/volume_force_field.hpp"

#include <cmath>
#include <map>
#include <utility>

#include "msfem/massspring/errors.hpp"
#include "msfem/massspring/modal_damping.hpp"
#include "msfem/massspring/topology_builders.hpp"

namespace msfem::massspring {

void geodesic_sphere(int frequency, double radius, Eigen::MatrixX3d& vertices,
                     Eigen::MatrixX3i& triangles) {
  if (frequency < 1)
    throw ModelError("geodesic sphere: frequency " + std::to_string(frequency) + " must be >= 1");
  const int m = frequency;
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> points = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                                         {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                                         {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  const int faces[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                            {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                            {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                            {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  // Points along each icosahedron edge are made once, from the lower corner id, so that the two
  // faces sharing the edge use the same vertices.
  std::map<std::pair<int, int>, std::vector<int>> edge_points;
  auto edge_point = [&](int from, int to, int k) {  // k-th of m steps from `from` to `to`
    if (k == 0) return from;
    if (k == m) return to;
    const int lo = std::min(from, to), hi = std::max(from, to);
    auto [it, inserted] = edge_points.try_emplace({lo, hi});
    if (inserted)
      for (int j = 1; j < m; ++j) {
        points.push_back(points[lo] + (points[hi] - points[lo]) * (static_cast<double>(j) / m));
        it->second.push_back(static_cast<int>(points.size()) - 1);
      }
    return it->second[(from == lo ? k : m - k) - 1];
  };
  std::vector<Eigen::Vector3i> triangle_list;
  for (const auto& face : faces) {
    const int a = face[0], b = face[1], c = face[2];
    // Grid id(i, j) = A + i/m (B - A) + j/m (C - A), i + j <= m.
    std::vector<std::vector<int>> id(m + 1, std::vector<int>(m + 1, -1));
    for (int i = 0; i <= m; ++i)
      for (int j = 0; i + j <= m; ++j) {
        if (j == 0)
          id[i][j] = edge_point(a, b, i);
        else if (i == 0)
          id[i][j] = edge_point(a, c, j);
        else if (i + j == m)
          id[i][j] = edge_point(b, c, j);
        else {
          points.push_back(points[a] + (points[b] - points[a]) * (static_cast<double>(i) / m) +
                           (points[c] - points[a]) * (static_cast<double>(j) / m));
          id[i][j] = static_cast<int>(points.size()) - 1;
        }
      }
    for (int i = 0; i < m; ++i)
      for (int j = 0; i + j < m; ++j) {
        triangle_list.emplace_back(id[i][j], id[i + 1][j], id[i][j + 1]);
        if (i + j < m - 1) triangle_list.emplace_back(id[i + 1][j], id[i + 1][j + 1], id[i][j + 1]);
      }
  }
  vertices.resize(static_cast<Eigen::Index>(points.size()), 3);
  for (std::size_t p = 0; p < points.size(); ++p)
    vertices.row(p) = radius * points[p].normalized().transpose();
  triangles.resize(static_cast<Eigen::Index>(triangle_list.size()), 3);
  for (std::size_t f = 0; f < triangle_list.size(); ++f)
    triangles.row(f) = triangle_list[f].transpose();
}

namespace {

// The three tiers as msfem run builds them by default: each spring's damper at half of critical
// for its two end masses (mass spring/damping ratio = 0.5), so that the bench streams the
// per-spring damping a simulator running a case streams.
SpringNetwork brain_three_tier(const Eigen::MatrixX3d& vertices,
                               const Eigen::MatrixX3i& triangles) {
  ThreeTierOptions options;
  options.material.youngs_modulus = 3000.0;
  options.material.density = 1040.0;
  SpringNetwork network = build_three_tier(vertices, triangles, options);
  network.damping = damping_for_ratio(network, 0.5);
  return network;
}

}  // namespace

std::vector<BenchmarkCase> benchmark_cases(const std::optional<Eigen::MatrixX3d>& brain_vertices,
                                           const std::optional<Eigen::MatrixX3i>& brain_triangles,
                                           bool include_10x) {
  std::vector<BenchmarkCase> cases;
  Eigen::MatrixX3d v;
  Eigen::MatrixX3i f;
  geodesic_sphere(8, 0.05, v, f);
  cases.push_back(
      {"seed_sphere", "icosphere level 3 (642 vertices), R = 5 cm", brain_three_tier(v, f)});
  if (brain_vertices && brain_triangles) {
    cases.push_back({"brain_scale",
                     "brain surface, " + std::to_string(brain_vertices->rows()) + " vertices",
                     brain_three_tier(*brain_vertices, *brain_triangles)});
  } else {
    geodesic_sphere(30, 0.07, v, f);
    cases.push_back(
        {"brain_scale",
         "geodesic sphere m = 30 (9,002 vertices, stands in for the 9,177-vertex brain)",
         brain_three_tier(v, f)});
  }
  cases.push_back(cases[1]);
  cases.back().name = "brain_scale_volume";
  cases.back().description += ", volume preservation on the shell prisms";
  cases.back().volume_preservation = true;
  if (include_10x) {
    geodesic_sphere(96, 0.08, v, f);
    cases.push_back(
        {"brain_10x", "geodesic sphere m = 96 (92,162 vertices)", brain_three_tier(v, f)});
  }
  return cases;
}

std::unique_ptr<MassSpringModel> benchmark_model(const BenchmarkCase& benchmark_case,
                                                 std::string* note) {
  if (benchmark_case.model) return std::make_unique<MassSpringModel>(*benchmark_case.model);
  auto model = std::make_unique<MassSpringModel>(benchmark_case.network);
  if (benchmark_case.volume_preservation) {
    const SpringNetwork& n = benchmark_case.network;
    const int per_tier = n.num_nodes() / 3;
    VolumeElements elements = tier_prisms(n.rest_positions, n.surface_triangles, per_tier, 3,
                                          volume_modulus_for(3000.0, 0.45));
    const int all = elements.num_elements();
    const int removed = remove_degenerate_elements(elements, n.rest_positions, 1e-3);
    model->set_volume(VolumeForceField(model->num_nodes(), std::move(elements)));
    if (note)
      *note = std::to_string(all - removed) + " volume elements (" + std::to_string(removed) +
              " inverted or flat at rest left out)";
  }
  return model;
}

SteppingBenchmarkResult run_benchmark_case(const BenchmarkCase& benchmark_case,
                                           const SteppingBenchmarkOptions& options) {
  SteppingBenchmarkOptions case_options = options;
  const auto take = [](double& step, double given) {
    if (given > 0) step = given;
  };
  take(case_options.timed_dt.symplectic_euler, benchmark_case.timed_dt.symplectic_euler);
  take(case_options.timed_dt.explicit_euler, benchmark_case.timed_dt.explicit_euler);
  take(case_options.timed_dt.rk4, benchmark_case.timed_dt.rk4);
  if (benchmark_case.model) return run_stepping_benchmark(*benchmark_case.model, case_options);
  std::string note;
  const std::unique_ptr<MassSpringModel> model = benchmark_model(benchmark_case, &note);
  SteppingBenchmarkResult result = run_stepping_benchmark(*model, case_options);
  if (!note.empty()) result.notes.push_back(note);
  return result;
}

}  // namespace msfem::massspring
