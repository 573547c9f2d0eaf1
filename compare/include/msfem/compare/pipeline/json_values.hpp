#pragma once
// How every msfem JSON file spells a value that may be absent: null, never a zero that reads as a
// measurement.

#include <nlohmann/json.hpp>
#include <optional>

namespace msfem::compare {

template <class T>
nlohmann::json json_or_null(const std::optional<T>& value) {
  return value ? nlohmann::json(*value) : nlohmann::json();
}

}  // namespace msfem::compare
