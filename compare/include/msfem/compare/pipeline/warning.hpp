#pragma once
// A variant's warnings in a run: a kind that code acts on (msfem run repeats the ones under the
// tool on stderr), the load each concerns, its data, and the sentence the reports write.

#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "msfem/compare/pipeline/metrics.hpp"

namespace msfem::compare {

struct Warning {
  enum class Kind {
    network,                     ///< from the network's builder (an inner tier outside the surface)
    degenerate_volume_elements,  ///< volume elements inverted or flat at rest, left out
    file_setting_not_applied,    ///< a network file's scene value (grav, visc) the case overrides
    buckling,                    ///< gives way under the tool along its loading path
    lost_tool,                   ///< no force on the tool where the FEM pushes back
    no_tool_force,               ///< an outside simulator's answer without the tool's force
    unresolved_metrics,          ///< metrics within 3x of the reference's own estimated error
  };
  Warning() = default;
  Warning(Kind kind, std::string text, std::optional<std::size_t> load = std::nullopt,
          std::vector<Metric> metrics = {})
      : kind(kind), text(std::move(text)), load(load), metrics(std::move(metrics)) {}

  Kind kind = Kind::network;
  std::string text;                 ///< the sentence, without the load it concerns
  std::optional<std::size_t> load;  ///< the tool position it concerns (none: the variant as built)
  std::vector<Metric> metrics;      ///< unresolved_metrics: which ones

  /// A variant that buckles or loses the tool gives no answer there (msfem run says so on stderr).
  bool under_tool() const { return kind == Kind::buckling || kind == Kind::lost_tool; }
  /// What the reports write: the text, after "at tool k: " for every tool but the first.
  std::string written() const;
};

/// Every warning as the reports write it (Warning::written), in order.
std::vector<std::string> written(const std::vector<Warning>& warnings);

}  // namespace msfem::compare
