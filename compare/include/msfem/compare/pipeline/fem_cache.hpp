#pragma once
// The FEM reference depends only on the geometry, material, supports, loads and FEM settings, not
// on the springs: runs that change spring parameters reuse it. Entries are keyed by a hash of
// everything the FEM depends on and stored as CBOR files under <output directory>/.fem-cache/.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "msfem/compare/pipeline/case_run.hpp"

namespace msfem::compare {

/// What a run needs of the FEM.
struct FemCacheEntry {
  fem_reference::VolumeMesh mesh;
  FemSolution solution;
  std::vector<ForceDepthPoint> force_depth;
  /// The problem's second and later tools at full depth (surface displacement, force, statistics).
  std::vector<FemSolution> other_tools;
  FemErrorEstimate error_estimate;  ///< the reference's own error (fem/error estimate)
};

/// 16 hex digits of a 64-bit FNV-1a hash of the problem's FEM inputs and the curve depths, and
/// whether the entry holds the other tools' solutions too.
std::string fem_cache_key(const Problem& problem, const std::vector<double>& curve_depths,
                          bool other_tools = false);

/// The entry for `key` under `directory`, or none (missing or unreadable: a stale or damaged
/// entry is recomputed, never trusted).
std::optional<FemCacheEntry> load_fem_cache(const std::filesystem::path& directory,
                                            const std::string& key);

/// Stores an entry (atomically).
void store_fem_cache(const std::filesystem::path& directory, const std::string& key,
                     const FemCacheEntry& entry);

}  // namespace msfem::compare
