#pragma once
// What one rank computes of one spring variant when several ranks share a run's variants, and its
// passage as bytes to the other ranks. Private to the pipeline: run_case (case_run.cpp) and the
// shared loop (shared_variants.cpp).

#include <string>
#include <vector>

#include "msfem/compare/pipeline/case_run.hpp"

namespace msfem::compare::detail {

/// One variant as far as one rank took it: every field of `result` but `loads` and `timing` is the
/// variant's own (the same on each rank that built it); `loads[i]` is the run's load
/// `load_indices[i]`; `timing` is meaningful where `timed`.
struct VariantShare {
  int variant = 0;  ///< index in the case's variant list
  VariantResult result;
  std::vector<int> load_indices;
  bool timed = false;
  long long tetrahedra = 0;  ///< the variant's volume elements (its buckling warning counts them)
  /// The first step that failed with a solver's error, in the order one rank would take them
  /// (load 0 = 0, the timing = 1, load k = k + 1); -1 when none did.
  int failure_order = -1;
  std::string failure;
};

/// The shares as bytes (taken by value: the shared field code sizes what it writes as it reads).
std::string to_bytes(std::vector<VariantShare> shares);
std::vector<VariantShare> shares_from_bytes(const std::string& bytes);

// The steps of one variant's run (case_run.cpp), shared by the loop on one rank and on several.

/// The variant pressed along the loading path at one load and measured there.
ToolLoadVariant at_load(const Problem& problem, BuiltVariant& built, const LoadReference& load,
                        const std::vector<double>& path);
/// The warnings a variant's result at `load` raises (buckling under its tool; at the first load,
/// the metrics the reference does not resolve), appended to `r.warnings`.
void warn_at_load(const CaseRun& run, long long tetrahedra, std::size_t load, VariantResult& r);
/// A new result for the built variant: what it is, its parameters and its builder's warnings.
VariantResult variant_header(const BuiltVariant& built);

/// Every variant of the case at every load of `run`, shared across the ranks (ranks::count() > 1)
/// and gathered on every rank: `run.variants` and `run.failed_variants` as one rank would fill
/// them. Timing runs on one rank at a time while the others sleep. Bad input on any rank is thrown
/// on every rank.
void run_variants_across_ranks(CaseRun& run, const std::vector<double>& path,
                               const RunSettings& settings, const Progress& progress);

}  // namespace msfem::compare::detail
