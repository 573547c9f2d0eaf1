// The spring variants of a run shared across MPI ranks. The unit of work is one variant at one
// load (its statics along the loading path), dealt by estimated cost (ranks::deal): the three
// tiers have three times the nodes of one surface, and at one load (a sweep's resolution) dealing
// round-robin would give the three tiers and the skeleton to one rank and the single layer alone
// to the other. Each rank builds a variant once for its loads. The timing
// (steps per second) runs afterwards on one rank at a time, the others asleep in a barrier, so
// that no rank competes for the timed rank's core.
#include <algorithm>
#include <cmath>
#include <exception>
#include <optional>

#include "msfem/cases/errors.hpp"
#include "msfem/cases/setting_names.hpp"
#include "msfem/compare/pipeline/ranks.hpp"
#include "pipeline/builtin_variants.hpp"
#include "variant_share.hpp"

namespace msfem::compare::detail {
namespace {

// The nodes a variant will have, before it is built: the statics' cost grows with them (sparse
// Cholesky, about the 1.5th power in a volume).
double estimated_nodes(const CaseRun& run, const VariantSpec& spec) {
  // A user's network is not read before it is built: as many nodes as the three tiers, most.
  if (!spec.builtin) return 3.0 * static_cast<double>(run.problem.surface.num_vertices());
  return builtin_variant(*spec.builtin).estimated_nodes(run.problem, run.mesh);
}

// Whether this rank presses variant v at load k: mine[v][k], dealt by cost, alike on every rank.
std::vector<std::vector<bool>> this_ranks_items(const CaseRun& run) {
  const std::vector<VariantSpec> variants = variant_specs(run.problem.parameters);
  std::vector<double> cost;
  for (const VariantSpec& spec : variants)
    for (std::size_t k = 0; k < run.loads.size(); ++k)
      cost.push_back(std::pow(estimated_nodes(run, spec), 1.5));
  const std::vector<int> owner = ranks::deal(cost);
  std::vector<std::vector<bool>> mine(variants.size(), std::vector<bool>(run.loads.size()));
  for (std::size_t v = 0; v < variants.size(); ++v)
    for (std::size_t k = 0; k < run.loads.size(); ++k)
      mine[v][k] = owner[v * run.loads.size() + k] == ranks::index();
  return mine;
}

struct Pending {
  std::optional<BuiltVariant> built;  // kept for the timing where this rank pressed load 0
  VariantShare share;
};

// This rank's loads of variant v, in increasing order; a solver's failure ends the variant here.
// The built variant is kept where it is to be timed.
Pending press_share(const CaseRun& run, int v, const std::vector<bool>& mine,
                    const std::vector<double>& path, bool timed) {
  const VariantSpec spec = variant_specs(run.problem.parameters).at(std::size_t(v));
  Pending p;
  p.built = build_variant(spec, run.problem, run.mesh, run.loads.front().tool);
  VariantShare& s = p.share;
  s.variant = v;
  s.result = variant_header(*p.built);
  s.tetrahedra = p.built->tetrahedra.rows();
  for (std::size_t k = 0; k < run.loads.size(); ++k) {
    if (!mine[k]) continue;
    try {
      s.result.loads.push_back(at_load(run.problem, *p.built, run.loads[k], path));
      s.load_indices.push_back(static_cast<int>(k));
    } catch (const cases::InputError&) {
      throw;
    } catch (const std::runtime_error& e) {
      s.failure_order = k == 0 ? 0 : static_cast<int>(k) + 1;
      s.failure = e.what();
      break;
    }
  }
  if (!timed || s.load_indices.empty() || s.load_indices.front() != 0) p.built.reset();
  return p;
}

// Times the variant from its equilibrium at the first load, the tool put back there.
void time_share(const CaseRun& run, Pending& p) {
  if (!p.built) return;
  VariantShare& s = p.share;
  if (run.loads.front().tool) set_tool_depth(*p.built, *run.loads.front().tool);
  try {
    s.result.timing =
        time_variant(*p.built, run.problem.parameters.timing, s.result.loads.front().equilibrium);
    s.timed = true;
  } catch (const cases::InputError&) {
    throw;
  } catch (const std::runtime_error& e) {
    if (s.failure_order < 0 || s.failure_order > 1) s.failure_order = 1, s.failure = e.what();
  }
  p.built.reset();
}

// This rank's shares. An exception is kept, not thrown, until every rank has passed the timing's
// barriers: a rank leaving early would leave the others waiting there.
std::vector<VariantShare> this_ranks_shares(const CaseRun& run, const std::vector<double>& path,
                                            const RunSettings& settings, const Progress& progress,
                                            std::exception_ptr& error) {
  std::vector<Pending> pending;
  const auto start = Clock::now();
  const std::vector<VariantSpec> variants = variant_specs(run.problem.parameters);
  const int total = static_cast<int>(variants.size());
  const std::vector<std::vector<bool>> mine = this_ranks_items(run);
  try {
    for (int v = 0; v < total; ++v) {
      const std::vector<bool>& loads = mine[static_cast<std::size_t>(v)];
      if (std::find(loads.begin(), loads.end(), true) != loads.end())
        pending.push_back(press_share(run, v, loads, path, settings.time_dynamics));
      progress.advance("variant " + variants[std::size_t(v)].name + " (this rank's loads)", v + 1,
                       total, seconds_since(start));
    }
  } catch (...) {
    error = std::current_exception();
  }
  for (int turn = 0; settings.time_dynamics && turn < ranks::count(); ++turn) {
    ranks::idle_barrier();
    if (turn != ranks::index() || error) continue;
    if (turn == 0) progress.stage("timing the variants, one rank at a time");
    try {
      for (Pending& p : pending)
        time_share(run, p);
    } catch (...) {
      error = std::current_exception();
    }
  }
  std::vector<VariantShare> shares;
  for (Pending& p : pending)
    shares.push_back(std::move(p.share));
  return shares;
}

// The ranks' shares put together, variant by variant.
struct Assembly {
  explicit Assembly(std::size_t variants, std::size_t loads)
      : results(variants),
        built(variants, false),
        tetrahedra(variants, 0),
        failure_order(variants, -1),
        failure(variants),
        loads(loads) {}
  void add(VariantShare& share) {
    const std::size_t v = static_cast<std::size_t>(share.variant);
    if (!built[v]) {
      results[v] = share.result;
      results[v].loads.assign(loads, {});
      tetrahedra[v] = share.tetrahedra;
      built[v] = true;
    }
    if (share.timed) results[v].timing = share.result.timing;
    for (std::size_t i = 0; i < share.load_indices.size(); ++i)
      results[v].loads[share.load_indices[i]] = std::move(share.result.loads[i]);
    // The failure one rank running the variant alone would have met first.
    if (share.failure_order >= 0 &&
        (failure_order[v] < 0 || share.failure_order < failure_order[v])) {
      failure_order[v] = share.failure_order;
      failure[v] = share.failure;
    }
  }
  std::vector<VariantResult> results;
  std::vector<bool> built;
  std::vector<long long> tetrahedra;
  std::vector<int> failure_order;
  std::vector<std::string> failure;
  std::size_t loads;
};

}  // namespace

void run_variants_across_ranks(CaseRun& run, const std::vector<double>& path,
                               const RunSettings& settings, const Progress& progress) {
  progress.stage("the spring variants at " + std::to_string(run.loads.size()) +
                 " load(s), shared across " + std::to_string(ranks::count()) + " ranks");
  std::exception_ptr error;
  std::vector<VariantShare> own = this_ranks_shares(run, path, settings, progress, error);
  ranks::agree([&] {
    if (error) std::rethrow_exception(error);
  });
  const std::size_t variants = variant_specs(run.problem.parameters).size();
  Assembly all(variants, run.loads.size());
  for (const std::string& bytes : ranks::gather_on_all(to_bytes(std::move(own))))
    for (VariantShare& share : shares_from_bytes(bytes))
      all.add(share);
  for (std::size_t v = 0; v < variants; ++v) {
    VariantResult& r = all.results[v];
    if (all.failure_order[v] >= 0) {
      run.failed_variants.emplace_back(r.name, all.failure[v]);
      progress.stage("variant " + r.name + " failed: " + all.failure[v]);
      continue;
    }
    for (std::size_t load = 0; load < r.loads.size(); ++load)
      warn_at_load(run, all.tetrahedra[v], load, r);
    run.variants.push_back(std::move(r));
  }
}

}  // namespace msfem::compare::detail
