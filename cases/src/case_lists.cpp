// The list-valued keys whose entries carry their own syntax, parsed and checked entry by entry so
// that an error names the entry at fault.
#include "case_lists.hpp"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <set>
#include <sstream>

#include "msfem/cases/errors.hpp"
#include "msfem/cases/setting_names.hpp"

namespace msfem::cases {
namespace {

std::string trimmed(const std::string& text) {
  const auto first = text.find_first_not_of(" \t");
  if (first == std::string::npos) return "";
  return text.substr(first, text.find_last_not_of(" \t") - first + 1);
}

bool is_name(const std::string& name) {
  if (name.empty()) return false;
  for (const char c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_') return false;
  return true;
}

}  // namespace

std::vector<std::pair<std::string, double>> parse_group_scales(
    const std::vector<std::string>& list) {
  std::vector<std::pair<std::string, double>> scales;
  for (const auto& entry : list) {
    const auto colon = entry.find(':');
    char* end = nullptr;
    const double factor =
        colon == std::string::npos ? 0.0 : std::strtod(entry.c_str() + colon + 1, &end);
    if (colon == std::string::npos || !end || *end != '\0' || !(factor > 0) ||
        !std::isfinite(factor))
      throw InputError("mass spring/group scales: '" + entry +
                       "' is not GROUP:FACTOR with a positive factor");
    scales.emplace_back(entry.substr(0, colon), factor);
  }
  return scales;
}

std::vector<MassSpringParameters::Network> parse_networks(const std::string& text) {
  std::vector<MassSpringParameters::Network> networks;
  std::set<std::string> names;
  std::istringstream in(text);
  for (std::string entry; std::getline(in, entry, ';');) {
    entry = trimmed(entry);
    if (entry.empty()) continue;
    const auto eq = entry.find('=');
    const std::string name = eq == std::string::npos ? "" : trimmed(entry.substr(0, eq));
    const std::string file = eq == std::string::npos ? "" : trimmed(entry.substr(eq + 1));
    if (!is_name(name) || file.empty())
      throw InputError("mass spring/networks: '" + entry +
                       "' is not NAME=FILE (NAME of letters, digits and '_')");
    for (const auto& builtin : names_of(Variant{}).entries)
      if (name == builtin.name)
        throw InputError("mass spring/networks: '" + name +
                         "' is a built-in variant's name; name the network otherwise");
    if (!names.insert(name).second)
      throw InputError("mass spring/networks: the name '" + name + "' is given twice");
    networks.push_back({name, file});
  }
  return networks;
}

}  // namespace msfem::cases
