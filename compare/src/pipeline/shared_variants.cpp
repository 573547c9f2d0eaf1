// The spring variants of a run shared across MPI ranks. The unit of work is one variant at one
// load (its statics along the loading path), dealt round-robin: with the brain's four variants at
// four tool positions each rank presses every variant at half the positions, so the ranks finish
// together whatever the variants cost. Each rank builds a variant once for its loads. The timing
// (steps per second) runs afterwards on one rank at a time, the others asleep in a barrier, so
// that no rank competes for the timed rank's core.
#include <exception>
#include <optional>

#include "msfem/cases/errors.hpp"
#include "msfem/cases/setting_names.hpp"
#include "msfem/compare/pipeline/ranks.hpp"
#include "variant_share.hpp"

namespace msfem::compare::detail {
namespace {

// Variant v's load k is pressed on this rank; offset by the variant so that the first loads (each
// carrying its variant's timing) fall on different ranks.
bool mine(int variant, std::size_t load) {
  return (static_cast<std::size_t>(variant) + load) % static_cast<std::size_t>(ranks::count()) ==
         static_cast<std::size_t>(ranks::index());
}

struct Pending {
  std::optional<BuiltVariant> built;  // kept for the timing where this rank pressed load 0
  VariantShare share;
};

// This rank's loads of variant v, in increasing order; a solver's failure ends the variant here.
// The built variant is kept where it is to be timed.
Pending press_share(const CaseRun& run, int v, const std::vector<double>& path, bool timed) {
  const cases::Variant kind = run.problem.parameters.mass_spring.variants[v];
  Pending p;
  p.built = build_variant(kind, run.problem, run.mesh, run.loads.front().tool);
  VariantShare& s = p.share;
  s.variant = v;
  s.result = variant_header(*p.built);
  s.tetrahedra = p.built->tetrahedra.rows();
  for (std::size_t k = 0; k < run.loads.size(); ++k) {
    if (!mine(v, k)) continue;
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
  const auto& variants = run.problem.parameters.mass_spring.variants;
  const int total = static_cast<int>(variants.size());
  try {
    for (int v = 0; v < total; ++v) {
      bool any = false;
      for (std::size_t k = 0; k < run.loads.size(); ++k)
        any = any || mine(v, k);
      if (any) pending.push_back(press_share(run, v, path, settings.time_dynamics));
      progress.advance("variant " + cases::name_of(variants[v]) + " (this rank's loads)", v + 1,
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
  const auto& variants = run.problem.parameters.mass_spring.variants;
  Assembly all(variants.size(), run.loads.size());
  for (const std::string& bytes : ranks::gather_on_all(to_bytes(std::move(own))))
    for (VariantShare& share : shares_from_bytes(bytes))
      all.add(share);
  for (std::size_t v = 0; v < variants.size(); ++v) {
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
