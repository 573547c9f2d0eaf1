#include "msfem/compare/pipeline/warning.hpp"

namespace msfem::compare {

std::string Warning::written() const {
  if (!load || *load == 0) return text;
  return "at tool " + std::to_string(*load) + ": " + text;
}

std::vector<std::string> written(const std::vector<Warning>& warnings) {
  std::vector<std::string> all;
  all.reserve(warnings.size());
  for (const Warning& w : warnings)
    all.push_back(w.written());
  return all;
}

}  // namespace msfem::compare
