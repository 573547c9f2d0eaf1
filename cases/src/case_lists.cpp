// The list-valued keys whose entries carry their own syntax, parsed and checked entry by entry so
// that an error names the entry at fault.
#include "case_lists.hpp"

#include <algorithm>

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <set>
#include <sstream>

#include "msfem/cases/errors.hpp"
#include "msfem/cases/setting_names.hpp"
#include "msfem/cases/text.hpp"

namespace msfem::cases {
namespace {

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

// NAME=FILE[,FILE...] entries separated by ';' under `key`; a name is letters, digits and '_',
// not a built-in variant's and not one of `taken`.
std::vector<std::pair<std::string, std::vector<std::string>>> parse_named_files(
    const std::string& text, const std::string& key, std::set<std::string> taken) {
  std::vector<std::pair<std::string, std::vector<std::string>>> entries;
  std::istringstream in(text);
  for (std::string entry; std::getline(in, entry, ';');) {
    entry = trimmed(entry);
    if (entry.empty()) continue;
    const auto eq = entry.find('=');
    const std::string name = eq == std::string::npos ? "" : trimmed(entry.substr(0, eq));
    std::vector<std::string> files;
    if (eq != std::string::npos) {
      std::istringstream list(entry.substr(eq + 1));
      for (std::string file; std::getline(list, file, ',');)
        files.push_back(trimmed(file));
    }
    if (!is_name(name) || files.empty() ||
        std::any_of(files.begin(), files.end(), [](const auto& f) { return f.empty(); }))
      throw InputError(key + ": '" + entry +
                       "' is not NAME=FILE (NAME of letters, digits and '_')");
    for (const auto& builtin : names_of(Variant{}).entries)
      if (name == builtin.name)
        throw InputError(key + ": '" + name +
                         "' is a built-in variant's name; give it another name");
    if (!taken.insert(name).second)
      throw InputError(key + ": the name '" + name + "' is given twice");
    entries.emplace_back(name, files);
  }
  return entries;
}

std::vector<MassSpringParameters::Network> parse_networks(const std::string& text) {
  std::vector<MassSpringParameters::Network> networks;
  for (const auto& [name, files] : parse_named_files(text, "mass spring/networks", {})) {
    if (files.size() != 1)
      throw InputError("mass spring/networks: " + name + " names " + std::to_string(files.size()) +
                       " files; a network is one file");
    networks.push_back({name, files.front()});
  }
  return networks;
}

std::vector<MassSpringParameters::Result> parse_results(
    const std::string& text, const std::vector<MassSpringParameters::Network>& networks) {
  std::set<std::string> taken;
  for (const auto& n : networks)
    taken.insert(n.name);
  std::vector<MassSpringParameters::Result> results;
  for (const auto& [name, files] : parse_named_files(text, "mass spring/results", taken))
    results.push_back({name, {files.begin(), files.end()}});
  return results;
}

}  // namespace msfem::cases
