#include "msfem/compare/pipeline/sweep.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <sstream>
#include <thread>
#include <tuple>

#include "msfem/cases/setting_names.hpp"
#include "msfem/cases/surface_generators.hpp"
#include "msfem/cases/surface_io.hpp"
#include "msfem/compare/pipeline/case_run.hpp"
#include "msfem/compare/pipeline/ranks.hpp"
#include "pipeline/byte_packing.hpp"

namespace msfem::compare {

std::string SweepPoint::model_name(const std::string& variant, bool volume_preservation,
                                   std::optional<double> contact_edge_m) {
  std::string name = volume_preservation ? variant + "+volume" : variant;
  if (contact_edge_m) {
    char edge[48];
    std::snprintf(edge, sizeof edge, "+refined@%.3gmm", *contact_edge_m * 1e3);
    name += edge;
  }
  return name;
}

namespace {

std::vector<int> default_resolutions(const cases::CaseParameters& p) {
  if (cases::is_surface_generator(p.geometry.source)) return {2, 3, 4, 5};
  std::vector<std::string> notes;
  const int available = static_cast<int>(source_surface(p, notes).num_vertices());
  std::vector<int> r;
  for (int n : {2000, 5000, 9177, 20000, 40000})
    if (n < 0.95 * available) r.push_back(n);  // not a near-copy of the surface as read
  r.push_back(available);
  return r;
}

// The case at one resolution: the icosphere level replaced, or the simplification target set.
cases::CaseParameters at_resolution(cases::CaseParameters p, int resolution) {
  if (cases::is_surface_generator(p.geometry.source)) {
    const auto first = p.geometry.source.find(':');
    const auto second = p.geometry.source.find(':', first + 1);
    p.geometry.source = p.geometry.source.substr(0, first + 1) + std::to_string(resolution) +
                        (second == std::string::npos ? "" : p.geometry.source.substr(second));
  } else {
    p.geometry.simplify_to_vertices = resolution;
  }
  return p;
}

// Variant `v` of the run with one integrator, timed at half that integrator's stable step.
SweepPoint timed_point(const CaseRun& run, const VariantResult& v, const BuiltVariant& built,
                       massspring::IntegratorKind integrator, bool single_precision,
                       int resolution) {
  const LoadReference& load = run.loads.front();
  const ToolLoadVariant& at_load = v.loads.front();
  cases::TimingParameters timing = run.problem.parameters.timing;
  timing.integrator = integrator;
  timing.dt_s = 0.0;  // each integrator at half its own stable step
  timing.single_precision = single_precision;
  // From run_case's equilibrium, reached from rest as here.
  // Under mpirun the ranks on a machine time one item each at the same time: each takes its share
  // of the cores, so that no timed thread waits on a barrier for a thread that has no core.
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const int threads = std::max(1, cores / ranks::on_this_machine());
  const Timing t =
      time_variant(built, timing, at_load.equilibrium, /*measure_settling=*/false, threads);
  SweepPoint pt;
  pt.variant = v.name;
  pt.integrator = massspring::to_string(integrator);
  pt.stepper = t.stepper;
  pt.precision = t.precision;
  pt.volume_preservation = v.parameters.volume_preservation.has_value();
  if (run.problem.local_refinement) pt.contact_edge_m = run.problem.local_refinement->edge_m;
  pt.resolution = resolution;
  pt.surface_vertices = static_cast<int>(run.problem.surface.num_vertices());
  pt.nodes = v.nodes;
  pt.springs = v.springs;
  pt.rel_l2_error = at_load.displacement.all.rel_l2_error;
  pt.reaction_force_rel_error = at_load.reaction_force_rel_error;
  pt.stable_dt_s = t.stable_dt_s;
  pt.steps_per_second = t.steps_per_second;
  pt.realtime_factor = t.realtime_factor;
  pt.dt_s = t.dt_s;
  pt.ms_per_60hz_frame = t.ms_per_60hz_frame;
  pt.fem_estimated_rel_l2_error = load.fem_error.rel_l2_error;
  pt.fem_estimated_force_rel_error = load.fem_error.force_rel_error;
  pt.not_resolved_by_reference = unresolved_metrics(run, at_load, 0);
  return pt;
}

template <typename Io, typename P>
void point_fields(Io& io, P& p) {  // SweepPoint
  io.io(p.variant), io.io(p.integrator), io.io(p.stepper), io.io(p.precision);
  io.io(p.volume_preservation);
  io.io(p.contact_edge_m), io.io(p.resolution), io.io(p.surface_vertices), io.io(p.nodes);
  io.io(p.springs), io.io(p.rel_l2_error), io.io(p.reaction_force_rel_error);
  io.io(p.stable_dt_s), io.io(p.steps_per_second), io.io(p.realtime_factor), io.io(p.dt_s);
  io.io(p.ms_per_60hz_frame), io.io(p.fem_estimated_rel_l2_error);
  io.io(p.fem_estimated_force_rel_error), io.io(p.not_resolved_by_reference);
}

// Under mpirun each rank timed the items it owns; every rank gets all of them, in item order.
void share_points(std::vector<SweepPoint>& points, const std::vector<bool>& mine) {
  detail::Writer own;
  for (std::size_t j = 0; j < points.size(); ++j)
    if (mine[j]) {
      long long item = static_cast<long long>(j);
      own.io(item);
      point_fields(own, points[j]);
    }
  for (const std::string& part : ranks::gather_on_all(own.p.bytes())) {
    detail::Reader from{detail::Unpacker(part)};
    while (!from.u.done()) {
      long long item = 0;
      from.io(item);
      point_fields(from, points.at(static_cast<std::size_t>(item)));
    }
  }
}

// Which rank times each (variant, integrator) item. A timing costs about the model's nodes times
// its integrator's price per step (on the fast kernels, in contact, implicit Euler's warm-started
// CG step some 3-9 symplectic steps on the sphere, RK4's four force passes 4-9).
// One timing of a sweep: a variant of the run, an integrator and the arithmetic.
struct SweepItem {
  std::size_t variant;
  massspring::IntegratorKind integrator;
  bool single_precision;
};

std::vector<int> owners(const CaseRun& run, const std::vector<SweepItem>& items) {
  std::vector<double> cost(items.size());
  for (std::size_t j = 0; j < items.size(); ++j) {
    const massspring::IntegratorKind k = items[j].integrator;
    const double price = k == massspring::IntegratorKind::implicit_euler ? 6.0
                         : k == massspring::IntegratorKind::rk4          ? 6.0
                                                                         : 1.0;
    cost[j] = price * run.variants[items[j].variant].nodes;
  }
  return ranks::deal(cost);
}

// The resolution the case has as written: its icosphere level, its simplification target, or its
// surface's vertex count.
SweepResult::OwnResolution own_resolution(const cases::CaseParameters& p) {
  SweepResult::OwnResolution own;
  const std::string& source = p.geometry.source;
  if (cases::is_surface_generator(source)) {
    const auto first = source.find(':');
    own.resolution = std::stoi(source.substr(first + 1));
  } else if (p.geometry.simplify_to_vertices > 0) {
    own.resolution = p.geometry.simplify_to_vertices;
  } else {
    std::vector<std::string> notes;
    own.resolution = static_cast<int>(source_surface(p, notes).num_vertices());
  }
  std::string names;
  for (const auto& n : p.mass_spring.networks)
    own.networks.push_back(n.name);
  for (const auto& name : own.networks)
    names += (names.empty() ? "" : ", ") + name;
  own.note = "networks " + names + " swept at the case's own resolution " +
             std::to_string(own.resolution) +
             " only: msfem cannot re-mesh a user's network, nor refine it at the tool";
  return own;
}

// One pass's settings beside the resolution: volume preservation and contact refinement.
struct SweepPass {
  bool volume = false;
  std::optional<double> contact_edge_m;  ///< none: refinement off; 0: the case's edge length
};

// One resolution's points with volume preservation as `volume`: every variant that has the
// setting's model with every integrator (a variant without volume elements is left out of the
// volume-preserving pass: it would repeat the other's points). The FEM comes from the cache after
// the first pass. Under mpirun the (variant, integrator) items are dealt out (owners) and timed at
// the same time, one per rank: each timing is single-threaded on its rank's own core.
std::vector<SweepPoint> sweep_resolution(cases::CaseParameters p, int resolution,
                                         const SweepSettings& settings, const SweepPass& pass,
                                         const std::filesystem::path& fem_cache_directory,
                                         std::vector<SweepResult::FailedVariant>& failed) {
  const bool volume = pass.volume;
  p.mass_spring.volume_preservation = volume;
  if (!settings.contact_refinement.empty()) {
    p.mass_spring.contact_refinement.enabled = pass.contact_edge_m.has_value();
    if (pass.contact_edge_m && *pass.contact_edge_m > 0)
      p.mass_spring.contact_refinement.edge_m = *pass.contact_edge_m;
  }
  RunSettings run_settings;
  run_settings.quiet = true;
  run_settings.force_depth_curve = false;
  run_settings.time_dynamics = false;
  run_settings.all_tools = false;  // accuracy against speed at the case's first tool
  run_settings.fem_cache_directory = fem_cache_directory;
  const CaseRun run = run_case(p, run_settings);
  std::optional<double> edge;
  if (run.problem.local_refinement) edge = run.problem.local_refinement->edge_m;
  for (const auto& [name, why] : run.failed_variants)
    failed.push_back({resolution, SweepPoint::model_name(name, volume, edge), why});
  const std::vector<bool> precisions = settings.single_precision.empty()
                                           ? std::vector<bool>{p.timing.single_precision}
                                           : settings.single_precision;
  std::vector<SweepItem> items;
  for (std::size_t v = 0; v < run.variants.size(); ++v)
    if (!volume || run.variants[v].parameters.volume_preservation)
      for (const auto& integrator : settings.integrators)
        for (const bool single : precisions)
          items.push_back({v, integrator, single});
  std::vector<SweepPoint> points(items.size());
  std::vector<bool> mine(items.size());
  const std::vector<int> owner = owners(run, items);
  for (std::size_t j = 0; j < items.size(); ++j)
    mine[j] = owner[j] == ranks::index();
  ranks::agree([&] {
    std::optional<std::pair<std::size_t, BuiltVariant>> built;  // the last variant built here
    for (std::size_t j = 0; j < items.size(); ++j) {
      if (!mine[j]) continue;
      const VariantResult& v = run.variants[items[j].variant];
      if (!built || built->first != items[j].variant)
        built.emplace(items[j].variant,
                      build_variant(v.spec, run.problem, run.mesh, run.loads.front().tool));
      points[j] = timed_point(run, v, built->second, items[j].integrator, items[j].single_precision,
                              resolution);
    }
  });
  if (ranks::count() > 1) share_points(points, mine);
  return points;
}

}  // namespace

SweepResult run_sweep(const cases::CaseParameters& parameters, const SweepSettings& settings,
                      const std::filesystem::path& fem_cache_directory) {
  const std::vector<int> resolutions =
      settings.resolutions.empty() ? default_resolutions(parameters) : settings.resolutions;
  const std::vector<bool> volume_settings =
      settings.volume_preservation.empty()
          ? std::vector<bool>{parameters.mass_spring.volume_preservation}
          : settings.volume_preservation;
  const std::vector<std::optional<double>> refinement_settings =
      settings.contact_refinement.empty() ? std::vector<std::optional<double>>{std::nullopt}
                                          : settings.contact_refinement;
  std::vector<SweepPass> passes;
  for (const bool volume : volume_settings)
    for (const auto& edge : refinement_settings)
      passes.push_back({volume, edge});
  const Progress progress(settings.quiet);
  const auto start = std::chrono::steady_clock::now();
  SweepResult result;
  std::vector<SweepPoint>& points = result.points;
  std::exception_ptr first_failure;
  // The built-in variants at every resolution, then the networks at the case's own.
  cases::CaseParameters builtin = parameters;
  builtin.mass_spring.networks.clear();
  builtin.mass_spring.results.clear();
  std::vector<std::pair<int, cases::CaseParameters>> sweeps;
  if (!builtin.mass_spring.variants.empty())
    for (const int resolution : resolutions)
      sweeps.emplace_back(resolution, at_resolution(builtin, resolution));
  if (!parameters.mass_spring.networks.empty()) {
    cases::CaseParameters networks = parameters;
    networks.mass_spring.variants.clear();
    networks.mass_spring.results.clear();
    result.networks = own_resolution(parameters);
    sweeps.emplace_back(result.networks->resolution, networks);
    progress.stage(result.networks->note);
  }
  if (!parameters.mass_spring.results.empty())
    progress.stage(
        "mass spring/results are not swept: an outside answer has one resolution and "
        "no speed msfem can measure (msfem run compares it)");
  for (std::size_t r = 0; r < sweeps.size(); ++r) {
    const bool of_networks = sweeps[r].second.mass_spring.variants.empty();
    try {
      // All of a resolution's points or none of them.
      std::vector<SweepPoint> more;
      std::vector<SweepResult::FailedVariant> failed;
      for (const SweepPass& pass : of_networks ? std::vector<SweepPass>{{}} : passes) {
        const std::vector<SweepPoint> swept = sweep_resolution(
            sweeps[r].second, sweeps[r].first, settings, pass, fem_cache_directory, failed);
        more.insert(more.end(), swept.begin(), swept.end());
      }
      points.insert(points.end(), more.begin(), more.end());
      for (const auto& f : failed)
        progress.stage("sweep resolution " + std::to_string(f.resolution) + ": variant " + f.model +
                       " failed: " + f.error);
      result.failed_variants.insert(result.failed_variants.end(), failed.begin(), failed.end());
    } catch (const std::exception& e) {
      if (!first_failure) first_failure = std::current_exception();
      result.failed_resolutions.emplace_back(sweeps[r].first, e.what());
      progress.stage("sweep resolution " + std::to_string(sweeps[r].first) +
                     " failed: " + e.what());
    }
    progress.advance(
        "sweep resolution " + std::to_string(sweeps[r].first), static_cast<int>(r + 1),
        static_cast<int>(sweeps.size()),
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  // Nothing to show: the first failure as it was (bad input stays bad input).
  if (points.empty() && first_failure) std::rethrow_exception(first_failure);
  return result;
}

std::vector<VariantConvergence> convergence_by_variant(const std::vector<SweepPoint>& points) {
  std::vector<VariantConvergence> result;
  for (const auto& p : points) {
    auto it = std::find_if(result.begin(), result.end(),
                           [&](const VariantConvergence& v) { return v.variant == p.model(); });
    if (it == result.end()) it = result.insert(result.end(), {p.model(), {}, std::nullopt});
    auto& at = it->error_at_vertices;
    if (std::none_of(at.begin(), at.end(),
                     [&](const auto& e) { return e.first == p.surface_vertices; }))
      at.emplace_back(p.surface_vertices, p.rel_l2_error);
  }
  for (auto& v : result) {
    auto& at = v.error_at_vertices;
    std::sort(at.begin(), at.end());
    if (at.size() >= 2 && at.front().second > 0 && at.back().second > 0)
      v.observed_order = -2.0 * std::log(at.back().second / at.front().second) /
                         std::log(double(at.back().first) / double(at.front().first));
  }
  return result;
}

bool keeps_real_time(const SweepPoint& point, double rate_hz) {
  if (!(point.dt_s > 0) || !(point.steps_per_second > 0)) return false;
  const double steps_per_tick = std::ceil(1.0 / (rate_hz * point.dt_s) - 1e-9);
  return point.steps_per_second >= rate_hz * steps_per_tick;
}

}  // namespace msfem::compare
