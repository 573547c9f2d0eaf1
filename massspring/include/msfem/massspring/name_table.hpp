#pragma once
// One list of an enumeration's names. A case file's Selection pattern, the case and command-line
// parsers, and the names written into results all read the same table, so a value one of them
// accepts is a value the others know (a name list kept by hand in each drifts apart).

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace msfem::massspring {

template <typename Enum>
struct NamedValue {
  Enum value;
  const char* name;
};

/// The first entry of a value gives its name; further entries of the same value are aliases that
/// parse to it (a case file's `prescribed` for `bonded`).
template <typename Enum, std::size_t N>
struct NameTable {
  std::array<NamedValue<Enum>, N> entries;

  const char* name(Enum value) const {
    for (const auto& e : entries)
      if (e.value == value) return e.name;
    return "?";  // unreachable for a value of the enumeration
  }

  std::optional<Enum> find(std::string_view name) const {
    for (const auto& e : entries)
      if (name == e.name) return e.value;
    return std::nullopt;
  }

  /// Every accepted name, aliases included, joined by `separator` ("|" is deal.II's Selection).
  std::string names(std::string_view separator) const {
    std::string joined;
    for (const auto& e : entries)
      joined.append(joined.empty() ? "" : separator).append(e.name);
    return joined;
  }

  /// Each value once, in table order.
  std::vector<Enum> values() const {
    std::vector<Enum> distinct;
    for (const auto& e : entries)
      if (name(e.value) == e.name) distinct.push_back(e.value);  // its first entry, not an alias
    return distinct;
  }
};

}  // namespace msfem::massspring
