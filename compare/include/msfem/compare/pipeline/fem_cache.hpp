#pragma once
// The FEM reference depends only on the geometry, material, supports, loads and FEM settings, not
// on the springs: runs that change spring parameters reuse it. Entries are keyed by a hash of
// everything the FEM depends on and stored as CBOR files under <output directory>/.fem-cache/.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "msfem/compare/pipeline/fem_references.hpp"

namespace msfem::compare {

/// The FEM at one load.
struct FemCacheEntry {
  fem_reference::VolumeMesh mesh;  ///< the one mesh of every load of the command
  FemSolution solution;
  std::vector<ForceDepthPoint> force_depth;
  /// The reference's own error (fem/error estimate): method and cost, and this load's values.
  FemErrorEstimate error_estimate;
};

/// A hash of everything the FEM reference at `tool` depends on (surface, material, supports, loads,
/// mesh and solver settings): two runs with the same hash solve the same problem.
std::string reference_inputs_hash(const Problem& problem,
                                  const std::vector<ToolPlacement>& refine_near,
                                  const std::optional<ToolPlacement>& tool);

/// 16 hex digits of a 64-bit FNV-1a hash of what the FEM at one load depends on: the problem's FEM
/// inputs, where its mesh is refined, the load's tool and its force-depth curve's depths.
std::string fem_cache_key(const Problem& problem, const std::vector<ToolPlacement>& refine_near,
                          const std::optional<ToolPlacement>& tool,
                          const std::vector<double>& curve_depths);

/// The entry for `key` under `directory`, or none (missing or unreadable: a stale or damaged
/// entry is recomputed, never trusted).
std::optional<FemCacheEntry> load_fem_cache(const std::filesystem::path& directory,
                                            const std::string& key);

/// Stores an entry (atomically).
void store_fem_cache(const std::filesystem::path& directory, const std::string& key,
                     const FemCacheEntry& entry);

}  // namespace msfem::compare
